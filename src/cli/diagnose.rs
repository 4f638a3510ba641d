//! `cablemap diagnose DATA`: finds, names and adds the missing effect, with
//! a Markdown report and plots.

use anyhow::Context;
use super::calibrate::FitArgs;
use super::ActuatorArgs;
use cablemap::calibrate::diagnose::{diagnose, DiagnoseSpec};
use cablemap::calibrate::read_measurements;
use cablemap::calibrate::report::write_report;
use cablemap::model::SolverOptions;
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `cablemap diagnose`.
#[derive(Debug, Clone, Args)]
pub struct DiagnoseArgs {
    /// Measurement file (CSV, or Parquet by its .parquet extension); see docs/measurements.md.
    pub data: PathBuf,
    /// Routing left out of every fit; the gap on it is shown before and after.
    #[arg(long, value_name = "ROUTING")]
    pub holdout: Option<String>,
    /// Report directory (report.md and PNG plots) [default: DATA's name with
    /// `-diagnosis`, beside the data file: measurements.csv → measurements-diagnosis/].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Skip the report and plots.
    #[arg(long)]
    pub no_report: bool,
    /// Noise, held parameters, loss, shapes.
    #[command(flatten)]
    pub fit: FitArgs,
    /// A model is consistent with the noise when the chi-square test's p ≥ this.
    #[arg(long, default_value_t = 1e-3, value_name = "P")]
    pub alpha: f64,
    /// BIC decrease an effect needs against the model without it.
    #[arg(long, default_value_t = 10.0)]
    pub threshold: f64,
    /// BIC lead an effect needs over the runner-up.
    #[arg(long, default_value_t = 10.0)]
    pub margin: f64,
    /// Most effects added (forward-stepwise).
    #[arg(long, default_value_t = 2)]
    pub max_effects: usize,
    /// Print one JSON object instead of a summary.
    #[arg(long)]
    pub json: bool,
    /// Starting values and fixed parameters (e.g. --creep-time-s).
    #[command(flatten)]
    pub actuator: ActuatorArgs,
}

/// Runs `cablemap diagnose`.
/// The report directory: `--out`, else beside the data file, so that a run
/// never litters the current directory.
fn report_dir(args: &DiagnoseArgs) -> PathBuf {
    args.out.clone().unwrap_or_else(|| {
        let stem = args.data.file_stem().map_or_else(|| "measurements".into(), |s| s.to_string_lossy().into_owned());
        args.data.with_file_name(format!("{stem}-diagnosis"))
    })
}

pub fn run(args: &DiagnoseArgs) -> anyhow::Result<()> {
    let out_dir = report_dir(args);
    if !args.no_report {
        // Before the fits, not after them.
        cablemap::io::check_not_in_run_dir(&out_dir, "the report directory").map_err(anyhow::Error::msg).context("--out")?;
    }
    let data = read_measurements(&args.data)?;
    let base = args.actuator.resolve(data.actuator.as_ref())?;
    base.validate()?;
    let options = args.actuator.solver_options(&SolverOptions::default());
    let (fit, start, held_effects) = args.fit.spec(&base, &data)?;
    let spec = DiagnoseSpec {
        holdout: args.holdout.clone(),
        fit,
        threshold: args.threshold,
        margin: args.margin,
        max_effects: args.max_effects.max(1),
        alpha: args.alpha,
        held_effects,
    };
    let d = diagnose(&start, &options, &data, &spec)?;
    let report = if args.no_report { None } else { Some(write_report(&out_dir, &args.data, &data, &d, &spec)?) };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        let mut v = d.to_json();
        v["report"] = serde_json::to_value(report.as_ref().map(|p| p.display().to_string()))?;
        writeln!(out, "{v}")?;
        return Ok(());
    }
    writeln!(out, "verdict: {}", d.verdict)?;
    writeln!(out, "  {}", d.reason)?;
    for n in &d.partial_effects {
        writeln!(out, "  helps but does not explain: {} {} = {} (ΔBIC {:.1})", n.effect, n.parameter_name, value(n.parameter), n.delta_bic)?;
    }
    if let Some(sig) = &d.signature {
        writeln!(out, "  residual signature ({}):", sig.model)?;
        for line in &sig.summary {
            writeln!(out, "    {line}")?;
        }
    }
    for n in &d.named {
        let se = cablemap::io::fmt_sig(n.parameter_se, 3);
        writeln!(out, "  {} {} = {} ± {se} (ΔBIC {:.1})", n.effect, n.parameter_name, value(n.parameter), n.delta_bic)?;
    }
    if let Some(m) = &d.separating_measurement {
        writeln!(out, "  cannot tell {} from {}: {m}", d.ambiguous_between[0], d.ambiguous_between[1])?;
    }
    let b = &d.baseline;
    writeln!(
        out,
        "thesis model: χ²/dof = {:.3} ({:.1} on {} dof, {}){}",
        b.reduced_chi2,
        b.chi2,
        b.dof,
        cablemap::calibrate::report::p_text(b.p_value),
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
            writeln!(out, "held-out routing {h}: RMS {b:.4} mm with the thesis model, {a:.4} mm {}", cablemap::calibrate::diagnose::model_name(&d.extended))?;
        }
    }
    writeln!(out, "criterion: {}", d.criterion)?;
    if d.verdict == "none" || !d.named.is_empty() && d.verdict != "unexplained" && d.verdict != "inconclusive" {
        write!(out, "{}", next_step(&d.extended))?;
    }
    if let Some(p) = report {
        writeln!(out, "report: {}", p.display())?;
    }
    Ok(())
}

/// The candidate table, one line each, its columns as wide as their longest
/// entry (`stiffness_gradient`, `clamp_stiffness_n_mm_per_rad`), so the
/// numbers line up whatever the effect.
fn candidate_lines(candidates: &[cablemap::calibrate::diagnose::Candidate]) -> Vec<String> {
    let width = |text: &dyn Fn(&cablemap::calibrate::diagnose::Candidate) -> String| {
        candidates.iter().map(|c| text(c).chars().count()).max().unwrap_or(0)
    };
    let rank_w = width(&|c| c.rank.to_string());
    let effect_w = width(&|c| c.effect.to_string());
    let parameter_w = width(&|c| c.parameter_name.to_string());
    let se_w = width(&|c| cablemap::io::fmt_sig(c.parameter_se, 3));
    candidates
        .iter()
        .map(|c| {
            format!(
                "  {:>rank_w$}. {:<effect_w$} {:<parameter_w$} {:>12} ± {:<se_w$} ΔBIC {:>9.2}  χ²/dof {:>8.3}{}",
                c.rank,
                c.effect,
                c.parameter_name,
                value(c.parameter),
                cablemap::io::fmt_sig(c.parameter_se, 3),
                c.delta_bic,
                c.reduced_chi2,
                c.failure().map(|f| format!("  (not counted: {f})")).unwrap_or_default()
            )
        })
        .collect()
}

/// A parameter value for the summary: fixed point unless very large or small.
fn value(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:.5e}")
    } else {
        format!("{v:.5}")
    }
}

/// Five significant digits: what a fitted value with a standard error of a
/// few per cent supports, and short enough to paste.
fn sig5(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (4 - v.abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{v:.digits$}");
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_string() } else { text }
}

/// The lines to paste to use the fitted model: flags for `simulate`,
/// `design` and `sweep`-free commands, and the TOML block for a spec.
fn next_step(fit: &cablemap::calibrate::FitResult) -> String {
    let a = &fit.actuator;
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
            cablemap::model::effects::Section::Effects => effects.push_str(&format!("{} = {}\n", info.key, sig5(value))),
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
    use super::{candidate_lines, sig5};
    use cablemap::calibrate::diagnose::Candidate;

    fn candidate(rank: usize, effect: &'static str, parameter_name: &'static str, parameter_se: f64) -> Candidate {
        Candidate {
            rank,
            effect,
            parameter_name,
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
            candidate(1, "friction", "friction_mu", 1.54),
            candidate(2, "stiffness_gradient", "stiffness_gradient_beta", 0.0021),
            candidate(3, "clamp_compliance", "clamp_stiffness_n_mm_per_rad", 1234.4),
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
