//! A planar diagnosis's residual picture (`residuals.png` beside
//! `report.md`): every reading's simulated − measured tip x, y and weighted
//! angle, by the thesis model and by the final model.

use super::{draw_series_labels, register_fonts, PlotError, FONT};
use crate::calibrate::data::{Dataset, Direction, RoutingGroup};
use crate::calibrate::diagnose::Diagnosis;
use crate::calibrate::observations::measurements::MeasurementsReport;
use crate::calibrate::observations::measurements::row_residual;
use crate::calibrate::predict::Prediction;
use plotters::prelude::*;
use std::path::Path;

/// Draws the residuals of `d`'s models over `groups`' readings into `path`
/// (`after`: the final model's label, when it differs from the thesis
/// model; `w`: mm per degree of the angle).
pub fn draw_diagnosis_residuals(path: &Path, data: &Dataset, groups: &[RoutingGroup], d: &Diagnosis<MeasurementsReport>, after: Option<&str>, w: f64) -> Result<(), PlotError> {
    register_fonts();
    let height = if after.is_some() { 800 } else { 420 };
    let root = super::png_backend(path, (1100, height))?.into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let panels = root.split_evenly((if after.is_some() { 2 } else { 1 }, 1));
    let order: Vec<usize> = groups.iter().flat_map(|g| g.rows.iter().copied()).collect();
    let series = |preds: &[Option<Prediction>]| -> Vec<[f64; 3]> {
        order.iter().map(|&i| row_residual(&data.rows[i], &preds[i].as_ref().expect("predicted").pose, w)).collect()
    };
    let before = series(&d.details.baseline_predictions);
    let after_r = series(&d.details.extended_predictions);
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
        draw_series_labels(&mut chart, path, SeriesLabelPosition::LowerRight, 13)?;
    }
    root.present().map_err(|e| PlotError::new(path, e))
}
