//! The PNG of a spatial simulation: two orthogonal views of the hanging rod,
//! x–y (looking along z) and x–z (looking along y), on one scale, with the
//! body's silhouette, the centreline, every cable's path and the tip.

use super::{clamp_series, draw_legend, draw_series_on, legend_size, register_fonts, Mark, PictureSeries, PlotError, FONT};
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
    let root = crate::plot::png_backend(path, (1400, 760))?.into_drawing_area();
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
        // Series in the view's body frame (x, lateral), as the planar pictures.
        let in_view = |p: [f64; 3]| (p[0], p[a]);
        let (left, right) = silhouette(sim, a, radius);
        let tip: Vec<(f64, f64)> = left.last().into_iter().chain(right.last()).copied().collect();
        let mut series = vec![clamp_series(radius)];
        series.push(PictureSeries {
            legend: "body (silhouette of radius r)".into(),
            colour: BLUE_800.to_rgba(),
            mark: Mark::Lines { paths: [left, right, tip].into_iter().filter(|p| p.len() > 1).collect(), width_px: 2 },
        });
        series.push(PictureSeries {
            legend: "centreline".into(),
            colour: BLUE_800.mix(0.4),
            mark: Mark::Lines { paths: vec![sim.nodes.iter().map(|n| in_view(n.p_mm)).collect()], width_px: 1 },
        });
        for (i, cable) in paths.iter().enumerate() {
            series.push(PictureSeries {
                legend: format!("cable {} ({:.2} N)", i + 1, sim.actuator.cables[i].tension_n),
                colour: CABLE_COLOURS[i % CABLE_COLOURS.len()].to_rgba(),
                mark: Mark::Lines { paths: vec![cable.iter().map(|&p| in_view(p)).collect()], width_px: 2 },
            });
        }
        if let Some(n) = sim.nodes.last() {
            let mark = Mark::Dot { at: in_view(n.p_mm), radius_px: 5 };
            series.push(PictureSeries { legend: "tip".into(), colour: BLUE_800.to_rgba(), mark });
        }
        for s in &series {
            draw_series_on(&mut chart, path, s)?;
        }
        // The legend in the plot's upper right corner (the rod hangs from the top centre).
        let plot = chart.plotting_area().strip_coord_spec();
        let (w, _) = legend_size(&plot, &series);
        draw_legend(&plot, path, &series, (plot.dim_in_pixel().0 as i32 - w - 10, 10))?;
    }
    root.present().map_err(|e| PlotError::new(path, e))?;
    Ok(())
}

/// Points (x, lateral) of one side of a body outline, mm.
type Outline = Vec<(f64, f64)>;

/// The body's outline in the view plane (x, lateral axis `a`), mm: at each node the cross-section (a disc of radius r spanned by
/// the body y and z axes) reaches r·|(b_y·N, b_z·N)| along the in-view
/// normal N of the projected centreline.
fn silhouette(sim: &SpatialSimulation, a: usize, radius: f64) -> (Outline, Outline) {
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
        left.push((n.p_mm[0] + reach * nx, n.p_mm[a] + reach * nl));
        right.push((n.p_mm[0] - reach * nx, n.p_mm[a] - reach * nl));
    }
    (left, right)
}

/// One reach map: the two coordinate names (page across, page down) and
/// the counts per cell (i, j) of size `cell_mm`.
pub struct ReachPlane<'a> {
    /// Coordinate across the page and down the page, e.g. ("y", "x").
    pub axes: (&'a str, &'a str),
    /// (i across, j down, count): the cell covers [i·cell, (i+1)·cell) × [j·cell, (j+1)·cell).
    pub cells: Vec<(i32, i32, i64)>,
}

/// Draws reach maps side by side (counts per cell on a log10 viridis
/// scale, shared by all panels), each at equal aspect. The coordinate
/// called "x" (the clamp axis) runs down the page, as in every drawing of
/// the hanging rod.
pub fn draw_reach_maps(path: &Path, title: &str, planes: &[ReachPlane<'_>], cell_mm: f64) -> Result<(), PlotError> {
    use plotters::style::colors::colormaps::ViridisRGB;
    register_fonts();
    let panel = 560u32;
    let root = crate::plot::png_backend(path, (panel * planes.len().max(1) as u32, panel + 110))?.into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let root = root.titled(title, (FONT, 20)).map_err(|e| PlotError::new(path, e))?;
    let max = planes.iter().flat_map(|p| p.cells.iter().map(|c| c.2)).max().unwrap_or(1).max(1) as f64;
    let hi = max.log10().max(1e-9);
    let (maps, bar) = root.split_vertically(panel);
    for (area, plane) in maps.split_evenly((1, planes.len().max(1))).iter().zip(planes) {
        // "x" runs down the page (negated), the other coordinate across.
        let down_is_x = plane.axes.1 == "x";
        let (mut lo_i, mut hi_i, mut lo_j, mut hi_j) = (0i32, 0i32, 0i32, 0i32);
        for &(i, j, _) in &plane.cells {
            (lo_i, hi_i, lo_j, hi_j) = (lo_i.min(i), hi_i.max(i + 1), lo_j.min(j), hi_j.max(j + 1));
        }
        let span = ((hi_i - lo_i).max(hi_j - lo_j) as f64 + 4.0) * cell_mm;
        let ci = 0.5 * (lo_i + hi_i) as f64 * cell_mm;
        let cj = 0.5 * (lo_j + hi_j) as f64 * cell_mm;
        let page_j = |j: f64| if down_is_x { -j } else { j };
        let (j0, j1) = if down_is_x { (-(cj + span / 2.0), -(cj - span / 2.0)) } else { (cj - span / 2.0, cj + span / 2.0) };
        let mut chart = ChartBuilder::on(area)
            .caption(
                if down_is_x { format!("x–{} plane", plane.axes.0) } else { format!("{}–{} plane", plane.axes.0, plane.axes.1) },
                (FONT, 17),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(ci - span / 2.0..ci + span / 2.0, j0..j1)
            .map_err(|e| PlotError::new(path, e))?;
        chart
            .configure_mesh()
            .x_desc(format!("{} (mm)", plane.axes.0))
            .y_desc(if down_is_x { "x (mm, downward)".to_string() } else { format!("{} (mm)", plane.axes.1) })
            .y_label_formatter(&|v| format!("{:.0}", if down_is_x { -v + 0.0 } else { *v }))
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .draw()
            .map_err(|e| PlotError::new(path, e))?;
        chart
            .draw_series(plane.cells.iter().map(|&(i, j, n)| {
                let (a0, a1) = (i as f64 * cell_mm, (i + 1) as f64 * cell_mm);
                let (b0, b1) = (page_j(j as f64 * cell_mm), page_j((j + 1) as f64 * cell_mm));
                let c = ViridisRGB.get_color_normalized((n as f64).log10() as f32, 0.0, hi as f32);
                Rectangle::new([(a0, b0), (a1, b1)], c.filled())
            }))
            .map_err(|e| PlotError::new(path, e))?;
    }
    // Colour bar: log10 count from 0 (1 solution) to the largest.
    let bar = bar.margin(20, 40, 60, 60);
    let (w, _) = bar.dim_in_pixel();
    let steps = 200;
    for k in 0..steps {
        let t = k as f64 / steps as f64;
        let c = ViridisRGB.get_color_normalized((t * hi) as f32, 0.0, hi as f32);
        let x0 = (t * f64::from(w)) as i32;
        let x1 = ((k + 1) as f64 / steps as f64 * f64::from(w)) as i32 + 1;
        bar.draw(&Rectangle::new([(x0, 0), (x1, 18)], c.filled())).map_err(|e| PlotError::new(path, e))?;
    }
    let label = format!("solutions per {cell_mm} mm cell (log scale): 1 … {max:.0}");
    bar.draw(&Text::new(label, (0, 24), (FONT, 14))).map_err(|e| PlotError::new(path, e))?;
    root.present().map_err(|e| PlotError::new(path, e))?;
    Ok(())
}
