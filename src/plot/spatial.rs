//! The PNG of a spatial simulation: two orthogonal views of the hanging rod,
//! x–y (looking along z) and x–z (looking along y), on one scale, with the
//! body's silhouette, the centreline, every cable's path and the tip.

use super::{register_fonts, PlotError, FONT};
use crate::model::spatial::SpatialSimulation;
use plotters::prelude::*;
use plotters::style::full_palette::{BLUE_800, BROWN, ORANGE, PURPLE};
use std::path::Path;

/// Colours of cables 1–8.
const CABLE_COLOURS: [RGBColor; 8] = [RED, ORANGE, PURPLE, GREEN, MAGENTA, CYAN, BROWN, BLACK];

/// One view: the lateral coordinate (1 = y, 2 = z) and its name.
struct View {
    axis: usize,
    name: &'static str,
}

/// Draws `sim` as two side-by-side views into `path` (PNG, 1400 × 760 px).
pub fn draw_spatial(path: &Path, title: &str, sim: &SpatialSimulation) -> Result<(), PlotError> {
    register_fonts();
    let root = BitMapBackend::new(path, (1400, 760)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let root = root.titled(title, (FONT, 22)).map_err(|e| PlotError::new(path, e))?;
    let panels = root.split_evenly((1, 2));
    let radius = sim.actuator.rod.radius_mm;
    let paths = sim.cable_paths_mm();
    // One scale for both views: the range of x and of both lateral coordinates.
    let (mut lo, mut hi) = ([0.0f64; 3], [0.0f64; 3]);
    for n in &sim.nodes {
        for i in 0..3 {
            lo[i] = lo[i].min(n.p_mm[i] - radius);
            hi[i] = hi[i].max(n.p_mm[i] + radius);
        }
    }
    let lat_lo = lo[1].min(lo[2]);
    let lat_hi = hi[1].max(hi[2]);
    let span = (hi[0] - lo[0]).max(lat_hi - lat_lo) + 10.0;
    let (cx, cl) = (0.5 * (lo[0] + hi[0]), 0.5 * (lat_lo + lat_hi));
    let x_range = (cx - span / 2.0, cx + span / 2.0);
    let lat_range = (cl - span / 2.0, cl + span / 2.0);
    for (panel, view) in panels.iter().zip([View { axis: 1, name: "y" }, View { axis: 2, name: "z" }]) {
        let mut chart = ChartBuilder::on(panel)
            .caption(format!("x–{} view (looking along {})", view.name, if view.axis == 1 { "z" } else { "y" }), (FONT, 18))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(55)
            .build_cartesian_2d(lat_range.0..lat_range.1, -x_range.1..-x_range.0)
            .map_err(|e| PlotError::new(path, e))?;
        chart
            .configure_mesh()
            .x_desc(format!("{} (mm)", view.name))
            .y_desc("x (mm, along the clamp axis, downward)")
            .y_label_formatter(&|v| format!("{:.0}", -v + 0.0))
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .draw()
            .map_err(|e| PlotError::new(path, e))?;
        let a = view.axis;
        let page = |p: [f64; 3]| (p[a], -p[0]);
        chart
            .draw_series(std::iter::once(Rectangle::new([(-8.0, 3.0), (8.0, 0.0)], BLACK.mix(0.5).filled())))
            .map_err(|e| PlotError::new(path, e))?;
        let (left, right) = silhouette(sim, a, radius);
        for side in [&left, &right] {
            chart
                .draw_series(LineSeries::new(side.iter().copied(), BLUE_800.stroke_width(2)))
                .map_err(|e| PlotError::new(path, e))?;
        }
        if let (Some(&l), Some(&r)) = (left.last(), right.last()) {
            chart.draw_series(LineSeries::new([l, r], BLUE_800.stroke_width(2))).map_err(|e| PlotError::new(path, e))?;
        }
        chart
            .draw_series(LineSeries::new(sim.nodes.iter().map(|n| page(n.p_mm)), BLUE_800.mix(0.4).stroke_width(1)))
            .map_err(|e| PlotError::new(path, e))?
            .label("body (silhouette of radius r)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE_800.stroke_width(2)));
        for (i, cable) in paths.iter().enumerate() {
            let colour = CABLE_COLOURS[i % CABLE_COLOURS.len()];
            let tension = sim.actuator.cables[i].tension_n;
            chart
                .draw_series(LineSeries::new(cable.iter().map(|&p| page(p)), colour.stroke_width(2)))
                .map_err(|e| PlotError::new(path, e))?
                .label(format!("cable {} ({tension:.2} N)", i + 1))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
        }
        if let Some(n) = sim.nodes.last() {
            chart.draw_series(std::iter::once(Circle::new(page(n.p_mm), 5, BLUE_800.filled()))).map_err(|e| PlotError::new(path, e))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font((FONT, 13))
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| PlotError::new(path, e))?;
    }
    root.present().map_err(|e| PlotError::new(path, e))?;
    Ok(())
}

/// The body's outline in the view plane (x, lateral axis `a`), as page
/// points: at each node the cross-section (a disc of radius r spanned by
/// the body y and z axes) reaches r·|(b_y·N, b_z·N)| along the in-view
/// normal N of the projected centreline.
fn silhouette(sim: &SpatialSimulation, a: usize, radius: f64) -> (Vec<(f64, f64)>, Vec<(f64, f64)>) {
    let nodes = &sim.nodes;
    let mut left = Vec::with_capacity(nodes.len());
    let mut right = Vec::with_capacity(nodes.len());
    for (k, n) in nodes.iter().enumerate() {
        let (prev, next) = (&nodes[k.saturating_sub(1)], &nodes[(k + 1).min(nodes.len() - 1)]);
        let (tx, tl) = (next.p_mm[0] - prev.p_mm[0], next.p_mm[a] - prev.p_mm[a]);
        let norm = tx.hypot(tl);
        if norm == 0.0 {
            continue;
        }
        // In-view normal (x, lateral) = (−t_lat, t_x)/|t|.
        let (nx, nl) = (-tl / norm, tx / norm);
        let r = n.rotation;
        let dot = |col: usize| r[0][col] * nx + r[a][col] * nl;
        let reach = radius * dot(1).hypot(dot(2));
        left.push((n.p_mm[a] + reach * nl, -(n.p_mm[0] + reach * nx)));
        right.push((n.p_mm[a] - reach * nl, -(n.p_mm[0] - reach * nx)));
    }
    (left, right)
}
