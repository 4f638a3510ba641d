//! A planar diagnosis's loop picture (`loops.png`): the tip angle against
//! the tension per routing, measured and simulated.

use super::{draw_series_labels, register_fonts, PlotError, FONT};
use crate::calibrate::data::{Dataset, Direction, RoutingGroup};
use crate::calibrate::diagnose::Diagnosis;
use crate::calibrate::observations::measurements::MeasurementsReport;
use crate::calibrate::predict::Prediction;
use plotters::prelude::*;
use std::path::Path;

/// Draws the tip angle against the tension of each routing of `groups`,
/// measured and by `d`'s models, into `path`.
pub fn draw_diagnosis_loops(path: &Path, data: &Dataset, groups: &[RoutingGroup], d: &Diagnosis<MeasurementsReport>, after: Option<&str>) -> Result<(), PlotError> {
    register_fonts();
    let cols = groups.len().clamp(1, 3);
    let rows = groups.len().div_ceil(cols).max(1);
    let root = super::png_backend(path, (420 * cols as u32, 360 * rows as u32))?.into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let panels = root.split_evenly((rows, cols));
    let orange = RGBColor(230, 120, 0);
    for (panel, g) in panels.iter().zip(groups) {
        let angle = |i: usize, preds: &[Option<Prediction>]| preds[i].as_ref().expect("predicted").pose.tip_angle_rad.to_degrees();
        let measured: Vec<(f64, f64, Direction)> =
            g.rows.iter().map(|&i| (data.rows[i].tension_n, data.rows[i].tip_angle_rad.to_degrees(), data.rows[i].direction)).collect();
        let base: Vec<(f64, f64)> = g.rows.iter().map(|&i| (data.rows[i].tension_n, angle(i, &d.details.baseline_predictions))).collect();
        let ext: Vec<(f64, f64)> = g.rows.iter().map(|&i| (data.rows[i].tension_n, angle(i, &d.details.extended_predictions))).collect();
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
        draw_series_labels(&mut chart, path, SeriesLabelPosition::UpperLeft, 11)?;
    }
    root.present().map_err(|e| PlotError::new(path, e))
}
