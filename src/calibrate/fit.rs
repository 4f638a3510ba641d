//! Least-squares fit of EA, GA, EI (thesis eq. 2.14), optionally together
//! with effect parameters.
//!
//! The residuals of a row are the simulated minus measured tip x and y (mm)
//! and tip angle, the angle in degrees times a weight in mm per degree
//! (1 by default: 1° counts like 1 mm). Parameters are fitted in
//! unconstrained coordinates (logs of the rigidities, see
//! [`Effect::to_internal`]) by Levenberg–Marquardt with a central
//! finite-difference Jacobian. Standard errors come from σ² (JᵀJ)⁻¹ at the
//! optimum, with one σ² per measured channel (x, y, θ: different
//! instruments, different noise) in a sandwich, mapped to the parameters by
//! the delta method; correlations from the same matrix.
//!
//! The optimiser is written here (about fifty lines) rather than taken from
//! the `levenberg-marquardt` crate because a trial step whose solve fails
//! (a rod that collapses at absurd rigidities) must simply be rejected, and
//! the noise-free tests need the stopping rule to run down to rounding.

use super::data::{Dataset, RoutingGroup};
use super::effect::Effect;
use super::predict::{predict, Prediction};
use super::CalibrateError;
use crate::model::{Actuator, SolverOptions};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use serde::Serialize;

/// What to fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSpec {
    /// Effects fitted together with EA, GA, EI (empty: the thesis model).
    pub effects: Vec<Effect>,
    /// Weight of the tip angle: mm of residual per degree.
    pub angle_weight_mm_per_deg: f64,
}

impl Default for FitSpec {
    fn default() -> Self {
        Self { effects: Vec::new(), angle_weight_mm_per_deg: 1.0 }
    }
}

/// One fitted parameter.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FittedParameter {
    /// Name with unit (`ea_n`, `friction_mu`, …).
    pub name: String,
    /// Fitted value.
    pub value: f64,
    /// Standard error (same unit).
    pub se: f64,
}

/// RMS residual of one routing.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RoutingRms {
    /// Routing id.
    pub routing: String,
    /// Rows used.
    pub rows: usize,
    /// RMS over x, y (mm) and weighted angle, mm.
    pub rms_mm: f64,
    /// RMS of the tip position error |Δp|, mm.
    pub rms_position_mm: f64,
    /// RMS of the tip angle error, degrees.
    pub rms_angle_deg: f64,
}

/// The result of a fit.
#[derive(Debug, Clone)]
pub struct FitResult {
    /// Effects that were fitted.
    pub effects: Vec<Effect>,
    /// The base actuator with the fitted values.
    pub actuator: Actuator,
    /// EA, GA, EI, then each effect's parameter.
    pub parameters: Vec<FittedParameter>,
    /// Correlation matrix of the parameters (same order).
    pub correlation: Vec<Vec<f64>>,
    /// Residual sum of squares, mm².
    pub rss: f64,
    /// Number of residuals (3 per row).
    pub n_residuals: usize,
    /// Bayesian information criterion n ln(RSS/n) + p ln n.
    pub bic: f64,
    /// RMS over all residuals, mm.
    pub rms_mm: f64,
    /// RMS per routing.
    pub per_routing: Vec<RoutingRms>,
    /// Levenberg–Marquardt iterations.
    pub iterations: usize,
    /// Whether the stopping rule was met (not the iteration cap).
    pub converged: bool,
    /// Predictions at the optimum, indexed like the data's rows.
    pub predictions: Vec<Option<Prediction>>,
}

impl FitResult {
    /// The fitted value and SE of `effect`, if it was fitted.
    pub fn effect_parameter(&self, effect: Effect) -> Option<&FittedParameter> {
        let i = self.effects.iter().position(|&e| e == effect)?;
        self.parameters.get(3 + i)
    }
}

/// Weighted residuals of the rows of `groups`, 3 per row in group order.
pub fn residuals(
    data: &Dataset,
    groups: &[RoutingGroup],
    predictions: &[Option<Prediction>],
    angle_weight_mm_per_deg: f64,
) -> Vec<f64> {
    let mut r = Vec::new();
    for g in groups {
        for &i in &g.rows {
            let (m, p) = (&data.rows[i], &predictions[i].as_ref().expect("predicted").pose);
            r.extend(row_residual(m, p, angle_weight_mm_per_deg));
        }
    }
    r
}

/// Residual of one row: Δx, Δy (mm) and weighted Δθ (mm-equivalent).
pub fn row_residual(m: &super::Measurement, p: &crate::model::TipPose, angle_weight_mm_per_deg: f64) -> [f64; 3] {
    [
        p.tip_x_mm - m.tip_x_mm,
        p.tip_y_mm - m.tip_y_mm,
        (p.tip_angle_rad - m.tip_angle_rad).to_degrees() * angle_weight_mm_per_deg,
    ]
}

/// RMS of the residuals of `groups`' rows, per routing.
pub fn rms_per_routing(
    data: &Dataset,
    groups: &[RoutingGroup],
    predictions: &[Option<Prediction>],
    angle_weight_mm_per_deg: f64,
) -> Vec<RoutingRms> {
    groups
        .iter()
        .map(|g| {
            let (mut all, mut pos, mut ang) = (0.0, 0.0, 0.0);
            for &i in &g.rows {
                let m = &data.rows[i];
                let p = &predictions[i].as_ref().expect("predicted").pose;
                let r = row_residual(m, p, angle_weight_mm_per_deg);
                all += r.iter().map(|v| v * v).sum::<f64>();
                pos += r[0] * r[0] + r[1] * r[1];
                ang += (p.tip_angle_rad - m.tip_angle_rad).to_degrees().powi(2);
            }
            let n = g.rows.len() as f64;
            RoutingRms {
                routing: g.routing.clone(),
                rows: g.rows.len(),
                rms_mm: (all / (3.0 * n)).sqrt(),
                rms_position_mm: (pos / n).sqrt(),
                rms_angle_deg: (ang / n).sqrt(),
            }
        })
        .collect()
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

/// The fit problem: maps the unconstrained coordinates to an actuator.
struct Problem<'a> {
    base: &'a Actuator,
    options: &'a SolverOptions,
    data: &'a Dataset,
    groups: &'a [RoutingGroup],
    spec: &'a FitSpec,
}

impl Problem<'_> {
    fn actuator(&self, x: &[f64]) -> Actuator {
        let mut a = self.base.clone();
        a.ea_n = x[0].exp();
        a.ga_n = x[1].exp();
        a.ei_n_mm2 = x[2].exp();
        for (e, &xi) in self.spec.effects.iter().zip(&x[3..]) {
            e.apply(&mut a, e.from_internal(xi));
        }
        a
    }

    fn evaluate(&self, x: &[f64]) -> Result<(Vec<f64>, Vec<Option<Prediction>>), CalibrateError> {
        let a = self.actuator(x);
        let preds = predict(&a, self.options, self.data, self.groups, false)?;
        Ok((residuals(self.data, self.groups, &preds, self.spec.angle_weight_mm_per_deg), preds))
    }

    fn residuals(&self, x: &[f64]) -> Result<Vec<f64>, CalibrateError> {
        self.evaluate(x).map(|(r, _)| r)
    }

    /// Central-difference Jacobian, columns in parallel.
    fn jacobian(&self, x: &[f64], n: usize) -> Result<DMatrix<f64>, CalibrateError> {
        const H: f64 = 1e-6;
        let columns: Vec<Vec<f64>> = (0..x.len())
            .into_par_iter()
            .map(|j| {
                let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
                xp[j] += H;
                xm[j] -= H;
                let (rp, rm) = (self.residuals(&xp)?, self.residuals(&xm)?);
                Ok(rp.iter().zip(&rm).map(|(a, b)| (a - b) / (2.0 * H)).collect())
            })
            .collect::<Result<_, CalibrateError>>()?;
        Ok(DMatrix::from_fn(n, x.len(), |i, j| columns[j][i]))
    }
}

/// Fits the rigidities (and `spec.effects`) of `base` to the rows of
/// `groups`, starting from `base`'s values (an effect switched off on `base`
/// starts from [`Effect::start`]). Effects set on `base` but not fitted stay
/// as they are.
pub fn fit(
    base: &Actuator,
    options: &SolverOptions,
    data: &Dataset,
    groups: &[RoutingGroup],
    spec: &FitSpec,
) -> Result<FitResult, CalibrateError> {
    fit_observed(base, options, data, groups, spec, &mut |_| {})
}

/// Where a running fit is: reported after every accepted step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitProgress {
    /// Iterations done (of at most 200).
    pub iteration: usize,
    /// Weighted RMS residual after this iteration, mm.
    pub rms_mm: f64,
}

/// [`fit`], calling `observe` after every accepted step, so that a long fit
/// (10⁵ readings) can show progress.
pub fn fit_observed(
    base: &Actuator,
    options: &SolverOptions,
    data: &Dataset,
    groups: &[RoutingGroup],
    spec: &FitSpec,
    observe: &mut dyn FnMut(FitProgress),
) -> Result<FitResult, CalibrateError> {
    if !(spec.angle_weight_mm_per_deg.is_finite() && spec.angle_weight_mm_per_deg >= 0.0) {
        return Err(CalibrateError::Invalid(format!(
            "the angle weight must be a finite number ≥ 0 mm per degree, got {}",
            spec.angle_weight_mm_per_deg
        )));
    }
    base.validate()?;
    let problem = Problem { base, options, data, groups, spec };
    let mut x: Vec<f64> = vec![base.ea_n.ln(), base.ga_n.ln(), base.ei_n_mm2.ln()];
    x.extend(spec.effects.iter().map(|e| e.to_internal(e.current(base).unwrap_or_else(|| e.start()))));
    let p = x.len();
    let mut r = problem.residuals(&x)?;
    let n = r.len();
    if n <= p {
        return Err(CalibrateError::Invalid(format!(
            "{n} residuals ({} rows) cannot determine {p} parameters; measure more steps or routings",
            n / 3
        )));
    }
    let mut cost: f64 = r.iter().map(|v| v * v).sum();
    if !cost.is_finite() {
        // Residuals so large their squares overflow: no step can lower an
        // infinite cost, and "no step lowers the cost" must not read as a
        // converged fit.
        let worst = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        return Err(CalibrateError::Invalid(format!(
            "the measurements are absurdly far from any shape the actuator can take (a weighted residual of {} mm): \
             check the units (mm and degrees) and the column order of the data",
            crate::io::fmt_num(worst)
        )));
    }
    let mut lambda = 1e-3;
    let mut converged = false;
    let mut iterations = 0;
    const MAX_ITERATIONS: usize = 200;
    while iterations < MAX_ITERATIONS {
        iterations += 1;
        let j = problem.jacobian(&x, n)?;
        let rv = DVector::from_column_slice(&r);
        let a = j.transpose() * &j;
        let g = j.transpose() * rv;
        let diag_floor = a.diagonal().max() * 1e-12 + 1e-300;
        let mut accepted = None;
        while lambda < 1e12 {
            let mut m = a.clone();
            for k in 0..p {
                m[(k, k)] += lambda * a[(k, k)].max(diag_floor);
            }
            let Some(chol) = m.cholesky() else {
                lambda *= 5.0;
                continue;
            };
            let step = chol.solve(&(-&g));
            let trial: Vec<f64> = x.iter().zip(step.iter()).map(|(a, b)| a + b).collect();
            match problem.residuals(&trial) {
                Ok(rt) => {
                    let ct: f64 = rt.iter().map(|v| v * v).sum();
                    if ct < cost {
                        accepted = Some((trial, rt, ct, step.amax()));
                        lambda = (lambda / 5.0).max(1e-12);
                        break;
                    }
                    lambda *= 5.0;
                }
                // A trial the model cannot solve is simply a bad step.
                Err(_) => lambda *= 5.0,
            }
        }
        let Some((trial, rt, ct, step_size)) = accepted else {
            // No step lowers the cost: a minimum to within rounding.
            converged = true;
            break;
        };
        let reduction = (cost - ct) / cost.max(1e-300);
        x = trial;
        r = rt;
        cost = ct;
        observe(FitProgress { iteration: iterations, rms_mm: (cost / n as f64).sqrt() });
        if cost < 1e-24 * n as f64 || reduction < 1e-12 || step_size < 1e-11 {
            converged = true;
            break;
        }
    }
    // Uncertainties from the Jacobian at the optimum.
    let j = problem.jacobian(&x, n)?;
    let jtj = j.transpose() * &j;
    // x, y and θ are measured by different means with different noise: each
    // channel gets its own variance from its residuals, and the covariance
    // is the sandwich (JᵀJ)⁻¹ Jᵀ Σ J (JᵀJ)⁻¹ (σ² (JᵀJ)⁻¹ when they agree).
    let dof_share = (n - p) as f64 / n as f64;
    let channel_var: [f64; 3] = std::array::from_fn(|c| {
        let (sum, count) = r.iter().skip(c).step_by(3).fold((0.0, 0usize), |(s, k), v| (s + v * v, k + 1));
        sum / (count as f64 * dof_share)
    });
    let (inv, unidentified) = pseudo_inverse(&jtj);
    let mut meat = DMatrix::<f64>::zeros(p, p);
    for (i, row) in j.row_iter().enumerate() {
        meat += row.transpose() * row * channel_var[i % 3];
    }
    let mut cov = &inv * meat * &inv;
    // A parameter the data cannot determine (a rigidity run off to where it
    // no longer matters) has no finite standard error.
    for (k, &bad) in unidentified.iter().enumerate() {
        if bad {
            cov[(k, k)] = f64::INFINITY;
        }
    }
    let cov = Some(cov);
    let (_, predictions) = problem.evaluate(&x)?;
    let actuator = problem.actuator(&x);
    let mut names: Vec<String> = vec!["ea_n".into(), "ga_n".into(), "ei_n_mm2".into()];
    names.extend(spec.effects.iter().map(|e| e.parameter_name().to_string()));
    let mut values = vec![actuator.ea_n, actuator.ga_n, actuator.ei_n_mm2];
    let mut derivs = values.clone(); // d value / d log value
    for (e, &xi) in spec.effects.iter().zip(&x[3..]) {
        values.push(e.from_internal(xi));
        derivs.push(e.derivative(xi));
    }
    let parameters = (0..p)
        .map(|k| FittedParameter {
            name: names[k].clone(),
            value: values[k],
            se: match cov.as_ref().map(|c| c[(k, k)]) {
                Some(v) if v.is_finite() => derivs[k].abs() * v.max(0.0).sqrt(),
                _ => f64::INFINITY,
            },
        })
        .collect();
    let correlation = (0..p)
        .map(|a| {
            (0..p)
                .map(|b| match &cov {
                    // No correlation is defined with an undetermined parameter.
                    Some(c) if c[(a, a)].is_finite() && c[(b, b)].is_finite() => c[(a, b)] / (c[(a, a)] * c[(b, b)]).sqrt(),
                    Some(_) => f64::NAN,
                    None => f64::NAN,
                })
                .collect()
        })
        .collect();
    let nf = n as f64;
    Ok(FitResult {
        effects: spec.effects.clone(),
        per_routing: rms_per_routing(data, groups, &predictions, spec.angle_weight_mm_per_deg),
        actuator,
        parameters,
        correlation,
        rss: cost,
        n_residuals: n,
        bic: nf * (cost / nf).max(1e-300).ln() + p as f64 * nf.ln(),
        rms_mm: (cost / nf).sqrt(),
        iterations,
        converged,
        predictions,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::synth::{default_routings, synthesize, SynthSpec};

    fn truth() -> Actuator {
        Actuator { ea_n: 30.0, ga_n: 1.5, ei_n_mm2: 100.0, ..Actuator::default() }
    }

    #[test]
    fn recovers_the_rigidities_from_noise_free_data() {
        let spec = SynthSpec {
            actuator: truth(),
            noise_mm: 0.0,
            noise_deg: 0.0,
            routings: default_routings()[..3].to_vec(),
            load_steps: 4,
            ..SynthSpec::default()
        };
        let (data, _) = synthesize(&spec, 0).unwrap();
        let t0 = std::time::Instant::now();
        let mut seen = Vec::new();
        let result = fit_observed(&Actuator::default(), &SolverOptions::default(), &data, &data.groups(), &FitSpec::default(), &mut |p| {
            seen.push(p)
        })
        .unwrap();
        eprintln!("noise-free fit: {:?}, {} iterations", t0.elapsed(), result.iterations);
        assert!(result.converged);
        // Progress: one report per accepted step, iterations rising, RMS falling.
        assert!(!seen.is_empty() && seen.len() <= result.iterations);
        assert!(seen.windows(2).all(|w| w[0].iteration < w[1].iteration && w[0].rms_mm >= w[1].rms_mm));
        let t = truth();
        for (p, want) in result.parameters.iter().zip([t.ea_n, t.ga_n, t.ei_n_mm2]) {
            assert!(((p.value - want) / want).abs() < 1e-6, "{}: {} vs {want}", p.name, p.value);
        }
        assert!(result.rms_mm < 1e-6, "{}", result.rms_mm);
    }

    #[test]
    fn noisy_fit_lands_within_its_uncertainty() {
        let t = truth();
        for seed in 1..=3 {
            let spec = SynthSpec { actuator: t.clone(), seed, routings: default_routings()[..4].to_vec(), ..SynthSpec::default() };
            let (data, _) = synthesize(&spec, 0).unwrap();
            let r = fit(&Actuator::default(), &SolverOptions::default(), &data, &data.groups(), &FitSpec::default()).unwrap();
            for (p, want) in r.parameters.iter().zip([t.ea_n, t.ga_n, t.ei_n_mm2]) {
                assert!(p.se > 0.0 && p.se.is_finite());
                // 3.5 standard errors: a failure here is a real error, not bad luck (p < 5e-4).
                assert!((p.value - want).abs() < 3.5 * p.se, "seed {seed} {}: {} ± {} vs {want}", p.name, p.value, p.se);
            }
            // The noise is 0.4 mm on x, y and 1° (1 mm) on θ: RMS ≈ sqrt((0.16+0.16+1)/3).
            assert!((0.5..0.8).contains(&r.rms_mm), "{}", r.rms_mm);
            for row in &r.correlation {
                assert!(row.iter().all(|c| c.abs() <= 1.0 + 1e-9));
            }
        }
    }
}
