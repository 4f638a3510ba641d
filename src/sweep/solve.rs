//! Solving one routing of a sweep into its rows, for each kind of sweep:
//! the planar routing through its rising tension ladder, a routing of
//! several or spatial cables through its tension grid in snake order. Each
//! routing is solved from cold, independent of every other, so rows do not
//! depend on threads or shards. The rows are the batch builders' input
//! ([`super::schema`]).

use super::schema::{CableRow, SolvedRouting, SolvedRow, STATUS_FAILED, STATUS_INVALID_ROUTING};
use crate::model::routing::ControlPoints;
use crate::solver::spatial::{Actuator, SpatialError};
use crate::solver::{ladder, Given, Solver};
use crate::model::{Actuation, Routing};
use crate::solver::{Simulator, SolveFailure, SolverOptions, TipPose, STATUS_OK};
use crate::sweep::spec::Ladder;
use crate::shape::LengthBasis;

/// What each solve of a sweep stores besides its pose: a_0 … a_`order` per
/// unit of `length_basis`, and (planar rows) the centreline when `centreline`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stored {
    /// Highest Legendre order.
    pub order: usize,
    /// The length the a_i are per unit of.
    pub length_basis: LengthBasis,
    /// Store each solve's centreline.
    pub centreline: bool,
}

/// Solves the planar routing `routing` (id `id`, control points
/// `routing_mm`) through the actuation ladder `ladder` (rising tensions,
/// or rising displacements with each tension found: continuation from one
/// value to the next).
pub fn planar_routing(sim: &mut Simulator, id: u64, routing_mm: ControlPoints, routing: &Routing, ladder: &Ladder, stored: Stored) -> SolvedRouting {
    sim.set_routing(routing);
    let rows = match ladder {
        Ladder::TensionN(tensions) => tensions.iter().map(|&t| planar_row(sim, Actuation::Tension(t), &mut [t], stored)).collect(),
        Ladder::DisplacementMm(displacements) => {
            // The tension found at one displacement starts the next.
            let mut tension = [0.0];
            displacements.iter().map(|&d| planar_row(sim, Actuation::Displacement(d), &mut tension, stored)).collect()
        }
    };
    SolvedRouting { id, routing_mm, rows }
}

/// One planar solve as a row: outputs only for a successful, finite solve.
/// The row's tension and displacement are the command and what it produced
/// (a tension's displacement; a displacement's tension, unknown when it failed).
/// A displacement's solve starts from (and leaves its tension in) `tension`.
fn planar_row(sim: &mut Simulator, actuation: Actuation, tension: &mut [f64; 1], stored: Stored) -> SolvedRow {
    let (solved, command) = match actuation {
        Actuation::Tension(t) => (sim.solve(t), (t, f64::NAN)),
        Actuation::Displacement(d) => {
            let solved = sim.solve_actuation(Actuation::Displacement(d), tension);
            if solved.is_err() {
                // A failed rung leaves no tension to start from: the next starts from zero.
                tension[0] = 0.0;
            }
            (solved, (f64::NAN, d))
        }
    };
    let failed = |status| SolvedRow { tension_n: command.0, displacement_mm: command.1, status, pose: None, a: Vec::new(), centreline: None };
    match solved {
        Ok(pose) => {
            let mut a = vec![0.0; stored.order + 1];
            // Coefficients the discretisation does not resolve are a failure too.
            if let Err(failure) = sim.coefficients_checked(stored.length_basis, &mut a) {
                return failed(failure.status());
            }
            let scalars = [pose.tip_x_mm, pose.tip_y_mm, pose.tip_angle_rad, pose.base_angle_rad, pose.length_mm];
            if !scalars.iter().chain(&a).all(|v| v.is_finite()) {
                // Stored as a failure so that outputs are never NaN.
                return failed(SolveFailure::NonFinite { s_mm: None }.status());
            }
            let centreline = stored.centreline.then(|| {
                let points = sim.centreline();
                (points.iter().map(|p| p.x_mm).collect(), points.iter().map(|p| p.y_mm).collect())
            });
            // The command exactly; what it produced from the pose.
            let tension_n = if command.0.is_nan() { pose.tension_n() } else { command.0 };
            let displacement_mm = if command.1.is_nan() { pose.displacement_mm() } else { command.1 };
            SolvedRow { tension_n, displacement_mm, status: STATUS_OK, pose: Some(pose), a, centreline }
        }
        Err(failure) => failed(failure.status()),
    }
}

/// A routing's actuation grids, per cable (tensions, N, or displacements,
/// mm), and their combinations in the order they are solved (snake order).
/// Computed once per worker.
#[derive(Debug, Clone, PartialEq)]
pub struct TensionCombinations {
    /// Each cable's grid.
    pub grids: Vec<Vec<f64>>,
    /// Which cables are driven by their displacement (their grid in mm).
    pub by_displacement: Vec<bool>,
    /// Every combination (per-cable grid indices), in snake order.
    pub snake: Vec<Vec<usize>>,
}

impl TensionCombinations {
    /// The combinations of `grids`; `by_displacement[i]`: cable i's grid is of displacements.
    pub fn new(grids: Vec<Vec<f64>>, by_displacement: Vec<bool>) -> Self {
        Self { snake: snake(&grids), grids, by_displacement }
    }

    /// Each cable's command at combination `combo`.
    fn values(&self, combo: &[usize]) -> Vec<f64> {
        combo.iter().zip(&self.grids).map(|(&j, g)| g[j]).collect()
    }

    /// Whether any cable is driven by its displacement.
    fn any_displacement(&self) -> bool {
        self.by_displacement.iter().any(|&d| d)
    }

    /// Solves at `values` (each cable's command, scaled by `scale`): the
    /// tension-driven cables at theirs, the others' tensions found from
    /// `tensions_n` (which receives them).
    fn solve(&self, solver: &mut Simulator, values: &[f64], scale: f64, tensions_n: &mut [f64]) -> Result<TipPose, SpatialError> {
        if !self.any_displacement() {
            let t: Vec<f64> = values.iter().map(|v| v * scale).collect();
            return solver.solve_tensions(&t);
        }
        let mut rung = [Actuation::Tension(0.0); crate::model::MAX_CABLES];
        for (i, (&v, &d)) in values.iter().zip(&self.by_displacement).enumerate() {
            rung[i] = if d { Actuation::Displacement(v * scale) } else { Actuation::Tension(v * scale) };
        }
        Solver::solve(solver, &rung[..values.len()], tensions_n)
    }
}

/// Tension combinations in snake order: each step changes one cable's
/// tension by one grid step, so the solver's warm start (and its
/// extrapolation along a straight run) stays close.
fn snake(grids: &[Vec<f64>]) -> Vec<Vec<usize>> {
    let mut out: Vec<Vec<usize>> = vec![vec![]];
    for grid in grids {
        let mut next = Vec::with_capacity(out.len() * grid.len());
        for (k, prefix) in out.iter().enumerate() {
            let order: Vec<usize> = if k % 2 == 0 { (0..grid.len()).collect() } else { (0..grid.len()).rev().collect() };
            for j in order {
                let mut p = prefix.clone();
                p.push(j);
                next.push(p);
            }
        }
        out = next;
    }
    out
}

/// Position of a tension combination (per-cable grid indices) in grid
/// order: cable 1's index most significant.
pub fn combination_index(combo: &[usize], grids: &[Vec<f64>]) -> usize {
    combo.iter().zip(grids).fold(0, |k, (&j, g)| k * g.len() + j)
}

/// Solves routing `id` of a cable sweep, `actuator` (its cables' tensions
/// are set per combination), through every tension combination by one
/// solver, the backend serving the actuator ([`Simulator::serving`]: the
/// planar one for one in-plane cable, as for a single simulation): from
/// zero up to the first combination, then along the snake. Returns the rows
/// in grid order (cable 1's tension slowest). An actuator the solver
/// refuses gives rows of [`STATUS_INVALID_ROUTING`].
pub fn cable_routing(id: u64, mut actuator: Actuator, options: &SolverOptions, stored: Stored, combinations: &TensionCombinations) -> Vec<CableRow> {
    let combos = &combinations.snake;
    let geometry: Vec<_> = actuator.cables.iter().map(|c| (c.y_mm, c.z_mm)).collect();
    // A row's tension and displacement per cable: the command exactly, and
    // what the solve produced (NaN, stored as null, when it failed).
    let row = |combo: &[usize], status, passes, pose: Option<TipPose>, a| {
        let values = combinations.values(combo);
        let (mut tensions, mut displacements) = (vec![f64::NAN; values.len()], vec![f64::NAN; values.len()]);
        for (i, (&v, &d)) in values.iter().zip(&combinations.by_displacement).enumerate() {
            let (command, produced, from_pose) = if d { (&mut displacements, &mut tensions, pose.map(|p| p.tensions_n[i])) } else { (&mut tensions, &mut displacements, pose.map(|p| p.displacements_mm[i])) };
            command[i] = v;
            produced[i] = from_pose.unwrap_or(f64::NAN);
        }
        CableRow { routing_id: id as i64, cables: geometry.clone(), tensions, displacements, status, passes, pose, a }
    };
    // Build with the first combination's commands so validation sees them.
    let first = combinations.values(&combos[0]);
    for ((c, &v), &d) in actuator.cables.iter_mut().zip(&first).zip(&combinations.by_displacement) {
        if d {
            c.displacement_mm = Some(v);
        } else {
            c.tension_n = v;
        }
    }
    let mut solver = match Simulator::serving(&actuator, options, Given::default()) {
        Ok(s) => s,
        Err(_) => return combos.iter().map(|c| row(c, STATUS_INVALID_ROUTING, 0, None, None)).collect(),
    };
    let mut rows: Vec<Option<CableRow>> = vec![None; combos.len()];
    let mut tensions = vec![0.0; first.len()];
    // Continuation from zero to the first combination (rungs of ≤ 0.25 N
    // and ≤ 0.5 mm).
    let rung = |(&v, &d): (&f64, &bool)| if d { v / ladder::DISPLACEMENT_RUNG_MM } else { v / ladder::TENSION_RUNG_N };
    let top = first.iter().zip(&combinations.by_displacement).map(rung).fold(0.0, f64::max);
    let rungs = (top.ceil() as usize).max(1);
    for k in 1..rungs {
        // A rung that fails only leaves a worse warm start; the rows report failures.
        if combinations.solve(&mut solver, &first, k as f64 / rungs as f64, &mut tensions).is_err() {
            tensions.iter_mut().for_each(|t| *t = 0.0);
        }
    }
    for combo in combos {
        let values = combinations.values(combo);
        let solved = match combinations.solve(&mut solver, &values, 1.0, &mut tensions) {
            Ok(pose) => match solver.coefficients(stored.order, stored.length_basis) {
                Ok(a) if finite_cable_row(&pose, &a) => row(combo, STATUS_OK, pose.iterations as i32, Some(pose), Some(a)),
                _ => row(combo, STATUS_FAILED, 0, None, None),
            },
            Err(_) => {
                // No tension to start the next displacement from.
                tensions.iter_mut().for_each(|t| *t = 0.0);
                row(combo, STATUS_FAILED, 0, None, None)
            }
        };
        rows[combination_index(combo, &combinations.grids)] = Some(solved);
    }
    // Rows in grid order (cable 1's command slowest), whatever the snake.
    rows.into_iter().map(|r| r.expect("the snake visits every combination")).collect()
}

/// A solve whose outputs are all finite (others are stored as failures, so
/// that no output is NaN).
fn finite_cable_row(pose: &TipPose, a: &[Vec<f64>; 3]) -> bool {
    let p = pose;
    p.tip_mm().iter().chain(&p.tip_tangent()).chain(&p.tip_body_y_axis()).chain([&p.angle_from_clamp_axis_rad(), &p.length_mm]).all(|v| v.is_finite())
        && a.iter().flatten().all(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snake_order_visits_every_combination_one_step_at_a_time() {
        let grids = vec![vec![0.0, 1.0, 2.0], vec![0.0, 1.0], vec![5.0, 6.0]];
        let s = snake(&grids);
        assert_eq!(s.len(), 12);
        let unique: std::collections::BTreeSet<_> = s.iter().cloned().collect();
        assert_eq!(unique.len(), 12);
        for w in s.windows(2) {
            let steps: usize = w[0].iter().zip(&w[1]).map(|(a, b)| a.abs_diff(*b)).sum();
            assert_eq!(steps, 1, "{w:?}");
        }
        for (k, combo) in s.iter().enumerate() {
            assert!(combination_index(combo, &grids) < 12, "{k}");
        }
    }
}
