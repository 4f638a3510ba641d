//! The naming rule both diagnoses share (planar tip data in this folder's
//! `analysis.rs`, 3-D markers in `captures.rs`): a
//! candidate effect refitted with the body, the ranking of a round's
//! candidates by BIC, and the decision of a round — an effect is named when
//! its fit lowers the BIC by at least `threshold` against the model without
//! it, leads the runner-up by at least `margin`, converged and has a
//! plausible value; two that fit within `margin` of each other are
//! ambiguous.

use crate::calibrate::effect::Effect;
use crate::calibrate::stats;
use serde::Serialize;

/// One candidate effect refitted with the body.
#[derive(Debug, Clone, Serialize)]
pub struct Candidate {
    /// Rank (1 = lowest BIC).
    pub rank: usize,
    /// The effect.
    pub effect: Effect,
    /// Parameter name with unit.
    pub parameter_name: &'static str,
    /// Fitted value (NaN if the fit failed).
    pub parameter: f64,
    /// Its standard error.
    pub parameter_se: f64,
    /// BIC change against the model without the effect (negative: better).
    pub delta_bic: f64,
    /// RMS residual of the fit, mm (planar: the tip's; 3-D: the markers').
    pub rms_mm: f64,
    /// χ² of the whitened residuals (planar: outliers set aside).
    pub chi2: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// χ²/dof.
    pub reduced_chi2: f64,
    /// P(χ²_dof ≥ χ²).
    pub p_value: f64,
    /// Whether the fit converged.
    pub converged: bool,
    /// Whether the values are physically plausible and determined (effect and body).
    pub plausible: bool,
    /// Implausible or undetermined values, in words.
    pub flags: Vec<String>,
    /// Why the fit failed, if it did.
    pub error: Option<String>,
}

impl Candidate {
    /// The candidate whose fit failed with `error`: it counts as no evidence.
    pub fn failed(effect: Effect, error: String) -> Self {
        Candidate {
            rank: 0,
            effect,
            parameter_name: effect.parameter_name(),
            parameter: f64::NAN,
            parameter_se: f64::NAN,
            delta_bic: f64::INFINITY,
            rms_mm: f64::NAN,
            chi2: f64::NAN,
            dof: 0,
            reduced_chi2: f64::NAN,
            p_value: f64::NAN,
            converged: false,
            plausible: false,
            flags: Vec::new(),
            error: Some(error),
        }
    }

    /// Whether this fit counts as evidence: it ran, converged and its
    /// values are plausible.
    pub fn counts(&self) -> bool {
        self.error.is_none() && self.converged && self.plausible && self.delta_bic.is_finite()
    }

    /// Why it does not count, in words (None when it does).
    pub fn failure(&self) -> Option<String> {
        if let Some(e) = &self.error {
            return Some(format!("fit failed: {e}"));
        }
        if !self.converged {
            return Some("did not converge".into());
        }
        if !self.plausible {
            return Some(if self.flags.is_empty() { "implausible or undetermined value".into() } else { self.flags.join("; ") });
        }
        None
    }
}

/// A named effect of the final model.
#[derive(Debug, Clone, Serialize)]
pub struct NamedEffect {
    /// The effect.
    pub effect: Effect,
    /// Parameter name.
    pub parameter_name: &'static str,
    /// Fitted value.
    pub parameter: f64,
    /// Standard error.
    pub parameter_se: f64,
    /// BIC change that admitted it.
    pub delta_bic: f64,
}

impl NamedEffect {
    /// The effect of candidate `c`, with its fitted value.
    pub fn of(c: &Candidate) -> Self {
        NamedEffect { effect: c.effect, parameter_name: c.effect.parameter_name(), parameter: c.parameter, parameter_se: c.parameter_se, delta_bic: c.delta_bic }
    }
}

/// The thresholds of the naming rule.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rule {
    /// Required BIC decrease against the model without the effect.
    pub threshold: f64,
    /// Required BIC lead over the runner-up.
    pub margin: f64,
}

/// Outcome of one round of the rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Decision {
    /// No candidate is warranted.
    None,
    /// This effect is.
    Named(Effect),
    /// These two fit within the margin of each other (the better first).
    Ambiguous(Effect, Effect),
}

/// Sorts a round's candidates by BIC change (best first) and numbers them.
pub fn rank(candidates: &mut [Candidate]) {
    candidates.sort_by(|a, b| a.delta_bic.total_cmp(&b.delta_bic));
    for (k, c) in candidates.iter_mut().enumerate() {
        c.rank = k + 1;
    }
}

/// The rule on `ranked` (best first, as [`rank`] leaves them): only
/// candidates that count are evidence.
pub fn decide(ranked: &[Candidate], rule: Rule) -> Decision {
    let mut ok = ranked.iter().filter(|c| c.counts());
    let Some(best) = ok.next() else { return Decision::None };
    if best.delta_bic > -rule.threshold {
        return Decision::None;
    }
    match ok.next() {
        Some(runner) if runner.delta_bic - best.delta_bic < rule.margin => Decision::Ambiguous(best.effect, runner.effect),
        _ => Decision::Named(best.effect),
    }
}

/// "χ² = … on … dof, χ²/dof = …, p = …" of a fit, for verdicts' reasons.
pub fn chi2_text(chi2: f64, dof: usize, reduced_chi2: f64, p_value: f64) -> String {
    format!("χ² = {chi2:.1} on {dof} dof, χ²/dof = {reduced_chi2:.2}, {}", stats::p_text(p_value))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cand(effect: Effect, delta_bic: f64, plausible: bool) -> Candidate {
        Candidate {
            rank: 0,
            effect,
            parameter_name: effect.parameter_name(),
            parameter: 1.0,
            parameter_se: 0.1,
            delta_bic,
            rms_mm: 1.0,
            chi2: 100.0,
            dof: 100,
            reduced_chi2: 1.0,
            p_value: 0.5,
            converged: true,
            plausible,
            flags: Vec::new(),
            error: None,
        }
    }

    #[test]
    fn the_rule_names_refuses_or_calls_it_ambiguous() {
        let rule = Rule { threshold: 10.0, margin: 10.0 };
        let named = |c: &[Candidate]| match decide(c, rule) {
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
        // An unconverged or failed fit is no evidence, however good its BIC.
        let mut stuck = cand(Creep, -90.0, true);
        stuck.converged = false;
        assert_eq!(named(&[stuck, cand(Friction, -50.0, true)]), "friction");
        assert_eq!(named(&[Candidate::failed(Creep, "no".into()), cand(Friction, -50.0, true)]), "friction");
    }

    #[test]
    fn ranking_orders_by_bic_change_and_failures_last() {
        let mut c = vec![cand(Effect::Creep, -5.0, true), Candidate::failed(Effect::Gravity, "x".into()), cand(Effect::Friction, -50.0, true)];
        rank(&mut c);
        let order: Vec<(usize, Effect)> = c.iter().map(|c| (c.rank, c.effect)).collect();
        assert_eq!(order, vec![(1, Effect::Friction), (2, Effect::Creep), (3, Effect::Gravity)]);
        assert_eq!(c[2].failure().unwrap(), "fit failed: x");
        assert_eq!(NamedEffect::of(&c[0]).parameter, 1.0);
    }
}
