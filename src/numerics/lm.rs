//! One bounded Levenberg–Marquardt minimiser for every nonlinear least-squares
//! problem of the library: the fit of EA, GA, EI and effects to measurements
//! (`calibrate::fit`) and the search for a routing and tension (eq. 3.17,
//! `design::optimise`).
//!
//! The step solves (JᵀJ + λ diag(JᵀJ)) δ = −Jᵀr by Cholesky (Marquardt's
//! scaling, with a floor so a column that vanishes still gets damped); λ is
//! divided by 5 after an accepted step and multiplied by 5 after a rejected
//! one. Box bounds are held by projection: a trial point is clamped into the
//! box, and a coordinate at its bound whose descent direction points outward
//! is held for that iteration so the others can settle (a bound-active
//! optimum, such as the thesis's Target II at τ = τ_u, is then reached
//! exactly instead of approached through a flattening transformation).
//!
//! Written here rather than taken from the `levenberg-marquardt` crate
//! because: a trial point whose model cannot be solved (a rod that collapses
//! at absurd rigidities, a routing the solver cannot follow) must simply be
//! rejected as a bad step, where the crate ends the whole minimisation; the
//! crate has no bounds; the noise-free fits need the stopping rule to run
//! down to rounding; and the problems own mutable state (a warm-started
//! simulator, an evaluation budget, the best point seen) that the crate's
//! `&self` problem would force behind `Cell`/`RefCell`.

use nalgebra::{DMatrix, DVector};

/// A least-squares problem: residuals r(x) whose sum of squares is minimised.
pub trait Problem {
    /// The residuals at `x` (every coordinate, free or not); `None` when the
    /// model cannot be evaluated there (the step is rejected).
    fn residuals(&mut self, x: &[f64]) -> Option<Vec<f64>>;

    /// The Jacobian of the residuals at `x` (where they are `r`) with respect
    /// to the coordinates `free`, one column each, in that order; `None`
    /// ends the minimisation ([`Termination::JacobianFailed`]).
    fn jacobian(&mut self, x: &[f64], r: &[f64], free: &[usize]) -> Option<DMatrix<f64>>;

    /// Whether to stop now (an evaluation budget spent, an exact fit found
    /// elsewhere); asked before every Jacobian and every trial point.
    fn stop(&mut self) -> bool {
        false
    }
}

/// What to minimise over and how long.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Box bounds (lower, upper) of every coordinate; infinite for none.
    pub bounds: Vec<(f64, f64)>,
    /// The coordinates that move; the others stay at their start.
    pub free: Vec<usize>,
    /// Most iterations (Jacobians).
    pub max_iterations: usize,
}

/// Why the minimisation ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Termination {
    /// No free coordinate: the start is the answer.
    NothingFree,
    /// No trial step lowers the cost, however damped: a minimum to within rounding.
    NoDescent,
    /// The cost is zero to within rounding.
    ZeroResidual,
    /// The last step lowered the cost by less than [`MIN_RELATIVE_REDUCTION`].
    SmallReduction,
    /// The last step moved no coordinate by more than [`MIN_STEP`].
    SmallStep,
    /// [`Settings::max_iterations`] reached.
    IterationCap,
    /// The problem asked to stop ([`Problem::stop`]).
    Stopped,
    /// The Jacobian could not be evaluated.
    JacobianFailed,
}

impl Termination {
    /// Whether the stopping rule was met (a minimum, not a cap or a stop).
    pub fn converged(self) -> bool {
        matches!(self, Termination::NothingFree | Termination::NoDescent | Termination::ZeroResidual | Termination::SmallReduction | Termination::SmallStep)
    }
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Termination::NothingFree => "nothing to fit",
            Termination::NoDescent => "converged: no step lowers the objective",
            Termination::ZeroResidual => "converged: zero residual",
            Termination::SmallReduction => "converged: relative reduction below 1e-12",
            Termination::SmallStep => "converged: step below 1e-11",
            Termination::IterationCap => "iteration cap reached",
            Termination::Stopped => "stopped",
            Termination::JacobianFailed => "the Jacobian could not be evaluated",
        })
    }
}

/// An accepted step, as reported to the observer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// Iterations done.
    pub iteration: usize,
    /// Sum of squared residuals after the step.
    pub cost: f64,
    /// Number of residuals.
    pub residuals: usize,
}

/// The end of a minimisation.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// The last accepted point.
    pub x: Vec<f64>,
    /// Its residuals.
    pub r: Vec<f64>,
    /// Its sum of squared residuals.
    pub cost: f64,
    /// Iterations (Jacobians) done.
    pub iterations: usize,
    /// Why it ended.
    pub termination: Termination,
}

/// A relative cost reduction below this ends the minimisation.
pub const MIN_RELATIVE_REDUCTION: f64 = 1e-12;
/// A step that moves no coordinate by more than this ends the minimisation.
pub const MIN_STEP: f64 = 1e-11;
/// Below this cost per residual the residuals are zero to within rounding.
const ZERO_COST_PER_RESIDUAL: f64 = 1e-24;
/// The damping at the start.
const LAMBDA_START: f64 = 1e-3;
/// Damping factor after a rejected step (its inverse after an accepted one).
const LAMBDA_FACTOR: f64 = 5.0;
/// No step is tried with more damping than this: the step is then below
/// rounding in every coordinate.
const LAMBDA_MAX: f64 = 1e12;
/// Within this of a bound a coordinate counts as on it.
const ON_BOUND: f64 = 1e-9;

/// Minimises Σ r² from `x` (where the residuals are `r`), calling `observe`
/// after every accepted step.
pub fn minimise(problem: &mut dyn Problem, x: Vec<f64>, r: Vec<f64>, settings: &Settings, observe: &mut dyn FnMut(Step)) -> Outcome {
    let (mut x, mut r) = (x, r);
    let n = r.len();
    let free = &settings.free;
    let bounds = &settings.bounds;
    let p = free.len();
    let mut cost: f64 = r.iter().map(|v| v * v).sum();
    let mut lambda = LAMBDA_START;
    let mut iterations = 0;
    let done = |x, r, cost, iterations, termination| Outcome { x, r, cost, iterations, termination };
    if p == 0 {
        return done(x, r, cost, iterations, Termination::NothingFree);
    }
    loop {
        if iterations >= settings.max_iterations {
            return done(x, r, cost, iterations, Termination::IterationCap);
        }
        if problem.stop() {
            return done(x, r, cost, iterations, Termination::Stopped);
        }
        iterations += 1;
        let Some(j) = problem.jacobian(&x, &r, free) else {
            return done(x, r, cost, iterations, Termination::JacobianFailed);
        };
        let rv = DVector::from_column_slice(&r);
        let mut a = j.transpose() * &j;
        let mut g = j.transpose() * rv;
        // A coordinate at its bound whose descent direction points outward
        // is held this iteration (a projected step), so the others can settle.
        for (k, &idx) in free.iter().enumerate() {
            let (lo, hi) = bounds[idx];
            if (x[idx] <= lo + ON_BOUND && g[k] > 0.0) || (x[idx] >= hi - ON_BOUND && g[k] < 0.0) {
                g[k] = 0.0;
                for c in 0..p {
                    a[(k, c)] = 0.0;
                    a[(c, k)] = 0.0;
                }
                a[(k, k)] = 1.0;
            }
        }
        let diag_floor = a.diagonal().max() * 1e-12 + 1e-300;
        let mut accepted = None;
        while lambda < LAMBDA_MAX {
            let mut m = a.clone();
            for k in 0..p {
                m[(k, k)] += lambda * a[(k, k)].max(diag_floor);
            }
            let Some(chol) = m.clone().cholesky() else {
                lambda *= LAMBDA_FACTOR;
                continue;
            };
            let mut step = chol.solve(&(-&g));
            // A step that would carry coordinates past their bounds puts them
            // on the bounds and is solved again for the others given that
            // move, so that the trial point is the damped model's best point
            // in the box's face rather than a clipped step.
            let past: Vec<usize> = (0..p).filter(|&k| step[k] != (x[free[k]] + step[k]).clamp(bounds[free[k]].0, bounds[free[k]].1) - x[free[k]]).collect();
            if !past.is_empty() && past.len() < p {
                let rest: Vec<usize> = (0..p).filter(|k| !past.contains(k)).collect();
                let moved: Vec<f64> = past.iter().map(|&k| (x[free[k]] + step[k]).clamp(bounds[free[k]].0, bounds[free[k]].1) - x[free[k]]).collect();
                let sub = DMatrix::from_fn(rest.len(), rest.len(), |i, c| m[(rest[i], rest[c])]);
                let rhs = DVector::from_fn(rest.len(), |i, _| -g[rest[i]] - past.iter().zip(&moved).map(|(&k, d)| m[(rest[i], k)] * d).sum::<f64>());
                if let Some(sub_step) = sub.cholesky().map(|c| c.solve(&rhs)) {
                    for (&k, d) in past.iter().zip(&moved) {
                        step[k] = *d;
                    }
                    for (i, &k) in rest.iter().enumerate() {
                        step[k] = sub_step[i];
                    }
                }
            }
            let mut trial = x.clone();
            for (k, &idx) in free.iter().enumerate() {
                trial[idx] = (x[idx] + step[k]).clamp(bounds[idx].0, bounds[idx].1);
            }
            let moved = trial.iter().zip(&x).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            if problem.stop() {
                return done(x, r, cost, iterations, Termination::Stopped);
            }
            match problem.residuals(&trial) {
                Some(rt) => {
                    let ct: f64 = rt.iter().map(|v| v * v).sum();
                    if ct < cost {
                        accepted = Some((trial, rt, ct, moved));
                        lambda = (lambda / LAMBDA_FACTOR).max(1e-12);
                        break;
                    }
                    lambda *= LAMBDA_FACTOR;
                }
                // A trial the model cannot solve is simply a bad step.
                None => lambda *= LAMBDA_FACTOR,
            }
        }
        let Some((trial, rt, ct, moved)) = accepted else {
            return done(x, r, cost, iterations, Termination::NoDescent);
        };
        let reduction = (cost - ct) / cost.max(1e-300);
        x = trial;
        r = rt;
        cost = ct;
        observe(Step { iteration: iterations, cost, residuals: n });
        let termination = if cost < ZERO_COST_PER_RESIDUAL * n as f64 {
            Termination::ZeroResidual
        } else if reduction < MIN_RELATIVE_REDUCTION {
            Termination::SmallReduction
        } else if moved < MIN_STEP {
            Termination::SmallStep
        } else {
            continue;
        };
        return done(x, r, cost, iterations, termination);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rosenbrock's valley as residuals (10 (y − x²), 1 − x), optionally
    /// refusing points with x > `wall`.
    struct Rosenbrock {
        wall: f64,
        evaluations: usize,
    }

    impl Problem for Rosenbrock {
        fn residuals(&mut self, x: &[f64]) -> Option<Vec<f64>> {
            self.evaluations += 1;
            (x[0] <= self.wall).then(|| vec![10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]])
        }

        fn jacobian(&mut self, x: &[f64], _r: &[f64], free: &[usize]) -> Option<DMatrix<f64>> {
            let full = DMatrix::from_row_slice(2, 2, &[-20.0 * x[0], 10.0, -1.0, 0.0]);
            Some(DMatrix::from_fn(2, free.len(), |i, k| full[(i, free[k])]))
        }
    }

    fn settings(bounds: Vec<(f64, f64)>) -> Settings {
        Settings { bounds, free: vec![0, 1], max_iterations: 200 }
    }

    fn run(problem: &mut Rosenbrock, settings: &Settings) -> Outcome {
        let x = vec![-1.2, 1.0];
        let r = problem.residuals(&x).unwrap();
        minimise(problem, x, r, settings, &mut |_| {})
    }

    #[test]
    fn finds_the_minimum_down_to_rounding() {
        let mut p = Rosenbrock { wall: f64::INFINITY, evaluations: 0 };
        let out = run(&mut p, &settings(vec![(f64::NEG_INFINITY, f64::INFINITY); 2]));
        assert!(out.termination.converged(), "{:?}", out.termination);
        assert!((out.x[0] - 1.0).abs() < 1e-10 && (out.x[1] - 1.0).abs() < 1e-10, "{:?}", out.x);
    }

    #[test]
    fn a_bound_active_minimum_is_reached_exactly() {
        let mut p = Rosenbrock { wall: f64::INFINITY, evaluations: 0 };
        let out = run(&mut p, &settings(vec![(-2.0, 0.5), (-2.0, 2.0)]));
        assert!(out.termination.converged(), "{:?}", out.termination);
        assert_eq!(out.x[0], 0.5);
        assert!((out.x[1] - 0.25).abs() < 1e-10, "{:?}", out.x);
    }

    #[test]
    fn unsolvable_trial_points_are_rejected_not_fatal() {
        // Points beyond x = 0.9 cannot be evaluated: the minimum on the
        // solvable side is approached from the left.
        let mut p = Rosenbrock { wall: 0.9, evaluations: 0 };
        let out = run(&mut p, &settings(vec![(f64::NEG_INFINITY, f64::INFINITY); 2]));
        assert!(out.x[0] <= 0.9 && out.cost < 0.02, "{out:?}");
    }

    #[test]
    fn held_coordinates_stay_and_stop_is_obeyed() {
        let mut p = Rosenbrock { wall: f64::INFINITY, evaluations: 0 };
        let s = Settings { free: vec![1], ..settings(vec![(f64::NEG_INFINITY, f64::INFINITY); 2]) };
        let out = run(&mut p, &s);
        assert_eq!(out.x[0], -1.2);
        assert!((out.x[1] - 1.44).abs() < 1e-10 && out.termination.converged(), "{out:?}");

        struct Budget(Rosenbrock);
        impl Problem for Budget {
            fn residuals(&mut self, x: &[f64]) -> Option<Vec<f64>> {
                self.0.residuals(x)
            }
            fn jacobian(&mut self, x: &[f64], r: &[f64], free: &[usize]) -> Option<DMatrix<f64>> {
                self.0.jacobian(x, r, free)
            }
            fn stop(&mut self) -> bool {
                self.0.evaluations >= 5
            }
        }
        let mut b = Budget(Rosenbrock { wall: f64::INFINITY, evaluations: 0 });
        let x = vec![-1.2, 1.0];
        let r = b.residuals(&x).unwrap();
        let out = minimise(&mut b, x, r, &settings(vec![(f64::NEG_INFINITY, f64::INFINITY); 2]), &mut |_| {});
        assert_eq!(out.termination, Termination::Stopped);
        assert_eq!(b.0.evaluations, 5);
    }
}
