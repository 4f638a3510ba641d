//! The diagnosis report: Markdown with the ranked candidate table, the
//! residual diagnostics, the fitted parameters and three PNG plots
//! (residuals before/after, load/unload loops, measured vs simulated shapes).

use super::analysis::{DiagnoseSpec, Diagnosis};
use super::criterion::Candidate;
use super::Verdict;
use crate::calibrate::data::{CentrelinePoints, Dataset, Direction, MarkerPoints, RoutingGroup};
use crate::calibrate::fit::{row_residual, FitResult};
use crate::calibrate::predict::Prediction;
use crate::calibrate::CalibrateError;
use crate::plot::{register_fonts, PlotError, FONT};
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Writes `report.md` and its plots into `dir` (created if needed);
/// returns the report's path. [`crate::calibrate::diagnose::run()`] has refused a `dir` inside a
/// sweep run before reading the measurements.
/// The pictures beside `report.md`.
pub const PICTURES: [&str; 3] = ["residuals.png", "loops.png", "shapes.png"];

pub(super) fn write_report(
    dir: &Path,
    data_path: &Path,
    data: &Dataset,
    d: &Diagnosis,
    spec: &DiagnoseSpec,
) -> Result<PathBuf, CalibrateError> {
    std::fs::create_dir_all(dir)
        .map_err(|source| CalibrateError::Io { context: format!("creating report directory {}", dir.display()), source })?;
    let groups = data.groups();
    let angle_weight_mm_per_deg = spec.fit.angle_weight_mm_per_deg;
    let centrelines = (!spec.fit.shapes.centrelines.is_empty()).then_some(&spec.fit.shapes.centrelines);
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
    atomic("residuals.png", &|p| residual_plot(p, data, &groups, d, after_label, angle_weight_mm_per_deg))?;
    atomic("loops.png", &|p| loop_plot(p, data, &groups, d, after_label))?;
    let markers = (!spec.fit.shapes.markers.is_empty()).then_some(&spec.fit.shapes.markers);
    atomic("shapes.png", &|p| shape_plot(p, data, &groups, d, centrelines, markers, after_label))?;
    crate::io::sync_dir(dir);
    let md = markdown(data_path, data, d, after_label, centrelines, spec.fit.noise.mm);
    let path = dir.join("report.md");
    crate::io::write_atomic(&path, md.as_bytes())
        .map_err(|source| CalibrateError::Io { context: format!("writing {}", path.display()), source })?;
    Ok(path)
}

fn model_label(f: &FitResult) -> String {
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
fn adequacy_line(f: &FitResult) -> String {
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

fn fit_section(out: &mut String, title: &str, f: &FitResult) {
    let _ = writeln!(out, "### {title}\n");
    out.push_str("| parameter | value | SE |\n|---|---|---|\n");
    for p in &f.parameters {
        let se = if p.fixed { "held".to_string() } else { num(p.se) };
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

fn markdown(data_path: &Path, data: &Dataset, d: &Diagnosis, after_label: Option<&str>, centrelines: Option<&CentrelinePoints>, noise_mm: f64) -> String {
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
                for (name, n, pos, ang) in &sig.by_tension {
                    let _ = writeln!(out, "| {name} | {n} | {} | {} |", num(*pos), num(*ang));
                }
                out.push_str("\n| routing | tip position RMS (mm) | tip angle RMS (°) |\n|---|---|---|\n");
                for (r, pos, ang) in &sig.by_routing {
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
    for c in &d.diagnostics.classes {
        let _ = writeln!(out, "| {} | {} | {} | {} | {} | {} |", c.class, c.rows, num(c.rms_mm), num(c.mean_dx_mm), num(c.mean_dy_mm), num(c.mean_dtheta_deg));
    }
    let _ = writeln!(
        out,
        "\n- Load/unload gap the model misses (mean |Δθ_unload − Δθ_load| at equal tension): {}°  (friction or creep open a loop)\n- Rest-state shift the model misses (last rest − first rest): {}°  (creep leaves a residual bend)\n",
        num(d.diagnostics.loop_gap_deg),
        num(d.diagnostics.rest_shift_deg)
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

fn coefficient_section(out: &mut String, data: &Dataset, d: &Diagnosis, centrelines: &CentrelinePoints, after_label: Option<&str>, noise_mm: f64) {
    let length = d.baseline.actuator.length_mm;
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
        let spread = coefficient_noise(&d.baseline_predictions[i], points.len(), m.noise_mm.unwrap_or(noise_mm), length);
        rows.push((g.routing.clone(), m.measurement, m.tension_n, measured, spread, simulated(&d.baseline_predictions), simulated(&d.extended_predictions)));
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

type Chart<'a, 'b> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>>;

/// Draws the series legend of `chart` at `position` in `font_size` points.
fn draw_legend<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>, path: &Path, position: SeriesLabelPosition, font_size: u32) -> Result<(), PlotError> {
    chart
        .configure_series_labels()
        .position(position)
        .label_font((FONT, font_size))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| PlotError::new(path, e))
}

fn residual_plot(path: &Path, data: &Dataset, groups: &[RoutingGroup], d: &Diagnosis, after: Option<&str>, w: f64) -> Result<(), PlotError> {
    register_fonts();
    let height = if after.is_some() { 800 } else { 420 };
    let root = crate::plot::png_backend(path, (1100, height))?.into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let panels = root.split_evenly((if after.is_some() { 2 } else { 1 }, 1));
    let order: Vec<usize> = groups.iter().flat_map(|g| g.rows.iter().copied()).collect();
    let series = |preds: &[Option<Prediction>]| -> Vec<[f64; 3]> {
        order.iter().map(|&i| row_residual(&data.rows[i], &preds[i].as_ref().expect("predicted").pose, w)).collect()
    };
    let before = series(&d.baseline_predictions);
    let after_r = series(&d.extended_predictions);
    let lim = before.iter().chain(&after_r).flat_map(|r| r.iter().map(|v| v.abs())).fold(1.0, f64::max) * 1.1;
    let mut shown = vec![(&before, "thesis model".to_string())];
    if let Some(label) = after {
        shown.push((&after_r, label.to_string()));
    }
    for (panel, (res, title)) in panels.iter().zip(shown) {
        let mut chart = ChartBuilder::on(panel)
            .caption(format!("residuals (simulated − measured), {title}"), (FONT, 20))
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .build_cartesian_2d(-0.5..order.len() as f64 - 0.5, -lim..lim)
            .map_err(|e| PlotError::new(path, e))?;
        chart
            .configure_mesh()
            .x_desc("reading (routings in protocol order; loading ●, unloading ○, rest or static ×)")
            .y_desc("mm  (θ: mm-equivalent)")
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .draw()
            .map_err(|e| PlotError::new(path, e))?;
        // The held-out routing's readings on a grey band, so they stand apart.
        let mut start = 0;
        for g in groups {
            let end = start + g.rows.len();
            if d.holdout.as_deref() == Some(g.routing.as_str()) {
                let band = Rectangle::new([(start as f64 - 0.5, -lim), (end as f64 - 0.5, lim)], BLACK.mix(0.07).filled());
                chart.draw_series(std::iter::once(band)).map_err(|e| PlotError::new(path, e))?;
            }
            start = end;
        }
        // Loading filled, unloading open, rest and static captures as crosses:
        // a friction or creep loop shows as two marker kinds apart.
        let direction = |k: usize| data.rows[order[k]].direction;
        let is_rest = |k: usize| matches!(direction(k), Direction::Rest | Direction::Static);
        for (c, (name, colour)) in [("Δx", BLUE), ("Δy", GREEN), ("Δθ·w", RGBColor(230, 120, 0))].into_iter().enumerate() {
            let at = |k: usize| (k as f64, res[k][c]);
            chart
                .draw_series((0..res.len()).filter(|&k| direction(k) == Direction::Load).map(|k| Circle::new(at(k), 3, colour.filled())))
                .map_err(|e| PlotError::new(path, e))?
                .label(name)
                .legend(move |(x, y)| Circle::new((x + 8, y), 4, colour.filled()));
            chart
                .draw_series((0..res.len()).filter(|&k| direction(k) == Direction::Unload).map(|k| Circle::new(at(k), 3, colour.stroke_width(2))))
                .map_err(|e| PlotError::new(path, e))?;
            chart
                .draw_series((0..res.len()).filter(|&k| is_rest(k)).map(|k| Cross::new(at(k), 3, colour.stroke_width(2))))
                .map_err(|e| PlotError::new(path, e))?;
        }
        // Routing boundaries and names (the held-out one marked).
        let mut k = 0;
        for g in groups {
            let first = k;
            k += g.rows.len();
            let x = k as f64 - 0.5;
            chart.draw_series(LineSeries::new(vec![(x, -lim), (x, lim)], BLACK.mix(0.3))).map_err(|e| PlotError::new(path, e))?;
            let held = d.holdout.as_deref() == Some(g.routing.as_str());
            let name = format!("{}{}", g.routing, if held { " (held out)" } else { "" });
            chart
                .draw_series(std::iter::once(Text::new(name, (first as f64, lim * 0.97), (FONT, 12))))
                .map_err(|e| PlotError::new(path, e))?;
        }
        draw_legend(&mut chart, path, SeriesLabelPosition::LowerRight, 13)?;
    }
    root.present().map_err(|e| PlotError::new(path, e))
}

fn loop_plot(path: &Path, data: &Dataset, groups: &[RoutingGroup], d: &Diagnosis, after: Option<&str>) -> Result<(), PlotError> {
    register_fonts();
    let cols = groups.len().clamp(1, 3);
    let rows = groups.len().div_ceil(cols).max(1);
    let root = crate::plot::png_backend(path, (420 * cols as u32, 360 * rows as u32))?.into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let panels = root.split_evenly((rows, cols));
    let orange = RGBColor(230, 120, 0);
    for (panel, g) in panels.iter().zip(groups) {
        let angle = |i: usize, preds: &[Option<Prediction>]| preds[i].as_ref().expect("predicted").pose.tip_angle_rad.to_degrees();
        let measured: Vec<(f64, f64, Direction)> =
            g.rows.iter().map(|&i| (data.rows[i].tension_n, data.rows[i].tip_angle_rad.to_degrees(), data.rows[i].direction)).collect();
        let base: Vec<(f64, f64)> = g.rows.iter().map(|&i| (data.rows[i].tension_n, angle(i, &d.baseline_predictions))).collect();
        let ext: Vec<(f64, f64)> = g.rows.iter().map(|&i| (data.rows[i].tension_n, angle(i, &d.extended_predictions))).collect();
        let ys = measured.iter().map(|m| m.1).chain(base.iter().map(|b| b.1)).chain(ext.iter().map(|b| b.1));
        let (lo, hi) = ys.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
        let pad = 0.05 * (hi - lo).max(1.0);
        let tmax = measured.iter().map(|m| m.0).fold(0.0, f64::max).max(1e-3) * 1.05;
        let held = d.holdout.as_deref() == Some(g.routing.as_str());
        let mut chart = ChartBuilder::on(panel)
            .caption(format!("{}{}", g.routing, if held { " (held out)" } else { "" }), (FONT, 18))
            .margin(8)
            .x_label_area_size(35)
            .y_label_area_size(50)
            .build_cartesian_2d(-0.02 * tmax..tmax, (lo - pad)..(hi + pad))
            .map_err(|e| PlotError::new(path, e))?;
        chart
            .configure_mesh()
            .x_desc("tension (N)")
            .y_desc("tip angle (°)")
            .label_style((FONT, 12))
            .axis_desc_style((FONT, 13))
            .draw()
            .map_err(|e| PlotError::new(path, e))?;
        chart
            .draw_series(LineSeries::new(base, BLUE.stroke_width(2)))
            .map_err(|e| PlotError::new(path, e))?
            .label("thesis model")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLUE.stroke_width(2)));
        if let Some(label) = after {
            chart
                .draw_series(LineSeries::new(ext, orange.stroke_width(2)))
                .map_err(|e| PlotError::new(path, e))?
                .label(label.to_string())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], orange.stroke_width(2)));
        }
        for (dir, colour, label) in [
            (Direction::Load, BLACK, "measured, load"),
            (Direction::Unload, RED, "measured, unload"),
            (Direction::Rest, RGBColor(120, 120, 120), "measured, rest"),
            (Direction::Static, RGBColor(60, 60, 200), "measured, static"),
        ] {
            // A legend entry only for kinds of reading this routing has.
            if !measured.iter().any(|m| m.2 == dir) {
                continue;
            }
            chart
                .draw_series(measured.iter().filter(|m| m.2 == dir).map(|m| Circle::new((m.0, m.1), 4, colour.filled())))
                .map_err(|e| PlotError::new(path, e))?
                .label(label)
                .legend(move |(x, y)| Circle::new((x + 8, y), 4, colour.filled()));
        }
        draw_legend(&mut chart, path, SeriesLabelPosition::UpperLeft, 11)?;
    }
    root.present().map_err(|e| PlotError::new(path, e))
}

fn shape_plot(
    path: &Path,
    data: &Dataset,
    groups: &[RoutingGroup],
    d: &Diagnosis,
    centrelines: Option<&CentrelinePoints>,
    markers: Option<&MarkerPoints>,
    after: Option<&str>,
) -> Result<(), PlotError> {
    register_fonts();
    // The reading at the top tension of each routing.
    let picks: Vec<(&RoutingGroup, usize)> = groups
        .iter()
        .filter_map(|g| g.rows.iter().copied().max_by(|&a, &b| data.rows[a].tension_n.total_cmp(&data.rows[b].tension_n)).map(|i| (g, i)))
        .collect();
    let line = |preds: &[Option<Prediction>], i: usize| -> Vec<(f64, f64)> {
        preds[i].as_ref().and_then(|p| p.centreline.as_ref()).map(|c| c.iter().map(|p| (p.y_mm, -p.x_mm)).collect()).unwrap_or_default()
    };
    let mut pts: Vec<(f64, f64)> = vec![(0.0, 0.0)];
    for &(_, i) in &picks {
        pts.extend(line(&d.baseline_predictions, i));
        pts.extend(line(&d.extended_predictions, i));
        pts.push((data.rows[i].tip_y_mm, -data.rows[i].tip_x_mm));
    }
    let (x0, x1) = pts.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (y0, y1) = pts.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let span = (x1 - x0).max(y1 - y0) + 10.0;
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let root = crate::plot::png_backend(path, (850, 850))?.into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let title = "shapes at the top tension: measured vs simulated";
    let mut chart = crate::plot::hanging_chart(&root, path, title, (cx - span / 2.0, cx + span / 2.0), (cy - span / 2.0, cy + span / 2.0))?;
    let orange = RGBColor(230, 120, 0);
    for (k, &(g, i)) in picks.iter().enumerate() {
        let first = k == 0;
        let s = chart.draw_series(LineSeries::new(line(&d.baseline_predictions, i), BLUE.stroke_width(2))).map_err(|e| PlotError::new(path, e))?;
        if first {
            s.label("thesis model").legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLUE.stroke_width(2)));
        }
        if let Some(label) = after {
            let s = chart.draw_series(LineSeries::new(line(&d.extended_predictions, i), orange.stroke_width(2))).map_err(|e| PlotError::new(path, e))?;
            if first {
                s.label(label.to_string()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], orange.stroke_width(2)));
            }
        }
        let m = &data.rows[i];
        let s = chart
            .draw_series(std::iter::once(Cross::new((m.tip_y_mm, -m.tip_x_mm), 7, BLACK.stroke_width(2))))
            .map_err(|e| PlotError::new(path, e))?;
        if first {
            s.label("measured tip").legend(|(x, y)| Cross::new((x + 8, y), 5, BLACK.stroke_width(2)));
        }
        if let Some(points) = centrelines.and_then(|c| c.get(&m.measurement)) {
            chart
                .draw_series(points.iter().map(|p| Circle::new((p[1], -p[0]), 2, BLACK.mix(0.6).filled())))
                .map_err(|e| PlotError::new(path, e))?;
        }
        if let Some(ms) = markers.and_then(|c| c.get(&m.measurement)) {
            let s = chart
                .draw_series(ms.iter().map(|p| TriangleMarker::new((p.y_mm, -p.x_mm), 5, RED.filled())))
                .map_err(|e| PlotError::new(path, e))?;
            if first {
                s.label("measured markers").legend(|(x, y)| TriangleMarker::new((x + 8, y), 4, RED.filled()));
            }
        }
        chart
            .draw_series(std::iter::once(Text::new(g.routing.clone(), (m.tip_y_mm + 2.0, -m.tip_x_mm + 2.0), (FONT, 13))))
            .map_err(|e| PlotError::new(path, e))?;
    }
    draw_legend(&mut chart, path, SeriesLabelPosition::LowerLeft, 13)?;
    root.present().map_err(|e| PlotError::new(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::stats::p_text;

    fn fit_with_p(p_value: f64) -> FitResult {
        FitResult {
            effects: Vec::new(),
            actuator: crate::model::Rod::default(),
            parameters: Vec::new(),
            correlation: Vec::new(),
            rss: 1.0,
            n_residuals: 10,
            bic: 0.0,
            chi2: 5000.0,
            dof: 9,
            reduced_chi2: 555.6,
            p_value,
            outliers: Vec::new(),
            flags: Vec::new(),
            implausible: false,
            rms_mm: 1.0,
            per_routing: Vec::new(),
            iterations: 3,
            converged: true,
            predictions: Vec::new(),
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
