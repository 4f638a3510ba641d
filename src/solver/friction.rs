//! Cable–channel friction (model-notes §6): the capstan law
//! dτ/ds = −η μ τ |ψ'|, with ψ the cable's global angle φ + α and the slip
//! sign η = +1 while loading, −1 while unloading.
//!
//! The cut equations hold unchanged with τ(s) at the cut, because friction
//! acts inside the distal free body. So friction is a profile τ(s)/τ(0) held
//! at every point of the integrator and updated from the cable angles of the
//! last pass until it stops changing (a fixed point that contracts like
//! μ·|Δψ|; warm-started from the previous solve). This type holds the profile
//! and the angles; the integrators call [`Friction::record_cable_direction`]
//! during a pass and one of the two updates after it.

use super::SolveFailure;

/// Most re-integrations while the friction tension profile settles.
pub(crate) const MAX_PASSES: usize = 60;
/// Largest change of τ(s)/τ(0) accepted as settled.
pub(crate) const TOLERANCE: f64 = 1e-10;

/// The friction state of a simulator: coefficient, slip sign and the
/// tension profile at every point of the integrator.
#[derive(Debug, Clone)]
pub(super) struct Friction {
    /// Friction coefficient μ (0: no friction).
    mu: f64,
    /// Slip sign η of the next solves: +1 loading, −1 unloading.
    slip_sign: f64,
    /// Cable tension at each point relative to the base tension.
    ratio: Vec<f64>,
    /// Cable's global direction (cos ψ, sin ψ) at each point, last pass
    /// (recorded by RK4 only; collocation reads ψ from its own state).
    cable_global: Vec<(f64, f64)>,
}

impl Friction {
    /// No tension loss yet (τ(s) = τ(0)) at each of `points` points.
    pub(super) fn new(mu: f64, slip_sign: f64, points: usize) -> Self {
        Self { mu, slip_sign, ratio: vec![1.0; points], cable_global: vec![(1.0, 0.0); points] }
    }

    /// Whether the actuator has friction at all.
    #[inline]
    pub(super) fn is_on(&self) -> bool {
        self.mu > 0.0
    }

    /// Whether friction changes the tension profile at base tension `tension`
    /// (a slack cable has no friction to settle).
    #[inline]
    pub(super) fn acts_at(&self, tension: f64) -> bool {
        self.mu > 0.0 && tension > 0.0
    }

    /// Sets the slip sign η of the next solves.
    pub(super) fn set_slip_sign(&mut self, slip_sign: f64) {
        self.slip_sign = slip_sign;
    }

    /// Forgets the profile (warm start): τ(s) = τ(0).
    pub(super) fn forget(&mut self) {
        self.ratio.iter_mut().for_each(|r| *r = 1.0);
    }

    /// τ(s)/τ(0) at point `k`.
    #[inline]
    pub(super) fn ratio(&self, k: usize) -> f64 {
        self.ratio[k]
    }

    /// The whole profile τ(s)/τ(0).
    pub(super) fn ratios(&self) -> &[f64] {
        &self.ratio
    }

    /// The profile, to be replaced by an accelerated iterate.
    pub(super) fn ratios_mut(&mut self) -> &mut [f64] {
        &mut self.ratio
    }

    /// μ η: the exponent's factor in τ(s)/τ(0) = exp(−μ η ∫|ψ'|).
    #[inline]
    fn signed_mu(&self) -> f64 {
        self.mu * self.slip_sign
    }

    /// Records the cable's global direction at point `k`: the body frame's
    /// `(sin φ, cos φ)` turning the cable direction `(cos α, sin α)`.
    #[inline]
    pub(super) fn record_cable_direction(&mut self, k: usize, (sp, cp): (f64, f64), dir: (f64, f64)) {
        self.cable_global[k] = (cp * dir.0 - sp * dir.1, sp * dir.0 + cp * dir.1);
    }

    /// RK4: recomputes the profile from the cable directions recorded at the
    /// nodes of the last pass (capstan law between neighbouring nodes, exact
    /// for a constant |ψ'| between them); returns the largest change.
    ///
    /// The points are RK4's stage points, 2n + 1 per span of n steps. Only
    /// the nodes (accepted states) are used, not the predictor stages; the
    /// stage point between two nodes gets their geometric mean.
    pub(super) fn update_from_rk4_nodes(&mut self, n: usize) -> f64 {
        let span_len = 2 * n + 1;
        let k_node = |node: usize| -> usize {
            // Span 0's last node is the same point as span 1's first.
            if node < n {
                2 * node
            } else {
                span_len + 2 * (node - n)
            }
        };
        let mu = self.signed_mu();
        let mut change: f64 = 0.0;
        let mut ratio = 1.0;
        let mut prev_dir = self.cable_global[k_node(0)];
        let mut set = |ratio_vec: &mut Vec<f64>, k: usize, value: f64| {
            change = change.max((ratio_vec[k] - value).abs());
            ratio_vec[k] = value;
        };
        set(&mut self.ratio, 0, 1.0);
        for node in 1..=2 * n {
            let dir = self.cable_global[k_node(node)];
            let turn = (prev_dir.0 * dir.1 - prev_dir.1 * dir.0).atan2(prev_dir.0 * dir.0 + prev_dir.1 * dir.1);
            let next = ratio * (-mu * turn.abs()).exp();
            let k = k_node(node);
            let mid = (ratio * next).sqrt();
            set(&mut self.ratio, k_node(node - 1) + 1, mid);
            set(&mut self.ratio, k, next);
            if node == n {
                set(&mut self.ratio, 2 * n, next);
            }
            ratio = next;
            prev_dir = dir;
        }
        change
    }

    /// Sets the profile at point `k` from the cable's total turning
    /// ∫_0^s |ψ'| ds there (rad); returns the change at that point.
    #[inline]
    pub(super) fn set_from_turning(&mut self, k: usize, turning_rad: f64) -> f64 {
        let ratio = (-self.signed_mu() * turning_rad).exp();
        let change = (self.ratio[k] - ratio).abs();
        self.ratio[k] = ratio;
        change
    }
}

/// Settles the profile: `update` recomputes it from the last pass (returning
/// its largest change), and `repass` re-solves with it (returning the passes
/// used), until the change is below [`TOLERANCE`]. Returns the passes.
pub(super) fn settle<S>(
    sim: &mut S,
    mut update: impl FnMut(&mut S) -> f64,
    mut repass: impl FnMut(&mut S) -> Result<u32, SolveFailure>,
) -> Result<u32, SolveFailure> {
    let mut passes = 0;
    for _ in 0..MAX_PASSES {
        if update(sim) < TOLERANCE {
            return Ok(passes);
        }
        passes += repass(sim)?;
    }
    Err(SolveFailure::FrictionNotConverged)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_profile_follows_the_capstan_law_with_the_slip_sign() {
        for slip_sign in [1.0, -1.0] {
            let mut f = Friction::new(0.2, slip_sign, 3);
            let change = f.set_from_turning(1, 0.5);
            let want = (-0.2 * slip_sign * 0.5f64).exp();
            assert_eq!(f.ratio(1), want);
            assert_eq!(change, (1.0 - want).abs());
            // Settled: setting it again changes nothing.
            assert_eq!(f.set_from_turning(1, 0.5), 0.0);
            f.forget();
            assert!(f.ratios().iter().all(|&r| r == 1.0));
        }
        assert!(!Friction::new(0.0, 1.0, 1).acts_at(1.0) && !Friction::new(0.1, 1.0, 1).acts_at(0.0));
    }

    #[test]
    fn rk4_nodes_turning_evenly_lose_tension_geometrically() {
        // n = 2 steps per span: nodes at stage points 0, 2 | 5, 7, 9 (4 shares node 2's point).
        let n = 2;
        let (mu, turn) = (0.3, 0.1);
        let mut f = Friction::new(mu, 1.0, 2 * (2 * n + 1));
        let node_points = [0, 2, 5, 7, 9];
        for (node, &k) in node_points.iter().enumerate() {
            let psi = turn * node as f64;
            f.record_cable_direction(k, (0.0, 1.0), (psi.cos(), psi.sin()));
        }
        assert!(f.update_from_rk4_nodes(n) > 0.0);
        for (node, &k) in node_points.iter().enumerate() {
            let want = (-mu * turn * node as f64).exp();
            assert!((f.ratio(k) - want).abs() < 1e-14, "node {node}: {} vs {want}", f.ratio(k));
        }
        // The knot's copy in span 0, and the stages between nodes (geometric mean).
        assert_eq!(f.ratio(4), f.ratio(5));
        assert!((f.ratio(1) - (f.ratio(0) * f.ratio(2)).sqrt()).abs() < 1e-15);
        assert!((f.ratio(8) - (f.ratio(7) * f.ratio(9)).sqrt()).abs() < 1e-15);
        assert!(f.update_from_rk4_nodes(n) < 1e-15);
    }

    #[test]
    fn settle_counts_passes_and_gives_up() {
        let mut changes = vec![1.0, 0.1, 0.0];
        let passes = settle(&mut changes, |c| c.remove(0), |_| Ok(2)).unwrap();
        assert_eq!(passes, 4);
        let mut never = 0u32;
        let err = settle(&mut never, |_| 1.0, |n| {
            *n += 1;
            Ok(1)
        });
        assert_eq!(err, Err(SolveFailure::FrictionNotConverged));
        assert_eq!(never as usize, MAX_PASSES);
    }
}
