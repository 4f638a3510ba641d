//! The report directory of a 3-D diagnosis (`diagnose CAPTURES --actuator
//! A --markers M --out DIR`): `report.md` (the verdict, the candidates, the
//! fits' values and the per-marker RMS) and one picture per capture, the
//! measured and simulated markers with the final model's body in two views
//! (x–y and x–z, [`crate::plot::spatial`]).

use super::captures::{summary, FitSummary};
use super::diagnosis::Diagnosis;
use crate::calibrate::observations::captures::CapturesReport;
use crate::calibrate::observations::captures::files::{Actuation, Capture, CaptureSet};
use crate::calibrate::fit::Status;
use crate::calibrate::observations::captures::simulate::solve_captures;
use crate::calibrate::diagnose::markdown::candidate_table;
use crate::calibrate::CalibrateError;
use crate::solver::simulate::simulate_spatial_held;
use crate::solver::SolverOptions;
use crate::model::{Actuator, LoadDirection};
use crate::solver::{Hold, Simulation};
use crate::plot::spatial::{draw_spatial_with_points, SpatialPoints};
use crate::shape::LengthBasis;
use plotters::prelude::{Color, BLACK, RED};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// What the report names as its inputs.
#[derive(Debug, Clone, Copy)]
pub struct ReportSources<'a> {
    /// The captures file.
    pub captures: &'a Path,
    /// The markers file, if separate.
    pub markers: Option<&'a Path>,
    /// The actuator file.
    pub actuator: &'a Path,
}

/// The file name of capture `measurement`'s picture.
pub fn capture_picture_name(measurement: i64) -> String {
    format!("capture_{measurement}.png")
}

/// The capture's body simulated alone with `actuator` (its cables'
/// actuation set, reached in the capture's direction and held its dwell
/// from a virgin rod): the body a picture draws.
fn capture_body(actuator: &Actuator, options: &SolverOptions, c: &Capture) -> Result<Simulation, CalibrateError> {
    let mut a = actuator.clone();
    for (cable, act) in a.cables.iter_mut().zip(&c.actuation) {
        match *act {
            Actuation::Tension(t) => {
                cable.tension_n = t;
                cable.displacement_mm = None;
            }
            Actuation::Displacement(d) => cable.displacement_mm = Some(d),
        }
    }
    let direction = if c.direction == crate::calibrate::data::Direction::Unload { LoadDirection::Unload } else { LoadDirection::Load };
    simulate_spatial_held(&a, options, 3, LengthBasis::Rest, Some(Hold { direction, dwell_s: c.dwell_s }))
        .map_err(|failure| CalibrateError::Capture { measurement: c.measurement, row: c.row, failure })
}

/// Writes `report.md` and a picture per capture of `set` into `dir`
/// (created if needed), the pictures with the diagnosis's final model;
/// returns the files written (the report first).
pub fn write_report(dir: &Path, sources: ReportSources<'_>, set: &CaptureSet, d: &Diagnosis<CapturesReport>, options: &SolverOptions) -> Result<Vec<PathBuf>, CalibrateError> {
    let io = |context: String| move |source| CalibrateError::Io { context, source };
    std::fs::create_dir_all(dir).map_err(io(format!("creating report directory {}", dir.display())))?;
    let solutions = solve_captures(&d.extended.actuator, options, set)?;
    let model = summary(&d.extended).model;
    let names: Vec<String> = set.captures.iter().map(|c| capture_picture_name(c.measurement)).collect();
    let fitted = |c: &Capture| match d.holdout {
        Some(k) => !c.pulling_cables().contains(&k),
        None => true,
    };
    let pictures: Vec<Result<PathBuf, CalibrateError>> = set
        .captures
        .par_iter()
        .zip(&solutions)
        .zip(&names)
        .map(|((c, sol), name)| {
            let body = capture_body(&d.extended.actuator, options, c)?;
            let markers = set.markers.get(&c.measurement).map(Vec::as_slice).unwrap_or(&[]);
            let points = [
                SpatialPoints { legend: "markers measured".into(), colour: BLACK.to_rgba(), points_mm: markers.iter().map(|m| m.measured_mm).collect(), crosses: true },
                SpatialPoints { legend: "markers simulated".into(), colour: RED.mix(0.8), points_mm: sol.markers_mm.clone(), crosses: false },
            ];
            let tensions: Vec<String> = sol.pose.tensions_n.iter().enumerate().map(|(k, t)| format!("τ{} = {t:.2} N", k + 1)).collect();
            let title = format!(
                "capture {} ({}{}): {}",
                c.measurement,
                tensions.join(", "),
                if fitted(c) { "" } else { "; held out" },
                model
            );
            let path = dir.join(name);
            // Drawn to a temporary file and renamed into place: a failure
            // never leaves a half-drawn picture over an older report's.
            let tmp = dir.join(format!(".tmp-{}-{name}", crate::io::unique_token()));
            if let Err(e) = draw_spatial_with_points(&tmp, &title, &body, &points) {
                let _ = std::fs::remove_file(&tmp);
                return Err(e.into());
            }
            std::fs::rename(&tmp, &path).map_err(io(format!("writing {}", path.display())))?;
            Ok(path)
        })
        .collect();
    let pictures: Vec<PathBuf> = pictures.into_iter().collect::<Result<_, _>>()?;
    crate::io::sync_dir(dir);
    let path = dir.join("report.md");
    crate::io::write_atomic(&path, markdown(sources, set, d, &names).as_bytes()).map_err(io(format!("writing {}", path.display())))?;
    Ok(std::iter::once(path).chain(pictures).collect())
}

fn num(v: f64) -> String {
    if v.is_finite() {
        crate::io::fmt_sig(v, 4)
    } else {
        "—".into()
    }
}

fn fit_section(out: &mut String, title: &str, f: &FitSummary) {
    let _ = writeln!(out, "### {title}: {}\n", f.model);
    out.push_str("| parameter | value ± SE | start | status |\n|---|---|---|---|\n");
    for p in &f.parameters {
        let status = match p.status {
            Status::Fitted => "fitted",
            Status::Held => "held",
            Status::Undetermined => "undetermined: held at its start",
            Status::AtBound => "at the bound of its range",
        };
        let _ = writeln!(out, "| `{}` | {} ± {} | {} | {status} |", p.name, num(p.value), num(p.se), num(p.start));
    }
    let _ = writeln!(
        out,
        "\nχ² = {:.1} on {} dof (χ²/dof = {:.3}, {}); BIC {:.1}; marker RMS {:.3} mm; {} iterations, {}.\n",
        f.chi2,
        f.dof,
        f.reduced_chi2,
        crate::calibrate::stats::p_text(f.p_value),
        f.bic,
        f.rms_mm,
        f.iterations,
        if f.converged { "converged" } else { "not converged" }
    );
}

fn markdown(sources: ReportSources<'_>, set: &CaptureSet, d: &Diagnosis<CapturesReport>, names: &[String]) -> String {
    let (baseline, extended) = (summary(&d.baseline), summary(&d.extended));
    let mut out = String::new();
    let _ = writeln!(out, "# Diagnosis of {}\n", sources.captures.display());
    let _ = writeln!(
        out,
        "{} captures ({} fitted), markers {}, actuator {}.\n",
        set.captures.len(),
        d.fitted,
        sources.markers.map_or_else(|| "from the captures file".to_string(), |m| m.display().to_string()),
        sources.actuator.display()
    );
    let _ = writeln!(out, "## Verdict: {}\n\n{}\n", d.verdict, d.reason);
    for n in &d.named {
        let _ = writeln!(out, "- `{}` = {} ± {} (ΔBIC {:.1})", n.parameter_name, num(n.parameter), num(n.parameter_se), n.delta_bic);
    }
    for n in &d.partial_effects {
        let _ = writeln!(out, "- helps but does not explain: `{}` = {} ± {} (ΔBIC {:.1})", n.parameter_name, num(n.parameter), num(n.parameter_se), n.delta_bic);
    }
    if let Some(m) = &d.separating_measurement {
        let _ = writeln!(out, "- to separate {}: {m}", d.ambiguous_between.iter().map(|e| e.name()).collect::<Vec<_>>().join(" and "));
    }
    let _ = writeln!(out, "\nCriterion: {}\n", d.criterion);
    out.push_str("## Candidates (each refitted with the body)\n\n");
    candidate_table(&mut out, &d.candidates, "marker RMS (mm)");
    for n in &d.not_candidates {
        let _ = writeln!(out, "\nNot a candidate: {n}");
    }
    if !d.second_round.is_empty() {
        out.push_str("\n### Second round (with the first effect)\n\n");
        candidate_table(&mut out, &d.second_round, "marker RMS (mm)");
    }
    out.push_str("\n## Fits\n\n");
    fit_section(&mut out, "Body fit", &baseline);
    if extended.model != baseline.model {
        fit_section(&mut out, "Final model", &extended);
    }
    out.push_str("## Per-marker RMS of the 3-D errors (mm)\n\n| marker | body fit | final model |\n|---|---|---|\n");
    for (marker, before) in &baseline.rms_by_marker_mm {
        let after = extended.rms_by_marker_mm.get(marker).copied().unwrap_or(f64::NAN);
        let _ = writeln!(out, "| {marker} | {before:.3} | {after:.3} |");
    }
    let _ = writeln!(out, "| all | {:.3} | {:.3} |\n", baseline.rms_mm, extended.rms_mm);
    if let Some(s) = &d.signature {
        let _ = writeln!(out, "## Residual signature ({})\n", s.model);
        for line in &s.summary {
            let _ = writeln!(out, "- {line}");
        }
        out.push('\n');
    }
    if let (Some(k), Some(b), Some(a)) = (d.holdout, d.holdout_rms_before, d.holdout_rms_after) {
        let _ = writeln!(out, "## Held out\n\nThe captures where cable {k} pulls: marker RMS {b:.3} mm with the body fit, {a:.3} mm with the final model.\n");
    }
    out.push_str("## Captures\n\nEach picture: the final model's body (silhouette, centreline, cables) in the x–y and x–z views, the measured markers (crosses) and the simulated ones (dots). The body is the capture solved from a virgin rod.\n\n");
    for (c, name) in set.captures.iter().zip(names) {
        let pulls: Vec<String> = c.pulling_cables().iter().map(|k| k.to_string()).collect();
        let pulls = if pulls.is_empty() { "none".to_string() } else { pulls.join(" + ") };
        let _ = writeln!(out, "- capture {} (cables pulling: {pulls}): ![capture {}]({name})", c.measurement, c.measurement);
    }
    out
}
