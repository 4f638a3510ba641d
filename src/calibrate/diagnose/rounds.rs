//! The one diagnosis state machine, for every kind of data: from the
//! baseline fit (the body without candidate effects), rounds of refits
//! with each candidate effect, the naming rule on each round
//! ([`criterion::decide`]), and the verdict judged against the noise.
//!
//! 1. A first round refits every candidate on top of the baseline. An
//!    effect is named when its fit lowers the BIC by at least `threshold`
//!    against the model without it, leads the runner-up by at least
//!    `margin`, converged and has a plausible value; two within `margin`
//!    are ambiguous. A second round adds a second effect by the same rule
//!    (at most `max_effects`).
//! 2. Adequacy: `inconclusive` when the baseline fit did not converge;
//!    otherwise the judged model (the named one, the better of an
//!    ambiguous pair) is tested by χ² against the noise (p ≥ `alpha`):
//!    consistent gives `none`, the named effect or `ambiguous`, and
//!    `inconclusive` when no candidate fit counts; above the noise, the best
//!    one or two library effects are tried and, when even they stay above
//!    it, the verdict is `unexplained`.
//!
//! The kind of data ([`Evidence`]) makes the fits and the sentences, and
//! says how far to search ([`Search`]).

use super::criterion::{self, decide, rank, Candidate, Decision, NamedEffect, Rule};
use super::Verdict;
use crate::calibrate::fit::{FitReport, FitResult};
use crate::calibrate::{CalibrateError, Effect, Parameter};
use rayon::prelude::*;

/// How far a diagnosis searches beyond the first round.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Search {
    /// A second round after every named effect; when nothing is named and
    /// the data are above the noise, the best candidate and a second
    /// effect on top of it; the best model is the lowest χ² of every model
    /// tried. Planar fits are cheap.
    Thorough,
    /// A second round only when the named effect leaves the fit above the
    /// noise; when nothing is named, only the best single candidate. Every
    /// fit re-solves each capture in 3-D.
    Frugal,
}

/// What the rounds read of a fit.
pub trait Judged {
    /// χ² of the whitened residuals.
    fn chi2(&self) -> f64;
    /// P(χ²_dof ≥ χ²).
    fn p_value(&self) -> f64;
    /// The BIC.
    fn bic(&self) -> f64;
    /// Whether the fit met its stopping rule.
    fn converged(&self) -> bool;
    /// The fitted value and standard error of `effect`, if it was fitted.
    fn effect_parameter(&self, effect: Effect) -> Option<(f64, f64)>;
    /// "χ² = … on … dof, χ²/dof = …, p = …".
    fn chi2_text(&self) -> String;
}

impl<R: FitReport> Judged for FitResult<R> {
    fn chi2(&self) -> f64 {
        self.chi2
    }

    fn p_value(&self) -> f64 {
        self.p_value
    }

    fn bic(&self) -> f64 {
        self.bic
    }

    fn converged(&self) -> bool {
        self.converged
    }

    fn effect_parameter(&self, effect: Effect) -> Option<(f64, f64)> {
        self.parameter(Parameter::Effect(effect)).map(|p| (p.value, p.se))
    }

    fn chi2_text(&self) -> String {
        criterion::chi2_text(self.chi2, self.dof, self.reduced_chi2, self.p_value)
    }
}

/// A fit and the candidate effects fitted in it, in the order added.
#[derive(Debug, Clone)]
pub struct Model<F> {
    /// The fit.
    pub fit: F,
    /// Its candidate effects.
    pub effects: Vec<Effect>,
}

/// A kind of data as the diagnosis sees it: the refits of a round, a
/// candidate read from its fit, and the verdict's sentences.
pub trait Evidence: Sync {
    /// The kind's fit result.
    type Fit: Judged + Clone + Send + Sync;
    /// How far to search.
    fn search(&self) -> Search;
    /// The effects a round may add, in order.
    fn candidate_effects(&self) -> &[Effect];
    /// A fit with `effects` (the last one new), from `reference`'s optimum.
    fn refit(&self, effects: &[Effect], reference: &Self::Fit) -> Result<Self::Fit, CalibrateError>;
    /// The round's candidate for `effect` from its fit.
    fn candidate(&self, effect: Effect, reference_bic: f64, fit: &Result<Self::Fit, CalibrateError>) -> Candidate;
    /// Why nothing can be concluded when the baseline did not converge.
    fn not_converged(&self, baseline: &Self::Fit) -> String;
    /// Why nothing can be concluded when the baseline is consistent but no candidate counts.
    fn nothing_counts(&self) -> String;
    /// The baseline explains the data.
    fn baseline_explains(&self, baseline: &Self::Fit) -> String;
    /// `model` explains the data.
    fn model_explains(&self, model: &Model<Self::Fit>) -> String;
    /// Even `best`, the best model tried, stays above the noise at `alpha`.
    fn unexplained(&self, best: &Model<Self::Fit>, alpha: f64) -> String;
}

/// The thresholds of a diagnosis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Thresholds {
    /// The naming rule.
    pub rule: Rule,
    /// Most effects added.
    pub max_effects: usize,
    /// Consistent with the noise when P(χ²_dof ≥ χ²) ≥ alpha.
    pub alpha: f64,
}

/// What the rounds conclude.
#[derive(Debug, Clone)]
pub struct Rounds<F> {
    /// The verdict.
    pub verdict: Verdict,
    /// Why, in one sentence.
    pub reason: String,
    /// Effects of the final model, in the order added.
    pub named: Vec<NamedEffect>,
    /// With `unexplained`: effects that lower the BIC but leave the fit above the noise.
    pub partial_effects: Vec<NamedEffect>,
    /// The two effects the data cannot tell apart, if ambiguous.
    pub ambiguous_between: Vec<Effect>,
    /// The measurement that would separate them.
    pub separating_measurement: Option<String>,
    /// Ranked candidates of the first round.
    pub candidates: Vec<Candidate>,
    /// Ranked candidates of the second round.
    pub second_round: Vec<Candidate>,
    /// The final model (the baseline if nothing was named).
    pub extended: Model<F>,
    /// The best model tried, whose residuals a signature describes.
    pub best: Model<F>,
}

/// One round: every candidate not in `effects`, refitted with them from
/// `reference`'s optimum (in parallel), ranked.
fn round<E: Evidence>(evidence: &E, effects: &[Effect], reference: &E::Fit) -> (Vec<Candidate>, Vec<(Effect, E::Fit)>) {
    let todo: Vec<Effect> = evidence.candidate_effects().iter().copied().filter(|e| !effects.contains(e)).collect();
    let results: Vec<(Effect, Result<E::Fit, CalibrateError>)> = todo
        .par_iter()
        .map(|&e| {
            let mut with = effects.to_vec();
            with.push(e);
            (e, evidence.refit(&with, reference))
        })
        .collect();
    let mut candidates = Vec::new();
    let mut fits = Vec::new();
    for (e, r) in results {
        candidates.push(evidence.candidate(e, reference.bic(), &r));
        if let Ok(f) = r {
            fits.push((e, f));
        }
    }
    rank(&mut candidates);
    (candidates, fits)
}

fn fit_of<F: Clone>(fits: &[(Effect, F)], e: Effect) -> F {
    fits.iter().find(|(f, _)| *f == e).expect("a candidate that counts was fitted").1.clone()
}

fn candidate_of(candidates: &[Candidate], e: Effect) -> &Candidate {
    candidates.iter().find(|c| c.effect == e).expect("candidate")
}

/// Runs the rounds from `baseline`.
pub fn run<E: Evidence>(evidence: &E, baseline: &E::Fit, thresholds: Thresholds) -> Rounds<E::Fit> {
    let Thresholds { rule, max_effects, alpha } = thresholds;
    let search = evidence.search();
    let base_model = Model { fit: baseline.clone(), effects: Vec::new() };
    let (candidates, fits) = round(evidence, &[], baseline);
    let mut named: Vec<NamedEffect> = Vec::new();
    let mut ambiguous_between = Vec::new();
    let mut separating_measurement = None;
    let mut second_round = Vec::new();
    let mut extended = base_model.clone();
    let mut verdict;
    let decision = decide(&candidates, rule);
    match decision {
        Decision::None => verdict = Verdict::Consistent,
        Decision::Ambiguous(a, b) => {
            ambiguous_between = vec![a, b];
            separating_measurement = Some(a.separating_measurement(b).to_string());
            verdict = Verdict::Ambiguous(a, b);
        }
        Decision::Named(e) => {
            named.push(NamedEffect::of(candidate_of(&candidates, e)));
            extended = Model { fit: fit_of(&fits, e), effects: vec![e] };
            let second = match search {
                Search::Thorough => true,
                Search::Frugal => !extended.fit.p_value().ge(&alpha),
            };
            if max_effects > 1 && second {
                let (cands2, fits2) = round(evidence, &[e], &extended.fit);
                if let Decision::Named(e2) = decide(&cands2, rule) {
                    let f2 = fit_of(&fits2, e2);
                    // The first effect's value is re-estimated with the second.
                    if let Some((value, se)) = f2.effect_parameter(e) {
                        named[0].parameter = value;
                        named[0].parameter_se = se;
                    }
                    named.push(NamedEffect::of(candidate_of(&cands2, e2)));
                    extended = Model { fit: f2, effects: vec![e, e2] };
                }
                second_round = cands2;
            }
            verdict = Verdict::Named(e);
        }
    }
    // The model judged against the noise: the named one, or for an
    // ambiguous pair the better of the two.
    let mut judged = match decision {
        Decision::Ambiguous(a, _) => Model { fit: fit_of(&fits, a), effects: vec![a] },
        _ => extended.clone(),
    };
    let any_counts = candidates.iter().any(Candidate::counts);
    let mut partial_effects = Vec::new();
    let reason;
    if !baseline.converged() {
        verdict = Verdict::Inconclusive;
        named.clear();
        extended = base_model;
        reason = evidence.not_converged(baseline);
    } else if judged.fit.p_value() >= alpha {
        reason = match verdict {
            Verdict::Consistent if !any_counts => {
                verdict = Verdict::Inconclusive;
                evidence.nothing_counts()
            }
            Verdict::Consistent => evidence.baseline_explains(baseline),
            Verdict::Ambiguous(..) => {
                format!("two effects fit equally well and the better one is consistent with the noise ({})", judged.fit.chi2_text())
            }
            _ => evidence.model_explains(&extended),
        };
    } else {
        // Not explained yet: the best one (or two) library effects.
        let mut best_pair: Option<(Effect, E::Fit, Candidate, Candidate)> = None;
        let look = match search {
            Search::Thorough => max_effects > 1,
            Search::Frugal => true,
        };
        if !matches!(decision, Decision::Named(_)) && look {
            if let Some(c1) = candidates.iter().find(|c| c.counts()) {
                let e1 = c1.effect;
                let f1 = fit_of(&fits, e1);
                if search == Search::Thorough {
                    let (cands2, fits2) = round(evidence, &[e1], &f1);
                    if let Decision::Named(e2) = decide(&cands2, rule) {
                        best_pair = Some((e1, fit_of(&fits2, e2), c1.clone(), candidate_of(&cands2, e2).clone()));
                    }
                    second_round = cands2;
                }
                if f1.chi2() < judged.fit.chi2() {
                    judged = Model { fit: f1, effects: vec![e1] };
                }
            }
        }
        match best_pair {
            Some((e1, f2, c1, c2)) if f2.p_value() >= alpha => {
                let mut n1 = NamedEffect::of(&c1);
                if let Some((value, se)) = f2.effect_parameter(e1) {
                    n1.parameter = value;
                    n1.parameter_se = se;
                }
                named = vec![n1, NamedEffect::of(&c2)];
                ambiguous_between.clear();
                separating_measurement = None;
                extended = Model { fit: f2, effects: vec![e1, c2.effect] };
                verdict = Verdict::Named(e1);
                reason = evidence.model_explains(&extended);
            }
            pair => {
                if search == Search::Thorough {
                    if let Some((e1, f2, _, c2)) = pair {
                        if f2.chi2() < judged.fit.chi2() {
                            judged = Model { fit: f2, effects: vec![e1, c2.effect] };
                        }
                    }
                    if extended.fit.chi2() < judged.fit.chi2() {
                        judged = extended.clone();
                    }
                }
                // The effects that help, kept for the report, named nowhere.
                partial_effects = std::mem::take(&mut named);
                if partial_effects.is_empty() {
                    if let Some(c) = candidates.iter().find(|c| c.counts() && c.delta_bic <= -rule.threshold) {
                        partial_effects.push(NamedEffect::of(c));
                    }
                }
                ambiguous_between.clear();
                separating_measurement = None;
                extended = base_model;
                verdict = Verdict::Unexplained;
                reason = evidence.unexplained(&judged, alpha);
            }
        }
    }
    let best = if search == Search::Frugal || judged.fit.chi2() <= extended.fit.chi2() { judged } else { extended.clone() };
    Rounds { verdict, reason, named, partial_effects, ambiguous_between, separating_measurement, candidates, second_round, extended, best }
}
