//! One diagnosis for every kind of data: its settings ([`DiagnoseSpec`]),
//! its outcome ([`Diagnosis`]) and the residual's signature
//! ([`Signature`]). What differs between planar measurements and captures
//! with 3-D markers (how residuals are formed, what is held out, where the
//! residuals are described to sit, what the report draws) is named by the
//! kind's fit report through [`DiagnosisKind`].

use super::criterion::{self, Candidate, NamedEffect};
use super::rounds::Thresholds;
use super::Verdict;
use crate::calibrate::fit::{FitReport, FitResult, FitSpec};
use crate::calibrate::Effect;
use crate::solver::SolverOptions;
use serde::Serialize;
use std::fmt::Debug;
use std::path::PathBuf;

/// A kind of data a diagnosis reads, named by its fit report.
pub trait DiagnosisKind: FitReport {
    /// How the kind's readings become whitened residuals (the noise, and
    /// for planar measurements their shapes and the angle's weight).
    type Settings: Clone + Debug + PartialEq;
    /// What is held out of every fit to measure the gap: a routing's name,
    /// or the cable (1-based) whose pulling captures are left out.
    type Holdout: Clone + Debug + PartialEq;
    /// Where the residuals sit, for the signature.
    type Sites: Clone + Debug + Serialize;
    /// What the kind's report reads beyond the rounds.
    type Details: Clone + Debug;
}

/// Settings of a diagnosis.
#[derive(Debug, Clone, PartialEq)]
pub struct DiagnoseSpec<K: DiagnosisKind> {
    /// The body's parameters (some held), loss and iteration cap of every
    /// fit; the candidates' effects are added to them.
    pub fit: FitSpec,
    /// How the readings become residuals.
    pub settings: K::Settings,
    /// The solver's settings.
    pub options: SolverOptions,
    /// What is held out of every fit.
    pub holdout: Option<K::Holdout>,
    /// Effects held at given values on the starting actuator (`--fix`):
    /// part of every model, not candidates.
    pub held_effects: Vec<Effect>,
    /// Required BIC decrease against the model without the effect.
    pub threshold: f64,
    /// Required BIC lead over the runner-up.
    pub margin: f64,
    /// Most effects added.
    pub max_effects: usize,
    /// A model is consistent with the noise when P(χ²_dof ≥ χ²) ≥ alpha.
    pub alpha: f64,
}

impl<K: DiagnosisKind> DiagnoseSpec<K> {
    /// The naming rule's thresholds.
    pub fn rule(&self) -> criterion::Rule {
        criterion::Rule { threshold: self.threshold, margin: self.margin }
    }

    /// The rounds' thresholds.
    pub fn thresholds(&self) -> Thresholds {
        Thresholds { rule: self.rule(), max_effects: self.max_effects, alpha: self.alpha }
    }

    /// Refuses a noise level outside (0, 1).
    pub fn check(&self) -> Result<(), crate::calibrate::CalibrateError> {
        if self.alpha > 0.0 && self.alpha < 1.0 {
            Ok(())
        } else {
            Err(crate::calibrate::InvalidRequest::Alpha { alpha: self.alpha }.into())
        }
    }
}

/// Where the best model's residuals sit, when no library effect explains them.
#[derive(Debug, Clone, Serialize)]
#[serde(bound(serialize = ""))]
pub struct Signature<K: DiagnosisKind> {
    /// The model whose residuals are described.
    pub model: String,
    /// Where they sit.
    #[serde(flatten)]
    pub sites: K::Sites,
    /// The same in words.
    pub summary: Vec<String>,
}

/// The outcome of a diagnosis.
#[derive(Debug, Clone)]
pub struct Diagnosis<K: DiagnosisKind> {
    /// The verdict.
    pub verdict: Verdict,
    /// Why, in one sentence (states the test).
    pub reason: String,
    /// Effects of the final model, in the order they were added.
    pub named: Vec<NamedEffect>,
    /// With `unexplained`: library effects that lower the BIC but leave the
    /// fit above the noise.
    pub partial_effects: Vec<NamedEffect>,
    /// The two effects the data cannot tell apart, if ambiguous.
    pub ambiguous_between: Vec<Effect>,
    /// The measurement that would separate them.
    pub separating_measurement: Option<String>,
    /// Ranked candidates of the first round.
    pub candidates: Vec<Candidate>,
    /// Ranked candidates of the second round (given the first effect).
    pub second_round: Vec<Candidate>,
    /// Effects left out of the candidates, and why.
    pub not_candidates: Vec<String>,
    /// The fit without candidate effects.
    pub baseline: FitResult<K>,
    /// The final model's fit (the baseline if nothing was named).
    pub extended: FitResult<K>,
    /// The best model tried (lowest χ² among the fits that count), whose
    /// residuals the signature describes.
    pub best: FitResult<K>,
    /// The residual's signature (with `unexplained`).
    pub signature: Option<Signature<K>>,
    /// What was held out.
    pub holdout: Option<K::Holdout>,
    /// RMS of the held-out data with the baseline, mm.
    pub holdout_rms_before: Option<f64>,
    /// With the final model, mm.
    pub holdout_rms_after: Option<f64>,
    /// The decision rule in words.
    pub criterion: String,
    /// The noise test's level.
    pub alpha: f64,
    /// Readings fitted (rows of planar measurements, captures).
    pub fitted: usize,
    /// Wall time, s.
    pub elapsed_s: f64,
    /// What the kind's report reads beyond the rounds.
    pub details: K::Details,
    /// The report's files, when written (`report.md` first, then its pictures).
    pub written: Vec<PathBuf>,
}

impl<K: DiagnosisKind> Diagnosis<K> {
    /// The first named effect (its parameter is the `--json` object's
    /// `parameter`).
    pub fn first_named(&self) -> Option<&NamedEffect> {
        self.named.first()
    }

    /// The pictures written beside the report (none without one).
    pub fn pictures(&self) -> Vec<PathBuf> {
        self.written.iter().skip(1).cloned().collect()
    }
}

/// The `--json` fields of every diagnosis: the verdict, its first named
/// effect's parameter, the rounds, the rule and the hold-out gap; each
/// kind adds its fits and what it holds out.
#[derive(Serialize)]
pub(super) struct VerdictJson<'a> {
    verdict: Verdict,
    reason: &'a str,
    parameter_name: Option<&'static str>,
    parameter: Option<f64>,
    parameter_se: Option<f64>,
    effects: &'a [NamedEffect],
    partial_effects: &'a [NamedEffect],
    ambiguous_between: &'a [Effect],
    separating_measurement: &'a Option<String>,
    candidates: &'a [Candidate],
    second_round: &'a [Candidate],
    criterion: &'a str,
    alpha: f64,
    holdout_rms_before: Option<f64>,
    holdout_rms_after: Option<f64>,
}

impl<K: DiagnosisKind> Diagnosis<K> {
    /// The `--json` fields every kind writes.
    pub(super) fn verdict_json(&self) -> VerdictJson<'_> {
        let first = self.first_named();
        VerdictJson {
            verdict: self.verdict,
            reason: &self.reason,
            parameter_name: first.map(|n| n.parameter_name),
            parameter: first.map(|n| n.parameter),
            parameter_se: first.map(|n| n.parameter_se),
            effects: &self.named,
            partial_effects: &self.partial_effects,
            ambiguous_between: &self.ambiguous_between,
            separating_measurement: &self.separating_measurement,
            candidates: &self.candidates,
            second_round: &self.second_round,
            criterion: &self.criterion,
            alpha: self.alpha,
            holdout_rms_before: self.holdout_rms_before,
            holdout_rms_after: self.holdout_rms_after,
        }
    }
}

/// The effects a fit added to the body, in the order of its parameters
/// (the order they were added).
pub fn fitted_effects<R: FitReport>(f: &FitResult<R>) -> Vec<Effect> {
    f.parameters
        .iter()
        .filter_map(|p| match p.param {
            crate::calibrate::Parameter::Effect(e) => Some(e),
            _ => None,
        })
        .collect()
}
