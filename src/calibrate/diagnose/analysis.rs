//! The model-discrepancy workflow: fit the thesis model, judge whether it
//! explains the data to within the measurement noise, look at where the
//! residuals sit, refit with each candidate effect, name the effect the data
//! call for (or none, or say which two it cannot tell apart, or that no
//! library effect explains the data) and show the gap on a held-out routing
//! before and after.
//!
//! Adequacy comes before naming: a fit's χ² of the noise-whitened residuals
//! (outliers set aside) is tested against χ²_dof. The verdict is `none` only
//! when the thesis model is consistent with the noise (p ≥ `alpha`, 1e-3)
//! and at least one candidate fit converged; `unexplained` when even the
//! best model with one or two library effects stays above the noise
//! (p < `alpha`); `inconclusive` when the thesis-model fit itself did not
//! converge. Only converged fits with plausible values count as evidence.
//!
//! Naming (stated in every report): with the BIC n ln(Σρ/n) + p ln n of the
//! whitened residuals, an effect is named when its fit lowers the BIC by at
//! least `threshold` (10) against the model without it, beats the runner-up
//! by at least `margin` (10) and has a physically plausible value
//! ([`Effect::plausible`]). Effects are added forward-stepwise by the same
//! rule (at most `max_effects`).

use super::criterion::Candidate;
use super::diagnosis::{DiagnoseSpec, Diagnosis, DiagnosisKind, Signature};
use super::rounds::{self, Evidence, Judged, Model, Rounds, Search};
use super::Verdict;
use crate::calibrate::data::{split_holdout, Dataset, Direction, RoutingGroup};
use crate::calibrate::effect::Effect;
use crate::calibrate::fit::{FitResult, Loss};
use crate::calibrate::observations::measurements::{
    closest_on_centreline, fit_measurements, planar_spec, residuals, rms_per_routing, MeasurementSettings, MeasurementsReport, RoutingRms,
};
use crate::calibrate::predict::{predict, Prediction};
use crate::calibrate::CalibrateError;
use crate::model::Rod;
use crate::solver::SolverOptions;
use serde::Serialize;

impl DiagnosisKind for MeasurementsReport {
    type Settings = MeasurementSettings;
    type Holdout = String;
    type Sites = ReadingSites;
    type Details = MeasurementsDetails;
}

impl Default for DiagnoseSpec<MeasurementsReport> {
    fn default() -> Self {
        Self {
            fit: planar_spec(&[], [false; 3], Loss::default(), 200),
            settings: MeasurementSettings::default(),
            options: SolverOptions::default(),
            holdout: None,
            held_effects: Vec::new(),
            threshold: 10.0, margin: 10.0, max_effects: 2,
            alpha: 1e-3,
        }
    }
}

/// What the planar report reads beyond the rounds: where the baseline's
/// residuals sit and every row's predictions by both models.
#[derive(Debug, Clone)]
pub struct MeasurementsDetails {
    /// Residual diagnostics of the baseline.
    pub diagnostics: ResidualDiagnostics,
    /// Predictions of every row (held-out included) by the baseline.
    pub baseline_predictions: Vec<Option<Prediction>>,
    /// Predictions of every row by the final model.
    pub extended_predictions: Vec<Option<Prediction>>,
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

/// Where planar residuals sit: by reading class and by routing, and along the body.
#[derive(Debug, Clone, Serialize)]
pub struct ReadingSites {
    /// By direction and tension band: rows, tip position RMS (mm), tip angle RMS (°).
    pub by_tension: Vec<(String, usize, f64, f64)>,
    /// Per routing, worst first: routing, tip position RMS (mm), tip angle RMS (°).
    pub by_routing: Vec<(String, f64, f64)>,
    /// Shape residual RMS (mm) in the four quarters of the rod from the
    /// clamp (centreline points by their closest point, markers by s);
    /// empty without shape data.
    pub along_body_mm: Vec<f64>,
}

fn candidate(effect: Effect, reference_bic: f64, result: &Result<FitResult<MeasurementsReport>, CalibrateError>) -> Candidate {
    match result {
        Ok(f) => {
            let p = f.effect_parameter(effect).expect("fitted effect");
            Candidate {
                rank: 0,
                effect,
                parameter_name: effect.parameter_name(),
                parameter: p.value,
                parameter_se: p.se,
                delta_bic: f.bic - reference_bic,
                rms_mm: f.rms_mm,
                chi2: f.chi2,
                dof: f.dof,
                reduced_chi2: f.reduced_chi2,
                p_value: f.p_value,
                converged: f.converged,
                plausible: effect.plausible(p.value) && p.se.is_finite() && !f.implausible,
                flags: f.flags.clone(),
                error: None,
            }
        }
        Err(e) => Candidate::failed(effect, e.to_string()),
    }
}

/// Planar measurements as the diagnosis's evidence: the training routings,
/// the starting rod and every candidate not held.
struct MeasurementsEvidence<'a> {
    base: &'a Rod,
    data: &'a Dataset,
    train: &'a [RoutingGroup],
    spec: &'a DiagnoseSpec<MeasurementsReport>,
    candidates: Vec<Effect>,
}

impl Evidence for MeasurementsEvidence<'_> {
    type Fit = FitResult<MeasurementsReport>;

    fn search(&self) -> Search {
        Search::Thorough
    }

    fn candidate_effects(&self) -> &[Effect] {
        &self.candidates
    }

    fn refit(&self, effects: &[Effect], reference: &FitResult<MeasurementsReport>) -> Result<FitResult<MeasurementsReport>, CalibrateError> {
        // Start from the baseline's starting rigidities (a reference fit
        // may have run a rigidity off to where it no longer matters) and
        // the reference's effects.
        let mut start = reference.rod().clone();
        start.ea_n = self.base.ea_n;
        start.ga_n = self.base.ga_n;
        start.ei_n_mm2 = self.base.ei_n_mm2;
        let fs = self.spec.fit.with_effects(effects);
        fit_measurements(&start, &self.spec.options, self.data, self.train, &self.spec.settings, &fs, &mut |_| {})
    }

    fn candidate(&self, effect: Effect, reference_bic: f64, fit: &Result<FitResult<MeasurementsReport>, CalibrateError>) -> Candidate {
        candidate(effect, reference_bic, fit)
    }

    fn not_converged(&self, baseline: &FitResult<MeasurementsReport>) -> String {
        format!(
            "the thesis-model fit did not converge ({} iterations{}), so nothing can be concluded; no verdict is drawn from unconverged fits",
            baseline.iterations,
            if baseline.flags.is_empty() { String::new() } else { format!("; {}", baseline.flags.join("; ")) }
        )
    }

    fn nothing_counts(&self) -> String {
        "the thesis model is consistent with the noise, but no candidate fit converged to a plausible value, so no effect can be ruled out".to_string()
    }

    fn baseline_explains(&self, baseline: &FitResult<MeasurementsReport>) -> String {
        format!(
            "{} explains the data to within the stated noise ({}) and no candidate effect is warranted",
            if self.spec.held_effects.is_empty() {
                "the thesis model".to_string()
            } else {
                let held: Vec<String> =
                    self.spec.held_effects.iter().map(|e| format!("{} = {}", e.parameter_name(), e.current(self.base).unwrap_or(0.0))).collect();
                format!("the thesis model with {} held", held.join(", "))
            },
            baseline.chi2_text()
        )
    }

    fn model_explains(&self, model: &Model<FitResult<MeasurementsReport>>) -> String {
        format!("the model {} explains the data to within the stated noise ({})", model_name(&model.fit), model.fit.chi2_text())
    }

    fn unexplained(&self, best: &Model<FitResult<MeasurementsReport>>, alpha: f64) -> String {
        format!(
            "even the best model tried ({}) stays above the stated noise: {}, below {:.0e} (chi-square test of the noise-whitened residuals); the data show something no candidate effect describes, or the noise is larger than stated",
            model_name(&best.fit),
            best.fit.chi2_text(),
            alpha
        )
    }
}

/// Runs the whole workflow on `data` with `base` as the starting actuator.
pub fn diagnose(base: &Rod, data: &Dataset, spec: &DiagnoseSpec<MeasurementsReport>) -> Result<Diagnosis<MeasurementsReport>, CalibrateError> {
    let started = std::time::Instant::now();
    spec.check()?;
    let options = &spec.options;
    let (train, held) = split_holdout(data, spec.holdout.as_deref())?;
    let w = spec.settings.angle_weight_mm_per_deg;
    let baseline = fit_measurements(base, options, data, &train, &spec.settings, &spec.fit.with_effects(&[]), &mut |_| {})?;
    let diagnostics = residual_diagnostics(data, &train, &baseline.predictions, w);
    let candidates: Vec<Effect> = Effect::ALL.into_iter().filter(|e| !spec.held_effects.contains(e)).collect();
    let evidence = MeasurementsEvidence { base, data, train: &train, spec, candidates };
    let Rounds { verdict, reason, named, partial_effects, ambiguous_between, separating_measurement, candidates, second_round, extended, best } =
        rounds::run(&evidence, &baseline, spec.thresholds());
    let (extended, best) = (extended.fit, best.fit);
    let signature = (verdict == Verdict::Unexplained).then(|| signature(data, &train, &best, &spec.settings));
    // Predict every row (the held-out routing too) with both models.
    let all = data.groups();
    let keep = true;
    let baseline_predictions = predict(baseline.rod(), options, data, &all, keep)?;
    let extended_predictions = predict(extended.rod(), options, data, &all, keep)?;
    let (holdout_rms_before, holdout_rms_after) = match &held {
        Some(g) => {
            let g = std::slice::from_ref(g);
            let rms = |p: &[Option<Prediction>]| rms_per_routing(data, g, p, w)[0].rms_mm;
            (Some(rms(&baseline_predictions)), Some(rms(&extended_predictions)))
        }
        None => (None, None),
    };
    let criterion = format!(
        "residuals are simulated − measured over the noise ({}); adequacy: χ² of these (readings beyond {} σ set aside as outliers, at most 2 or 5 %) \
         against χ²_dof, consistent when p ≥ {:.0e}; `none` only when the thesis model is consistent and a candidate fit converged, \
         `unexplained` when the best model with one or two library effects has p < {:.0e}; an effect is named when refitting it with EA, GA, EI lowers the BIC \
         (n ln(Σρ/n) + p ln n) by at least {} against the model without it, leads the runner-up by at least {} and has physically plausible values; \
         effects are added forward-stepwise by the same rule (at most {}); only converged fits count",
        spec.fit.loss.describe(),
        crate::calibrate::observations::measurements::OUTLIER_Z,
        spec.alpha,
        spec.alpha,
        spec.threshold,
        spec.margin,
        spec.max_effects
    );
    Ok(Diagnosis {
        verdict,
        reason,
        named,
        partial_effects,
        ambiguous_between,
        separating_measurement,
        candidates,
        second_round,
        not_candidates: Vec::new(),
        baseline,
        extended,
        best,
        signature,
        holdout: held.map(|g| g.routing),
        holdout_rms_before,
        holdout_rms_after,
        criterion,
        alpha: spec.alpha,
        fitted: train.iter().map(|g| g.rows.len()).sum(),
        elapsed_s: started.elapsed().as_secs_f64(),
        details: MeasurementsDetails { diagnostics, baseline_predictions, extended_predictions },
        written: Vec::new(),
    })
}

/// "the thesis model" or "with friction + creep".
pub fn model_name(f: &FitResult<MeasurementsReport>) -> String {
    if f.effects.is_empty() {
        "the thesis model".into()
    } else {
        format!("with {}", f.effects.iter().map(|e| e.name()).collect::<Vec<_>>().join(" + "))
    }
}

/// Where the residuals of `f` sit: by direction and tension, by routing,
/// along the body (from shapes), with a few sentences.
pub fn signature(data: &Dataset, groups: &[RoutingGroup], f: &FitResult<MeasurementsReport>, spec: &MeasurementSettings) -> Signature<MeasurementsReport> {
    let rows: Vec<usize> = groups.iter().flat_map(|g| g.rows.iter().copied()).collect();
    let max_t = rows.iter().map(|&i| data.rows[i].tension_n).fold(0.0, f64::max);
    let err = |i: usize| {
        let p = &f.predictions[i].as_ref().expect("predicted").pose;
        let m = &data.rows[i];
        ((p.tip_x_mm - m.tip_x_mm).hypot(p.tip_y_mm - m.tip_y_mm), (p.tip_angle_rad - m.tip_angle_rad).to_degrees())
    };
    let class = |name: &str, keep: &dyn Fn(usize) -> bool| {
        let picked: Vec<usize> = rows.iter().copied().filter(|&i| keep(i)).collect();
        let n = picked.len().max(1) as f64;
        let pos = (picked.iter().map(|&i| err(i).0.powi(2)).sum::<f64>() / n).sqrt();
        let ang = (picked.iter().map(|&i| err(i).1.powi(2)).sum::<f64>() / n).sqrt();
        (name.to_string(), picked.len(), pos, ang)
    };
    let d = |i: usize| data.rows[i].direction;
    let t = |i: usize| data.rows[i].tension_n;
    let by_tension: Vec<(String, usize, f64, f64)> = vec![
        class("rest (0 N)", &|i| t(i) == 0.0),
        class("tension ≤ τ_max/2", &|i| t(i) > 0.0 && t(i) <= 0.5 * max_t),
        class("tension > τ_max/2", &|i| t(i) > 0.5 * max_t),
        class("load", &|i| d(i) == Direction::Load),
        class("unload", &|i| d(i) == Direction::Unload),
        class("static", &|i| d(i) == Direction::Static),
    ]
    .into_iter()
    .filter(|c| c.1 > 0)
    .collect();
    let mut by_routing: Vec<(String, f64, f64)> = f.per_routing.iter().map(|r| (r.routing.clone(), r.rms_position_mm, r.rms_angle_deg)).collect();
    by_routing.sort_by(|a, b| b.1.total_cmp(&a.1));
    // Along the body: shape residuals binned by quarter of the rest length.
    let length = f.rod().length_mm;
    let (mut ss, mut count) = ([0.0; 4], [0usize; 4]);
    let mut add = |s_mm: f64, d2: f64| {
        let q = ((s_mm / length * 4.0).floor().max(0.0) as usize).min(3);
        ss[q] += d2;
        count[q] += 1;
    };
    for &i in &rows {
        let id = data.rows[i].measurement;
        let Some(line) = f.predictions[i].as_ref().and_then(|p| p.centreline.as_deref()) else { continue };
        for p in spec.shapes.centrelines.get(&id).into_iter().flatten() {
            let (dist, s_mm) = closest_on_centreline(*p, line);
            add(s_mm, dist * dist);
        }
        for m in spec.shapes.markers.get(&id).into_iter().flatten() {
            let q = crate::calibrate::observations::measurements::simulated_marker(m, line);
            add(m.s_mm, (q[0] - m.x_mm).powi(2) + (q[1] - m.y_mm).powi(2));
        }
    }
    let along_body_mm: Vec<f64> =
        if count.iter().sum::<usize>() == 0 { Vec::new() } else { (0..4).map(|q| if count[q] > 0 { (ss[q] / count[q] as f64).sqrt() } else { f64::NAN }).collect() };
    let mut summary = Vec::new();
    let get = |name: &str| by_tension.iter().find(|c| c.0.starts_with(name));
    if let (Some(lo), Some(hi)) = (get("tension ≤"), get("tension >")) {
        let rest = get("rest");
        let trend = if hi.2 > 1.5 * lo.2 {
            "grows with tension"
        } else if lo.2 > 1.5 * hi.2 {
            "shrinks with tension"
        } else {
            "is about the same at low and high tension"
        };
        summary.push(format!(
            "The tip error {trend}: {}{:.2} mm / {:.2}° at low tension, {:.2} mm / {:.2}° at high tension.",
            rest.map_or(String::new(), |r| format!("{:.2} mm / {:.2}° at rest, ", r.2, r.3)),
            lo.2,
            lo.3,
            hi.2,
            hi.3
        ));
    }
    if let (Some(l), Some(u)) = (get("load"), get("unload")) {
        let what = if (l.2 - u.2).abs() > 0.3 * l.2.max(u.2) { "differs between" } else { "is alike on" };
        summary.push(format!("It {what} loading ({:.2} mm / {:.2}°) and unloading ({:.2} mm / {:.2}°).", l.2, l.3, u.2, u.3));
    }
    if let (Some(worst), Some(best)) = (by_routing.first(), by_routing.last()) {
        summary.push(format!("Worst routing {} ({:.2} mm / {:.2}°), best {} ({:.2} mm / {:.2}°).", worst.0, worst.1, worst.2, best.0, best.1, best.2));
    }
    if !along_body_mm.is_empty() {
        let cells: Vec<String> = along_body_mm.iter().map(|v| if v.is_finite() { format!("{v:.2}") } else { "—".into() }).collect();
        summary.push(format!("Along the body (quarters from the clamp to the tip), shape error RMS {} mm.", cells.join(" / ")));
    }
    Signature { model: model_name(f), sites: ReadingSites { by_tension, by_routing, along_body_mm }, summary }
}

/// Residual statistics of the baseline over the fitted rows.
pub fn residual_diagnostics(data: &Dataset, groups: &[RoutingGroup], predictions: &[Option<Prediction>], w: f64) -> ResidualDiagnostics {
    let r = residuals(data, groups, predictions, w);
    let rows: Vec<usize> = groups.iter().flat_map(|g| g.rows.iter().copied()).collect();
    let max_t = rows.iter().map(|&i| data.rows[i].tension_n).fold(0.0, f64::max);
    let class = |name: &str, keep: &dyn Fn(usize) -> bool| -> ResidualClass {
        let picked: Vec<usize> = (0..rows.len()).filter(|&k| keep(rows[k])).collect();
        // An empty class has no mean (NaN, shown as "—"), not −0.
        let n = picked.len() as f64;
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
    let mut classes = vec![
        class("load", &|i| d(i) == Direction::Load),
        class("unload", &|i| d(i) == Direction::Unload),
        class("rest", &|i| d(i) == Direction::Rest),
        class("static", &|i| d(i) == Direction::Static),
        class("tension ≤ τ_max/2", &|i| t(i) > 0.0 && t(i) <= 0.5 * max_t),
        class("tension > τ_max/2", &|i| t(i) > 0.5 * max_t),
    ];
    // A static class only when there are static captures.
    classes.retain(|c| c.class != "static" || c.rows > 0);
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
