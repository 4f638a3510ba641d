//! The 3-D fit: rigidities (EI, EA, GA, GJ), the weight (density) and any
//! registry effect, fitted to body-fixed markers of several-cable captures
//! by the one bounded Levenberg–Marquardt ([`crate::numerics::lm`]).
//!
//! Residuals are the markers' 3-D errors, each coordinate divided by the
//! marker's noise σ = √(sd² + σ₀²) (its frame-to-frame s.d. from the file
//! and the system's error σ₀, which a frame-to-frame s.d. does not
//! contain). Parameters are fitted in logs (an effect in its registry
//! coordinate). The Jacobian is by one-sided differences, its columns in
//! parallel. A parameter the data do not determine — its column vanishes at
//! the start, or its fitted standard error spans more than a factor e, or
//! it runs to its bound — is held at its start and reported so, and the
//! others are fitted again without it.

use super::errors::ErrorReport;
use super::files::CaptureSet;
use super::simulate::{solve_captures, CaptureSolution};
use crate::calibrate::fit::Loss;
use crate::calibrate::{stats, CalibrateError, Parameter};
use crate::model::effects::Domain;
use crate::solver::SolverOptions;
use crate::model::Actuator;
use crate::numerics::lm;
use nalgebra::DMatrix;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use serde::Serialize;

/// What a 3-D fit fits and how.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit3Spec {
    /// Parameters to fit (those the data do not determine are held).
    pub params: Vec<Parameter>,
    /// The system's noise σ₀ per coordinate, mm, added in quadrature to a
    /// marker's own `sd_mm`.
    pub noise_mm: f64,
    /// Loss on the whitened residuals.
    pub loss: Loss,
    /// Most Levenberg–Marquardt iterations.
    pub max_iterations: usize,
    /// The 3-D solver's settings.
    pub options: SolverOptions,
}

impl Default for Fit3Spec {
    fn default() -> Self {
        Self { params: Parameter::BODY.to_vec(), noise_mm: 1.0, loss: Loss::Squared, max_iterations: 40, options: SolverOptions::default() }
    }
}

/// How a parameter ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Fitted.
    Fitted,
    /// Asked for, but the data do not determine it: held at its start.
    Undetermined,
    /// An effect run to a bound of its search range (toward its thesis
    /// value, or past any plausible size): the data do not call for it.
    AtBound,
}

/// One parameter of a 3-D fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Fitted3 {
    /// Name with unit.
    pub name: String,
    /// The parameter.
    #[serde(skip)]
    pub param: Parameter,
    /// Value (fitted, or the start when undetermined).
    pub value: f64,
    /// The starting value.
    pub start: f64,
    /// Standard error (same unit; NaN when undetermined).
    pub se: f64,
    /// Fitted or undetermined.
    pub status: Status,
}

/// The result of a 3-D fit; serialises to `fit.json`'s fit fields.
#[derive(Debug, Clone, Serialize)]
pub struct Fit3Result {
    /// The parameters asked for, fitted or held.
    pub parameters: Vec<Fitted3>,
    /// Correlations of the fitted parameters (order of `parameters`; NaN with a held one).
    pub correlation: Vec<Vec<f64>>,
    /// χ² = Σ z² of the whitened marker coordinates.
    pub chi2: f64,
    /// Its degrees of freedom: residuals less fitted parameters.
    pub dof: usize,
    /// χ²/dof.
    pub reduced_chi2: f64,
    /// P(χ²_dof ≥ χ²) under the stated noise.
    pub p_value: f64,
    /// The minimised loss Σ ρ(z).
    pub loss: f64,
    /// Residuals (3 per marker reading).
    pub n_residuals: usize,
    /// BIC = n ln(Σρ/n) + p ln n.
    pub bic: f64,
    /// Levenberg–Marquardt iterations (over every round).
    pub iterations: usize,
    /// Whether the last round met the stopping rule.
    pub converged: bool,
    /// Why it stopped, in words.
    pub termination: String,
    /// The noise σ₀ added to each marker's own, mm.
    pub noise_mm: f64,
    /// The marker errors at the fitted values.
    #[serde(flatten)]
    pub errors: ErrorReport,
    /// The fitted actuator.
    #[serde(skip)]
    pub actuator: Actuator,
    /// The solutions at the fitted values.
    #[serde(skip)]
    pub solutions: Vec<CaptureSolution>,
}

impl Fit3Result {
    /// A fitted (or held) parameter by kind.
    pub fn parameter(&self, p: Parameter) -> Option<&Fitted3> {
        self.parameters.iter().find(|f| f.param == p)
    }
}

/// The fit problem over the free parameters.
struct Problem<'a> {
    base: &'a Actuator,
    set: &'a CaptureSet,
    spec: &'a Fit3Spec,
    params: Vec<Parameter>,
    sigma: Vec<f64>,
    /// The relative cost reduction of the last accepted step (f64 bits):
    /// below [`ENOUGH_REDUCTION`] the fit stops.
    last_reduction: &'a AtomicU64,
    /// The last Jacobian (point, free columns, matrix): the fit's first
    /// iteration takes the one the check of negligible columns made.
    last_jacobian: Mutex<Option<(Vec<f64>, Vec<usize>, DMatrix<f64>)>>,
}

impl Problem<'_> {
    fn actuator(&self, x: &[f64]) -> Actuator {
        let mut a = self.base.clone();
        for (p, &xi) in self.params.iter().zip(x) {
            p.set(&mut a, p.from_internal(xi));
        }
        a
    }

    fn evaluate(&self, x: &[f64]) -> Result<(Vec<f64>, Vec<CaptureSolution>), CalibrateError> {
        let a = self.actuator(x);
        a.rod.validate().map_err(CalibrateError::from)?;
        let sols = solve_captures(&a, &self.spec.options, self.set)?;
        let mut z = Vec::with_capacity(self.sigma.len());
        for (i, c) in self.set.captures.iter().enumerate() {
            if let Some(ms) = self.set.markers.get(&c.measurement) {
                for (m, sim) in ms.iter().zip(&sols[i].markers_mm) {
                    for k in 0..3 {
                        z.push(sim[k] - m.measured_mm[k]);
                    }
                }
            }
        }
        for (v, s) in z.iter_mut().zip(&self.sigma) {
            *v /= s;
        }
        Ok((z, sols))
    }

    fn transformed(&self, x: &[f64]) -> Result<Vec<f64>, CalibrateError> {
        self.evaluate(x).map(|(z, _)| z.into_iter().map(|v| self.spec.loss.transform(v)).collect())
    }

    /// One-sided differences, columns in parallel; a column whose step
    /// cannot be solved is tried the other way, then smaller.
    fn differences(&self, x: &[f64], r: &[f64], free: &[usize]) -> Option<DMatrix<f64>> {
        let columns: Vec<Option<Vec<f64>>> = free
            .par_iter()
            .map(|&j| {
                for h in [1e-5, 1e-6] {
                    for sign in [1.0, -1.0] {
                        let mut xh = x.to_vec();
                        xh[j] += sign * h;
                        if let Ok(rh) = self.transformed(&xh) {
                            return Some(rh.iter().zip(r).map(|(a, b)| (a - b) / (sign * h)).collect());
                        }
                    }
                }
                None
            })
            .collect();
        let columns: Vec<Vec<f64>> = columns.into_iter().collect::<Option<_>>()?;
        let j = DMatrix::from_fn(r.len(), free.len(), |i, k| columns[k][i]);
        *self.last_jacobian.lock().expect("not poisoned") = Some((x.to_vec(), free.to_vec(), j.clone()));
        Some(j)
    }

    /// The Jacobian at `x` over `free`: the last one made when it was made
    /// there (for these columns or more), else by [`Problem::differences`].
    fn jacobian_at(&self, x: &[f64], r: &[f64], free: &[usize]) -> Option<DMatrix<f64>> {
        let last = self.last_jacobian.lock().expect("not poisoned").clone();
        if let Some((at, columns, j)) = last {
            let picked: Option<Vec<usize>> = free.iter().map(|k| columns.iter().position(|c| c == k)).collect();
            if let (true, Some(picked)) = (at.as_slice() == x, picked) {
                return Some(DMatrix::from_fn(j.nrows(), picked.len(), |i, c| j[(i, picked[c])]));
            }
        }
        self.differences(x, r, free)
    }
}

impl lm::Problem for Problem<'_> {
    fn stop(&mut self) -> bool {
        f64::from_bits(self.last_reduction.load(Ordering::Relaxed)) < ENOUGH_REDUCTION
    }

    fn residuals(&mut self, x: &[f64]) -> Option<Vec<f64>> {
        self.transformed(x).ok()
    }

    fn jacobian(&mut self, x: &[f64], r: &[f64], free: &[usize]) -> Option<DMatrix<f64>> {
        self.jacobian_at(x, r, free)
    }
}

/// An accepted step that lowers the cost by less than this share ends the
/// fit as converged: each further step re-solves every capture several
/// times for a change far below the standard errors (near the optimum the
/// cost is quadratic: a 1e-6 share of χ² ≈ dof is a hundredth of σ).
const ENOUGH_REDUCTION: f64 = 1e-6;

/// Parameters may move this factor either way from their start.
const RANGE: f64 = 100.0;
/// A positive effect parameter may move this factor either way from its start.
const EFFECT_RANGE: f64 = 1e4;
/// Bound of a signed effect parameter (a channel offset in mm, a stiffness gradient's β).
const EFFECT_SIGNED_BOUND: f64 = 10.0;
/// Bound of a fraction's logit (f from 3e-7 to 1 − 3e-7).
const EFFECT_LOGIT_BOUND: f64 = 15.0;
/// A fitted parameter whose standard error in its log spans more than this
/// (a factor e) is undetermined.
const UNDETERMINED_LOG_SE: f64 = 1.0;
/// A column of the starting Jacobian below this share of the largest is a
/// parameter the data do not feel.
const NEGLIGIBLE_COLUMN: f64 = 1e-6;

/// Fits `spec.params` of `base` to the markers of `set`.
pub fn fit_captures(base: &Actuator, set: &CaptureSet, spec: &Fit3Spec, observe: &mut dyn FnMut(lm::Step)) -> Result<Fit3Result, CalibrateError> {
    if !(spec.noise_mm.is_finite() && spec.noise_mm > 0.0) {
        return Err(crate::calibrate::NoiseError::Markers { value: spec.noise_mm }.into());
    }
    base.channels().map_err(|e| CalibrateError::Actuator(e.into()))?;
    let mut params: Vec<Parameter> = Vec::new();
    for &p in &spec.params {
        if p == Parameter::Density && !base.rod.gravity.enabled {
            return Err(crate::calibrate::InvalidRequest::DensityWithoutGravity.into());
        }
        if !params.contains(&p) {
            params.push(p);
        }
    }
    let sigma: Vec<f64> = set
        .readings()
        .flat_map(|(_, m)| {
            let s = (m.sd_mm.unwrap_or(0.0).powi(2) + spec.noise_mm.powi(2)).sqrt();
            [s; 3]
        })
        .collect();
    let start: Vec<f64> = params.iter().map(|p| p.to_internal(p.get(base))).collect();
    let bounds: Vec<(f64, f64)> = params
        .iter()
        .zip(&start)
        .map(|(p, &x)| match p {
            // An effect that the data do not call for runs toward its
            // thesis value (0, or an infinitely stiff clamp): bounded near
            // where it no longer matters, so the fit does not spend steps on the way.
            Parameter::Effect(e) => match e.fit().domain {
                Domain::Signed => (-EFFECT_SIGNED_BOUND, EFFECT_SIGNED_BOUND),
                Domain::Fraction => (-EFFECT_LOGIT_BOUND, EFFECT_LOGIT_BOUND),
                Domain::Positive => (x - EFFECT_RANGE.ln(), x + EFFECT_RANGE.ln()),
            },
            _ => (x - RANGE.ln(), x + RANGE.ln()),
        })
        .collect();
    let last_reduction = AtomicU64::new(f64::INFINITY.to_bits());
    let problem = Problem { base, set, spec, params: params.clone(), sigma, last_reduction: &last_reduction, last_jacobian: Mutex::new(None) };
    let n = problem.sigma.len();
    let r0 = problem.transformed(&start)?;
    let mut free: Vec<usize> = (0..params.len()).collect();
    // Parameters the data do not feel at all are held from the start.
    if let Some(j0) = problem.differences(&start, &r0, &free) {
        let norms: Vec<f64> = (0..free.len()).map(|k| j0.column(k).norm()).collect();
        let top = norms.iter().cloned().fold(0.0, f64::max);
        free.retain(|&k| norms[k] > NEGLIGIBLE_COLUMN * top);
    }
    if n <= free.len() {
        return Err(crate::calibrate::InvalidRequest::TooFewMarkerCoordinates { coordinates: n, parameters: free.len() }.into());
    }
    let mut problem = problem;
    let mut iterations = 0;
    let mut round_start = start.clone();
    let mut r = r0;
    let (x, r, cost, termination, cov_free, z, solutions) = loop {
        let settings = lm::Settings { bounds: bounds.clone(), free: free.clone(), max_iterations: spec.max_iterations };
        last_reduction.store(f64::INFINITY.to_bits(), Ordering::Relaxed);
        let mut previous = r.iter().map(|v| v * v).sum::<f64>();
        let outcome = lm::minimise(&mut problem, round_start.clone(), r.clone(), &settings, &mut |step| {
            last_reduction.store(((previous - step.cost) / previous.max(1e-300)).to_bits(), Ordering::Relaxed);
            previous = step.cost;
            observe(step)
        });
        iterations += outcome.iterations;
        let x = outcome.x;
        let (z, solutions) = problem.evaluate(&x)?;
        let chi2: f64 = z.iter().map(|v| v * v).sum();
        let p = free.len();
        let s2 = chi2 / (n - p).max(1) as f64;
        let cov = problem
            .jacobian_at(&x, &outcome.r, &free)
            .and_then(|j| (j.transpose() * j).try_inverse())
            .map(|inv| inv * s2);
        // Which free parameters the data do not determine.
        let bad: Vec<usize> = free
            .iter()
            .enumerate()
            .filter(|&(k, &idx)| {
                if matches!(params[idx], Parameter::Effect(_)) {
                    // Reported at its bound, not held: see `Status::AtBound`.
                    return false;
                }
                let (lo, hi) = bounds[idx];
                let at_bound = x[idx] <= lo + 1e-9 || x[idx] >= hi - 1e-9;
                let log_se = cov.as_ref().map_or(f64::INFINITY, |c| c[(k, k)].max(0.0).sqrt());
                at_bound || !(log_se <= UNDETERMINED_LOG_SE)
            })
            .map(|(_, &idx)| idx)
            .collect();
        if bad.is_empty() || free.len() == bad.len() {
            break (x, outcome.r, outcome.cost, outcome.termination, cov, z, solutions);
        }
        // Hold the worst-determined one at its start and fit the rest again.
        let worst = *bad.last().expect("not empty");
        free.retain(|&k| k != worst);
        round_start = x;
        round_start[worst] = start[worst];
        r = problem.transformed(&round_start)?;
    };
    let actuator = problem.actuator(&x);
    let p = free.len();
    let total = params.len();
    let cov_of = |a: usize, b: usize| -> f64 {
        let (Some(ka), Some(kb)) = (free.iter().position(|&k| k == a), free.iter().position(|&k| k == b)) else {
            return f64::NAN;
        };
        cov_free.as_ref().map_or(f64::INFINITY, |c| c[(ka, kb)])
    };
    let parameters: Vec<Fitted3> = params
        .iter()
        .enumerate()
        .map(|(k, &param)| {
            let fitted = free.contains(&k);
            let v = cov_of(k, k);
            Fitted3 {
                name: param.name().to_string(),
                param,
                value: param.from_internal(x[k]),
                start: param.from_internal(start[k]),
                se: if fitted { param.derivative(x[k]).abs() * v.max(0.0).sqrt() } else { f64::NAN },
                status: match (fitted, param) {
                    (false, _) => Status::Undetermined,
                    (true, Parameter::Effect(_)) if x[k] <= bounds[k].0 + 1e-9 || x[k] >= bounds[k].1 - 1e-9 => Status::AtBound,
                    _ => Status::Fitted,
                },
            }
        })
        .collect();
    let correlation = (0..total)
        .map(|a| (0..total).map(|b| cov_of(a, b) / (cov_of(a, a) * cov_of(b, b)).sqrt()).collect())
        .collect();
    let chi2: f64 = z.iter().map(|v| v * v).sum();
    let dof = n - p;
    let nf = n as f64;
    let _ = r;
    Ok(Fit3Result {
        parameters,
        correlation,
        chi2,
        dof,
        reduced_chi2: chi2 / dof as f64,
        p_value: stats::chi2_p_value(chi2, dof),
        loss: cost,
        n_residuals: n,
        bic: nf * (cost / nf).max(1e-300).ln() + p as f64 * nf.ln(),
        iterations,
        converged: termination.converged() || termination == lm::Termination::Stopped,
        termination: if termination == lm::Termination::Stopped {
            format!("converged: the last step lowered the cost by less than {ENOUGH_REDUCTION:e} of it")
        } else {
            termination.to_string()
        },
        noise_mm: spec.noise_mm,
        errors: ErrorReport::of(set, &solutions),
        actuator,
        solutions,
    })
}
