//! The thesis's design problem (eq. 3.17, one target): one cable in the
//! bending plane, its routing y_0…y_4 and its tension τ, inside box bounds.
//!
//! The unknowns are scaled into the unit box, u_i = y_i / Y ∈ [−1, 1] and
//! v = (τ − τ_l)/(τ_u − τ_l) ∈ [0, 1], so that one finite-difference step
//! and one stopping rule fit every variable. Its bounds are held by
//! projection: every trial point is a valid design (the simulator rejects
//! routings outside the body), and a bound-active optimum (the thesis's
//! Target II sits at τ = τ_u) is reached exactly. A trial point the model
//! cannot solve is a rejected step, not the end of the start. One warm
//! planar solver per start, fed the routing and the tension.
//!
//! Seeds come from a coarse grid of simulated designs of our own (5 levels
//! per control point, 5 tensions; half the routings simulated, the rest
//! mirrored) and optionally from a map's nearest designs; 3 × the starts
//! are explored briefly, no two within one grid step.

use super::{Exploration, Problem, SearchOptions, Seed, SeedSource, Seeds, Start, FD_STEP};
use crate::design::objective::{Bounds, Evaluation, Objective};
use crate::design::DesignError;
use crate::model::{ControlPoints, Routing};
use crate::solver::Simulator;
use crate::numerics::lm;
use nalgebra::DMatrix;
use rayon::prelude::*;

/// A design of the routing problem in millimetres and newtons: a grid
/// design or a map's nearest one, before it is a point of the unit box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Design {
    /// Control points, mm.
    pub routing_mm: ControlPoints,
    /// Tension, N.
    pub tension_n: f64,
    /// Where it came from.
    pub source: SeedSource,
}

/// The routing problem: the objective, the seed grid's settings and a
/// map's designs (which get up to half of the explored seeds).
#[derive(Debug, Clone)]
pub struct RoutingProblem<'a> {
    /// Eq. 3.17 with its bounds.
    pub objective: &'a Objective,
    /// The seed grid's levels.
    pub grid: &'a SearchOptions,
    /// A map's nearest designs.
    pub map_designs: Vec<Design>,
}

/// Seeds explored per converging start.
pub const EXPLORE_SEEDS_PER_START: usize = 3;

/// Evaluation budget of the first, exploratory pass of each start.
pub const EXPLORE_EVALUATIONS: usize = 100;

/// Index of the tension among the design variables.
const TENSION: usize = 5;

/// The design at unit-box coordinates `u` within `bounds`.
pub fn design_at(bounds: &Bounds, u: &[f64]) -> (ControlPoints, f64) {
    let b = bounds;
    let y = std::array::from_fn(|i| b.max_offset_mm * u[i]);
    let tension = b.tension_min_n + (b.tension_max_n - b.tension_min_n) * u[TENSION];
    (y.into(), tension)
}

/// Mirrors an evaluation (negated routing): model-notes §3, mirror symmetry.
fn mirrored(e: &Evaluation) -> Evaluation {
    let mut m = e.clone();
    m.routing_mm = e.routing_mm.mirrored();
    m.pose.tip_y_mm = -e.pose.tip_y_mm;
    m.pose.tip_angle_rad = -e.pose.tip_angle_rad;
    m.pose.tip_frame_angle_rad = -e.pose.tip_frame_angle_rad;
    m.pose.base_angle_rad = -e.pose.base_angle_rad;
    m.a.iter_mut().for_each(|a| *a = -*a);
    m
}

impl RoutingProblem<'_> {
    /// The design at unit-box coordinates `u`.
    pub fn design_of(&self, u: &[f64]) -> (ControlPoints, f64) {
        design_at(&self.objective.bounds, u)
    }

    /// The unit-box coordinates of a design, clamped into the bounds.
    pub fn unit_of(&self, y: &ControlPoints, tension: f64) -> Vec<f64> {
        let b = self.objective.bounds;
        let (mut y, mut tension) = (*y, tension);
        b.clamp(&mut y, &mut tension);
        let mut u: Vec<f64> = y.iter().map(|v| (v / b.max_offset_mm).clamp(-1.0, 1.0)).collect();
        let span = b.tension_max_n - b.tension_min_n;
        u.push(if span > 0.0 { ((tension - b.tension_min_n) / span).clamp(0.0, 1.0) } else { 0.0 });
        u
    }

    /// The smallest step of the seed grid, mm.
    fn grid_step_mm(&self) -> f64 {
        self.grid.grid_levels.windows(2).map(|w| (w[1] - w[0]).abs()).fold(f64::INFINITY, f64::min).min(1.0) * self.objective.bounds.max_offset_mm
    }

    /// Simulates the seed grid and returns every design with its cost, best first.
    pub fn grid_designs(&self) -> Vec<(f64, Design)> {
        let objective = self.objective;
        let b = objective.bounds;
        let levels: Vec<f64> = self.grid.grid_levels.iter().map(|f| f * b.max_offset_mm).collect();
        let mut tensions: Vec<f64> =
            self.grid.grid_tension_fractions.iter().map(|f| b.tension_min_n + f * (b.tension_max_n - b.tension_min_n)).collect();
        tensions.sort_by(f64::total_cmp);
        tensions.dedup();
        let nl = levels.len();
        let total = nl.pow(5);
        // Keep one routing of each mirror pair: the one whose first non-zero
        // control point is positive (the all-zero routing is its own mirror).
        let canonical = |idx: usize| -> Option<ControlPoints> {
            let mut y = [0.0; 5];
            let mut k = idx;
            for v in y.iter_mut() {
                *v = levels[k % nl];
                k /= nl;
            }
            match y.iter().find(|v| **v != 0.0) {
                Some(v) if *v < 0.0 => None,
                _ => Some(y.into()),
            }
        };
        let order = objective.target.order();
        let mut seeds: Vec<(f64, Design)> = (0..total)
            .into_par_iter()
            .filter_map(canonical)
            .map_init(
                || (objective.simulator(), vec![0.0; order + 1]),
                |(sim, a), y| {
                    let mut out = Vec::with_capacity(2 * tensions.len());
                    let routing = match Routing::for_actuator(&y, &objective.rod) {
                        Ok(r) => r,
                        Err(_) => return out,
                    };
                    sim.set_routing(&routing);
                    // The grid tensions in rising order form the continuation
                    // ladder; the first is solved cold (see `Objective::evaluate`),
                    // or climbed to from low tension if that fails.
                    let first = tensions[0];
                    let mut ladder: Vec<f64> = tensions.clone();
                    if sim.solve(first).is_err() {
                        sim.set_routing(&routing);
                        let rungs = crate::solver::ladder::tension_rungs(first);
                        ladder.splice(0..0, (1..rungs).map(|k| first * k as f64 / rungs as f64));
                    }
                    // (After a cold success the first rung repeats as a converged warm start.)
                    for t in ladder {
                        let Ok(pose) = sim.solve(t) else { return out };
                        if tensions.iter().any(|g| (g - t).abs() < 1e-12) {
                            sim.coefficients_into(objective.length_basis, a);
                            let e = Evaluation { routing_mm: y, tension_n: t, pose, a: a.clone() };
                            let m = mirrored(&e);
                            out.push((objective.cost(&e), Design { routing_mm: y, tension_n: t, source: SeedSource::Grid }));
                            if m.routing_mm != y {
                                out.push((objective.cost(&m), Design { routing_mm: m.routing_mm, tension_n: t, source: SeedSource::Grid }));
                            }
                        }
                    }
                    out
                },
            )
            .flatten()
            .collect();
        seeds.sort_by(|p, q| p.0.total_cmp(&q.0));
        seeds
    }

    /// Evaluates the map's designs under this objective, best first; designs
    /// outside the bounds are clamped into them.
    fn map_designs_ranked(&self) -> Vec<(f64, Design)> {
        let objective = self.objective;
        let mut out: Vec<(f64, Design)> = self
            .map_designs
            .par_iter()
            .map_init(
                || objective.simulator(),
                |sim, s| {
                    let mut s = *s;
                    objective.bounds.clamp(&mut s.routing_mm, &mut s.tension_n);
                    objective.evaluate(sim, &s.routing_mm, s.tension_n).ok().map(|e| (objective.cost(&e), s))
                },
            )
            .flatten()
            .collect();
        out.sort_by(|p, q| p.0.total_cmp(&q.0));
        out
    }
}

/// Picks up to `count` designs from `ranked` (best first), skipping any
/// within one grid step of a design already picked, so that the starts
/// explore different basins instead of one basin's neighbours.
fn diverse(ranked: &[(f64, Design)], count: usize, step_mm: f64) -> Vec<Design> {
    let mut picked: Vec<Design> = Vec::with_capacity(count);
    for (_, s) in ranked {
        if picked.len() == count {
            break;
        }
        let near = picked.iter().any(|p| {
            p.routing_mm.iter().zip(&s.routing_mm).map(|(a, b)| (a - b).abs()).sum::<f64>() <= 1.01 * step_mm
        });
        if !near {
            picked.push(*s);
        }
    }
    picked
}

impl Problem for RoutingProblem<'_> {
    type Solution = Evaluation;
    type Worker = Simulator;

    fn worker(&self) -> Simulator {
        self.objective.simulator()
    }

    /// The box bounds and the free variables: the tension is held when its
    /// bounds coincide.
    fn settings(&self) -> lm::Settings {
        let b = self.objective.bounds;
        let mut bounds = vec![(-1.0, 1.0); 5];
        bounds.push((0.0, 1.0));
        let free = if b.tension_max_n > b.tension_min_n { (0..6).collect() } else { (0..5).collect() };
        // The evaluation budget ends a start, not an iteration count.
        lm::Settings { bounds, free, max_iterations: usize::MAX }
    }

    fn solve(&self, sim: &mut Simulator, u: &[f64], evaluations: &mut usize) -> Option<(Vec<f64>, Evaluation)> {
        *evaluations += 1;
        let (y, tension) = self.design_of(u);
        let e = self.objective.evaluate(sim, &y, tension).ok()?;
        let mut r = vec![0.0; self.objective.residual_count()];
        self.objective.residuals_into(&e, &mut r);
        Some((r, e))
    }

    /// Forward differences, stepping inward at an upper bound (every point
    /// evaluated stays a valid design), and the other way round when a point
    /// cannot be solved.
    fn jacobian(start: &mut Start<'_, Self>, u: &[f64], r: &[f64], free: &[usize]) -> Option<DMatrix<f64>> {
        let mut jac = DMatrix::zeros(r.len(), free.len());
        for (k, &j) in free.iter().enumerate() {
            // Every variable's upper bound is 1.
            let mut h = if u[j] + FD_STEP > 1.0 { -FD_STEP } else { FD_STEP };
            let mut at = u.to_vec();
            at[j] += h;
            let rh = match start.evaluate(&at) {
                Some((rh, _)) => rh,
                None => {
                    h = -h;
                    at[j] = u[j] + h;
                    start.evaluate(&at)?.0
                }
            };
            for (i, (a, b)) in rh.iter().zip(r).enumerate() {
                jac[(i, k)] = (a - b) / h;
            }
        }
        Some(jac)
    }

    /// The map's designs (up to half of `count`, no two within one grid
    /// step), then the grid's, no two within one grid step.
    fn seeds(&self, count: usize) -> Result<Seeds, DesignError> {
        let step_mm = self.grid_step_mm();
        let mapped = self.map_designs_ranked();
        let picked = diverse(&mapped, count.div_ceil(2), step_mm);
        let grid = self.grid_designs();
        let simulated = self.map_designs.len() + grid.len();
        let mut merged: Vec<(f64, Design)> = picked.iter().map(|s| (f64::NEG_INFINITY, *s)).collect();
        merged.extend(grid);
        let seeds = diverse(&merged, count, step_mm)
            .into_iter()
            .map(|d| Seed { point: self.unit_of(&d.routing_mm, d.tension_n), source: d.source })
            .collect();
        Ok(Seeds { seeds, simulated })
    }

    fn exploration(&self) -> Option<Exploration> {
        Some(Exploration { seeds_per_start: EXPLORE_SEEDS_PER_START, evaluations: EXPLORE_EVALUATIONS })
    }

    /// The explored start's best design, as a design in mm (so clamped into the bounds).
    fn resume_point(&self, _u: &[f64], e: &Evaluation) -> Vec<f64> {
        self.unit_of(&e.routing_mm, e.tension_n)
    }

    /// The same routing (whatever the tension).
    fn same_channels(&self, a: &[f64], b: &[f64]) -> bool {
        self.design_of(a).0 == self.design_of(b).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::{Bounds, Target, Weights};
    use crate::model::Rod;
    use crate::solver::SolverOptions;

    fn objective() -> Objective {
        let act = Rod::default();
        let bounds = Bounds::thesis(act.radius_mm, 1.0, 2.0);
        Objective::new(act, SolverOptions::default(), Target::parse("x=50,y=5").unwrap(), Weights::default(), bounds).unwrap()
    }

    #[test]
    fn a_design_does_not_depend_on_thread_timing() {
        let obj = objective();
        let search = SearchOptions { starts: 4, ..SearchOptions::default() };
        let problem = RoutingProblem { objective: &obj, grid: &search, map_designs: Vec::new() };
        let runs: Vec<_> = (0..3).map(|_| super::super::search(&problem, &search).unwrap()).collect();
        for r in &runs[1..] {
            let (a, b) = (&r.solution, &runs[0].solution);
            assert_eq!((a.routing_mm, a.tension_n, r.cost), (b.routing_mm, b.tension_n, runs[0].cost));
        }
    }

    #[test]
    fn the_unit_box_round_trips_and_stays_inside() {
        let obj = objective();
        let grid = SearchOptions::default();
        let p = RoutingProblem { objective: &obj, grid: &grid, map_designs: Vec::new() };
        let y = [4.99, -4.99, 0.0, 1.234, -3.0];
        let (y2, t2) = p.design_of(&p.unit_of(&y.into(), 1.7));
        for (a, b) in y.iter().zip(&y2) {
            assert!((a - b).abs() < 1e-12);
        }
        assert!((t2 - 1.7).abs() < 1e-12);
        // The box's corners are the bounds' corners.
        let s = p.settings();
        for (corner, sign, tension) in [(s.bounds.iter().map(|b| b.0).collect::<Vec<_>>(), -1.0, 1.0), (s.bounds.iter().map(|b| b.1).collect(), 1.0, 2.0)] {
            let (y, t) = p.design_of(&corner);
            assert!(y.iter().all(|v| (v - sign * obj.bounds.max_offset_mm).abs() < 1e-12), "{y:?}");
            assert!((t - tension).abs() < 1e-12);
        }
    }

    #[test]
    fn diverse_skips_grid_neighbours_but_not_distinct_designs() {
        let seed = |y: [f64; 5], t: f64| (0.0, Design { routing_mm: y.into(), tension_n: t, source: SeedSource::Grid });
        let ranked = [
            seed([0.0, 0.0, 0.0, 0.0, 0.0], 1.0),
            seed([0.0, 0.0, 0.0, 0.0, 0.0], 2.0),
            seed([2.0, 0.0, 0.0, 0.0, 0.0], 1.0),
            seed([2.0, 2.0, 0.0, 0.0, 0.0], 1.0),
            seed([-4.0, 0.0, 0.0, 0.0, 4.0], 1.5),
        ];
        let picked = diverse(&ranked, 10, 2.0);
        assert_eq!(picked.len(), 3, "{picked:?}");
        assert_eq!(picked[1].routing_mm, [2.0, 2.0, 0.0, 0.0, 0.0]);
        assert_eq!(picked[2].routing_mm, [-4.0, 0.0, 0.0, 0.0, 4.0]);
        assert_eq!(diverse(&ranked, 1, 2.0).len(), 1);
    }

    #[test]
    fn mirrored_negates_lateral_quantities() {
        let obj = objective();
        let mut sim = obj.simulator();
        let e = obj.evaluate(&mut sim, &[1.0, -2.0, 3.0, 0.5, -1.5].into(), 1.4).unwrap();
        let m = obj.evaluate(&mut sim, &[-1.0, 2.0, -3.0, -0.5, 1.5].into(), 1.4).unwrap();
        let mm = mirrored(&e);
        assert!((mm.pose.tip_y_mm - m.pose.tip_y_mm).abs() < 1e-9 && (mm.pose.tip_x_mm - m.pose.tip_x_mm).abs() < 1e-9);
        for (a, b) in mm.a.iter().zip(&m.a) {
            assert!((a - b).abs() < 1e-9);
        }
    }
}
