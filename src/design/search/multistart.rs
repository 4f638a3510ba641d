//! The multi-start: the problem's seeds, refined in parallel (after a short
//! exploration pass when the problem explores), and the first exact fit,
//! else the least cost (ties to the earlier start): the same answer on every
//! run and thread count.

use super::start::{refine, Best};
use super::{ExactFit, Problem, Seed, SearchOptions, StartReport, COST_FLOOR};
use crate::design::DesignError;
use rayon::prelude::*;
use std::time::Instant;

/// The search's best design.
#[derive(Debug, Clone)]
pub struct Found<S> {
    /// Its unit-box point.
    pub x: Vec<f64>,
    /// Its solution.
    pub solution: S,
    /// Its cost.
    pub cost: f64,
    /// Every converging start: best first after an exploration, else in start order.
    pub starts: Vec<StartReport>,
    /// Designs simulated to seed the search.
    pub seeds_simulated: usize,
    /// Wall time, s.
    pub seconds: f64,
}

type Refined<S> = (Option<Best<S>>, StartReport);

/// The design a pass yields, from its results in start order: the first
/// start that fitted exactly, else the least cost (ties to the earlier
/// start). Starts after the first exact fit may have been stopped at any
/// point, so they never decide.
fn choice<S: Clone>(results: &[Refined<S>]) -> Option<Best<S>> {
    let found = results.iter().filter_map(|r| r.0.as_ref());
    match found.clone().find(|b| b.0 <= COST_FLOOR) {
        Some(exact) => Some(exact.clone()),
        None => found
            .fold(None, |best: Option<&Best<S>>, r| match best {
                Some(b) if b.0 <= r.0 => Some(b),
                _ => Some(r),
            })
            .cloned(),
    }
}

/// One pass: every seed refined within `budget`, in parallel.
fn pass<P: Problem>(problem: &P, seeds: &[Seed], budget: usize) -> (Vec<Refined<P::Solution>>, ExactFit) {
    let exact_fit = ExactFit::new();
    let results = seeds.par_iter().enumerate().map(|(i, seed)| refine(problem, seed, budget, i, &exact_fit)).collect();
    (results, exact_fit)
}

/// Searches `problem`: `options.starts` seeds refined to convergence, or,
/// when the problem explores, that many times more seeds looked at briefly
/// and the best `options.starts` of them (distinct channels) continued.
pub fn search<P: Problem>(problem: &P, options: &SearchOptions) -> Result<Found<P::Solution>, DesignError> {
    let started = Instant::now();
    if options.starts == 0 {
        return Err(DesignError::NoStarts);
    }
    let exploration = problem.exploration();
    let count = exploration.map_or(options.starts, |e| e.seeds_per_start * options.starts);
    let seeds = problem.seeds(count)?;
    if seeds.seeds.is_empty() {
        return Err(DesignError::NoSeed);
    }
    let budget = problem.budget(options.max_evaluations);
    let (mut results, chosen) = match exploration {
        None => {
            let (results, _) = pass(problem, &seeds.seeds, budget);
            let chosen = choice(&results);
            (results, chosen)
        }
        Some(e) => {
            let (mut first, exact_first) = pass(problem, &seeds.seeds, e.evaluations);
            let first_choice = choice(&first);
            first.sort_by(|p, q| p.1.cost.total_cmp(&q.1.cost));
            // The most promising, continuing from where the first pass stopped.
            let mut finalists: Vec<(usize, Seed)> = Vec::new();
            if !exact_first.any() {
                for (i, (best, report)) in first.iter().enumerate() {
                    if finalists.len() == options.starts {
                        break;
                    }
                    let Some((_, x, solution)) = best else { continue };
                    let point = problem.resume_point(x, solution);
                    if !finalists.iter().any(|(_, f)| problem.same_channels(&f.point, &point)) {
                        finalists.push((i, Seed { point, source: report.source }));
                    }
                }
            }
            if finalists.is_empty() {
                // An exact fit already (or nothing to continue): the first pass is the answer.
                (first, first_choice)
            } else {
                let finalist_seeds: Vec<Seed> = finalists.iter().map(|f| f.1.clone()).collect();
                let (mut results, _) = pass(problem, &finalist_seeds, budget);
                let chosen = choice(&results);
                // Each finalist reported against the seed it came from.
                for (result, (origin, _)) in results.iter_mut().zip(&finalists) {
                    let origin = &first[*origin].1;
                    result.1.evaluations += origin.evaluations;
                    result.1.seed_cost = origin.seed_cost;
                    result.1.seed = origin.seed.clone();
                    result.1.source = origin.source;
                }
                (results, chosen)
            }
        }
    };
    let (cost, x, solution) = chosen.ok_or(DesignError::NoSeed)?;
    if exploration.is_some() {
        results.sort_by(|p, q| p.1.cost.total_cmp(&q.1.cost));
    }
    let starts = results.into_iter().map(|r| r.1).collect();
    Ok(Found { x, solution, cost, starts, seeds_simulated: seeds.simulated, seconds: started.elapsed().as_secs_f64() })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::search::{SeedSource, Termination};

    #[test]
    fn the_choice_is_the_first_exact_fit_else_the_least_cost() {
        let report = |cost: f64| StartReport { seed: vec![0.0], source: SeedSource::Grid, seed_cost: 1.0, cost, evaluations: 1, termination: Termination::Budget };
        let result = |cost: f64| (Some((cost, vec![cost], ())), report(cost));
        let none: Refined<()> = (None, report(f64::INFINITY));
        // A later, smaller exact fit does not win: the later start may have been stopped anywhere.
        let exact = [none.clone(), result(0.5), result(COST_FLOOR / 2.0), result(COST_FLOOR / 100.0)];
        assert_eq!(choice(&exact).unwrap().0, COST_FLOOR / 2.0);
        let inexact = [result(0.5), none.clone(), result(0.25), result(0.25)];
        assert_eq!(choice(&inexact).unwrap().0, 0.25);
        assert!(choice(&[none]).is_none());
    }
}
