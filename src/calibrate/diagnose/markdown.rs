//! The diagnosis report: Markdown with the ranked candidate table, the
//! residual diagnostics, the fitted parameters and three PNG plots
//! (residuals before/after, load/unload loops, measured vs simulated shapes).

use super::diagnosis::{DiagnoseSpec, Diagnosis};
use super::criterion::Candidate;
use super::Verdict;
use crate::calibrate::data::{CentrelinePoints, Dataset};
use crate::calibrate::fit::FitResult;
use crate::calibrate::observations::measurements::MeasurementsReport;
use crate::calibrate::predict::Prediction;
use crate::calibrate::CalibrateError;
use crate::plot::PlotError;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The pictures beside `report.md`.
pub const PICTURES: [&str; 3] = ["residuals.png", "loops.png", "shapes.png"];

/// Writes `report.md` and its plots into `dir` (created if needed);
/// returns the files written, the report first, then [`PICTURES`].
/// [`crate::calibrate::diagnose::run()`] has refused a `dir` inside a
/// sweep run before reading the measurements.
pub(super) fn write_report(
    dir: &Path,
    data_path: &Path,
    data: &Dataset,
    d: &Diagnosis<MeasurementsReport>,
    spec: &DiagnoseSpec<MeasurementsReport>,
) -> Result<Vec<PathBuf>, CalibrateError> {
    std::fs::create_dir_all(dir)
        .map_err(|source| CalibrateError::Io { context: format!("creating report directory {}", dir.display()), source })?;
    let groups = data.groups();
    let angle_weight_mm_per_deg = spec.settings.angle_weight_mm_per_deg;
    let centrelines = (!spec.settings.shapes.centrelines.is_empty()).then_some(&spec.settings.shapes.centrelines);
    // The second model in plots and tables, only when it differs from the thesis model.
    let after_label = (!d.extended.effects.is_empty()).then(|| model_label(&d.extended));
    let after_label = after_label.as_deref();
    // Each picture is drawn to a temporary file and renamed into place, so
    // a failure never leaves a half-drawn picture over an older report.
    let atomic = |name: &str, draw: &dyn Fn(&Path) -> Result<(), PlotError>| -> Result<(), CalibrateError> {
        // The name keeps its extension last: the PNG encoder goes by it.
        let tmp = dir.join(format!(".tmp-{}-{name}", crate::io::unique_token()));
        let result = draw(&tmp);
        if let Err(e) = result {
            let _ = std::fs::remove_file(&tmp);
            return Err(e.into());
        }
        std::fs::rename(&tmp, dir.join(name))
            .map_err(|source| CalibrateError::Io { context: format!("writing {}", dir.join(name).display()), source })
    };
    atomic("residuals.png", &|p| crate::plot::draw_diagnosis_residuals(p, data, &groups, d, after_label, angle_weight_mm_per_deg))?;
    atomic("loops.png", &|p| crate::plot::draw_diagnosis_loops(p, data, &groups, d, after_label))?;
    let markers = (!spec.settings.shapes.markers.is_empty()).then_some(&spec.settings.shapes.markers);
    atomic("shapes.png", &|p| crate::plot::draw_diagnosis_shapes(p, data, &groups, d, centrelines, markers, after_label))?;
    crate::io::sync_dir(dir);
    let md = markdown(data_path, data, d, after_label, centrelines, spec.settings.noise.mm);
    let path = dir.join("report.md");
    crate::io::write_atomic(&path, md.as_bytes())
        .map_err(|source| CalibrateError::Io { context: format!("writing {}", path.display()), source })?;
    Ok(std::iter::once(path).chain(PICTURES.iter().map(|p| dir.join(p))).collect())
}

fn model_label(f: &FitResult<MeasurementsReport>) -> String {
    if f.effects.is_empty() {
        "thesis model".into()
    } else {
        format!("with {}", f.effects.iter().map(|e| e.name()).collect::<Vec<_>>().join(" + "))
    }
}

fn num(v: f64) -> String {
    if !v.is_finite() {
        return "—".into();
    }
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.3e}")
    } else {
        format!("{v:.4}")
    }
}


/// A round's candidates as a Markdown table (planar and 3-D reports), the
/// RMS column headed `rms`; the last column says whether each counts as
/// evidence and, if not, why.
pub(crate) fn candidate_table(out: &mut String, cands: &[Candidate], rms: &str) {
    let _ = writeln!(out, "| rank | effect | parameter | value ± SE | ΔBIC | χ²/dof | p | {rms} | counts as evidence |\n|---|---|---|---|---|---|---|---|---|");
    for c in cands {
        let _ = writeln!(
            out,
            "| {} | {} | `{}` | {} ± {} | {} | {} | {} | {} | {} |",
            c.rank,
            c.effect.name(),
            c.parameter_name,
            num(c.parameter),
            num(c.parameter_se),
            num(c.delta_bic),
            num(c.reduced_chi2),
            crate::calibrate::stats::p_cell(c.p_value),
            num(c.rms_mm),
            match c.failure() {
                None => "yes".to_string(),
                Some(why) => format!("no: {}", why.replace('|', "/").replace('\n', " ")),
            }
        );
    }
}

/// One line on a fit's adequacy: χ², dof, χ²/dof, p, outliers, convergence.
fn adequacy_line(f: &FitResult<MeasurementsReport>) -> String {
    let mut line = format!(
        "χ² = {} on {} degrees of freedom, χ²/dof = {}, {}",
        num(f.chi2),
        f.dof,
        num(f.reduced_chi2),
        crate::calibrate::stats::p_text(f.p_value)
    );
    if !f.outliers.is_empty() {
        let _ = write!(line, "; readings set aside as outliers (measurement ids): {}", f.outliers.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(", "));
    }
    if !f.converged {
        line.push_str("; **did not converge**");
    }
    line
}

fn fit_section(out: &mut String, title: &str, f: &FitResult<MeasurementsReport>) {
    let _ = writeln!(out, "### {title}\n");
    out.push_str("| parameter | value | SE |\n|---|---|---|\n");
    for p in &f.parameters {
        let se = if p.status == crate::calibrate::fit::Status::Held { "held".to_string() } else { num(p.se) };
        let _ = writeln!(out, "| `{}` | {} | {} |", p.name, num(p.value), se);
    }
    let _ = writeln!(out, "\nAdequacy: {}.", adequacy_line(f));
    for flag in &f.flags {
        let _ = writeln!(out, "\n- ⚠ {flag}");
    }
    out.push_str("\nCorrelations:\n\n|   |");
    for p in &f.parameters {
        let _ = write!(out, " {} |", p.name);
    }
    out.push_str("\n|---|");
    out.push_str(&"---|".repeat(f.parameters.len()));
    out.push('\n');
    for (p, row) in f.parameters.iter().zip(&f.correlation) {
        let _ = write!(out, "| {} |", p.name);
        for c in row {
            let _ = write!(out, " {} |", if c.is_finite() { format!("{c:+.3}") } else { "—".into() });
        }
        out.push('\n');
    }
    let _ = writeln!(
        out,
        "\nTip RMS {} mm; {} residuals (BIC {}, {} iterations{}).\n\n| routing | rows | RMS (mm) | tip position RMS (mm) | tip angle RMS (°) |\n|---|---|---|---|---|",
        num(f.rms_mm),
        f.n_residuals,
        num(f.bic),
        f.iterations,
        if f.converged { "" } else { ", not converged" }
    );
    for r in &f.per_routing {
        let _ = writeln!(out, "| {} | {} | {} | {} | {} |", r.routing, r.rows, num(r.rms_mm), num(r.rms_position_mm), num(r.rms_angle_deg));
    }
    out.push('\n');
}

fn markdown(data_path: &Path, data: &Dataset, d: &Diagnosis<MeasurementsReport>, after_label: Option<&str>, centrelines: Option<&CentrelinePoints>, noise_mm: f64) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# Model-discrepancy diagnosis\n\nData: `{}` ({} rows, {} routings).\n", data_path.display(), data.rows.len(), data.groups().len());
    out.push_str("## Verdict\n\n");
    match d.verdict {
        Verdict::Consistent => {
            let _ = writeln!(out, "**none**: {}.\n", d.reason);
        }
        Verdict::Inconclusive => {
            let _ = writeln!(out, "**inconclusive**: {}.\n", d.reason);
        }
        Verdict::Unexplained => {
            let _ = writeln!(out, "**unexplained**: {}.\n", d.reason);
            for n in &d.partial_effects {
                let _ = writeln!(
                    out,
                    "- {} helps (`{}` = {} ± {}, ΔBIC {}) but does not explain the data.",
                    n.effect.name(),
                    n.parameter_name,
                    num(n.parameter),
                    num(n.parameter_se),
                    num(n.delta_bic)
                );
            }
            if let Some(sig) = &d.signature {
                let _ = writeln!(out, "\n### Residual signature ({})\n", sig.model);
                for line in &sig.summary {
                    let _ = writeln!(out, "- {line}");
                }
                out.push_str("\n| rows | n | tip position RMS (mm) | tip angle RMS (°) |\n|---|---|---|---|\n");
                for (name, n, pos, ang) in &sig.sites.by_tension {
                    let _ = writeln!(out, "| {name} | {n} | {} | {} |", num(*pos), num(*ang));
                }
                out.push_str("\n| routing | tip position RMS (mm) | tip angle RMS (°) |\n|---|---|---|\n");
                for (r, pos, ang) in &sig.sites.by_routing {
                    let _ = writeln!(out, "| {r} | {} | {} |", num(*pos), num(*ang));
                }
            }
            out.push('\n');
        }
        Verdict::Ambiguous(..) => {
            let _ = writeln!(
                out,
                "**ambiguous**: the data cannot tell **{}** and **{}** apart ({}). To separate them: {}.\n",
                d.ambiguous_between[0].name(),
                d.ambiguous_between[1].name(),
                d.reason,
                d.separating_measurement.as_deref().unwrap_or("")
            );
        }
        Verdict::Named(_) => {
            for n in &d.named {
                let _ = writeln!(out, "- **{}**: `{}` = {} ± {} (ΔBIC {})", n.effect.name(), n.parameter_name, num(n.parameter), num(n.parameter_se), num(n.delta_bic));
            }
            let _ = writeln!(out, "\nWhy: {}.\n", d.reason);
        }
    }
    if let (Some(h), Some(b), Some(a)) = (&d.holdout, d.holdout_rms_before, d.holdout_rms_after) {
        match after_label {
            None => {
                let _ = writeln!(out, "Held-out routing `{h}`: RMS {} mm with the thesis model (no effect added).\n", num(b));
            }
            Some(label) => {
                let ratio = if a <= b { format!("{}× smaller", num(b / a)) } else { format!("{}× larger", num(a / b)) };
                let _ = writeln!(out, "Held-out routing `{h}`: RMS {} mm with the thesis model, {} mm {label} ({ratio}).\n", num(b), num(a));
            }
        }
    }
    let _ = writeln!(out, "Thesis model against the noise: {}.\n", adequacy_line(&d.baseline));
    let _ = writeln!(out, "Criterion: {}.\n", d.criterion);
    out.push_str("Cable stretch is not a candidate: under tension control the cable's stretch does not change the forces on the rod, so no tip reading can identify it.\n\n");
    out.push_str("## Candidates (each refitted with EA, GA, EI)\n\n");
    candidate_table(&mut out, &d.candidates, "tip RMS (mm)");
    if !d.second_round.is_empty() {
        let first = d.named.first().or(d.partial_effects.first()).map_or_else(|| d.candidates.first().map_or("", |c| c.effect.name()), |n| n.effect.name());
        let _ = writeln!(out, "\nSecond round (given {first}):\n");
        candidate_table(&mut out, &d.second_round, "tip RMS (mm)");
    }
    out.push_str("\n## Residual diagnostics of the thesis model\n\nResiduals are simulated − measured; θ is weighted so that the angle weight (mm per degree) converts it to mm.\n\n| rows | n | RMS (mm) | mean Δx (mm) | mean Δy (mm) | mean Δθ (°) |\n|---|---|---|---|---|---|\n");
    for c in &d.details.diagnostics.classes {
        let _ = writeln!(out, "| {} | {} | {} | {} | {} | {} |", c.class, c.rows, num(c.rms_mm), num(c.mean_dx_mm), num(c.mean_dy_mm), num(c.mean_dtheta_deg));
    }
    let _ = writeln!(
        out,
        "\n- Load/unload gap the model misses (mean |Δθ_unload − Δθ_load| at equal tension): {}°  (friction or creep open a loop)\n- Rest-state shift the model misses (last rest − first rest): {}°  (creep leaves a residual bend)\n",
        num(d.details.diagnostics.loop_gap_deg),
        num(d.details.diagnostics.rest_shift_deg)
    );
    if let Some(c) = centrelines {
        coefficient_section(&mut out, data, d, c, after_label, noise_mm);
    }
    out.push_str("## Fits\n\n");
    fit_section(&mut out, "Thesis model (EA, GA, EI)", &d.baseline);
    if let Some(label) = after_label {
        fit_section(&mut out, &format!("Model {label}"), &d.extended);
    }
    out.push_str("## Plots\n\n![residuals before and after](residuals.png)\n\n![load/unload loops](loops.png)\n\n![measured vs simulated shapes](shapes.png)\n");
    out
}

/// Highest Legendre order shown for measured vs simulated shapes.
const SHAPE_ORDER: usize = 3;

/// Legendre curvature coefficients a_0 … a_`order` of a centreline given
/// by points (clamp first), in the thesis's basis: per unit REST length L,
/// a_i = a_i^deformed · ℓ / L (model-notes §4). Measured and simulated
/// shapes both go through this one function so that they are compared in
/// the same basis; it is the place to switch to `shape::LengthBasis` when
/// that lands.
pub fn shape_coefficients_rest_basis(points: &[[f64; 2]], rest_length_mm: f64, order: usize) -> Result<Vec<f64>, crate::shape::ShapeError> {
    let c = crate::shape::coefficients_from_points(points, order)?;
    let factor = c.length_mm / rest_length_mm;
    Ok(c.a.iter().map(|a| a * factor).collect())
}

/// Measured vs simulated a_0 … a_n at the top tension of each routing with
/// a measured centreline.
/// Standard deviation of [`shape_coefficients_rest_basis`] over noisy
/// copies of the predicted centreline sampled at `count` points (the noise
/// `noise_mm` on x and y): how much of a measured a_i noise alone explains.
fn coefficient_noise(prediction: &Option<Prediction>, count: usize, noise_mm: f64, length_mm: f64) -> Option<Vec<f64>> {
    let line: Vec<[f64; 2]> = prediction.as_ref()?.centreline.as_ref()?.iter().map(|c| [c.x_mm, c.y_mm]).collect();
    let base = crate::calibrate::synth::resample(&line, count);
    let mut rng = crate::calibrate::rng::Rng::new(0x5eed);
    const DRAWS: usize = 40;
    let mut sum = [0.0; SHAPE_ORDER + 1];
    let mut sum2 = [0.0; SHAPE_ORDER + 1];
    for _ in 0..DRAWS {
        let noisy: Vec<[f64; 2]> = base.iter().map(|p| [p[0] + noise_mm * rng.normal(), p[1] + noise_mm * rng.normal()]).collect();
        let a = shape_coefficients_rest_basis(&noisy, length_mm, SHAPE_ORDER).ok()?;
        for (k, v) in a.iter().enumerate() {
            sum[k] += v;
            sum2[k] += v * v;
        }
    }
    let n = DRAWS as f64;
    Some(sum.iter().zip(&sum2).map(|(s, s2)| ((s2 - s * s / n) / (n - 1.0)).max(0.0).sqrt()).collect())
}

fn coefficient_section(out: &mut String, data: &Dataset, d: &Diagnosis<MeasurementsReport>, centrelines: &CentrelinePoints, after_label: Option<&str>, noise_mm: f64) {
    let length = d.baseline.rod().length_mm;
    let mut rows = Vec::new();
    for g in data.groups() {
        let Some(i) = g.rows.iter().copied().filter(|i| centrelines.get(&data.rows[*i].measurement).is_some_and(|p| p.len() >= 5)).max_by(|&a, &b| data.rows[a].tension_n.total_cmp(&data.rows[b].tension_n)) else {
            continue;
        };
        let m = &data.rows[i];
        let simulated = |preds: &[Option<Prediction>]| -> Option<Vec<f64>> {
            let line: Vec<[f64; 2]> = preds[i].as_ref()?.centreline.as_ref()?.iter().map(|c| [c.x_mm, c.y_mm]).collect();
            shape_coefficients_rest_basis(&line, length, SHAPE_ORDER).ok()
        };
        let points = &centrelines[&m.measurement];
        let measured = shape_coefficients_rest_basis(points, length, SHAPE_ORDER).ok();
        let spread = coefficient_noise(&d.details.baseline_predictions[i], points.len(), m.noise_mm.unwrap_or(noise_mm), length);
        rows.push((g.routing.clone(), m.measurement, m.tension_n, measured, spread, simulated(&d.details.baseline_predictions), simulated(&d.details.extended_predictions)));
    }
    if rows.is_empty() {
        return;
    }
    let _ = writeln!(
        out,
        "## Shapes: curvature coefficients, measured vs simulated\n\nLegendre coefficients a_0 … a_{SHAPE_ORDER} (1/mm) in the thesis's basis, per unit rest length L = {} mm (a_i = a_i^deformed · ℓ/L), computed the same way from the measured points and from the simulated centreline, at the top tension of each routing. The row ± noise is the standard deviation that the stated noise alone gives the measured coefficients (the simulated centreline sampled like the measurement, noised, 40 draws): higher orders from noisy points are mostly noise, which is why the fit uses point distances, not coefficients.\n",
        num(length)
    );
    let heads: Vec<String> = (0..=SHAPE_ORDER).map(|k| format!("a_{k}")).collect();
    let _ = writeln!(out, "| routing | reading | tension (N) | shape | {} |\n|---|---|---|---|{}", heads.join(" | "), "---|".repeat(SHAPE_ORDER + 1));
    let cells = |a: &Option<Vec<f64>>| match a {
        Some(a) => a.iter().map(|v| format!("{v:+.5}")).collect::<Vec<_>>().join(" | "),
        None => ["—"; SHAPE_ORDER + 1].join(" | "),
    };
    for (routing, id, t, measured, spread, base, ext) in &rows {
        let _ = writeln!(out, "| {routing} | {id} | {} | measured | {} |", num(*t), cells(measured));
        let _ = writeln!(out, "| | | | ± noise | {} |", cells(spread).replace('+', ""));
        let _ = writeln!(out, "| | | | thesis model | {} |", cells(base));
        if let Some(label) = after_label {
            let _ = writeln!(out, "| | | | {label} | {} |", cells(ext));
        }
    }
    out.push('\n');
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::stats::p_text;

    fn fit_with_p(p_value: f64) -> FitResult<MeasurementsReport> {
        FitResult {
            parameters: Vec::new(),
            correlation: Vec::new(),
            loss: 1.0,
            n_residuals: 10,
            bic: 0.0,
            chi2: 5000.0,
            dof: 9,
            reduced_chi2: 555.6,
            p_value,
            iterations: 3,
            converged: true,
            termination: crate::numerics::lm::Termination::NoDescent,
            actuator: crate::model::Actuator::with_cables(crate::model::Rod::default(), Vec::new()),
            report: MeasurementsReport {
                effects: Vec::new(),
                outliers: Vec::new(),
                flags: Vec::new(),
                implausible: false,
                rms_mm: 1.0,
                per_routing: Vec::new(),
                predictions: Vec::new(),
            },
        }
    }

    #[test]
    fn p_values_read_as_sentences() {
        let line = adequacy_line(&fit_with_p(0.0));
        assert!(line.contains("p < 1e-99") && !line.contains("p = <"), "{line}");
        assert!(adequacy_line(&fit_with_p(0.031)).contains("p = 0.031"));
        assert_eq!(p_text(2.4e-7), "p = 2.4e-7");
        assert_eq!(p_text(f64::NAN), "p = —");
    }
}
