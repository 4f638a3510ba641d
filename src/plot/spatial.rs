//! The PNG of an actuator's simulation: two orthogonal views of the hanging
//! rod, x–y (looking along z) and x–z (looking along y), on one scale, with
//! the body's silhouette, the centreline, every cable's path (up to where
//! it is knotted) and the tip.

use super::canvas::{png_backend, register_fonts, PlotError, FONT};
use super::series::{clamp_series, draw_legend, draw_series_on, legend_size, page_chart, Mark, PictureSeries};
use crate::model::Simulation;
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
pub fn draw_spatial(path: &Path, title: &str, sim: &Simulation) -> Result<(), PlotError> {
    register_fonts();
    let root = png_backend(path, (1400, 760))?.into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let root = root.titled(title, (FONT, 22)).map_err(|e| PlotError::new(path, e))?;
    let panels = root.split_evenly((1, 2));
    let radius = sim.actuator.rod.radius_mm;
    let paths = sim.cable_paths_mm();
    // One scale for both views: the range of x and of both lateral coordinates.
    let (mut lo, mut hi) = ([0.0f64; 3], [0.0f64; 3]);
    for n in &sim.centreline {
        let p = n.position_mm();
        for i in 0..3 {
            lo[i] = lo[i].min(p[i] - radius);
            hi[i] = hi[i].max(p[i] + radius);
        }
    }
    let lat_lo = lo[1].min(lo[2]);
    let lat_hi = hi[1].max(hi[2]);
    let span = (hi[0] - lo[0]).max(lat_hi - lat_lo) + 10.0;
    let (cx, cl) = (0.5 * (lo[0] + hi[0]), 0.5 * (lat_lo + lat_hi));
    let x_range = (cx - span / 2.0, cx + span / 2.0);
    let lat_range = (cl - span / 2.0, cl + span / 2.0);
    for (panel, view) in panels.iter().zip([View { axis: 1, name: "y" }, View { axis: 2, name: "z" }]) {
        let caption = format!("x–{} view (looking along {})", view.name, if view.axis == 1 { "z" } else { "y" });
        let lateral = format!("{} (mm)", view.name);
        let mut chart = page_chart(panel, path, (&caption, 18), (&lateral, lat_range), (-x_range.1, -x_range.0))?;
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
            mark: Mark::Lines { paths: vec![sim.centreline.iter().map(|n| in_view(n.position_mm())).collect()], width_px: 1 },
        });
        for (i, cable) in paths.iter().enumerate() {
            series.push(PictureSeries {
                legend: format!("cable {} ({:.2} N)", i + 1, sim.actuator.cables[i].tension_n),
                colour: CABLE_COLOURS[i % CABLE_COLOURS.len()].to_rgba(),
                mark: Mark::Lines { paths: vec![cable.iter().map(|&p| in_view(p)).collect()], width_px: 2 },
            });
        }
        if let Some(n) = sim.centreline.last() {
            let mark = Mark::Dot { at: in_view(n.position_mm()), radius_px: 5 };
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
fn silhouette(sim: &Simulation, a: usize, radius: f64) -> (Outline, Outline) {
    let nodes = &sim.centreline;
    let mut left = Vec::with_capacity(nodes.len());
    let mut right = Vec::with_capacity(nodes.len());
    for (k, n) in nodes.iter().enumerate() {
        let (prev, next) = (&nodes[k.saturating_sub(1)], &nodes[(k + 1).min(nodes.len() - 1)]);
        let (p, prev, next) = (n.position_mm(), prev.position_mm(), next.position_mm());
        let (tx, tl) = (next[0] - prev[0], next[a] - prev[a]);
        let norm = tx.hypot(tl);
        if norm == 0.0 {
            continue;
        }
        // In-view normal (x, lateral) = (−t_lat, t_x)/|t|.
        let (nx, nl) = (-tl / norm, tx / norm);
        let r = n.rotation;
        let dot = |col: usize| r[0][col] * nx + r[a][col] * nl;
        let reach = radius * dot(1).hypot(dot(2));
        left.push((p[0] + reach * nx, p[a] + reach * nl));
        right.push((p[0] - reach * nx, p[a] - reach * nl));
    }
    (left, right)
}

