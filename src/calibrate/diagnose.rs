//! The model-discrepancy workflow: fit the thesis model, look at where the
//! residuals sit, refit with each candidate effect, name the effect the data
//! call for (or none, or say which two it cannot tell apart) and show the
//! gap on a held-out routing before and after.
//!
//! Criterion (stated in every report): with the Gaussian BIC
//! n ln(RSS/n) + p ln n, an effect is named when its fit lowers the BIC by
//! at least `threshold` (10) against the model without it, beats the
//! runner-up by at least `margin` (10) and has a physically plausible value
//! ([`Effect::plausible`]). Effects are added forward-stepwise by the same
//! rule (at most `max_effects`).

use super::data::{Dataset, Direction, RoutingGroup};
use super::effect::Effect;
use super::fit::{fit, residuals, rms_per_routing, FitResult, FitSpec, RoutingRms};
use super::predict::predict;
use super::CalibrateError;
use crate::model::{Actuator, SolverOptions};
use rayon::prelude::*;
use serde::Serialize;

/// Settings of a diagnosis.
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoseSpec {
    /// Routing left out of every fit and used to measure the gap.
    pub holdout: Option<String>,
    /// Weight of the tip angle, mm per degree.
    pub angle_weight_mm_per_deg: f64,
    /// Required BIC decrease against the model without the effect.
    pub threshold: f64,
    /// Required BIC lead over the runner-up.
    pub margin: f64,
    /// Most effects added.
    pub max_effects: usize,
}

impl Default for DiagnoseSpec {
    fn default() -> Self {
        Self { holdout: None, angle_weight_mm_per_deg: 1.0, threshold: 10.0, margin: 10.0, max_effects: 2 }
    }
}

/// One candidate effect refitted with the rigidities.
#[derive(Debug, Clone, Serialize)]
pub struct Candidate {
    /// Rank (1 = lowest BIC).
    pub rank: usize,
    /// Effect name.
    pub effect: &'static str,
    /// Parameter name with unit.
    pub parameter_name: &'static str,
    /// Fitted value (NaN if the fit failed).
    pub parameter: f64,
    /// Its standard error.
    pub parameter_se: f64,
    /// BIC change against the model without the effect (negative: better).
    pub delta_bic: f64,
    /// RMS residual of the fit, mm.
    pub rms_mm: f64,
    /// Whether the value is physically plausible.
    pub plausible: bool,
    /// Why the fit failed, if it did.
    pub error: Option<String>,
}

/// Residual statistics of one class of rows.
#[derive(Debug, Clone, Serialize)]
pub struct ResidualClass {
    /// What the rows have in common.
    pub class: String,
    /// Rows.
    pub rows: usize,
    /// RMS over x, y and weighted θ, mm.
    pub rms_mm: f64,
    /// Mean Δx, mm.
    pub mean_dx_mm: f64,
    /// Mean Δy, mm.
    pub mean_dy_mm: f64,
    /// Mean Δθ, degrees.
    pub mean_dtheta_deg: f64,
}

/// Where the baseline's residuals sit.
#[derive(Debug, Clone, Serialize)]
pub struct ResidualDiagnostics {
    /// By load direction, by tension band and by rest state.
    pub classes: Vec<ResidualClass>,
    /// Mean |θ_unload − θ_load| of the measurement minus the model's at the
    /// same tension and routing, degrees (an open loop the model lacks).
    pub loop_gap_deg: f64,
    /// Mean measured − simulated change of the tip angle from the first to
    /// the last rest state, degrees (a residual bend after unloading).
    pub rest_shift_deg: f64,
    /// RMS per routing.
    pub per_routing: Vec<RoutingRms>,
}

/// A named effect of the final model.
#[derive(Debug, Clone, Serialize)]
pub struct NamedEffect {
    /// Effect name.
    pub effect: &'static str,
    /// Parameter name.
    pub parameter_name: &'static str,
    /// Fitted value.
    pub parameter: f64,
    /// Standard error.
    pub parameter_se: f64,
    /// BIC change that admitted it.
    pub delta_bic: f64,
}

/// The outcome of a diagnosis.
#[derive(Debug, Clone)]
pub struct Diagnosis {
    /// `none`, an effect name, or `ambiguous`.
    pub verdict: String,
    /// Effects of the final model, in the order they were added.
    pub named: Vec<NamedEffect>,
    /// The two effects the data cannot tell apart, if ambiguous.
    pub ambiguous_between: Vec<&'static str>,
    /// The measurement that would separate them.
    pub separating_measurement: Option<String>,
    /// Ranked candidates of the first round.
    pub candidates: Vec<Candidate>,
    /// Ranked candidates of the second round (given the first effect).
    pub second_round: Vec<Candidate>,
    /// The thesis-model fit.
    pub baseline: FitResult,
    /// The final model's fit (the baseline if nothing was named).
    pub extended: FitResult,
    /// Residual diagnostics of the baseline.
    pub diagnostics: ResidualDiagnostics,
    /// Held-out routing.
    pub holdout: Option<String>,
    /// Held-out RMS with the baseline, mm.
    pub holdout_rms_before: Option<f64>,
    /// Held-out RMS with the final model, mm.
    pub holdout_rms_after: Option<f64>,
    /// Predictions of every row (held-out included) by the baseline.
    pub baseline_predictions: Vec<Option<super::predict::Prediction>>,
    /// Predictions of every row by the final model.
    pub extended_predictions: Vec<Option<super::predict::Prediction>>,
    /// The decision rule in words.
    pub criterion: String,
}

impl Diagnosis {
    /// The `--json` object.
    pub fn to_json(&self) -> serde_json::Value {
        let first = self.named.first();
        serde_json::json!({
            "verdict": self.verdict,
            "parameter_name": first.map(|n| n.parameter_name),
            "parameter": first.map(|n| n.parameter),
            "parameter_se": first.map(|n| n.parameter_se),
            "effects": self.named,
            "ambiguous_between": self.ambiguous_between,
            "separating_measurement": self.separating_measurement,
            "candidates": self.candidates,
            "second_round": self.second_round,
            "criterion": self.criterion,
            "baseline": fit_json(&self.baseline),
            "extended": fit_json(&self.extended),
            "diagnostics": self.diagnostics,
            "holdout": self.holdout,
            "holdout_rms_before": self.holdout_rms_before,
            "holdout_rms_after": self.holdout_rms_after,
            "not_identifiable": ["cable_stretch: under tension control the cable's stretch does not change the forces on the rod, so no tip reading can show it"],
        })
    }
}

/// A fit as JSON: parameters with SEs, correlations, RMS per routing.
pub fn fit_json(f: &FitResult) -> serde_json::Value {
    serde_json::json!({
        "effects": f.effects,
        "parameters": f.parameters,
        "correlation": f.correlation,
        "rss": f.rss,
        "n_residuals": f.n_residuals,
        "bic": f.bic,
        "rms_mm": f.rms_mm,
        "per_routing": f.per_routing,
        "iterations": f.iterations,
        "converged": f.converged,
    })
}

/// Splits the routings into fitted and held-out ones.
pub fn split_holdout(data: &Dataset, holdout: Option<&str>) -> Result<(Vec<RoutingGroup>, Option<RoutingGroup>), CalibrateError> {
    let groups = data.groups();
    let Some(id) = holdout else {
        return Ok((groups, None));
    };
    let ids: Vec<&str> = groups.iter().map(|g| g.routing.as_str()).collect();
    let Some(pos) = groups.iter().position(|g| g.routing == id) else {
        return Err(CalibrateError::Invalid(format!("--holdout: no routing '{id}' in the data (routings: {})", ids.join(", "))));
    };
    let mut train = groups;
    let held = train.remove(pos);
    if train.is_empty() {
        return Err(CalibrateError::Invalid(format!("--holdout {id}: it is the only routing; nothing would be left to fit")));
    }
    Ok((train, Some(held)))
}

fn candidate(effect: Effect, reference_bic: f64, result: Result<FitResult, CalibrateError>) -> Candidate {
    match result {
        Ok(f) => {
            let p = f.effect_parameter(effect).expect("fitted effect");
            Candidate {
                rank: 0,
                effect: effect.name(),
                parameter_name: effect.parameter_name(),
                parameter: p.value,
                parameter_se: p.se,
                delta_bic: f.bic - reference_bic,
                rms_mm: f.rms_mm,
                plausible: effect.plausible(p.value) && p.se.is_finite(),
                error: None,
            }
        }
        Err(e) => Candidate {
            rank: 0,
            effect: effect.name(),
            parameter_name: effect.parameter_name(),
            parameter: f64::NAN,
            parameter_se: f64::NAN,
            delta_bic: f64::INFINITY,
            rms_mm: f64::NAN,
            plausible: false,
            error: Some(e.to_string()),
        },
    }
}

/// Outcome of one round of the criterion.
enum Decision {
    None,
    Named(Effect),
    Ambiguous(Effect, Effect),
}

fn decide(ranked: &[Candidate], spec: &DiagnoseSpec) -> Decision {
    let ok: Vec<&Candidate> = ranked.iter().filter(|c| c.plausible && c.delta_bic.is_finite()).collect();
    let Some(best) = ok.first() else { return Decision::None };
    if best.delta_bic > -spec.threshold {
        return Decision::None;
    }
    let e = Effect::parse(best.effect).expect("known effect");
    match ok.get(1) {
        Some(runner) if runner.delta_bic - best.delta_bic < spec.margin => {
            Decision::Ambiguous(e, Effect::parse(runner.effect).expect("known effect"))
        }
        _ => Decision::Named(e),
    }
}

/// One round: every effect not yet in `base_effects` is refitted with them.
fn round(
    base: &Actuator,
    options: &SolverOptions,
    data: &Dataset,
    train: &[RoutingGroup],
    spec: &DiagnoseSpec,
    base_effects: &[Effect],
    reference: &FitResult,
) -> (Vec<Candidate>, Vec<(Effect, FitResult)>) {
    let todo: Vec<Effect> = Effect::ALL.into_iter().filter(|e| !base_effects.contains(e)).collect();
    let results: Vec<(Effect, Result<FitResult, CalibrateError>)> = todo
        .par_iter()
        .map(|&e| {
            let mut effects = base_effects.to_vec();
            effects.push(e);
            // Start from the baseline's starting rigidities (a reference fit
            // may have run a rigidity off to where it no longer matters) and
            // the reference's effects.
            let mut start = reference.actuator.clone();
            start.ea_n = base.ea_n;
            start.ga_n = base.ga_n;
            start.ei_n_mm2 = base.ei_n_mm2;
            let fs = FitSpec { effects, angle_weight_mm_per_deg: spec.angle_weight_mm_per_deg };
            (e, fit(&start, options, data, train, &fs))
        })
        .collect();
    let mut cands = Vec::new();
    let mut fits = Vec::new();
    for (e, r) in results {
        let ok = r.as_ref().ok().cloned();
        cands.push(candidate(e, reference.bic, r));
        if let Some(f) = ok {
            fits.push((e, f));
        }
    }
    cands.sort_by(|a, b| a.delta_bic.total_cmp(&b.delta_bic));
    for (k, c) in cands.iter_mut().enumerate() {
        c.rank = k + 1;
    }
    (cands, fits)
}

/// Runs the whole workflow on `data` with `base` as the starting actuator.
pub fn diagnose(base: &Actuator, options: &SolverOptions, data: &Dataset, spec: &DiagnoseSpec) -> Result<Diagnosis, CalibrateError> {
    let (train, held) = split_holdout(data, spec.holdout.as_deref())?;
    let w = spec.angle_weight_mm_per_deg;
    let baseline = fit(base, options, data, &train, &FitSpec { effects: Vec::new(), angle_weight_mm_per_deg: w })?;
    let diagnostics = residual_diagnostics(data, &train, &baseline.predictions, w);
    let (candidates, fits) = round(base, options, data, &train, spec, &[], &baseline);
    let mut named = Vec::new();
    let mut ambiguous_between = Vec::new();
    let mut separating_measurement = None;
    let mut second_round = Vec::new();
    let mut extended = baseline.clone();
    let verdict = match decide(&candidates, spec) {
        Decision::None => "none".to_string(),
        Decision::Ambiguous(a, b) => {
            ambiguous_between = vec![a.name(), b.name()];
            separating_measurement = Some(a.separating_measurement(b).to_string());
            "ambiguous".to_string()
        }
        Decision::Named(e) => {
            let f = fits.iter().find(|(fe, _)| *fe == e).expect("named effect was fitted").1.clone();
            let c = candidates.iter().find(|c| c.effect == e.name()).expect("candidate");
            named.push(NamedEffect {
                effect: e.name(),
                parameter_name: e.parameter_name(),
                parameter: c.parameter,
                parameter_se: c.parameter_se,
                delta_bic: c.delta_bic,
            });
            extended = f;
            // Forward-stepwise: is a second effect warranted on top?
            if spec.max_effects > 1 {
                let (cands2, fits2) = round(base, options, data, &train, spec, &[e], &extended);
                if let Decision::Named(e2) = decide(&cands2, spec) {
                    let f2 = fits2.iter().find(|(fe, _)| *fe == e2).expect("fitted").1.clone();
                    let c2 = cands2.iter().find(|c| c.effect == e2.name()).expect("candidate");
                    // The first effect's value is re-estimated with the second.
                    if let Some(p1) = f2.effect_parameter(e) {
                        named[0].parameter = p1.value;
                        named[0].parameter_se = p1.se;
                    }
                    named.push(NamedEffect {
                        effect: e2.name(),
                        parameter_name: e2.parameter_name(),
                        parameter: c2.parameter,
                        parameter_se: c2.parameter_se,
                        delta_bic: c2.delta_bic,
                    });
                    extended = f2;
                }
                second_round = cands2;
            }
            e.name().to_string()
        }
    };
    // Predict every row (the held-out routing too) with both models.
    let all = data.groups();
    let baseline_predictions = predict(&baseline.actuator, options, data, &all, true)?;
    let extended_predictions = predict(&extended.actuator, options, data, &all, true)?;
    let (holdout_rms_before, holdout_rms_after) = match &held {
        Some(g) => {
            let g = std::slice::from_ref(g);
            let rms = |p: &[Option<super::predict::Prediction>]| rms_per_routing(data, g, p, w)[0].rms_mm;
            (Some(rms(&baseline_predictions)), Some(rms(&extended_predictions)))
        }
        None => (None, None),
    };
    let criterion = format!(
        "name an effect when refitting it with EA, GA, EI lowers the BIC (n ln(RSS/n) + p ln n) by at least {} against the model without it, \
         leads the runner-up by at least {} and has a physically plausible value; add effects forward-stepwise by the same rule (at most {})",
        spec.threshold, spec.margin, spec.max_effects
    );
    Ok(Diagnosis {
        verdict,
        named,
        ambiguous_between,
        separating_measurement,
        candidates,
        second_round,
        baseline,
        extended,
        diagnostics,
        holdout: held.map(|g| g.routing),
        holdout_rms_before,
        holdout_rms_after,
        baseline_predictions,
        extended_predictions,
        criterion,
    })
}

/// Residual statistics of the baseline over the fitted rows.
pub fn residual_diagnostics(
    data: &Dataset,
    groups: &[RoutingGroup],
    predictions: &[Option<super::predict::Prediction>],
    w: f64,
) -> ResidualDiagnostics {
    let r = residuals(data, groups, predictions, w);
    let rows: Vec<usize> = groups.iter().flat_map(|g| g.rows.iter().copied()).collect();
    let max_t = rows.iter().map(|&i| data.rows[i].tension_n).fold(0.0, f64::max);
    let class = |name: &str, keep: &dyn Fn(usize) -> bool| -> ResidualClass {
        let picked: Vec<usize> = (0..rows.len()).filter(|&k| keep(rows[k])).collect();
        let n = picked.len().max(1) as f64;
        let sum = |c: usize| picked.iter().map(|&k| r[3 * k + c]).sum::<f64>() / n;
        let ss: f64 = picked.iter().map(|&k| (0..3).map(|c| r[3 * k + c].powi(2)).sum::<f64>()).sum();
        ResidualClass {
            class: name.to_string(),
            rows: picked.len(),
            rms_mm: (ss / (3.0 * n)).sqrt(),
            mean_dx_mm: sum(0),
            mean_dy_mm: sum(1),
            mean_dtheta_deg: if w > 0.0 { sum(2) / w } else { f64::NAN },
        }
    };
    let d = |i: usize| data.rows[i].direction;
    let t = |i: usize| data.rows[i].tension_n;
    let classes = vec![
        class("load", &|i| d(i) == Direction::Load),
        class("unload", &|i| d(i) == Direction::Unload),
        class("rest", &|i| d(i) == Direction::Rest),
        class("tension ≤ τ_max/2", &|i| d(i) != Direction::Rest && t(i) <= 0.5 * max_t),
        class("tension > τ_max/2", &|i| t(i) > 0.5 * max_t),
    ];
    // Loop gap: pairs of load/unload rows at equal tension in a routing.
    let (mut gap, mut pairs) = (0.0, 0usize);
    let (mut shift, mut routings_with_rests) = (0.0, 0usize);
    for g in groups {
        let angle = |i: usize| data.rows[i].tip_angle_rad;
        let model = |i: usize| predictions[i].as_ref().expect("predicted").pose.tip_angle_rad;
        for &i in &g.rows {
            if d(i) != Direction::Load {
                continue;
            }
            if let Some(&j) = g.rows.iter().find(|&&j| d(j) == Direction::Unload && (t(j) - t(i)).abs() < 1e-9) {
                gap += ((angle(j) - angle(i)) - (model(j) - model(i))).to_degrees().abs();
                pairs += 1;
            }
        }
        let rests: Vec<usize> = g.rows.iter().copied().filter(|&i| d(i) == Direction::Rest).collect();
        if rests.len() >= 2 {
            let (a, b) = (rests[0], rests[rests.len() - 1]);
            shift += ((angle(b) - angle(a)) - (model(b) - model(a))).to_degrees();
            routings_with_rests += 1;
        }
    }
    ResidualDiagnostics {
        classes,
        loop_gap_deg: if pairs > 0 { gap / pairs as f64 } else { f64::NAN },
        rest_shift_deg: if routings_with_rests > 0 { shift / routings_with_rests as f64 } else { f64::NAN },
        per_routing: rms_per_routing(data, groups, predictions, w),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cand(effect: Effect, delta_bic: f64, plausible: bool) -> Candidate {
        Candidate {
            rank: 0,
            effect: effect.name(),
            parameter_name: effect.parameter_name(),
            parameter: 1.0,
            parameter_se: 0.1,
            delta_bic,
            rms_mm: 1.0,
            plausible,
            error: None,
        }
    }

    #[test]
    fn the_criterion_names_refuses_or_calls_it_ambiguous() {
        let spec = DiagnoseSpec::default();
        let named = |c: &[Candidate]| match decide(c, &spec) {
            Decision::None => "none".to_string(),
            Decision::Named(e) => e.name().to_string(),
            Decision::Ambiguous(a, b) => format!("{}|{}", a.name(), b.name()),
        };
        use Effect::*;
        assert_eq!(named(&[cand(Friction, -50.0, true), cand(Creep, -30.0, true)]), "friction");
        assert_eq!(named(&[cand(Friction, -50.0, true), cand(Creep, -45.0, true)]), "friction|creep");
        assert_eq!(named(&[cand(Friction, -9.0, true), cand(Creep, 3.0, true)]), "none");
        // An implausible value is passed over, for naming and as runner-up.
        assert_eq!(named(&[cand(Gravity, -80.0, false), cand(Friction, -50.0, true), cand(Creep, -20.0, true)]), "friction");
        assert_eq!(named(&[cand(Friction, -50.0, true), cand(Gravity, -48.0, false)]), "friction");
        assert_eq!(named(&[]), "none");
    }
}
