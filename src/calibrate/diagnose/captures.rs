//! The model-discrepancy workflow for captures with 3-D markers: the
//! planar diagnosis's verdicts (`none`, a named effect with its parameter,
//! `ambiguous`, `unexplained` with the residual's signature,
//! `inconclusive`) over the registry's effects in their 3-D form, by the
//! same rule ([`crate::calibrate::diagnose::analysis`]):
//!
//! 1. Fit the body (the rigidities and the weight the data determine) on
//!    the fitted captures (all, or those where the held-out cable does not
//!    pull).
//! 2. Refit with each candidate effect, from the baseline's optimum; an
//!    effect is named when its fit lowers the BIC by at least `threshold`
//!    against the model without it, leads the runner-up by at least
//!    `margin`, converged and has a plausible value; forward-stepwise, at
//!    most `max_effects`.
//! 3. Adequacy by the χ² of the noise-whitened marker coordinates: `none`
//!    only when the body fit is consistent with the noise (p ≥ `alpha`) and
//!    no effect is warranted; `unexplained` when even the best model with
//!    one or two library effects stays above the noise; `inconclusive`
//!    when the body fit did not converge.
//!
//! Gravity's scale is no candidate when the density is fitted: the two
//! scale the same weight.

use crate::calibrate::observations::captures::errors::ErrorReport;
use crate::calibrate::observations::captures::files::CaptureSet;
use crate::calibrate::fit::{fit, FitResult, FitSpec, FittedParameter, FitReport, Loss, Status};
use crate::calibrate::observations::captures::{Captures, CapturesReport};
use crate::solver::SolverOptions;
use crate::calibrate::Parameter;
use crate::calibrate::observations::captures::simulate::solve_captures;
use crate::calibrate::diagnose::criterion::Candidate;
use crate::calibrate::diagnose::diagnosis::{fitted_effects, DiagnoseSpec, Diagnosis, DiagnosisKind, Signature, VerdictJson};
use crate::calibrate::diagnose::rounds::{self, Evidence, Judged, Model, Rounds, Search};
use crate::calibrate::diagnose::Verdict;
use crate::calibrate::{CalibrateError, Effect};
use crate::model::Actuator;
use serde::Serialize;
use std::collections::BTreeMap;

impl DiagnosisKind for CapturesReport {
    /// The system's noise σ₀ per coordinate, mm, added in quadrature to a
    /// marker's own `sd_mm`.
    type Settings = f64;
    type Holdout = usize;
    type Sites = MarkerSites;
    type Details = ();
}

impl Default for DiagnoseSpec<CapturesReport> {
    fn default() -> Self {
        Self {
            fit: FitSpec { params: Parameter::BODY.to_vec(), held: Vec::new(), loss: Loss::Squared, max_iterations: 40 },
            settings: 1.0,
            options: SolverOptions::default(),
            holdout: None,
            held_effects: Vec::new(),
            threshold: 10.0, margin: 10.0, max_effects: 2, alpha: 1e-3 }
    }
}

/// A fit in brief, for the report.
#[derive(Debug, Clone, Serialize)]
pub struct FitSummary {
    /// The model: the body and its effects.
    pub model: String,
    /// Parameters (name, value, SE, status).
    #[serde(serialize_with = "parameters_json")]
    pub parameters: Vec<FittedParameter>,
    /// χ².
    pub chi2: f64,
    /// Degrees of freedom.
    pub dof: usize,
    /// χ²/dof.
    pub reduced_chi2: f64,
    /// P(χ²_dof ≥ χ²).
    pub p_value: f64,
    /// BIC.
    pub bic: f64,
    /// RMS of the 3-D marker errors, mm.
    pub rms_mm: f64,
    /// Per marker, mm.
    pub rms_by_marker_mm: BTreeMap<String, f64>,
    /// Whether it converged.
    pub converged: bool,
    /// Iterations.
    pub iterations: usize,
}

/// The parameters as a fit to 3-D markers writes them.
fn parameters_json<S: serde::Serializer>(parameters: &[FittedParameter], serializer: S) -> Result<S::Ok, S::Error> {
    CapturesReport::serialize_parameters(parameters, serializer)
}

fn model_name(effects: &[Effect]) -> String {
    if effects.is_empty() {
        "the body (rigidities and weight)".into()
    } else {
        format!("the body with {}", effects.iter().map(|e| e.name()).collect::<Vec<_>>().join(" and "))
    }
}

/// The fit `f` in brief.
pub(super) fn summary(f: &FitResult<CapturesReport>) -> FitSummary {
    FitSummary {
        model: model_name(&fitted_effects(f)),
        parameters: f.parameters.clone(),
        chi2: f.chi2,
        dof: f.dof,
        reduced_chi2: f.reduced_chi2,
        p_value: f.p_value,
        bic: f.bic,
        rms_mm: f.errors.rms_mm,
        rms_by_marker_mm: f.errors.rms_by_marker_mm.clone(),
        converged: f.converged,
        iterations: f.iterations,
    }
}

/// Where 3-D marker residuals sit: by marker and by the cables that pull.
#[derive(Debug, Clone, Serialize)]
pub struct MarkerSites {
    /// RMS per marker, mm.
    pub rms_by_marker_mm: BTreeMap<String, f64>,
    /// RMS of the captures grouped by the cables that pull (`1`, `2`, `1+2`, `none`), mm.
    pub rms_by_cables_mm: BTreeMap<String, f64>,
    /// Mean residual (simulated − measured) per marker, x y z, mm: a systematic offset.
    pub mean_residual_by_marker_mm: BTreeMap<String, [f64; 3]>,
}

fn signature(set: &CaptureSet, f: &FitResult<CapturesReport>) -> Signature<CapturesReport> {
    let mut by_cables: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    let mut sums: BTreeMap<String, ([f64; 3], usize)> = BTreeMap::new();
    for (c, e) in set.captures.iter().zip(&f.errors.captures) {
        let cables = c.pulling_cables();
        let key = if cables.is_empty() { "none".into() } else { cables.iter().map(|k| k.to_string()).collect::<Vec<_>>().join("+") };
        by_cables.entry(key).or_default().extend(e.markers.iter().map(|m| m.error_mm));
        for m in &e.markers {
            let s = sums.entry(m.marker.clone()).or_insert(([0.0; 3], 0));
            for k in 0..3 {
                s.0[k] += m.residual_mm[k];
            }
            s.1 += 1;
        }
    }
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt();
    let rms_by_cables_mm: BTreeMap<String, f64> = by_cables.iter().map(|(k, v)| (k.clone(), rms(v))).collect();
    let mean_residual_by_marker_mm: BTreeMap<String, [f64; 3]> = sums.into_iter().map(|(k, (s, n))| (k, s.map(|v| v / n as f64))).collect();
    let mut summary = Vec::new();
    if let Some((worst, v)) = f.errors.rms_by_marker_mm.iter().max_by(|a, b| a.1.total_cmp(b.1)) {
        summary.push(format!("the largest error is at marker {worst} ({v:.2} mm RMS; all markers {:.2} mm)", f.errors.rms_mm));
    }
    for (k, m) in &mean_residual_by_marker_mm {
        let norm = m.iter().map(|v| v * v).sum::<f64>().sqrt();
        let r = f.errors.rms_by_marker_mm.get(k).copied().unwrap_or(0.0);
        if norm > 0.5 * r && norm > 3.0 * f.noise_mm {
            summary.push(format!("marker {k} is off by a systematic ({:.2}, {:.2}, {:.2}) mm in every capture (a misplaced marker or a frame offset?)", m[0], m[1], m[2]));
        }
    }
    if rms_by_cables_mm.len() > 1 {
        let parts: Vec<String> = rms_by_cables_mm.iter().map(|(k, v)| format!("cable(s) {k}: {v:.2} mm")).collect();
        summary.push(format!("by the cables that pull: {}", parts.join(", ")));
    }
    Signature {
        model: model_name(&fitted_effects(f)),
        sites: MarkerSites { rms_by_marker_mm: f.errors.rms_by_marker_mm.clone(), rms_by_cables_mm, mean_residual_by_marker_mm },
        summary,
    }
}

fn candidate(effect: Effect, reference_bic: f64, result: &Result<FitResult<CapturesReport>, CalibrateError>) -> Candidate {
    match result {
        Ok(f) => {
            let p = f.parameter(Parameter::Effect(effect)).expect("fitted effect");
            let mut flags = Vec::new();
            match p.status {
                Status::Fitted | Status::Held => {}
                Status::Undetermined => flags.push(format!("{} is not determined by these data (held at its start)", p.name)),
                Status::AtBound => flags.push(format!("{} is at the bound of its range", p.name)),
            }
            if !effect.plausible(p.value) {
                flags.push(format!("{} = {:.4e} is outside the plausible range {}", p.name, p.value, effect.plausible_text()));
            } else if !p.se.is_finite() {
                flags.push(format!("{} has no finite standard error", p.name));
            }
            Candidate {
                rank: 0,
                effect,
                parameter_name: effect.parameter_name(),
                parameter: p.value,
                parameter_se: p.se,
                delta_bic: f.bic - reference_bic,
                rms_mm: f.errors.rms_mm,
                chi2: f.chi2,
                dof: f.dof,
                reduced_chi2: f.reduced_chi2,
                p_value: f.p_value,
                converged: f.converged,
                plausible: flags.is_empty(),
                flags,
                error: None,
            }
        }
        Err(e) => Candidate::failed(effect, e.to_string()),
    }
}

/// Captures as the diagnosis's evidence: the fitted captures, the
/// settings, the body parameters the baseline determined and the
/// candidate effects.
struct CapturesEvidence<'a> {
    set: &'a CaptureSet,
    spec: &'a DiagnoseSpec<CapturesReport>,
    body: Vec<Parameter>,
    candidates: Vec<Effect>,
}

impl Evidence for CapturesEvidence<'_> {
    type Fit = FitResult<CapturesReport>;

    fn search(&self) -> Search {
        Search::Frugal
    }

    fn candidate_effects(&self) -> &[Effect] {
        &self.candidates
    }

    fn refit(&self, effects: &[Effect], reference: &FitResult<CapturesReport>) -> Result<FitResult<CapturesReport>, CalibrateError> {
        let mut params = self.body.clone();
        params.extend(effects.iter().map(|&x| Parameter::Effect(x)));
        // From the reference's optimum, the new effect at its start.
        let mut start = reference.actuator.clone();
        let new = *effects.last().expect("a round adds an effect");
        Parameter::Effect(new).set(&mut start, new.start());
        let spec = FitSpec { params, ..self.spec.fit.clone() };
        fit(&start, &Captures::new(self.set, self.spec.settings, &self.spec.options), &spec, &mut |_| {})
    }

    fn candidate(&self, effect: Effect, reference_bic: f64, fit: &Result<FitResult<CapturesReport>, CalibrateError>) -> Candidate {
        candidate(effect, reference_bic, fit)
    }

    fn not_converged(&self, baseline: &FitResult<CapturesReport>) -> String {
        format!("the body fit did not converge ({}), so nothing can be concluded", baseline.report.termination)
    }

    fn nothing_counts(&self) -> String {
        "the body fit is consistent with the noise, but no candidate fit converged to a plausible value, so no effect can be ruled out".to_string()
    }

    fn baseline_explains(&self, baseline: &FitResult<CapturesReport>) -> String {
        format!(
            "the body (rigidities and weight) explains the markers to within the stated noise ({}) and no candidate effect is warranted",
            baseline.chi2_text()
        )
    }

    fn model_explains(&self, model: &Model<FitResult<CapturesReport>>) -> String {
        format!("{} explains the markers to within the stated noise ({})", model_name(&model.effects), model.fit.chi2_text())
    }

    fn unexplained(&self, best: &Model<FitResult<CapturesReport>>, alpha: f64) -> String {
        format!(
            "even the best model tried ({}) stays above the stated noise: {}, below {:.0e} (chi-square test of the noise-whitened marker coordinates); the markers show something no candidate effect describes, or the noise is larger than stated",
            model_name(&best.effects),
            best.fit.chi2_text(),
            alpha
        )
    }
}

/// Runs the 3-D diagnosis of `set` from the actuator `base`.
pub fn diagnose_captures(base: &Actuator, set: &CaptureSet, spec: &DiagnoseSpec<CapturesReport>) -> Result<Diagnosis<CapturesReport>, CalibrateError> {
    let started = std::time::Instant::now();
    spec.check()?;
    let (train, test) = set.hold_out_cable(spec.holdout, base.cables.len())?;
    let body: Vec<Parameter> = spec.fit.params.iter().copied().filter(|p| !matches!(p, Parameter::Effect(_))).collect();
    let baseline = fit(base, &Captures::new(&train, spec.settings, &spec.options), &FitSpec { params: body.clone(), ..spec.fit.clone() }, &mut |_| {})?;
    // The body parameters the baseline determined; undetermined ones stay held.
    let body: Vec<Parameter> = baseline.parameters.iter().filter(|p| p.status == Status::Fitted).map(|p| p.param).collect();
    let mut not_candidates = Vec::new();
    let candidates: Vec<Effect> = Effect::ALL
        .into_iter()
        .filter(|&e| {
            let keep = !(e == Effect::Gravity && body.contains(&Parameter::Density));
            if !keep {
                not_candidates.push(format!("{}: the density is fitted, and both scale the same weight", e.name()));
            }
            keep
        })
        .filter(|e| spec.fit.params.iter().all(|p| *p != Parameter::Effect(*e)) && !spec.held_effects.contains(e))
        .collect();
    let evidence = CapturesEvidence { set: &train, spec, body, candidates };
    let Rounds { verdict, reason, named, partial_effects, ambiguous_between, separating_measurement, candidates, second_round, extended, best } =
        rounds::run(&evidence, &baseline, spec.thresholds());
    let signature = (verdict == Verdict::Unexplained).then(|| signature(&train, &best.fit));
    let (extended, best) = (extended.fit, best.fit);
    let (holdout_rms_before, holdout_rms_after) = match &test {
        Some(t) => {
            let rms = |a: &Actuator| -> Result<f64, CalibrateError> { Ok(ErrorReport::of(t, &solve_captures(a, &spec.options, t)?).rms_mm) };
            (Some(rms(&baseline.actuator)?), Some(rms(&extended.actuator)?))
        }
        None => (None, None),
    };
    let criterion = format!(
        "residuals are the markers' 3-D errors over σ = √(sd² + {} mm²) per coordinate; adequacy: χ² of these against χ²_dof, consistent when p ≥ {:.0e}; \
         `none` only when the body fit is consistent and a candidate fit converged, `unexplained` when the best model with one or two library effects has p < {:.0e}; \
         an effect is named when refitting it with the body lowers the BIC (n ln(Σρ/n) + p ln n) by at least {} against the model without it, leads the runner-up \
         by at least {} and has a plausible, determined value; effects are added forward-stepwise by the same rule (at most {}); only converged fits count",
        spec.settings, spec.alpha, spec.alpha, spec.threshold, spec.margin, spec.max_effects
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
        not_candidates,
        baseline,
        extended,
        best,
        signature,
        holdout: spec.holdout,
        holdout_rms_before,
        holdout_rms_after,
        criterion,
        alpha: spec.alpha,
        fitted: train.captures.len(),
        elapsed_s: started.elapsed().as_secs_f64(),
        details: (),
        written: Vec::new(),
    })
}

/// The `--json` object's fields.
#[derive(Serialize)]
struct Json<'a> {
    #[serde(flatten)]
    verdict: VerdictJson<'a>,
    not_candidates: &'a [String],
    baseline: FitSummary,
    extended: FitSummary,
    signature: &'a Option<Signature<CapturesReport>>,
    holdout_cable: Option<usize>,
    captures_fitted: usize,
    elapsed_s: f64,
}

impl Serialize for Diagnosis<CapturesReport> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        Json {
            verdict: self.verdict_json(),
            not_candidates: &self.not_candidates,
            baseline: summary(&self.baseline),
            extended: summary(&self.extended),
            signature: &self.signature,
            holdout_cable: self.holdout,
            captures_fitted: self.fitted,
            elapsed_s: self.elapsed_s,
        }
        .serialize(serializer)
    }
}

impl std::fmt::Display for Diagnosis<CapturesReport> {
    fn fmt(&self, out: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(out, "verdict: {}", self.verdict)?;
        writeln!(out, "  {}", self.reason)?;
        for n in &self.named {
            writeln!(out, "  {} = {} ± {} (ΔBIC {:.1})", n.parameter_name, crate::io::fmt_sig(n.parameter, 4), crate::io::fmt_sig(n.parameter_se, 2), n.delta_bic)?;
        }
        for n in &self.partial_effects {
            writeln!(out, "  helps but does not explain: {} = {} (ΔBIC {:.1})", n.parameter_name, crate::io::fmt_sig(n.parameter, 4), n.delta_bic)?;
        }
        writeln!(out, "body fit on {} captures: marker RMS {:.3} mm, χ²/dof {:.3}", self.fitted, self.baseline.errors.rms_mm, self.baseline.reduced_chi2)?;
        writeln!(out, "candidates (ΔBIC against the body fit):")?;
        for c in &self.candidates {
            let status = if c.counts() { String::new() } else { format!("  (does not count: {})", c.error.clone().unwrap_or_else(|| if c.converged { "implausible or undetermined value".into() } else { "did not converge".into() })) };
            writeln!(out, "  {:>2}. {:<20} {:>12} ± {:<10} ΔBIC {:>10.1}  RMS {:.3} mm{status}", c.rank, c.effect.name(), crate::io::fmt_sig(c.parameter, 4), crate::io::fmt_sig(c.parameter_se, 2), c.delta_bic, c.rms_mm)?;
        }
        for n in &self.not_candidates {
            writeln!(out, "  not a candidate: {n}")?;
        }
        if let Some(s) = &self.signature {
            writeln!(out, "residual signature ({}):", s.model)?;
            for line in &s.summary {
                writeln!(out, "  {line}")?;
            }
        }
        if let (Some(k), Some(b), Some(a)) = (self.holdout, self.holdout_rms_before, self.holdout_rms_after) {
            writeln!(out, "held out (captures where cable {k} pulls): marker RMS {b:.3} mm with the body fit, {a:.3} mm with the final model")?;
        }
        writeln!(out, "{:.1} s", self.elapsed_s)?;
        if let Some(report) = self.written.first() {
            writeln!(out, "report: {} ({} pictures beside it)", report.display(), self.written.len() - 1)?;
        }
        Ok(())
    }
}
