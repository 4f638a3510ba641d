//! Minimising eq. 3.17: multi-start Levenberg–Marquardt over the routing
//! y_0…y_4 and the tension τ, inside box bounds.
//!
//! The search runs the library's one bounded Levenberg–Marquardt
//! ([`crate::numerics::lm`]) on the design scaled into the unit box,
//! u_i = y_i / Y ∈ [−1, 1] and v = (τ − τ_l)/(τ_u − τ_l) ∈ [0, 1], so that
//! one finite-difference step and one stopping rule fit every variable. Its
//! bounds are held by projection: every trial point is a valid design (the
//! simulator rejects routings outside the body), and a bound-active optimum
//! (the thesis's Target II sits at τ = τ_u) is reached exactly. A trial point
//! the model cannot solve is a rejected step, not the end of the start.
//!
//! Starts come from a coarse grid of simulated designs of our own (5 levels
//! per control point, 5 tensions; half the routings simulated, the rest
//! mirrored) and optionally from a map's nearest designs. The best few are
//! refined in parallel and the lowest cost wins.

use super::objective::{Evaluation, Objective};
use super::target::Component;
use super::DesignError;
use crate::model::{ControlPoints, Routing};
use crate::solver::{Simulator, SolveFailure};
use crate::numerics::lm;
use nalgebra::DMatrix;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Settings of the multi-start search.
#[derive(Debug, Clone, Serialize)]
pub struct SearchOptions {
    /// Levels per control point of the seed grid, as fractions of the
    /// largest offset (symmetric about 0).
    pub grid_levels: Vec<f64>,
    /// Tensions of the seed grid, as fractions of [τ_l, τ_u].
    pub grid_tension_fractions: Vec<f64>,
    /// How many of the best seeds to refine.
    pub starts: usize,
    /// Most simulator evaluations per refinement.
    pub max_evaluations: usize,
}

impl Default for SearchOptions {
    fn default() -> Self {
        Self {
            grid_levels: vec![-0.8, -0.4, 0.0, 0.4, 0.8],
            grid_tension_fractions: vec![0.0, 0.25, 0.5, 0.75, 1.0],
            starts: 8,
            max_evaluations: 1500,
        }
    }
}

/// A starting design for a refinement.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Seed {
    /// Control points, mm.
    pub routing_mm: ControlPoints,
    /// Tension, N.
    pub tension_n: f64,
    /// Where it came from.
    pub source: SeedSource,
}

/// Origin of a seed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SeedSource {
    /// The built-in seed grid.
    Grid,
    /// A simulated design from a feasibility map's `designs.parquet`.
    Map,
}

/// One refinement's outcome.
#[derive(Debug, Clone, Serialize)]
pub struct StartReport {
    /// The seed it started from.
    pub seed: Seed,
    /// Objective at the seed.
    pub seed_cost: f64,
    /// Objective at the end (inf if nothing converged).
    pub cost: f64,
    /// Simulator evaluations used.
    pub evaluations: usize,
    /// Why Levenberg–Marquardt stopped.
    pub termination: String,
}

/// The result of a multi-start design.
#[derive(Debug, Clone, Serialize)]
pub struct DesignOutcome {
    /// The best design found.
    pub best: Evaluation,
    /// Its objective (eq. 3.17).
    pub cost: f64,
    /// Every refinement, best first.
    pub starts: Vec<StartReport>,
    /// Seed designs simulated (grid and map).
    pub seeds_simulated: usize,
    /// Wall time, s.
    pub seconds: f64,
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

/// Simulates the seed grid and returns every design with its cost, best first.
pub fn grid_seeds(objective: &Objective, search: &SearchOptions) -> Vec<(f64, Seed)> {
    let b = objective.bounds;
    let levels: Vec<f64> = search.grid_levels.iter().map(|f| f * b.max_offset_mm).collect();
    let mut tensions: Vec<f64> =
        search.grid_tension_fractions.iter().map(|f| b.tension_min_n + f * (b.tension_max_n - b.tension_min_n)).collect();
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
    let mut seeds: Vec<(f64, Seed)> = (0..total)
        .into_par_iter()
        .filter_map(canonical)
        .map_init(
            || (objective.simulator(), vec![0.0; order + 1]),
            |(sim, a), y| {
                let mut out = Vec::with_capacity(2 * tensions.len());
                let routing = match Routing::for_actuator(&y, &objective.actuator) {
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
                    let rungs = ((first / super::objective::LADDER_STEP_N).ceil() as usize).max(1);
                    ladder.splice(0..0, (1..rungs).map(|k| first * k as f64 / rungs as f64));
                }
                // (After a cold success the first rung repeats as a converged warm start.)
                for t in ladder {
                    let Ok(pose) = sim.solve(t) else { return out };
                    if tensions.iter().any(|g| (g - t).abs() < 1e-12) {
                        sim.coefficients_into(objective.length_basis, a);
                        let e = Evaluation { routing_mm: y, tension_n: t, pose, a: a.clone() };
                        let m = mirrored(&e);
                        out.push((objective.cost(&e), Seed { routing_mm: y, tension_n: t, source: SeedSource::Grid }));
                        if m.routing_mm != y {
                            out.push((objective.cost(&m), Seed { routing_mm: m.routing_mm, tension_n: t, source: SeedSource::Grid }));
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

/// Evaluates extra seeds (e.g. from a map) under this objective, best first;
/// seeds outside the bounds are clamped into them.
pub fn evaluate_seeds(objective: &Objective, seeds: &[Seed]) -> Vec<(f64, Seed)> {
    let mut out: Vec<(f64, Seed)> = seeds
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

/// The least-squares problem in the unit box (see module docs).
struct Problem<'a> {
    objective: &'a Objective,
    sim: Simulator,
    /// Best design seen so far (a rejected trial point may be the best seen).
    best: Option<(f64, Evaluation)>,
    evaluations: usize,
    max_evaluations: usize,
    /// This start's place in its pass (the seeds' order).
    index: usize,
    /// Shared by a pass's starts: the lowest index that fitted exactly.
    exact_fit: &'a ExactFit,
}

/// The lowest start index of a pass that reached [`COST_FLOOR`]. A start
/// stops once a start *before* it has fitted exactly, never for one after it:
/// so the first start that fits exactly always runs as if alone, and the
/// design chosen (the first exact fit, else the least cost) does not depend
/// on which thread finished first.
#[derive(Debug)]
pub struct ExactFit(AtomicUsize);

impl ExactFit {
    /// No start has fitted exactly yet.
    pub fn new() -> Self {
        ExactFit(AtomicUsize::new(usize::MAX))
    }

    fn record(&self, index: usize) {
        self.0.fetch_min(index, Ordering::Relaxed);
    }

    /// Whether a start before `index` fitted exactly.
    fn before(&self, index: usize) -> bool {
        self.0.load(Ordering::Relaxed) < index
    }

    /// Whether any start fitted exactly.
    pub fn any(&self) -> bool {
        self.0.load(Ordering::Relaxed) != usize::MAX
    }
}

impl Default for ExactFit {
    fn default() -> Self {
        Self::new()
    }
}

/// An objective this small is an exact fit: errors near 1e-10 mm and
/// 1e-11 /mm, below the solver's own discretisation error. Reaching it ends
/// the search (without it, a zero-residual problem keeps LM iterating).
pub const COST_FLOOR: f64 = 1e-20;

/// Finite-difference step in the unit box (1e-5 mm in y at the thesis's
/// bounds): large against the solver's convergence noise (~1e-10 in a_i),
/// small against curvature.
const FD_STEP: f64 = 2e-6;

/// Index of the tension among the design variables.
const TENSION: usize = 5;

impl Problem<'_> {
    /// The design at unit-box coordinates `u`.
    fn design_of(&self, u: &[f64]) -> (ControlPoints, f64) {
        let b = self.objective.bounds;
        let y = std::array::from_fn(|i| b.max_offset_mm * u[i]);
        let tension = b.tension_min_n + (b.tension_max_n - b.tension_min_n) * u[TENSION];
        (y.into(), tension)
    }

    /// The unit-box coordinates of a design inside the bounds.
    fn unit_of(&self, y: &ControlPoints, tension: f64) -> Vec<f64> {
        let b = self.objective.bounds;
        let mut u: Vec<f64> = y.iter().map(|v| (v / b.max_offset_mm).clamp(-1.0, 1.0)).collect();
        let span = b.tension_max_n - b.tension_min_n;
        u.push(if span > 0.0 { ((tension - b.tension_min_n) / span).clamp(0.0, 1.0) } else { 0.0 });
        u
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

    fn residuals_at(&mut self, u: &[f64]) -> Result<Vec<f64>, SolveFailure> {
        self.evaluations += 1;
        let (y, tension) = self.design_of(u);
        let e = self.objective.evaluate(&mut self.sim, &y, tension)?;
        let mut r = vec![0.0; self.objective.residual_count()];
        self.objective.residuals_into(&e, &mut r);
        let cost = r.iter().map(|v| v * v).sum::<f64>();
        if self.best.as_ref().is_none_or(|(c, _)| cost < *c) {
            self.best = Some((cost, e));
        }
        Ok(r)
    }
}

impl lm::Problem for Problem<'_> {
    fn residuals(&mut self, u: &[f64]) -> Option<Vec<f64>> {
        self.residuals_at(u).ok()
    }

    /// Forward differences, stepping inward at an upper bound (every point
    /// evaluated stays a valid design), and the other way round when a point
    /// cannot be solved.
    fn jacobian(&mut self, u: &[f64], r: &[f64], free: &[usize]) -> Option<DMatrix<f64>> {
        let mut jac = DMatrix::zeros(r.len(), free.len());
        for (k, &j) in free.iter().enumerate() {
            // Every variable's upper bound is 1.
            let mut h = if u[j] + FD_STEP > 1.0 { -FD_STEP } else { FD_STEP };
            let mut at = u.to_vec();
            at[j] += h;
            let rh = match self.residuals_at(&at) {
                Ok(rh) => rh,
                Err(_) => {
                    h = -h;
                    at[j] = u[j] + h;
                    self.residuals_at(&at).ok()?
                }
            };
            for (i, (a, b)) in rh.iter().zip(r).enumerate() {
                jac[(i, k)] = (a - b) / h;
            }
        }
        Some(jac)
    }

    /// Exact fit here or in an earlier start, or out of budget: the best
    /// design seen is kept.
    fn stop(&mut self) -> bool {
        let exact = self.best.as_ref().is_some_and(|(c, _)| *c <= COST_FLOOR);
        if exact {
            self.exact_fit.record(self.index);
        }
        exact || self.exact_fit.before(self.index) || self.evaluations >= self.max_evaluations
    }
}

/// Refines one seed with bounded Levenberg–Marquardt; returns the best design
/// it saw (None if not even the seed could be simulated).
///
/// `index` is the start's place in its pass and `exact_fit` is shared by the
/// pass's parallel starts (see [`ExactFit`]).
pub fn refine(
    objective: &Objective,
    seed: &Seed,
    max_evaluations: usize,
    index: usize,
    exact_fit: &ExactFit,
) -> (Option<(f64, Evaluation)>, StartReport) {
    let mut problem = Problem { objective, sim: objective.simulator(), best: None, evaluations: 0, max_evaluations, index, exact_fit };
    let mut s = *seed;
    objective.bounds.clamp(&mut s.routing_mm, &mut s.tension_n);
    let u = problem.unit_of(&s.routing_mm, s.tension_n);
    let start = if lm::Problem::stop(&mut problem) { None } else { problem.residuals_at(&u).ok() };
    let seed_cost = start.as_ref().map_or(f64::INFINITY, |r| r.iter().map(|v| v * v).sum());
    let termination = match start {
        Some(r) => {
            let settings = problem.settings();
            lm::minimise(&mut problem, u, r, &settings, &mut |_| {}).termination.to_string()
        }
        None => "the seed could not be simulated".to_string(),
    };
    let best = problem.best.take();
    let report = StartReport {
        seed: s,
        seed_cost,
        cost: best.as_ref().map_or(f64::INFINITY, |b| b.0),
        evaluations: problem.evaluations,
        // Our own stops, named.
        termination: if best.as_ref().is_some_and(|(c, _)| *c <= COST_FLOOR) {
            "exact fit (objective at the noise floor)".to_string()
        } else if exact_fit.before(index) {
            "stopped: an earlier start fitted exactly".to_string()
        } else if problem.evaluations >= max_evaluations {
            "evaluation budget reached".to_string()
        } else {
            termination
        },
    };
    (best, report)
}

/// Picks up to `count` seeds from `ranked` (best first), skipping any within
/// one grid step of a seed already picked, so that the starts explore
/// different basins instead of one basin's neighbours.
fn diverse(ranked: &[(f64, Seed)], count: usize, step_mm: f64) -> Vec<Seed> {
    let mut picked: Vec<Seed> = Vec::with_capacity(count);
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

/// The design a pass yields, from its results in start order: the first
/// start that fitted exactly, else the least cost (ties to the earlier
/// start). Starts after the first exact fit may have been stopped at any
/// point, so they never decide.
fn choice(results: &[(Option<(f64, Evaluation)>, StartReport)]) -> Option<(f64, Evaluation)> {
    let found = results.iter().filter_map(|r| r.0.as_ref());
    match found.clone().find(|(c, _)| *c <= COST_FLOOR) {
        Some(exact) => Some(exact.clone()),
        None => found.fold(None, |best: Option<&(f64, Evaluation)>, r| match best {
            Some(b) if b.0 <= r.0 => Some(b),
            _ => Some(r),
        })
        .cloned(),
    }
}

/// Evaluation budget of the first, exploratory pass of each start.
pub const EXPLORE_EVALUATIONS: usize = 100;

/// Designs for `objective`: simulates the seed grid (plus `extra_seeds`,
/// e.g. a map's nearest designs, which get up to half of the starts),
/// explores 3 × `search.starts` diverse seeds with a short budget, then
/// refines the best `search.starts` of those to convergence in parallel and
/// returns the best.
pub fn design(objective: &Objective, search: &SearchOptions, extra_seeds: &[Seed]) -> Result<DesignOutcome, DesignError> {
    let started = Instant::now();
    let step_mm = search
        .grid_levels
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(f64::INFINITY, f64::min)
        .min(1.0)
        * objective.bounds.max_offset_mm;
    let explore = 3 * search.starts;
    let mapped = evaluate_seeds(objective, extra_seeds);
    let mut seeds = diverse(&mapped, explore.div_ceil(2), step_mm);
    let grid = grid_seeds(objective, search);
    let seeds_simulated = extra_seeds.len() + grid.len();
    let mut merged: Vec<(f64, Seed)> = seeds.iter().map(|s| (f64::NEG_INFINITY, *s)).collect();
    merged.extend(grid);
    seeds = diverse(&merged, explore, step_mm);
    if seeds.is_empty() {
        return Err(DesignError::NoSeed);
    }
    // Pass 1: a short look from every seed.
    let exact_first = ExactFit::new();
    let mut first: Vec<(Option<(f64, Evaluation)>, StartReport)> = seeds
        .par_iter()
        .enumerate()
        .map(|(i, seed)| refine(objective, seed, EXPLORE_EVALUATIONS, i, &exact_first))
        .collect();
    let first_choice = choice(&first);
    first.sort_by(|p, q| p.1.cost.total_cmp(&q.1.cost));
    // Pass 2: converge the most promising, continuing from where pass 1 stopped.
    let continued: Vec<(f64, Seed)> = first
        .iter()
        .filter_map(|(best, report)| {
            best.as_ref().map(|(c, e)| (*c, Seed { routing_mm: e.routing_mm, tension_n: e.tension_n, source: report.seed.source }))
        })
        .collect();
    let finalists = if exact_first.any() { Vec::new() } else { diverse(&continued, search.starts, 0.0) };
    let exact_final = ExactFit::new();
    let (mut results, chosen): (Vec<(Option<(f64, Evaluation)>, StartReport)>, _) = if finalists.is_empty() {
        // An exact fit already (or nothing to continue): pass 1 is the answer.
        (first.clone(), first_choice)
    } else {
        let results: Vec<_> = finalists
            .par_iter()
            .enumerate()
            .map(|(i, seed)| refine(objective, seed, search.max_evaluations, i, &exact_final))
            .collect();
        let chosen = choice(&results);
        (results, chosen)
    };
    // Report each finalist against the seed it came from.
    for (result, finalist) in results.iter_mut().zip(&finalists) {
        if let Some((_, origin)) = first.iter().find(|(b, _)| {
            b.as_ref().is_some_and(|(_, e)| e.routing_mm == finalist.routing_mm && e.tension_n == finalist.tension_n)
        }) {
            result.1.evaluations += origin.evaluations;
            result.1.seed_cost = origin.seed_cost;
            result.1.seed = origin.seed;
        }
    }
    let (cost, best) = chosen.ok_or(DesignError::NoSeed)?;
    results.sort_by(|p, q| p.1.cost.total_cmp(&q.1.cost));
    let starts: Vec<StartReport> = results.iter().map(|r| r.1.clone()).collect();
    Ok(DesignOutcome { best, cost, starts, seeds_simulated, seconds: started.elapsed().as_secs_f64() })
}

/// Per-component comparison of a design with its target.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComponentResult {
    /// Which component.
    pub component: Component,
    /// Requested value.
    pub target: f64,
    /// Achieved value.
    pub achieved: f64,
    /// 100 (achieved − target)/|target|, % (None for a zero target).
    pub error_pct: Option<f64>,
    /// Whether the component is met within the tolerance.
    pub met: bool,
}

/// Compares `eval` with the objective's target. A component is met when its
/// relative error is within `tolerance_pct`; a zero target is judged against
/// a natural scale instead (the rod length L for positions, 1/L for
/// curvature coefficients: one radian of bending over the rod).
pub fn compare(objective: &Objective, eval: &Evaluation, tolerance_pct: f64) -> Vec<ComponentResult> {
    let length = objective.actuator.length_mm;
    objective
        .target
        .components
        .iter()
        .map(|&(component, target)| {
            let achieved = eval.value(component).expect("order covers the target");
            let error_pct = super::target::error_pct(achieved, target);
            let met = match error_pct {
                Some(e) => e.abs() <= tolerance_pct,
                None => {
                    let scale = if matches!(component, Component::A(_)) { 1.0 / length } else { length };
                    (achieved - target).abs() <= tolerance_pct / 100.0 * scale
                }
            };
            ComponentResult { component, target, achieved, error_pct, met }
        })
        .collect()
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
    fn the_choice_is_the_first_exact_fit_else_the_least_cost() {
        let obj = objective();
        let mut sim = obj.simulator();
        let e = obj.evaluate(&mut sim, &[1.0, -2.0, 3.0, 0.5, -1.5].into(), 1.4).unwrap();
        let seed = Seed { routing_mm: e.routing_mm, tension_n: 1.4, source: SeedSource::Grid };
        let result = |cost: f64| {
            let report = StartReport { seed, seed_cost: 1.0, cost, evaluations: 1, termination: String::new() };
            (Some((cost, e.clone())), report)
        };
        let none = (None, StartReport { seed, seed_cost: 1.0, cost: f64::INFINITY, evaluations: 1, termination: String::new() });
        // A later, smaller exact fit does not win: the later start may have been stopped anywhere.
        let exact = [none.clone(), result(0.5), result(COST_FLOOR / 2.0), result(COST_FLOOR / 100.0)];
        assert_eq!(choice(&exact).unwrap().0, COST_FLOOR / 2.0);
        let inexact = [result(0.5), none.clone(), result(0.25), result(0.25)];
        assert_eq!(choice(&inexact).unwrap().0, 0.25);
        assert!(choice(&[none]).is_none());
    }

    #[test]
    fn a_design_does_not_depend_on_thread_timing() {
        let obj = objective();
        let search = SearchOptions { starts: 4, ..SearchOptions::default() };
        let runs: Vec<DesignOutcome> = (0..3).map(|_| design(&obj, &search, &[]).unwrap()).collect();
        for r in &runs[1..] {
            assert_eq!((r.best.routing_mm, r.best.tension_n, r.cost), (runs[0].best.routing_mm, runs[0].best.tension_n, runs[0].cost));
        }
    }

    #[test]
    fn the_unit_box_round_trips_and_stays_inside() {
        let obj = objective();
        let exact_fit = ExactFit::new();
        let p = Problem { objective: &obj, sim: obj.simulator(), best: None, evaluations: 0, max_evaluations: 10, index: 0, exact_fit: &exact_fit };
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
        let seed = |y: [f64; 5], t: f64| (0.0, Seed { routing_mm: y.into(), tension_n: t, source: SeedSource::Grid });
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
