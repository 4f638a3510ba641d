//! One start: bounded Levenberg–Marquardt from one seed, keeping the best
//! point it saw (a rejected trial point may be the best seen), stopped by an
//! exact fit here or in an earlier start, its budget, or a stall.

use super::{ExactFit, Problem, Seed, StartReport, Termination, COST_FLOOR};
use crate::numerics::lm;
use nalgebra::DMatrix;

/// The best point a start saw: its cost, unit-box point and solution.
pub type Best<S> = (f64, Vec<f64>, S);

/// One start in progress: the problem, its worker and what it has seen.
pub struct Start<'a, P: Problem> {
    /// The problem.
    pub problem: &'a P,
    /// This start's solver state.
    pub worker: P::Worker,
    /// The best point seen.
    pub best: Option<Best<P::Solution>>,
    /// Model solves so far.
    pub evaluations: usize,
    budget: usize,
    /// This start's place in its pass (the seeds' order).
    index: usize,
    /// Shared by a pass's starts: the lowest index that fitted exactly.
    exact_fit: &'a ExactFit,
    /// The best cost at each Jacobian (for the stalling rule).
    history: Vec<f64>,
}

impl<'a, P: Problem> Start<'a, P> {
    /// A start of `problem` with its own worker.
    pub fn new(problem: &'a P, budget: usize, index: usize, exact_fit: &'a ExactFit) -> Self {
        Self { problem, worker: problem.worker(), best: None, evaluations: 0, budget, index, exact_fit, history: Vec::new() }
    }

    /// Solves at `x` and keeps it when it is the best point seen.
    pub fn evaluate(&mut self, x: &[f64]) -> Option<(Vec<f64>, P::Solution)> {
        let (r, solution) = self.problem.solve(&mut self.worker, x, &mut self.evaluations)?;
        let cost: f64 = r.iter().map(|v| v * v).sum();
        if cost.is_finite() && self.best.as_ref().is_none_or(|b| cost < b.0) {
            self.best = Some((cost, x.to_vec(), solution.clone()));
        }
        Some((r, solution))
    }

    fn best_cost(&self) -> f64 {
        self.best.as_ref().map_or(f64::INFINITY, |b| b.0)
    }

    fn stalled(&self) -> bool {
        let Some(s) = self.problem.stall() else { return false };
        let h = &self.history;
        h.len() > s.iterations && h[h.len() - 1] > (1.0 - s.fraction) * h[h.len() - 1 - s.iterations]
    }
}

impl<P: Problem> lm::Problem for Start<'_, P> {
    fn residuals(&mut self, x: &[f64]) -> Option<Vec<f64>> {
        self.evaluate(x).map(|r| r.0)
    }

    fn jacobian(&mut self, x: &[f64], r: &[f64], free: &[usize]) -> Option<DMatrix<f64>> {
        let cost = self.best_cost();
        self.history.push(cost);
        P::jacobian(self, x, r, free)
    }

    /// Exact fit here or in an earlier start, out of budget, or stalled:
    /// the best design seen is kept.
    fn stop(&mut self) -> bool {
        let exact = self.best_cost() <= COST_FLOOR;
        if exact {
            self.exact_fit.record(self.index);
        }
        exact || self.exact_fit.before(self.index) || self.evaluations >= self.budget || self.stalled()
    }
}

/// Refines `seed` with bounded Levenberg–Marquardt within `budget` solves;
/// returns the best point it saw (None if not even the seed could be
/// solved) and its report. `index` is the start's place in its pass and
/// `exact_fit` is shared by the pass's parallel starts (see [`ExactFit`]).
pub fn refine<P: Problem>(problem: &P, seed: &Seed, budget: usize, index: usize, exact_fit: &ExactFit) -> (Option<Best<P::Solution>>, StartReport) {
    let mut start = Start::new(problem, budget, index, exact_fit);
    let first = if lm::Problem::stop(&mut start) { None } else { start.evaluate(&seed.point) };
    let seed_cost = first.as_ref().map_or(f64::INFINITY, |r| r.0.iter().map(|v| v * v).sum());
    let ending = match first {
        Some((r, _)) => Termination::Minimiser(lm::minimise(&mut start, seed.point.clone(), r, &problem.settings(), &mut |_| {}).termination),
        None => Termination::Unsolvable,
    };
    let cost = start.best_cost();
    // Our own stops, named.
    let termination = if cost <= COST_FLOOR {
        Termination::ExactFit
    } else if exact_fit.before(index) {
        Termination::EarlierStartFitted
    } else if start.evaluations >= budget {
        Termination::Budget
    } else if start.stalled() {
        Termination::Stalled(problem.stall().expect("stalled only with a stalling rule"))
    } else {
        ending
    };
    let report = StartReport { seed: seed.point.clone(), source: seed.source, seed_cost, cost, evaluations: start.evaluations, termination };
    (start.best, report)
}
