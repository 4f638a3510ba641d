//! The one fit of calibrate and diagnose: parameters of an actuator (the
//! rigidities, the weight, registry effects) fitted to observations of any
//! kind ([`Observations`]: planar measurement files, captures with 3-D
//! markers) by the library's one bounded Levenberg–Marquardt
//! ([`crate::numerics::lm`], shared with design).
//!
//! Every residual is simulated minus measured over its noise σ (the kind
//! says how, in [`Observations::whitened`]); the fit minimises Σ ρ(z) with
//! Huber's ρ (quadratic up to `k` σ, linear beyond: a couple of bad readings
//! cannot pull the fit over) or plain squares. Parameters move in
//! unconstrained coordinates (logs of the rigidities and the density, an
//! effect's registry coordinate) within bounds around their start. The
//! Jacobian is by one-sided differences, its columns in parallel; a step
//! the model cannot solve is tried the other way, then smaller. Standard
//! errors come from the Jacobian at the optimum, mapped to the parameters
//! by the delta method; correlations from the same matrix.
//!
//! What differs between kinds of data is stated by each kind as its
//! [`FitRules`] (the difference steps, the bounds, how the covariance is
//! estimated, whether undetermined parameters are held and the rest fitted
//! again, an early stop), never by a second fit.

use super::{CalibrateError, Parameter};
use crate::model::effects::Domain;
use crate::model::Actuator;
use crate::numerics::lm;
use nalgebra::DMatrix;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

/// The loss on whitened residuals z.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Loss {
    /// Σ z²: ordinary least squares.
    Squared,
    /// Huber: z² up to `k`, 2k|z| − k² beyond (`k` in σ).
    Huber {
        /// Where the loss turns linear, in σ.
        k: f64,
    },
}

impl Default for Loss {
    fn default() -> Self {
        Loss::Huber { k: 3.0 }
    }
}

impl Loss {
    /// The residual whose square is the loss of `z` (sign kept), so that a
    /// least-squares solver minimises Σ ρ.
    pub(crate) fn transform(self, z: f64) -> f64 {
        match self {
            Loss::Squared => z,
            Loss::Huber { k } if z.abs() > k => z.signum() * (2.0 * k * z.abs() - k * k).sqrt(),
            Loss::Huber { .. } => z,
        }
    }

    /// A short description for reports.
    pub fn describe(self) -> String {
        match self {
            Loss::Squared => "least squares".into(),
            Loss::Huber { k } => format!("Huber loss (quadratic up to {k} σ, linear beyond)"),
        }
    }
}

/// What to fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSpec {
    /// The parameters, in report order.
    pub params: Vec<Parameter>,
    /// Of `params`, those held at the start's value: reported, not fitted.
    pub held: Vec<Parameter>,
    /// Loss on the whitened residuals.
    pub loss: Loss,
    /// Most Levenberg–Marquardt iterations (per round).
    pub max_iterations: usize,
}

impl FitSpec {
    /// The same fit with `effects` (in order) in place of any effect it fits.
    pub fn with_effects(&self, effects: &[super::Effect]) -> FitSpec {
        let mut params: Vec<Parameter> = self.params.iter().copied().filter(|p| !matches!(p, Parameter::Effect(_))).collect();
        params.extend(effects.iter().map(|&e| Parameter::Effect(e)));
        FitSpec { params, ..self.clone() }
    }

    /// The effects fitted, in order.
    pub fn effects(&self) -> Vec<super::Effect> {
        self.params
            .iter()
            .filter_map(|p| match p {
                Parameter::Effect(e) => Some(*e),
                _ => None,
            })
            .collect()
    }
}

/// How a parameter ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Fitted.
    Fitted,
    /// Held at its given value, as asked ([`FitSpec::held`]).
    Held,
    /// Asked for, but the data do not determine it: held at its start.
    Undetermined,
    /// An effect run to a bound of its search range (toward its thesis
    /// value, or past any plausible size): the data do not call for it.
    AtBound,
}

/// One parameter of a fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FittedParameter {
    /// Name with unit (`ea_n`, an effect's parameter, …).
    pub name: String,
    /// The parameter.
    pub param: Parameter,
    /// Value (fitted, or the start when held).
    pub value: f64,
    /// The starting value.
    pub start: f64,
    /// Standard error (same unit): 0 when held as asked, NaN when
    /// undetermined, ∞ when the data cannot bound it.
    pub se: f64,
    /// How it ended.
    pub status: Status,
}

/// What a kind of data reports of a fit beyond what every fit reports; it
/// serialises (flattened) into the fit's JSON object, and says how a
/// parameter is written there.
pub trait FitReport: Serialize + Clone + std::fmt::Debug + Send + Sync {
    /// Writes `parameters` as the JSON's `parameters` list.
    fn serialize_parameters<S: serde::Serializer>(parameters: &[FittedParameter], serializer: S) -> Result<S::Ok, S::Error>;
}

fn serialize_parameters<R: FitReport, S: serde::Serializer>(parameters: &[FittedParameter], serializer: S) -> Result<S::Ok, S::Error> {
    R::serialize_parameters(parameters, serializer)
}

/// The result of a fit. It serialises to the fit's JSON object: the fields
/// every fit has and those of its kind's report `R`.
#[derive(Debug, Clone, Serialize)]
#[serde(bound(serialize = "R: FitReport"))]
pub struct FitResult<R: FitReport> {
    /// The parameters, fitted or held, in the spec's order.
    #[serde(serialize_with = "serialize_parameters::<R, _>")]
    pub parameters: Vec<FittedParameter>,
    /// Correlation matrix of the parameters (same order; NaN with a held
    /// or undetermined one).
    pub correlation: Vec<Vec<f64>>,
    /// The minimised loss Σ ρ(z) of the whitened residuals.
    pub loss: f64,
    /// Number of residuals.
    pub n_residuals: usize,
    /// Bayesian information criterion n ln(Σρ/n) + p ln n (p: fitted parameters).
    pub bic: f64,
    /// χ² of the whitened residuals (outliers set aside where the kind does).
    pub chi2: f64,
    /// Degrees of freedom of `chi2`: its residuals minus fitted parameters.
    pub dof: usize,
    /// χ² / dof (1 when the model explains the data to within the noise).
    pub reduced_chi2: f64,
    /// P(χ²_dof ≥ chi2): the chance of a χ² this large from noise alone.
    pub p_value: f64,
    /// Levenberg–Marquardt iterations (over every round).
    pub iterations: usize,
    /// Whether the stopping rule was met (not the iteration cap, and the
    /// Jacobian could be evaluated at the optimum).
    pub converged: bool,
    /// Why the last round stopped.
    #[serde(skip)]
    pub termination: lm::Termination,
    /// The start with the fitted values.
    #[serde(skip)]
    pub actuator: Actuator,
    /// The kind's report.
    #[serde(flatten)]
    pub report: R,
}

impl<R: FitReport> FitResult<R> {
    /// A fitted (or held) parameter by kind.
    pub fn parameter(&self, p: Parameter) -> Option<&FittedParameter> {
        self.parameters.iter().find(|f| f.param == p)
    }

    /// Whether the model is consistent with the noise at level `alpha` (p ≥ alpha).
    pub fn consistent_with_noise(&self, alpha: f64) -> bool {
        self.p_value >= alpha
    }
}

impl<R: FitReport> std::ops::Deref for FitResult<R> {
    type Target = R;

    /// The kind's report fields read as the fit's own.
    fn deref(&self) -> &R {
        &self.report
    }
}

/// Observations a fit can fit: the residuals of a simulated actuator
/// against them, and what a fit to them reports.
pub trait Observations: Sync {
    /// The simulated answer to every observation at one actuator.
    type Solution: Send;
    /// What a fit to these observations reports beyond the common fields.
    type Report: FitReport;

    /// How these observations are fitted.
    fn rules(&self) -> FitRules;

    /// Refuses a start or a spec these observations cannot be fitted with,
    /// before anything is solved.
    fn check(&self, base: &Actuator, spec: &FitSpec) -> Result<(), CalibrateError>;

    /// The whitened residuals z (simulated − measured over the noise) at
    /// `actuator`, and the solution they come from.
    fn whitened(&self, actuator: &Actuator) -> Result<(Vec<f64>, Self::Solution), CalibrateError>;

    /// Refuses a start no fit can use: no more residuals than `fitted`
    /// parameters, or residuals `r` too far off to be measurements of it.
    fn check_start(&self, r: &[f64], fitted: usize) -> Result<(), CalibrateError>;

    /// The channel of each residual: residuals measured by the same means
    /// share a variance ([`crate::calibrate::fit::Covariance::ByChannel`]).
    fn channels(&self) -> Vec<usize>;

    /// The χ² test of whitened residuals `z` with `fitted` parameters.
    fn adequacy(&self, z: &[f64], fitted: usize) -> Adequacy;

    /// The report of a fit that ended at `fitted` with `solution`.
    fn report(&self, fitted: &Fitted<'_>, solution: Self::Solution) -> Self::Report;
}

/// How the covariance of the fitted coordinates is estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Covariance {
    /// Each channel of residuals ([`Observations::channels`]) has its own
    /// variance, from its residuals: the sandwich (JᵀJ)⁺ Jᵀ Σ J (JᵀJ)⁺ by a
    /// pseudo-inverse, a direction the data do not determine unbounded.
    ByChannel,
    /// One variance s² = χ²/(n − p) for every residual: s² (JᵀJ)⁻¹.
    Pooled,
}

/// A Jacobian column no step can difference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FailedColumn {
    /// Zero, and the fit goes on; at the optimum it is reported and the
    /// fit does not count as converged.
    Zero,
    /// No Jacobian at that point (the minimisation ends there).
    NoJacobian,
}

/// Bounds of an effect's coordinate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EffectBounds {
    /// ±this in every effect's coordinate.
    Symmetric(f64),
    /// By the effect's domain: a signed value within ±`signed`, a
    /// fraction's logit within ±`logit`, a positive value within a factor
    /// `factor` of its start either way.
    ByDomain {
        /// Bound of a signed parameter.
        signed: f64,
        /// Bound of a fraction's logit.
        logit: f64,
        /// Factor of a positive parameter.
        factor: f64,
    },
}

/// How a kind of data is fitted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitRules {
    /// Difference steps in the fit's coordinates, tried in order (each
    /// forward, then backward).
    pub steps: &'static [f64],
    /// A column that cannot be differenced.
    pub failed_column: FailedColumn,
    /// A rigidity or the density may move this factor either way from its start.
    pub body_factor: f64,
    /// Bounds of the effects.
    pub effect_bounds: EffectBounds,
    /// An accepted step that lowers the cost by less than this share ends
    /// the fit as converged.
    pub enough_reduction: Option<f64>,
    /// A parameter the data do not determine (its column vanishes at the
    /// start, its standard error in its coordinate spans more than
    /// [`UNDETERMINED_SE`], or a rigidity runs to its bound) is held at its
    /// start and the others are fitted again without it.
    pub hold_undetermined: bool,
    /// How the covariance is estimated.
    pub covariance: Covariance,
}

/// A fitted parameter whose standard error in its coordinate spans more
/// than this (a factor e for a log) is undetermined.
pub const UNDETERMINED_SE: f64 = 1.0;
/// A column of the starting Jacobian below this share of the largest is a
/// parameter the data do not feel.
const NEGLIGIBLE_COLUMN: f64 = 1e-6;

/// A Jacobian over some columns at a point, with the columns that failed.
type Jacobian = (Vec<f64>, Vec<usize>, DMatrix<f64>, Vec<usize>);

/// The fit problem over the free coordinates.
struct Problem<'a, O: Observations> {
    base: &'a Actuator,
    observations: &'a O,
    params: &'a [Parameter],
    loss: Loss,
    rules: FitRules,
    /// The relative cost reduction of the last accepted step (f64 bits).
    last_reduction: &'a AtomicU64,
    /// The last Jacobian made: the next one asked for at the same point
    /// (for these columns or fewer) is taken from it.
    last_jacobian: Mutex<Option<Jacobian>>,
}

impl<O: Observations> Problem<'_, O> {
    fn actuator(&self, x: &[f64]) -> Actuator {
        let mut a = self.base.clone();
        for (p, &xi) in self.params.iter().zip(x) {
            p.set(&mut a, p.from_internal(xi));
        }
        a
    }

    fn evaluate(&self, x: &[f64]) -> Result<(Vec<f64>, O::Solution), CalibrateError> {
        self.observations.whitened(&self.actuator(x))
    }

    /// The residuals the solver squares: the loss's transform of z.
    fn transformed(&self, x: &[f64]) -> Result<Vec<f64>, CalibrateError> {
        self.evaluate(x).map(|(z, _)| z.into_iter().map(|v| self.loss.transform(v)).collect())
    }

    /// One-sided differences over `free`, columns in parallel; `r` are the
    /// residuals at `x`. A column whose step cannot be solved is tried the
    /// other way, then smaller; one that fails every way is zero and
    /// reported by coordinate.
    fn differences(&self, x: &[f64], r: &[f64], free: &[usize]) -> (DMatrix<f64>, Vec<usize>) {
        let columns: Vec<Option<Vec<f64>>> = free
            .par_iter()
            .map(|&j| {
                for &h in self.rules.steps {
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
        let failed: Vec<usize> = free.iter().zip(&columns).filter(|(_, c)| c.is_none()).map(|(&j, _)| j).collect();
        let j = DMatrix::from_fn(r.len(), free.len(), |i, k| columns[k].as_ref().map_or(0.0, |c| c[i]));
        *self.last_jacobian.lock().expect("not poisoned") = Some((x.to_vec(), free.to_vec(), j.clone(), failed.clone()));
        (j, failed)
    }

    /// The Jacobian at `x` over `free` and its failed columns: the last one
    /// made when it was made there, else by [`Problem::differences`].
    fn jacobian_at(&self, x: &[f64], r: &[f64], free: &[usize]) -> (DMatrix<f64>, Vec<usize>) {
        let last = self.last_jacobian.lock().expect("not poisoned").clone();
        if let Some((at, columns, j, failed)) = last {
            let picked: Option<Vec<usize>> = free.iter().map(|k| columns.iter().position(|c| c == k)).collect();
            if let (true, Some(picked)) = (at.as_slice() == x, picked) {
                let failed = failed.into_iter().filter(|k| free.contains(k)).collect();
                return (DMatrix::from_fn(j.nrows(), picked.len(), |i, c| j[(i, picked[c])]), failed);
            }
        }
        self.differences(x, r, free)
    }

    /// The Jacobian as the minimisation takes it (see [`FailedColumn`]).
    fn usable_jacobian(&self, x: &[f64], r: &[f64], free: &[usize]) -> Option<DMatrix<f64>> {
        let (j, failed) = self.jacobian_at(x, r, free);
        (failed.is_empty() || self.rules.failed_column == FailedColumn::Zero).then_some(j)
    }

    /// The covariance of the free coordinates at `x` (residuals `r`,
    /// whitened `z`), and the free coordinates whose column failed.
    fn covariance(&self, x: &[f64], r: &[f64], z: &[f64], free: &[usize]) -> (Option<DMatrix<f64>>, Vec<usize>) {
        let (n, p) = (r.len(), free.len());
        match self.rules.covariance {
            Covariance::Pooled => {
                let chi2: f64 = z.iter().map(|v| v * v).sum();
                let s2 = chi2 / (n - p).max(1) as f64;
                let cov = self.usable_jacobian(x, r, free).and_then(|j| (j.transpose() * j).try_inverse()).map(|inv| inv * s2);
                (cov, Vec::new())
            }
            Covariance::ByChannel => {
                let (j, failed) = self.jacobian_at(x, r, free);
                let jtj = j.transpose() * &j;
                // Residual channels are measured by different means: each
                // gets its own variance from its residuals (σ² (JᵀJ)⁻¹ when
                // they agree).
                let channels = self.observations.channels();
                let count = channels.iter().max().map_or(0, |&c| c + 1);
                let dof_share = (n - p) as f64 / n as f64;
                let channel_var: Vec<f64> = (0..count)
                    .map(|c| {
                        let (sum, k) = channels.iter().zip(r).filter(|(&ch, _)| ch == c).fold((0.0, 0usize), |(s, k), (_, v)| (s + v * v, k + 1));
                        if k == 0 {
                            0.0
                        } else {
                            sum / (k as f64 * dof_share)
                        }
                    })
                    .collect();
                let (inv, unidentified) = pseudo_inverse(&jtj);
                let mut meat = DMatrix::<f64>::zeros(p, p);
                for (i, row) in j.row_iter().enumerate() {
                    meat += row.transpose() * row * channel_var[channels[i]];
                }
                let mut cov = &inv * meat * &inv;
                // A parameter the data cannot determine (a rigidity run off
                // to where it no longer matters) has no finite standard error.
                for (k, &bad) in unidentified.iter().enumerate() {
                    if bad {
                        cov[(k, k)] = f64::INFINITY;
                    }
                }
                for (k, idx) in free.iter().enumerate() {
                    if failed.contains(idx) {
                        cov[(k, k)] = f64::INFINITY;
                    }
                }
                (Some(cov), failed)
            }
        }
    }
}

impl<O: Observations> lm::Problem for Problem<'_, O> {
    fn stop(&mut self) -> bool {
        self.rules.enough_reduction.is_some_and(|share| f64::from_bits(self.last_reduction.load(Ordering::Relaxed)) < share)
    }

    fn residuals(&mut self, x: &[f64]) -> Option<Vec<f64>> {
        self.transformed(x).ok()
    }

    fn jacobian(&mut self, x: &[f64], r: &[f64], free: &[usize]) -> Option<DMatrix<f64>> {
        self.usable_jacobian(x, r, free)
    }
}

/// Pseudo-inverse of the symmetric matrix `a` by eigen-decomposition,
/// ignoring directions with eigenvalue below 1e-12 of the largest, and
/// which parameters lean on those ignored directions.
fn pseudo_inverse(a: &DMatrix<f64>) -> (DMatrix<f64>, Vec<bool>) {
    let p = a.nrows();
    let eig = a.clone().symmetric_eigen();
    let top = eig.eigenvalues.amax();
    let mut inv = DMatrix::<f64>::zeros(p, p);
    let mut unidentified = vec![false; p];
    for (i, &l) in eig.eigenvalues.iter().enumerate() {
        let v = eig.eigenvectors.column(i);
        if l > 1e-12 * top && l > 0.0 {
            inv += v * v.transpose() / l;
        } else {
            for k in 0..p {
                if v[k].abs() > 1e-3 {
                    unidentified[k] = true;
                }
            }
        }
    }
    (inv, unidentified)
}

/// The bounds of each coordinate around its start `x`.
fn bounds(rules: &FitRules, params: &[Parameter], start: &[f64]) -> Vec<(f64, f64)> {
    params
        .iter()
        .zip(start)
        .map(|(p, &x)| match (p, rules.effect_bounds) {
            (Parameter::Effect(_), EffectBounds::Symmetric(b)) => (-b, b),
            // An effect the data do not call for runs toward its thesis
            // value (0, or an infinitely stiff clamp): bounded near where it
            // no longer matters, so the fit does not spend steps on the way.
            (Parameter::Effect(e), EffectBounds::ByDomain { signed, logit, factor }) => match e.fit().domain {
                Domain::Signed => (-signed, signed),
                Domain::Fraction => (-logit, logit),
                Domain::Positive => (x - factor.ln(), x + factor.ln()),
            },
            _ => (x - rules.body_factor.ln(), x + rules.body_factor.ln()),
        })
        .collect()
}

/// Fits `spec.params` of `base` to `observations`, calling `observe` after
/// every accepted step. Effects set on `base` but not fitted stay as they
/// are; an effect switched off on `base` starts from its registry start.
pub fn fit<O: Observations>(
    base: &Actuator,
    observations: &O,
    spec: &FitSpec,
    observe: &mut dyn FnMut(lm::Step),
) -> Result<FitResult<O::Report>, CalibrateError> {
    observations.check(base, spec)?;
    let rules = observations.rules();
    let mut params: Vec<Parameter> = Vec::new();
    for &p in &spec.params {
        if !params.contains(&p) {
            params.push(p);
        }
    }
    let start: Vec<f64> = params.iter().map(|p| p.to_internal(p.get(base))).collect();
    let bounds = bounds(&rules, &params, &start);
    let last_reduction = AtomicU64::new(f64::INFINITY.to_bits());
    let mut problem =
        Problem { base, observations, params: &params, loss: spec.loss, rules, last_reduction: &last_reduction, last_jacobian: Mutex::new(None) };
    let r0 = problem.transformed(&start)?;
    let n = r0.len();
    let mut free: Vec<usize> = (0..params.len()).filter(|&k| !spec.held.contains(&params[k])).collect();
    if rules.hold_undetermined {
        // Parameters the data do not feel at all are held from the start.
        let (j0, failed) = problem.differences(&start, &r0, &free);
        if failed.is_empty() {
            let norms: Vec<f64> = (0..free.len()).map(|k| j0.column(k).norm()).collect();
            let top = norms.iter().cloned().fold(0.0, f64::max);
            let kept: Vec<usize> = free.iter().enumerate().filter(|&(k, _)| norms[k] > NEGLIGIBLE_COLUMN * top).map(|(_, &i)| i).collect();
            free = kept;
        }
    }
    observations.check_start(&r0, free.len())?;
    let mut iterations = 0;
    let mut round_start = start.clone();
    let mut r = r0;
    let (x, r, cost, termination, cov_free, failed, z, solution) = loop {
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
        let (z, solution) = problem.evaluate(&x)?;
        let (cov, failed) = problem.covariance(&x, &outcome.r, &z, &free);
        // Which free parameters the data do not determine.
        let bad: Vec<usize> = if !rules.hold_undetermined {
            Vec::new()
        } else {
            free.iter()
                .enumerate()
                .filter(|&(k, &idx)| {
                    if matches!(params[idx], Parameter::Effect(_)) {
                        // Reported at its bound, not held: see `Status::AtBound`.
                        return false;
                    }
                    let (lo, hi) = bounds[idx];
                    let at_bound = x[idx] <= lo + 1e-9 || x[idx] >= hi - 1e-9;
                    let se = cov.as_ref().map_or(f64::INFINITY, |c| c[(k, k)].max(0.0).sqrt());
                    at_bound || !(se <= UNDETERMINED_SE)
                })
                .map(|(_, &idx)| idx)
                .collect()
        };
        if bad.is_empty() || free.len() == bad.len() {
            break (x, outcome.r, outcome.cost, outcome.termination, cov, failed, z, solution);
        }
        // Hold the worst-determined one at its start and fit the rest again.
        let worst = *bad.last().expect("not empty");
        free.retain(|&k| k != worst);
        round_start = x;
        round_start[worst] = start[worst];
        r = problem.transformed(&round_start)?;
    };
    let _ = r;
    let actuator = problem.actuator(&x);
    let p = free.len();
    let total = params.len();
    // The full covariance: zero with a parameter not fitted, unbounded
    // where none could be estimated.
    let mut cov = DMatrix::<f64>::zeros(total, total);
    for (a, &ia) in free.iter().enumerate() {
        for (b, &ib) in free.iter().enumerate() {
            cov[(ia, ib)] = cov_free.as_ref().map_or(f64::INFINITY, |c| c[(a, b)]);
        }
    }
    let parameters: Vec<FittedParameter> = params
        .iter()
        .enumerate()
        .map(|(k, &param)| {
            let status = match (free.contains(&k), param) {
                (false, _) if spec.held.contains(&param) => Status::Held,
                (false, _) => Status::Undetermined,
                (true, Parameter::Effect(_)) if rules.hold_undetermined && (x[k] <= bounds[k].0 + 1e-9 || x[k] >= bounds[k].1 - 1e-9) => Status::AtBound,
                _ => Status::Fitted,
            };
            let se = match status {
                Status::Held => 0.0,
                Status::Undetermined => f64::NAN,
                _ => match cov[(k, k)] {
                    v if v.is_finite() => param.derivative(x[k]).abs() * v.max(0.0).sqrt(),
                    _ => f64::INFINITY,
                },
            };
            FittedParameter { name: param.name().to_string(), param, value: param.from_internal(x[k]), start: param.from_internal(start[k]), se, status }
        })
        .collect();
    let correlation = (0..total)
        .map(|a| {
            (0..total)
                .map(|b| {
                    let (va, vb) = (cov[(a, a)], cov[(b, b)]);
                    // No correlation is defined with an undetermined or held parameter.
                    if va.is_finite() && vb.is_finite() && va > 0.0 && vb > 0.0 {
                        cov[(a, b)] / (va * vb).sqrt()
                    } else {
                        f64::NAN
                    }
                })
                .collect()
        })
        .collect();
    let adequacy = observations.adequacy(&z, p);
    let nf = n as f64;
    let converged = (termination.converged() || termination == lm::Termination::Stopped) && failed.is_empty();
    let fitted = Fitted { parameters: &parameters, x: &x, bounds: &bounds, free: &free, failed: &failed, termination, outliers: adequacy.outliers };
    let report = observations.report(&fitted, solution);
    Ok(FitResult {
        parameters,
        correlation,
        loss: cost,
        n_residuals: n,
        bic: nf * (cost / nf).max(1e-300).ln() + p as f64 * nf.ln(),
        chi2: adequacy.chi2,
        dof: adequacy.dof,
        reduced_chi2: if adequacy.dof > 0 { adequacy.chi2 / adequacy.dof as f64 } else { f64::NAN },
        p_value: adequacy.p_value,
        iterations,
        converged,
        termination,
        actuator,
        report,
    })
}

/// The χ² test of a fit's whitened residuals.
#[derive(Debug, Clone, PartialEq)]
pub struct Adequacy {
    /// χ² over the residuals not set aside.
    pub chi2: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// P(χ²_dof ≥ χ²).
    pub p_value: f64,
    /// Measurement ids of readings set aside as outliers.
    pub outliers: Vec<i64>,
}

/// The optimum as a kind's report reads it.
#[derive(Debug)]
pub struct Fitted<'a> {
    /// The parameters.
    pub parameters: &'a [FittedParameter],
    /// Their coordinates.
    pub x: &'a [f64],
    /// The coordinates' bounds.
    pub bounds: &'a [(f64, f64)],
    /// The coordinates fitted.
    pub free: &'a [usize],
    /// Fitted coordinates whose Jacobian column failed at the optimum.
    pub failed: &'a [usize],
    /// Why the last round stopped.
    pub termination: lm::Termination,
    /// Readings set aside as outliers in the χ² test.
    pub outliers: Vec<i64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huber_keeps_small_residuals_and_tames_large_ones() {
        let l = Loss::Huber { k: 3.0 };
        assert_eq!(l.transform(2.0), 2.0);
        assert!((l.transform(-50.0).powi(2) - (2.0 * 3.0 * 50.0 - 9.0)).abs() < 1e-9);
        assert!(l.transform(-50.0) < 0.0);
    }
}
