//! Actuation by displacement: cables driven by the length a motor pulled in
//! at the base rather than by their tension.
//!
//! A solver answers tensions with a pose whose `displacements_mm` are each
//! cable's Δℓ: its path's shortening from the straight, unloaded rod's plus
//! its own stretch (see [`super::TipPose::displacements_mm`]). For cables
//! given a displacement D_i the tensions are the root of Δ_i(τ) = D_i, with
//! slack: a cable whose commanded length is longer than its path at zero
//! tension (Δ_i(τ_i = 0) ≥ D_i) carries none, τ_i = 0. Δ_i rises with τ_i,
//! so Newton's method on the cables that pull (the Jacobian ∂Δ/∂τ by
//! forward differences of solves, each warm-started from the last) with the
//! tensions projected onto τ ≥ 0 converges; its steps are capped so that
//! the tensions move as a continuation ladder would.
//!
//! Written here rather than taken from a crate: the root-finder is a few
//! lines around the solvers' own warm-started solves, with the slack
//! (complementarity) condition no general solver crate expresses.

use super::TipPose;
use crate::model::cable::MAX_CABLES;

/// Displacement accepted, mm: at a slope dΔ/dτ of a few mm/N this leaves
/// the tension within ~1e-11 N and the shape within ~1e-9 mm.
pub const DISPLACEMENT_TOLERANCE_MM: f64 = 1e-11;
/// Largest tension change of one Newton step, N (the tension ladder's rung).
const MAX_TENSION_STEP_N: f64 = super::ladder::TENSION_RUNG_N;
/// Newton steps before giving up.
const MAX_ITERATIONS: usize = 400;

/// Newton's method did not meet a cable's displacement.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("cable {cable}: its displacement was not met within {iterations} steps (off by {off_mm:.3e} mm at {tension_n:.4} N); the commanded displacement may need more tension than the rod can take: lower it, or give that cable a tension")]
pub struct DisplacementNotMet {
    /// The cable (1-based).
    pub cable: usize,
    /// Its displacement less the commanded one, mm.
    pub off_mm: f64,
    /// Its tension at the last step, N.
    pub tension_n: f64,
    /// Newton steps taken.
    pub iterations: usize,
}

/// Meets each cable's actuation: `displacements_mm[i]` = Some(D) drives cable
/// i to the displacement D (its tension found), None keeps its tension at
/// `tensions_n[i]`. `tensions_n` holds the start (and, for displacement-driven
/// cables, receives the tensions found). Returns the pose of the last solve,
/// which is at the tensions returned.
/// `solve_tensions` is the solver's warm-started solve at given tensions
/// ([`super::Solver::solve_tensions`]); [`super::Solver::solve`] is the
/// entry.
pub(crate) fn meet_displacements<E: From<DisplacementNotMet>>(
    mut solve_tensions: impl FnMut(&[f64]) -> Result<TipPose, E>,
    displacements_mm: &[Option<f64>],
    tensions_n: &mut [f64],
) -> Result<TipPose, E> {
    let n = tensions_n.len();
    assert!(n <= MAX_CABLES && displacements_mm.len() == n);
    let driven: Vec<usize> = (0..n).filter(|&i| displacements_mm[i].is_some()).collect();
    let off = |pose: &TipPose, i: usize| pose.displacements_mm[i] - displacements_mm[i].expect("driven");
    let mut pose = solve_tensions(tensions_n)?;
    if driven.is_empty() {
        return Ok(pose);
    }
    for iteration in 0..MAX_ITERATIONS {
        // The cables that pull: a cable at zero tension whose path already
        // asks for at least its command is slack and stays at zero.
        let active: Vec<usize> = driven.iter().copied().filter(|&i| tensions_n[i] > 0.0 || off(&pose, i) < 0.0).collect();
        let worst = driven
            .iter()
            .map(|&i| if active.contains(&i) { off(&pose, i).abs() } else { (-off(&pose, i)).max(0.0) })
            .fold(0.0, f64::max);
        if worst <= DISPLACEMENT_TOLERANCE_MM {
            return Ok(pose);
        }
        if active.is_empty() {
            return Ok(pose);
        }
        // ∂Δ_i/∂τ_j over the active cables, by forward differences.
        let k = active.len();
        let base: Vec<f64> = tensions_n.to_vec();
        let residual: Vec<f64> = active.iter().map(|&i| off(&pose, i)).collect();
        let mut jacobian = nalgebra::DMatrix::<f64>::zeros(k, k);
        for (col, &j) in active.iter().enumerate() {
            let eps = 1e-6 * (1.0 + base[j]);
            tensions_n.copy_from_slice(&base);
            tensions_n[j] += eps;
            let probe = solve_tensions(tensions_n)?;
            for (row, &i) in active.iter().enumerate() {
                jacobian[(row, col)] = (off(&probe, i) - residual[row]) / eps;
            }
        }
        let rhs = nalgebra::DVector::from_iterator(k, residual.iter().map(|r| -r));
        let step = jacobian.lu().solve(&rhs);
        tensions_n.copy_from_slice(&base);
        let Some(step) = step else {
            let (i, r) = active.iter().zip(&residual).max_by(|a, b| a.1.abs().total_cmp(&b.1.abs())).map(|(&i, &r)| (i, r)).expect("active");
            return Err(DisplacementNotMet { cable: i + 1, off_mm: r, tension_n: base[i], iterations: iteration }.into());
        };
        // Capped like a ladder rung; projected onto τ ≥ 0.
        let largest = step.amax();
        let scale = if largest > MAX_TENSION_STEP_N { MAX_TENSION_STEP_N / largest } else { 1.0 };
        for (row, &i) in active.iter().enumerate() {
            tensions_n[i] = (base[i] + scale * step[row]).max(0.0);
        }
        pose = solve_tensions(tensions_n)?;
    }
    let (i, r) = driven.iter().map(|&i| (i, off(&pose, i))).max_by(|a, b| a.1.abs().total_cmp(&b.1.abs())).expect("driven");
    Err(DisplacementNotMet { cable: i + 1, off_mm: r, tension_n: tensions_n[i], iterations: MAX_ITERATIONS }.into())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Actuation;
    use crate::solver::Solver;
    use crate::solver::result::PerCable;

    /// A toy solver: Δ_i = a_i τ_i + b_i τ_j − c_i (c: the rest state's give).
    struct Toy {
        solves: usize,
    }

    #[derive(Debug)]
    struct ToyError;

    impl From<DisplacementNotMet> for ToyError {
        fn from(_: DisplacementNotMet) -> Self {
            ToyError
        }
    }

    impl Solver for Toy {
        type Error = ToyError;
        fn backend(&self) -> crate::solver::Backend {
            crate::solver::Backend::SpatialCollocation
        }
        fn hold_next(&mut self, _: crate::solver::Hold) {}
        fn centreline(&self) -> Vec<crate::solver::CentrelinePoint> {
            Vec::new()
        }
        fn coefficients(&mut self, order: usize, _: crate::shape::LengthBasis) -> Result<[Vec<f64>; 3], ToyError> {
            Ok(std::array::from_fn(|_| vec![0.0; order + 1]))
        }
        fn solve_tensions(&mut self, t: &[f64]) -> Result<TipPose, ToyError> {
            self.solves += 1;
            let mut d = PerCable::filled(2, 0.0);
            d[0] = 2.0 * t[0] + 0.3 * t[1] - 0.1 + 0.05 * t[0] * t[0];
            d[1] = 1.5 * t[1] + 0.2 * t[0] - 0.1;
            let mut tensions = PerCable::filled(2, 0.0);
            tensions.copy_from_slice(t);
            Ok(TipPose {
                tensions_n: tensions,
                displacements_mm: d,
                tip_x_mm: 0.0,
                tip_y_mm: 0.0,
                tip_z_mm: 0.0,
                tip_angle_rad: 0.0,
                tip_frame_angle_rad: 0.0,
                base_angle_rad: 0.0,
                length_mm: 0.0,
                iterations: 1,
                frame_3d: None,
            })
        }
    }

    #[test]
    fn meets_displacements_and_leaves_a_long_cable_slack() {
        let mut toy = Toy { solves: 0 };
        let mut t = [0.0, 0.0];
        let pose = meet_displacements(|t| toy.solve_tensions(t), &[Some(3.0), Some(0.5)], &mut t).unwrap();
        assert!((pose.displacements_mm[0] - 3.0).abs() < 1e-11 && (pose.displacements_mm[1] - 0.5).abs() < 1e-11, "{:?}", pose.displacements_mm);
        assert!(t[0] > 0.0 && t[1] > 0.0);
        // Cable 2 commanded less than its path needs even at zero tension: slack.
        let mut t = [0.0, 0.0];
        let pose = meet_displacements(|t| toy.solve_tensions(t), &[Some(3.0), Some(0.0)], &mut t).unwrap();
        assert_eq!(t[1], 0.0);
        assert!(pose.displacements_mm[1] >= 0.0 && (pose.displacements_mm[0] - 3.0).abs() < 1e-11);
        // A tension-driven cable keeps its tension.
        let mut t = [0.0, 0.7];
        meet_displacements(|t| toy.solve_tensions(t), &[Some(3.0), None], &mut t).unwrap();
        assert_eq!(t[1], 0.7);
        // The same through the interface's one actuation, and up its ladder.
        let mut t = [0.0, 0.0];
        let pose = toy.solve(&[Actuation::Displacement(3.0), Actuation::Tension(0.7)], &mut t).unwrap();
        assert!((pose.displacements_mm[0] - 3.0).abs() < 1e-11 && t[1] == 0.7, "{t:?}");
        let before = toy.solves;
        let pose = toy.climb(&[Actuation::Displacement(3.0), Actuation::Tension(0.7)], None).unwrap();
        assert!((pose.displacements_mm[0] - 3.0).abs() < 1e-11 && pose.tensions_n[1] == 0.7);
        assert!(toy.solves - before >= crate::solver::ladder::rungs(&[Actuation::Displacement(3.0)]), "one solve per rung at least");
    }
}
