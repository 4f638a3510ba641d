//! PNG pictures of the maps and the index page that shows them.
//!
//! Axes follow the actuator drawings: the lateral tip coordinate y runs
//! across the page, the clamp axis x runs down (the rod hangs), both in mm.

use super::{MapData, MapSummary, ReduceError, MODES};
use crate::plot::{register_fonts, BodyDrawing, PlotError, FONT};
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
use std::path::Path;

/// How values map to colours.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scale {
    /// Linear between the smallest and largest value.
    Linear,
    /// Linear in log10 (counts).
    Log,
    /// Symmetric about zero (signed coefficients).
    Symmetric,
}

/// One picture with the explanation the index page shows.
#[derive(Debug, Clone)]
pub struct Picture {
    /// File name in the map directory.
    pub file: String,
    /// Title.
    pub title: String,
    /// One line of explanation.
    pub explanation: String,
}

fn value_range(values: &[f64], scale: Scale) -> (f64, f64) {
    let (mut lo, mut hi) = values.iter().fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    if scale == Scale::Symmetric {
        let m = lo.abs().max(hi.abs());
        (lo, hi) = (-m, m);
    }
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        hi = lo + 1e-12_f64.max(lo.abs() * 1e-6);
    }
    (lo, hi)
}

fn colour(v: f64, lo: f64, hi: f64) -> RGBColor {
    ViridisRGB.get_color_normalized(v.clamp(lo, hi) as f32, lo as f32, hi as f32)
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// Draws cells coloured by value on `area` (no colour bar).
fn draw_cells(
    area: &Area,
    path: &Path,
    summary: &MapSummary,
    caption: &str,
    cells: &[(i32, i32, f64)],
    range: (f64, f64),
    label_size: u32,
) -> Result<(), PlotError> {
    let (x0, y0, c) = (summary.x_min_mm, summary.y_min_mm, summary.cell_mm);
    let (x1, y1) = (x0 + summary.nx as f64 * c, y0 + summary.ny as f64 * c);
    let mut chart = ChartBuilder::on(area)
        .caption(caption, (FONT, label_size + 4))
        .margin(8)
        .x_label_area_size(label_size * 3)
        .y_label_area_size(label_size * 3 + 5)
        .build_cartesian_2d(y0..y1, -x1..-x0)
        .map_err(|e| PlotError::new(path, e))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("tip y (mm)")
        .y_desc("tip x (mm, down)")
        .y_label_formatter(&|v| format!("{:.0}", -v + 0.0))
        .label_style((FONT, label_size))
        .axis_desc_style((FONT, label_size + 1))
        .draw()
        .map_err(|e| PlotError::new(path, e))?;
    chart
        .draw_series(cells.iter().map(|&(ix, iy, v)| {
            let (xa, ya) = (x0 + ix as f64 * c, y0 + iy as f64 * c);
            Rectangle::new([(ya, -xa), (ya + c, -(xa + c))], colour(v, range.0, range.1).filled())
        }))
        .map_err(|e| PlotError::new(path, e))?;
    Ok(())
}

/// Draws a vertical colour bar for `range` labelled `label`.
fn draw_colour_bar(area: &Area, path: &Path, range: (f64, f64), label: &str, scale: Scale) -> Result<(), PlotError> {
    let (lo, hi) = range;
    let mut chart = ChartBuilder::on(area)
        .margin_top(40)
        .margin_bottom(50)
        .margin_right(10)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(|e| PlotError::new(path, e))?;
    let fmt = move |v: &f64| -> String {
        match scale {
            Scale::Log => format!("{:.0}", 10f64.powf(*v)),
            _ if v.abs() < 1e-9 * (hi - lo) => "0".to_string(),
            _ if v.abs() < 1e-3 => format!("{v:.1e}"),
            _ => format!("{v:.4}"),
        }
    };
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(label)
        .y_label_formatter(&fmt)
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .draw()
        .map_err(|e| PlotError::new(path, e))?;
    let steps = 200;
    chart
        .draw_series((0..steps).map(|k| {
            let a = lo + (hi - lo) * k as f64 / steps as f64;
            let b = lo + (hi - lo) * (k + 1) as f64 / steps as f64;
            Rectangle::new([(0.0, a), (1.0, b)], colour(0.5 * (a + b), lo, hi).filled())
        }))
        .map_err(|e| PlotError::new(path, e))?;
    Ok(())
}

/// A map of one value per cell with a colour bar, 900×760 pixels.
pub fn draw_heatmap(
    path: &Path,
    summary: &MapSummary,
    title: &str,
    colour_label: &str,
    cells: &[(i32, i32, f64)],
    scale: Scale,
) -> Result<(), PlotError> {
    register_fonts();
    let root = BitMapBackend::new(path, (900, 760)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let shown: Vec<(i32, i32, f64)> = match scale {
        Scale::Log => cells.iter().map(|&(i, j, v)| (i, j, v.max(1.0).log10())).collect(),
        _ => cells.to_vec(),
    };
    let values: Vec<f64> = shown.iter().map(|c| c.2).collect();
    let range = value_range(&values, scale);
    let (left, right) = root.split_horizontally(760);
    draw_cells(&left, path, summary, title, &shown, range, 15)?;
    draw_colour_bar(&right, path, range, colour_label, scale)?;
    root.present().map_err(|e| PlotError::new(path, e))?;
    Ok(())
}

/// The 12 characteristic-mode maps in one figure (a_0 ranges down, a_1
/// ranges across), each with its representative shape drawn beside it.
pub fn draw_modes(path: &Path, map: &MapData, shapes: &[Option<BodyDrawing>]) -> Result<(), PlotError> {
    register_fonts();
    let root = BitMapBackend::new(path, (1800, 2000)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let (head, body) = root.split_vertically(60);
    head.draw(&Text::new(
        "Characteristic modes: tip cells where each (a_0 range, a_1 range) occurs; colour = log10 count; right: representative shape",
        (20, 20),
        (FONT, 22),
    ))
    .map_err(|e| PlotError::new(path, e))?;
    let panels = body.split_evenly((4, 3));
    for (m, (panel, mode)) in panels.iter().zip(&map.modes).enumerate().take(MODES) {
        let (map_area, shape_area) = panel.split_horizontally(360);
        let cells: Vec<(i32, i32, f64)> =
            map.cells.iter().filter(|c| c.modes[m] > 0).map(|c| (c.ix, c.iy, (c.modes[m] as f64).log10())).collect();
        let fmt = |(lo, hi): (f64, f64)| -> String {
            match (lo.is_finite(), hi.is_finite()) {
                (false, _) => format!("< {hi:.4}"),
                (_, false) => format!("≥ {lo:.4}"),
                _ => format!("{lo:.4}..{hi:.4}"),
            }
        };
        let caption = format!("mode {m}: a0 {}, a1 {} (n={})", fmt(mode.a0_bounds), fmt(mode.a1_bounds), mode.count);
        let values: Vec<f64> = cells.iter().map(|c| c.2).collect();
        let range = if values.is_empty() { (0.0, 1.0) } else { value_range(&values, Scale::Linear) };
        draw_cells(&map_area, path, &map.summary, &caption, &cells, range, 12)?;
        if let (Some(Some(shape)), Some(rep)) = (shapes.get(m), &mode.representative) {
            let caption = format!("τ = {:.2} N", rep.tension_n);
            draw_shape(&shape_area, path, shape, &caption)?;
        }
    }
    root.present().map_err(|e| PlotError::new(path, e))?;
    Ok(())
}

/// A small drawing of a body outline and cable (mode panels).
fn draw_shape(area: &Area, path: &Path, shape: &BodyDrawing, caption: &str) -> Result<(), PlotError> {
    let (l, r) = shape.outline();
    // Equal scale on both axes: one mm per pixel factor for the whole panel
    // (plot area ≈ panel less label areas and margins).
    let (w, h) = area.dim_in_pixel();
    let (pw, ph) = (w.saturating_sub(55).max(1) as f64, h.saturating_sub(75).max(1) as f64);
    let extent = l.iter().chain(&r).map(|p| p.1.abs()).fold(0.0, f64::max) + 3.0;
    let depth = l.iter().chain(&r).map(|p| p.0).fold(0.0, f64::max) + 5.0;
    let mm_per_px = (depth / ph).max(2.0 * extent / pw);
    let lateral = 0.5 * mm_per_px * pw;
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .caption(caption, (FONT, 12))
        .x_label_area_size(20)
        .y_label_area_size(25)
        .build_cartesian_2d(-lateral..lateral, -(mm_per_px * ph - 5.0)..5.0)
        .map_err(|e| PlotError::new(path, e))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(3)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .label_style((FONT, 10))
        .y_label_formatter(&|v| format!("{:.0}", -v + 0.0))
        .draw()
        .map_err(|e| PlotError::new(path, e))?;
    let page = |pts: &[(f64, f64)]| -> Vec<(f64, f64)> { pts.iter().map(|&(x, y)| (y, -x)).collect() };
    for side in [&l, &r] {
        chart.draw_series(LineSeries::new(page(side), shape.colour.stroke_width(2))).map_err(|e| PlotError::new(path, e))?;
    }
    chart.draw_series(LineSeries::new(page(&shape.cable), RED.stroke_width(1))).map_err(|e| PlotError::new(path, e))?;
    Ok(())
}

/// Writes index.html showing every picture with its explanation.
pub fn write_index(dir: &Path, summary: &MapSummary, pictures: &[Picture]) -> Result<(), ReduceError> {
    let mut html = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>cablemap feasibility maps</title>\n\
         <style>body{font-family:sans-serif;max-width:1000px;margin:auto}img{max-width:100%;border:1px solid #ccc}</style></head><body>\n\
         <h1>Feasibility maps</h1>\n",
    );
    html.push_str(&format!(
        "<p>{} simulations ({} converged, {} failed){}, binned on a {} mm grid of tip positions ({} non-empty cells). \
         Coefficients a_i are curvatures in mm⁻¹, {} (length basis <code>{}</code>). \
         Mode boundaries ({}): a0 {:?} mm⁻¹, a1 {:?} mm⁻¹. Data: <code>{}</code>. Tables: cells.parquet, modes.parquet, designs.parquet, summary.json.</p>\n",
        summary.rows_total,
        summary.rows_converged,
        summary.rows_failed,
        if summary.mirrored { ", mirrored half restored" } else { "" },
        summary.cell_mm,
        summary.cells,
        summary.length_basis.describe(),
        summary.length_basis,
        summary.mode_boundaries_source,
        summary.mode_boundaries.a0,
        summary.mode_boundaries.a1,
        html_escape(&summary.run_dir)
    ));
    for p in pictures {
        html.push_str(&format!(
            "<h2>{}</h2>\n<p>{}</p>\n<img src=\"{}\" alt=\"{}\">\n",
            html_escape(&p.title),
            html_escape(&p.explanation),
            html_escape(&p.file),
            html_escape(&p.title)
        ));
    }
    html.push_str("</body></html>\n");
    let path = dir.join("index.html");
    crate::io::write_atomic(&path, html.as_bytes())
        .map_err(|e| ReduceError::Write { path: path.display().to_string(), message: e.to_string() })
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}
