//! A planar diagnosis's shape picture (`shapes.png`): each routing's body
//! at its top tension, measured against simulated.

use super::{draw_series_labels, register_fonts, PlotError, FONT};
use crate::calibrate::data::{CentrelinePoints, Dataset, MarkerPoints, RoutingGroup};
use crate::calibrate::diagnose::Diagnosis;
use crate::calibrate::observations::measurements::MeasurementsReport;
use crate::calibrate::predict::Prediction;
use plotters::prelude::*;
use std::path::Path;

/// Draws each routing's body at its top tension by `d`'s models, with the
/// measured tip, centreline points and markers, into `path`.
pub fn draw_diagnosis_shapes(
    path: &Path,
    data: &Dataset,
    groups: &[RoutingGroup],
    d: &Diagnosis<MeasurementsReport>,
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
        pts.extend(line(&d.details.baseline_predictions, i));
        pts.extend(line(&d.details.extended_predictions, i));
        pts.push((data.rows[i].tip_y_mm, -data.rows[i].tip_x_mm));
    }
    let (x0, x1) = pts.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (y0, y1) = pts.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let span = (x1 - x0).max(y1 - y0) + 10.0;
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let root = super::png_backend(path, (850, 850))?.into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let title = "shapes at the top tension: measured vs simulated";
    let mut chart = super::hanging_chart(&root, path, title, (cx - span / 2.0, cx + span / 2.0), (cy - span / 2.0, cy + span / 2.0))?;
    let orange = RGBColor(230, 120, 0);
    for (k, &(g, i)) in picks.iter().enumerate() {
        let first = k == 0;
        let s = chart.draw_series(LineSeries::new(line(&d.details.baseline_predictions, i), BLUE.stroke_width(2))).map_err(|e| PlotError::new(path, e))?;
        if first {
            s.label("thesis model").legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLUE.stroke_width(2)));
        }
        if let Some(label) = after {
            let s = chart.draw_series(LineSeries::new(line(&d.details.extended_predictions, i), orange.stroke_width(2))).map_err(|e| PlotError::new(path, e))?;
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
    draw_series_labels(&mut chart, path, SeriesLabelPosition::LowerLeft, 13)?;
    root.present().map_err(|e| PlotError::new(path, e))
}
