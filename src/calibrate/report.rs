//! The diagnosis report: Markdown with the ranked candidate table, the
//! residual diagnostics, the fitted parameters and three PNG plots
//! (residuals before/after, load/unload loops, measured vs simulated shapes).

use super::data::{CentrelinePoints, Dataset, Direction, RoutingGroup};
use super::diagnose::{Candidate, Diagnosis};
use super::fit::{row_residual, FitResult};
use super::predict::Prediction;
use super::CalibrateError;
use crate::plot::{register_fonts, PlotError, FONT};
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Writes `report.md` and its plots into `dir` (created if needed);
/// returns the report's path.
pub fn write_report(
    dir: &Path,
    data_path: &Path,
    data: &Dataset,
    d: &Diagnosis,
    centrelines: Option<&CentrelinePoints>,
    angle_weight_mm_per_deg: f64,
) -> Result<PathBuf, CalibrateError> {
    crate::io::check_not_in_run_dir(dir, "--out").map_err(CalibrateError::Invalid)?;
    std::fs::create_dir_all(dir)
        .map_err(|source| CalibrateError::Io { context: format!("creating report directory {}", dir.display()), source })?;
    let groups = data.groups();
    let after_label = model_label(&d.extended);
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
    atomic("residuals.png", &|p| residual_plot(p, data, &groups, d, &after_label, angle_weight_mm_per_deg))?;
    atomic("loops.png", &|p| loop_plot(p, data, &groups, d, &after_label))?;
    atomic("shapes.png", &|p| shape_plot(p, data, &groups, d, centrelines, &after_label))?;
    crate::io::sync_dir(dir);
    let md = markdown(data_path, data, d, &after_label);
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

fn candidate_table(out: &mut String, cands: &[Candidate]) {
    out.push_str("| rank | effect | parameter | value ± SE | ΔBIC | RMS (mm) | plausible |\n|---|---|---|---|---|---|---|\n");
    for c in cands {
        let _ = writeln!(
            out,
            "| {} | {} | `{}` | {} ± {} | {} | {} | {} |",
            c.rank,
            c.effect,
            c.parameter_name,
            num(c.parameter),
            num(c.parameter_se),
            num(c.delta_bic),
            num(c.rms_mm),
            if c.error.is_some() { "fit failed" } else if c.plausible { "yes" } else { "no" }
        );
    }
}

fn fit_section(out: &mut String, title: &str, f: &FitResult) {
    let _ = writeln!(out, "### {title}\n");
    out.push_str("| parameter | value | SE |\n|---|---|---|\n");
    for p in &f.parameters {
        let _ = writeln!(out, "| `{}` | {} | {} |", p.name, num(p.value), num(p.se));
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
        "\nRMS {} mm over {} residuals (BIC {}, {} iterations{}).\n\n| routing | rows | RMS (mm) | tip position RMS (mm) | tip angle RMS (°) |\n|---|---|---|---|---|",
        num(f.rms_mm),
        f.n_residuals,
        num(f.bic),
        f.iterations,
        if f.converged { "" } else { ", iteration cap reached" }
    );
    for r in &f.per_routing {
        let _ = writeln!(out, "| {} | {} | {} | {} | {} |", r.routing, r.rows, num(r.rms_mm), num(r.rms_position_mm), num(r.rms_angle_deg));
    }
    out.push('\n');
}

fn markdown(data_path: &Path, data: &Dataset, d: &Diagnosis, after_label: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# Model-discrepancy diagnosis\n\nData: `{}` ({} rows, {} routings).\n", data_path.display(), data.rows.len(), data.groups().len());
    out.push_str("## Verdict\n\n");
    match d.verdict.as_str() {
        "none" => out.push_str("**none**: no candidate effect is warranted; the thesis model explains the data to within its noise.\n\n"),
        "ambiguous" => {
            let _ = writeln!(
                out,
                "**ambiguous**: the data cannot tell **{}** and **{}** apart. To separate them: {}.\n",
                d.ambiguous_between[0],
                d.ambiguous_between[1],
                d.separating_measurement.as_deref().unwrap_or("")
            );
        }
        _ => {
            for n in &d.named {
                let _ = writeln!(out, "- **{}**: `{}` = {} ± {} (ΔBIC {})", n.effect, n.parameter_name, num(n.parameter), num(n.parameter_se), num(n.delta_bic));
            }
            out.push('\n');
        }
    }
    if let (Some(h), Some(b), Some(a)) = (&d.holdout, d.holdout_rms_before, d.holdout_rms_after) {
        let _ = writeln!(out, "Held-out routing `{h}`: RMS {} mm with the thesis model, {} mm {} ({}× smaller).\n", num(b), num(a), after_label, num(b / a));
    }
    let _ = writeln!(out, "Criterion: {}.\n", d.criterion);
    out.push_str("Cable stretch is not a candidate: under tension control the cable's stretch does not change the forces on the rod, so no tip reading can identify it.\n\n");
    out.push_str("## Candidates (each refitted with EA, GA, EI)\n\n");
    candidate_table(&mut out, &d.candidates);
    if !d.second_round.is_empty() {
        let _ = writeln!(out, "\nSecond round (given {}):\n", d.named.first().map_or("", |n| n.effect));
        candidate_table(&mut out, &d.second_round);
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
    out.push_str("## Fits\n\n");
    fit_section(&mut out, "Thesis model (EA, GA, EI)", &d.baseline);
    if !d.extended.effects.is_empty() {
        fit_section(&mut out, &format!("Model {after_label}"), &d.extended);
    }
    out.push_str("## Plots\n\n![residuals before and after](residuals.png)\n\n![load/unload loops](loops.png)\n\n![measured vs simulated shapes](shapes.png)\n");
    out
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

fn residual_plot(path: &Path, data: &Dataset, groups: &[RoutingGroup], d: &Diagnosis, after: &str, w: f64) -> Result<(), PlotError> {
    register_fonts();
    let root = BitMapBackend::new(path, (1100, 800)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let panels = root.split_evenly((2, 1));
    let order: Vec<usize> = groups.iter().flat_map(|g| g.rows.iter().copied()).collect();
    let series = |preds: &[Option<Prediction>]| -> Vec<[f64; 3]> {
        order.iter().map(|&i| row_residual(&data.rows[i], &preds[i].as_ref().expect("predicted").pose, w)).collect()
    };
    let before = series(&d.baseline_predictions);
    let after_r = series(&d.extended_predictions);
    let lim = before.iter().chain(&after_r).flat_map(|r| r.iter().map(|v| v.abs())).fold(1.0, f64::max) * 1.1;
    for (panel, (res, title)) in panels.iter().zip([(&before, "thesis model".to_string()), (&after_r, after.to_string())]) {
        let mut chart = ChartBuilder::on(panel)
            .caption(format!("residuals (simulated − measured), {title}"), (FONT, 20))
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .build_cartesian_2d(-0.5..order.len() as f64 - 0.5, -lim..lim)
            .map_err(|e| PlotError::new(path, e))?;
        chart
            .configure_mesh()
            .x_desc("reading (routings in protocol order)")
            .y_desc("mm  (θ: mm-equivalent)")
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .draw()
            .map_err(|e| PlotError::new(path, e))?;
        for (c, (name, colour)) in [("Δx", BLUE), ("Δy", GREEN), ("Δθ·w", RGBColor(230, 120, 0))].into_iter().enumerate() {
            chart
                .draw_series(res.iter().enumerate().map(|(k, r)| Circle::new((k as f64, r[c]), 3, colour.filled())))
                .map_err(|e| PlotError::new(path, e))?
                .label(name)
                .legend(move |(x, y)| Circle::new((x + 8, y), 4, colour.filled()));
        }
        // Routing boundaries.
        let mut k = 0;
        for g in groups {
            k += g.rows.len();
            let x = k as f64 - 0.5;
            chart.draw_series(LineSeries::new(vec![(x, -lim), (x, lim)], BLACK.mix(0.3))).map_err(|e| PlotError::new(path, e))?;
        }
        draw_legend(&mut chart, path, SeriesLabelPosition::UpperRight, 13)?;
    }
    root.present().map_err(|e| PlotError::new(path, e))
}

fn loop_plot(path: &Path, data: &Dataset, groups: &[RoutingGroup], d: &Diagnosis, after: &str) -> Result<(), PlotError> {
    register_fonts();
    let cols = groups.len().clamp(1, 3);
    let rows = groups.len().div_ceil(cols).max(1);
    let root = BitMapBackend::new(path, (420 * cols as u32, 360 * rows as u32)).into_drawing_area();
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
        chart
            .draw_series(LineSeries::new(ext, orange.stroke_width(2)))
            .map_err(|e| PlotError::new(path, e))?
            .label(after.to_string())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], orange.stroke_width(2)));
        for (dir, colour, label) in [(Direction::Load, BLACK, "measured, load"), (Direction::Unload, RED, "measured, unload"), (Direction::Rest, RGBColor(120, 120, 120), "measured, rest")] {
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
    after: &str,
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
    let root = BitMapBackend::new(path, (850, 850)).into_drawing_area();
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
        let s = chart.draw_series(LineSeries::new(line(&d.extended_predictions, i), orange.stroke_width(2))).map_err(|e| PlotError::new(path, e))?;
        if first {
            s.label(after.to_string()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], orange.stroke_width(2)));
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
        chart
            .draw_series(std::iter::once(Text::new(g.routing.clone(), (m.tip_y_mm + 2.0, -m.tip_x_mm + 2.0), (FONT, 13))))
            .map_err(|e| PlotError::new(path, e))?;
    }
    draw_legend(&mut chart, path, SeriesLabelPosition::LowerLeft, 13)?;
    root.present().map_err(|e| PlotError::new(path, e))
}
