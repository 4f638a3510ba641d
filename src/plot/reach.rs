//! Reach maps of a several-cable sweep: counts of solutions per cell on
//! the coordinate planes, on a shared log10 viridis scale.

use super::canvas::{png_backend, register_fonts, PlotError, FONT};
use plotters::prelude::*;
use std::path::Path;

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
    let root = png_backend(path, (panel * planes.len().max(1) as u32, panel + 110))?.into_drawing_area();
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
