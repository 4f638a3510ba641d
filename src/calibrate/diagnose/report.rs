//! A finished diagnosis: what `cablemap diagnose` prints (its [`Display`])
//! and its `--json` object (its [`Serialize`]).
//!
//! [`Display`]: std::fmt::Display

use super::analysis::{model_name, ResidualDiagnostics};
use super::criterion::Candidate;
use super::diagnosis::{Diagnosis, Signature, VerdictJson};
use super::Verdict;
use crate::calibrate::observations::captures::CapturesReport;
use crate::calibrate::fit::FitResult;
use crate::calibrate::observations::measurements::MeasurementsReport;
use serde::Serialize;
use std::fmt;
use std::path::PathBuf;

/// A finished diagnosis of either kind of data: serialises to the
/// `--json` object, displays as the summary.
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum DiagnoseReport {
    /// Planar measurements.
    Measurements(Diagnosis<MeasurementsReport>),
    /// Captures with 3-D markers.
    Captures(Diagnosis<CapturesReport>),
}

impl DiagnoseReport {
    /// The `--json` object on one line (keys in alphabetical order).
    pub fn to_json_line(&self) -> String {
        serde_json::to_value(self).expect("a report serialises").to_string()
    }

    /// The pictures written beside the report (none without one).
    pub fn pictures(&self) -> Vec<PathBuf> {
        match self {
            DiagnoseReport::Measurements(d) => d.pictures(),
            DiagnoseReport::Captures(d) => d.pictures(),
        }
    }
}

impl fmt::Display for DiagnoseReport {
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DiagnoseReport::Measurements(m) => m.fmt(out),
            DiagnoseReport::Captures(d) => d.fmt(out),
        }
    }
}

/// The `--json` object's fields.
#[derive(Serialize)]
struct Json<'a> {
    #[serde(flatten)]
    verdict: VerdictJson<'a>,
    baseline: &'a FitResult<MeasurementsReport>,
    extended: &'a FitResult<MeasurementsReport>,
    best: &'a FitResult<MeasurementsReport>,
    signature: &'a Option<Signature<MeasurementsReport>>,
    diagnostics: &'a ResidualDiagnostics,
    holdout: &'a Option<String>,
    not_identifiable: [&'static str; 1],
    report: Option<String>,
}

impl Serialize for Diagnosis<MeasurementsReport> {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let d = self;
        Json {
            verdict: d.verdict_json(),
            baseline: &d.baseline,
            extended: &d.extended,
            best: &d.best,
            signature: &d.signature,
            diagnostics: &d.details.diagnostics,
            holdout: &d.holdout,
            not_identifiable: ["cable_stretch: under tension control the cable's stretch does not change the forces on the rod, so no tip reading can show it"],
            report: self.written.first().map(|p| p.display().to_string()),
        }
        .serialize(serializer)
    }
}

impl fmt::Display for Diagnosis<MeasurementsReport> {
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        let d = self;
        writeln!(out, "verdict: {}", d.verdict)?;
        writeln!(out, "  {}", d.reason)?;
        for n in &d.partial_effects {
            writeln!(out, "  helps but does not explain: {} {} = {} (ΔBIC {:.1})", n.effect.name(), n.parameter_name, value(n.parameter), n.delta_bic)?;
        }
        if let Some(sig) = &d.signature {
            writeln!(out, "  residual signature ({}):", sig.model)?;
            for line in &sig.summary {
                writeln!(out, "    {line}")?;
            }
        }
        for n in &d.named {
            let se = crate::io::fmt_sig(n.parameter_se, 3);
            writeln!(out, "  {} {} = {} ± {se} (ΔBIC {:.1})", n.effect.name(), n.parameter_name, value(n.parameter), n.delta_bic)?;
        }
        if let Some(m) = &d.separating_measurement {
            writeln!(out, "  cannot tell {} from {}: {m}", d.ambiguous_between[0].name(), d.ambiguous_between[1].name())?;
        }
        let b = &d.baseline;
        writeln!(
            out,
            "thesis model: χ²/dof = {:.3} ({:.1} on {} dof, {}){}",
            b.reduced_chi2,
            b.chi2,
            b.dof,
            crate::calibrate::stats::p_text(b.p_value),
            if b.converged { "" } else { ", NOT converged" }
        )?;
        if !b.outliers.is_empty() {
            writeln!(out, "  outliers set aside (measurement ids): {:?}", b.outliers)?;
        }
        for f in &b.flags {
            writeln!(out, "  warning: {f}")?;
        }
        writeln!(out, "candidates (ΔBIC against the thesis model):")?;
        for line in candidate_lines(&d.candidates) {
            writeln!(out, "{line}")?;
        }
        if let (Some(h), Some(b), Some(a)) = (&d.holdout, d.holdout_rms_before, d.holdout_rms_after) {
            if d.extended.effects.is_empty() {
                writeln!(out, "held-out routing {h}: RMS {b:.4} mm with the thesis model (no effect added)")?;
            } else {
                writeln!(out, "held-out routing {h}: RMS {b:.4} mm with the thesis model, {a:.4} mm {}", model_name(&d.extended))?;
            }
        }
        writeln!(out, "criterion: {}", d.criterion)?;
        if d.verdict == Verdict::Consistent || !d.named.is_empty() && !matches!(d.verdict, Verdict::Unexplained | Verdict::Inconclusive) {
            write!(out, "{}", next_step(&d.extended))?;
        }
        if let Some(p) = self.written.first() {
            writeln!(out, "report: {}", p.display())?;
        }
        Ok(())
    }
}

/// The candidate table, one line each, its columns as wide as their longest
/// entry (`stiffness_gradient`, `clamp_stiffness_n_mm_per_rad`), so the
/// numbers line up whatever the effect.
pub fn candidate_lines(candidates: &[Candidate]) -> Vec<String> {
    let width = |text: &dyn Fn(&Candidate) -> String| {
        candidates.iter().map(|c| text(c).chars().count()).max().unwrap_or(0)
    };
    let rank_w = width(&|c| c.rank.to_string());
    let effect_w = width(&|c| c.effect.name().to_string());
    let parameter_w = width(&|c| c.parameter_name.to_string());
    let se_w = width(&|c| crate::io::fmt_sig(c.parameter_se, 3));
    candidates
        .iter()
        .map(|c| {
            format!(
                "  {:>rank_w$}. {:<effect_w$} {:<parameter_w$} {:>12} ± {:<se_w$} ΔBIC {:>9.2}  χ²/dof {:>8.3}{}",
                c.rank,
                c.effect.name(),
                c.parameter_name,
                value(c.parameter),
                crate::io::fmt_sig(c.parameter_se, 3),
                c.delta_bic,
                c.reduced_chi2,
                c.failure().map(|f| format!("  (not counted: {f})")).unwrap_or_default()
            )
        })
        .collect()
}

/// A parameter value for the summary: fixed point unless very large or small.
pub fn value(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:.5e}")
    } else {
        format!("{v:.5}")
    }
}

/// Five significant digits: what a fitted value with a standard error of a
/// few per cent supports, and short enough to paste.
pub fn sig5(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (4 - v.abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{v:.digits$}");
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_string() } else { text }
}

/// The lines to paste to use the fitted model: flags for `simulate`,
/// `design` and `sweep`-free commands, and the TOML block for a spec.
pub fn next_step(fit: &FitResult<MeasurementsReport>) -> String {
    let a = fit.rod();
    let mut flags = vec![format!("--ea-n {}", sig5(a.ea_n)), format!("--ga-n {}", sig5(a.ga_n)), format!("--ei-n-mm2 {}", sig5(a.ei_n_mm2))];
    let mut toml = format!("[actuator]\nea_n = {}\nga_n = {}\nei_n_mm2 = {}\n", sig5(a.ea_n), sig5(a.ga_n), sig5(a.ei_n_mm2));
    // A non-uniform body stays as it was given (the fitted rigidities are
    // those of a section of radius radius_mm).
    if !a.radius_profile_mm.is_empty() {
        let points: Vec<String> = a.radius_profile_mm.iter().map(|(s, r)| format!("{s}:{r}")).collect();
        let pairs: Vec<String> = a.radius_profile_mm.iter().map(|(s, r)| format!("[{s}, {r}]")).collect();
        flags.push(format!("--radius-profile-mm \"{}\"", points.join(",")));
        toml.push_str(&format!("radius_profile_mm = [{}]\n", pairs.join(", ")));
    }
    if let Some(k) = a.cable_anchor_mm {
        flags.push(format!("--cable-anchor-mm {k}"));
        toml.push_str(&format!("cable_anchor_mm = {k}\n"));
    }
    if !a.segments.is_empty() {
        toml.push_str("# and the [[actuator.segments]] of the actuator file\n");
    }
    let mut effects = String::new();
    for e in &fit.effects {
        // The flag, spec key and table from the effect's registry entry.
        let info = e.info();
        let value = (info.get)(a);
        flags.push(format!("{} {}", info.flag, sig5(value)));
        match info.section {
            crate::model::effects::Section::Effects => effects.push_str(&format!("{} = {}\n", info.key, sig5(value))),
            section => toml.push_str(&format!("[actuator.{}]\n{} = {}\n", section.key(), info.key, sig5(value))),
        }
    }
    if !effects.is_empty() {
        toml.push_str("[actuator.effects]\n");
        toml.push_str(&effects);
    }
    let mut s = String::from("next step: use the fitted model\n");
    s.push_str(&format!("  simulate / design / calibrate flags: {}\n", flags.join(" ")));
    s.push_str("  in a sweep spec:\n");
    for line in toml.lines() {
        s.push_str(&format!("    {line}\n"));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::Effect;

    fn candidate(rank: usize, effect: Effect, parameter_se: f64) -> Candidate {
        Candidate {
            rank,
            effect,
            parameter_name: effect.parameter_name(),
            parameter: 0.1,
            parameter_se,
            delta_bic: -12.5,
            rms_mm: 0.4,
            chi2: 100.0,
            dof: 90,
            reduced_chi2: 1.1,
            p_value: 0.2,
            converged: true,
            plausible: true,
            flags: Vec::new(),
            error: None,
        }
    }

    #[test]
    fn candidate_columns_line_up_for_the_longest_names() {
        let lines = candidate_lines(&[
            candidate(1, Effect::Friction, 1.54),
            candidate(2, Effect::StiffnessGradient, 0.0021),
            candidate(3, Effect::ClampCompliance, 1234.4),
        ]);
        let column = |l: &str, what: &str| l.chars().collect::<String>().find(what).map(|i| l[..i].chars().count());
        for what in ["±", "ΔBIC", "χ²/dof"] {
            let at: Vec<_> = lines.iter().map(|l| column(l, what)).collect();
            assert!(at.iter().all(|a| a.is_some() && *a == at[0]), "{what} at {at:?}:\n{}", lines.join("\n"));
        }
        // Standard errors in plain decimals, not `1.540e0`.
        assert!(lines[0].contains("± 1.54 ") && lines[1].contains("± 0.0021") && lines[2].contains("± 1234 "), "{}", lines.join("\n"));
    }

    #[test]
    fn five_significant_digits() {
        assert_eq!(sig5(0.0961123), "0.096112");
        assert_eq!(sig5(115.1172), "115.12");
        assert_eq!(sig5(26.69641), "26.696");
        assert_eq!(sig5(12345.67), "12346");
        assert_eq!(sig5(-0.5), "-0.5");
    }
}
