//! PNG pictures of the maps (for papers; the explorer page draws its own).
//!
//! Axes follow the actuator drawings: the lateral tip coordinate y runs
//! across the page, the clamp axis x runs down (the rod hangs), both in mm,
//! at equal aspect: one mm across is one mm down.

use super::{MapData, MapSummary, MODES};
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

/// Blue–white–red, centred on zero (ColorBrewer RdBu, reversed): signed
/// coefficients read at a glance, zero is white.
const DIVERGING: [(u8, u8, u8); 11] = [
    (5, 48, 97),
    (33, 102, 172),
    (67, 147, 195),
    (146, 197, 222),
    (209, 229, 240),
    (247, 247, 247),
    (253, 219, 199),
    (244, 165, 130),
    (214, 96, 77),
    (178, 24, 43),
    (103, 0, 31),
];

fn diverging(t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0) * (DIVERGING.len() - 1) as f64;
    let i = (t.floor() as usize).min(DIVERGING.len() - 2);
    let f = t - i as f64;
    let mix = |a: u8, b: u8| (f64::from(a) + f * (f64::from(b) - f64::from(a))).round() as u8;
    let (a, b) = (DIVERGING[i], DIVERGING[i + 1]);
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The colour of `v` on `scale` over (lo, hi): diverging for signed values
/// (symmetric scales), viridis for counts and spreads.
fn colour(v: f64, (lo, hi): (f64, f64), scale: Scale) -> RGBColor {
    match scale {
        Scale::Symmetric => diverging((v - lo) / (hi - lo)),
        _ => ViridisRGB.get_color_normalized(v.clamp(lo, hi) as f32, lo as f32, hi as f32),
    }
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// The mm extent every map shows (the grid, the clamp at the origin and the
/// rest tip at (L, 0)) and the pixels a map of it takes at equal aspect:
/// one mm across is one mm down.
#[derive(Debug, Clone, Copy)]
struct Frame {
    /// Clamp-axis range (down the page), mm.
    x: (f64, f64),
    /// Lateral range (across the page), mm.
    y: (f64, f64),
}

/// Pixels around a map's plot area: tick labels left and below.
const MAP_MARGIN: u32 = 8;

impl Frame {
    fn of(summary: &MapSummary) -> Self {
        let c = summary.cell_mm;
        let (x0, y0) = (summary.x_min_mm, summary.y_min_mm);
        let (x1, y1) = (x0 + summary.nx as f64 * c, y0 + summary.ny as f64 * c);
        Self { x: (x0.min(-2.0), x1.max(summary.length_mm + 2.0)), y: (y0.min(-2.0), y1.max(2.0)) }
    }

    /// Size of a map area (plot plus label areas) whose plot is `plot_w`
    /// pixels wide.
    fn area_size(&self, plot_w: u32, label_size: u32) -> (u32, u32) {
        let px_per_mm = f64::from(plot_w) / (self.y.1 - self.y.0);
        let plot_h = (px_per_mm * (self.x.1 - self.x.0)).round() as u32;
        (plot_w + y_label_area(label_size) + 2 * MAP_MARGIN, plot_h + x_label_area(label_size) + 2 * MAP_MARGIN)
    }
}

fn x_label_area(label_size: u32) -> u32 {
    label_size * 3
}

fn y_label_area(label_size: u32) -> u32 {
    label_size * 3 + 8
}

/// Draws cells coloured by value on `area` (sized by [`Frame::area_size`]),
/// the clamp and the rest tip, and `overlay` (a body in the same mm frame).
#[allow(clippy::too_many_arguments)]
fn draw_cells(
    area: &Area,
    path: &Path,
    summary: &MapSummary,
    cells: &[(i32, i32, f64)],
    range: (f64, f64),
    scale: Scale,
    label_size: u32,
    overlay: Option<&BodyDrawing>,
) -> Result<(), PlotError> {
    let frame = Frame::of(summary);
    let (x0, y0, c) = (summary.x_min_mm, summary.y_min_mm, summary.cell_mm);
    let mut chart = ChartBuilder::on(area)
        .margin(MAP_MARGIN)
        .x_label_area_size(x_label_area(label_size))
        .y_label_area_size(y_label_area(label_size))
        .build_cartesian_2d(frame.y.0..frame.y.1, -frame.x.1..-frame.x.0)
        .map_err(|e| PlotError::new(path, e))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("tip y (mm)")
        .y_desc("tip x (mm, down)")
        .y_label_formatter(&|v| format!("{:.0}", -v + 0.0))
        .x_label_formatter(&|v| format!("{v:.0}"))
        .label_style((FONT, label_size))
        .axis_desc_style((FONT, label_size))
        .draw()
        .map_err(|e| PlotError::new(path, e))?;
    chart
        .draw_series(cells.iter().map(|&(ix, iy, v)| {
            let (xa, ya) = (x0 + ix as f64 * c, y0 + iy as f64 * c);
            Rectangle::new([(ya, -xa), (ya + c, -(xa + c))], colour(v, range, scale).filled())
        }))
        .map_err(|e| PlotError::new(path, e))?;
    // The clamp (a bar at the origin) and the rest tip (a circle at (L, 0)).
    let r = summary.radius_mm * 1.6;
    chart.draw_series(std::iter::once(Rectangle::new([(-r, 0.6), (r, 0.0)], BLACK.filled()))).map_err(|e| PlotError::new(path, e))?;
    chart
        .draw_series(std::iter::once(Circle::new((0.0, -summary.length_mm), 4, BLACK.stroke_width(1))))
        .map_err(|e| PlotError::new(path, e))?;
    if let Some(body) = overlay {
        let (left, right) = body.outline();
        let page = |pts: &[(f64, f64)]| -> Vec<(f64, f64)> { pts.iter().map(|&(x, y)| (y, -x)).collect() };
        for side in [&left, &right] {
            chart.draw_series(LineSeries::new(page(side), body.colour.stroke_width(2))).map_err(|e| PlotError::new(path, e))?;
        }
        for cable in std::iter::once(&body.cable).chain(&body.further_cables) {
            chart.draw_series(LineSeries::new(page(cable), RED.stroke_width(1))).map_err(|e| PlotError::new(path, e))?;
        }
    }
    Ok(())
}

/// Draws a horizontal colour bar for `range` labelled `label` (under a map
/// or a figure of maps).
fn draw_colour_bar(area: &Area, path: &Path, range: (f64, f64), label: &str, scale: Scale, font: u32) -> Result<(), PlotError> {
    let (lo, hi) = range;
    let fmt = move |v: &f64| -> String {
        match scale {
            // Three significant digits: a short log range must not read "1 1 2 2".
            Scale::Log => {
                let n = 10f64.powf(*v);
                let digits = (2 - n.log10().floor() as i32).max(0) as usize;
                format!("{n:.digits$}")
            }
            _ if v.abs() < 1e-9 * (hi - lo) => "0".to_string(),
            _ if v.abs() < 1e-3 => format!("{v:.1e}"),
            _ => format!("{v:.4}"),
        }
    };
    let mut chart = ChartBuilder::on(area)
        .margin_left(40)
        .margin_right(40)
        .margin_top(6)
        .x_label_area_size(font * 3)
        .build_cartesian_2d(lo..hi, 0.0..1.0)
        .map_err(|e| PlotError::new(path, e))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .disable_y_axis()
        .x_desc(label)
        .x_label_formatter(&fmt)
        .label_style((FONT, font))
        .axis_desc_style((FONT, font))
        .draw()
        .map_err(|e| PlotError::new(path, e))?;
    let steps = 200;
    chart
        .draw_series((0..steps).map(|k| {
            let a = lo + (hi - lo) * k as f64 / steps as f64;
            let b = lo + (hi - lo) * (k + 1) as f64 / steps as f64;
            Rectangle::new([(a, 0.0), (b, 1.0)], colour(0.5 * (a + b), range, scale).filled())
        }))
        .map_err(|e| PlotError::new(path, e))?;
    Ok(())
}

/// Width of a single map's plot area in pixels (the image is sized from it
/// at equal aspect).
const HEATMAP_PLOT_W: u32 = 760;
/// Height of the title strip above a map, pixels.
const TITLE_H: u32 = 44;
/// Height of the colour-bar strip under a map, pixels.
const BAR_H: u32 = 80;

/// A map of one value per cell with a colour bar, at equal aspect (1 mm
/// across = 1 mm down); its size follows the map's extent. Returns the
/// image size in pixels.
pub fn draw_heatmap(
    path: &Path,
    summary: &MapSummary,
    title: &str,
    colour_label: &str,
    cells: &[(i32, i32, f64)],
    scale: Scale,
) -> Result<(u32, u32), PlotError> {
    register_fonts();
    let label_size = 17;
    let (map_w, map_h) = Frame::of(summary).area_size(HEATMAP_PLOT_W, label_size);
    let size = (map_w, TITLE_H + map_h + BAR_H);
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let shown: Vec<(i32, i32, f64)> = match scale {
        Scale::Log => cells.iter().map(|&(i, j, v)| (i, j, v.max(1.0).log10())).collect(),
        _ => cells.to_vec(),
    };
    let values: Vec<f64> = shown.iter().map(|c| c.2).collect();
    let range = value_range(&values, scale);
    let (head, body) = root.split_vertically(TITLE_H);
    head.draw(&Text::new(title.to_string(), (12, 12), (FONT, 22))).map_err(|e| PlotError::new(path, e))?;
    let (map_area, bar) = body.split_vertically(map_h);
    draw_cells(&map_area, path, summary, &shown, range, scale, label_size, None)?;
    draw_colour_bar(&bar, path, range, colour_label, scale, 15)?;
    root.present().map_err(|e| PlotError::new(path, e))?;
    Ok(size)
}

/// The 12 characteristic-mode maps in one figure (a_0 ranges down, a_1
/// ranges across), all at equal aspect on one log colour scale, each with
/// its representative shape drawn in the same mm frame (the clamp at the
/// origin), so every panel shares its axes. Returns the image size.
pub fn draw_modes(path: &Path, map: &MapData, shapes: &[Option<BodyDrawing>]) -> Result<(u32, u32), PlotError> {
    register_fonts();
    let label_size = 14;
    let panel_title_h = 46;
    let (map_w, map_h) = Frame::of(&map.summary).area_size(430, label_size);
    let (panel_w, panel_h) = (map_w + 10, map_h + panel_title_h);
    let (head_h, bar_h) = (56, 80);
    let size = (3 * panel_w, head_h + 4 * panel_h + bar_h);
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let (head, rest) = root.split_vertically(head_h);
    let (body, bar) = rest.split_vertically(4 * panel_h);
    head.draw(&Text::new(
        "Characteristic modes: a0 in 4 ranges (rows) × a1 in 3 (columns); colour = simulations of the mode per cell",
        (12, 8),
        (FONT, 20),
    ))
    .map_err(|e| PlotError::new(path, e))?;
    head.draw(&Text::new(
        format!("blue: the simulation nearest the mode's median (a0, a1), cable in red; a_i in mm⁻¹, {}", map.summary.length_basis.describe()),
        (12, 32),
        (FONT, 15),
    ))
    .map_err(|e| PlotError::new(path, e))?;
    let counts: Vec<f64> = map.cells.iter().flat_map(|c| c.modes.iter().filter(|&&n| n > 0).map(|&n| (n as f64).log10())).collect();
    let range = if counts.is_empty() { (0.0, 1.0) } else { value_range(&counts, Scale::Log) };
    let range = (0.0_f64.min(range.0), range.1);
    let panels = body.split_evenly((4, 3));
    let fmt = |(lo, hi): (f64, f64)| -> String {
        match (lo.is_finite(), hi.is_finite()) {
            (false, _) => format!("< {hi:.4}"),
            (_, false) => format!("≥ {lo:.4}"),
            _ => format!("{lo:.4} … {hi:.4}"),
        }
    };
    for (m, (panel, mode)) in panels.iter().zip(&map.modes).enumerate().take(MODES) {
        let (title, area) = panel.split_vertically(panel_title_h);
        title
            .draw(&Text::new(format!("mode {m}  (n = {})", mode.count), (10, 4), (FONT, 17)))
            .map_err(|e| PlotError::new(path, e))?;
        let tension = mode.representative.as_ref().map_or(String::new(), |r| format!(", shape at τ = {:.2} N", r.tension_n));
        title
            .draw(&Text::new(format!("a0 {}, a1 {}{tension}", fmt(mode.a0_bounds), fmt(mode.a1_bounds)), (10, 25), (FONT, 13)))
            .map_err(|e| PlotError::new(path, e))?;
        let cells: Vec<(i32, i32, f64)> =
            map.cells.iter().filter(|c| c.modes[m] > 0).map(|c| (c.ix, c.iy, (c.modes[m] as f64).log10())).collect();
        let overlay = shapes.get(m).and_then(Option::as_ref);
        draw_cells(&area, path, &map.summary, &cells, range, Scale::Log, label_size, overlay)?;
    }
    draw_colour_bar(&bar, path, range, "simulations of the mode per cell (log scale, all panels)", Scale::Log, 15)?;
    root.present().map_err(|e| PlotError::new(path, e))?;
    Ok(size)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reduce::ModeBoundaries;
    use crate::shape::LengthBasis;

    fn summary() -> MapSummary {
        MapSummary {
            format: crate::reduce::tables::MAP_FORMAT.into(),
            cell_mm: 5.0,
            x_min_mm: 20.0,
            y_min_mm: -40.0,
            nx: 10,
            ny: 16,
            order: 2,
            mirrored: false,
            rows_total: 3,
            rows_converged: 3,
            rows_failed: 0,
            failed_by_status: Default::default(),
            mode_boundaries: ModeBoundaries { a0: [-0.01, 0.0, 0.01], a1: [-0.01, 0.01] },
            mode_boundaries_source: "explicit".into(),
            cells: 3,
            tension_range_n: [1.0, 2.0],
            radius_mm: 5.0,
            length_mm: 65.0,
            run_dir: "test".into(),
            spec_hash: "h".into(),
            length_basis: LengthBasis::Rest,
            body: Default::default(),
        }
    }

    #[test]
    fn a_cell_is_drawn_square_one_mm_across_equals_one_mm_down() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("map.png");
        // The largest value (one cell) gets the top of the diverging ramp.
        let cells = [(2, 3, 1.0), (5, 9, -0.5), (7, 1, 0.2)];
        draw_heatmap(&path, &summary(), "test", "v", &cells, Scale::Symmetric).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        let top = DIVERGING[DIVERGING.len() - 1];
        // Pixels of that colour above the colour bar: the one cell.
        let hits: Vec<(u32, u32)> = img
            .enumerate_pixels()
            .filter(|p| p.2 .0 == [top.0, top.1, top.2] && p.1 < img.height() - BAR_H)
            .map(|p| (p.0, p.1))
            .collect();
        assert!(hits.len() > 400, "cell of {} px", hits.len());
        let (mut xs, mut ys): (Vec<u32>, Vec<u32>) = hits.into_iter().unzip();
        xs.sort_unstable();
        ys.sort_unstable();
        let (cw, ch) = (xs[xs.len() - 1] - xs[0] + 1, ys[ys.len() - 1] - ys[0] + 1);
        assert!(cw.abs_diff(ch) <= 1, "cell drawn {cw}×{ch} px: not square");
    }

    #[test]
    fn zero_is_white_on_the_signed_scale() {
        assert_eq!(colour(0.0, (-1.0, 1.0), Scale::Symmetric), RGBColor(247, 247, 247));
        let neg = colour(-1.0, (-1.0, 1.0), Scale::Symmetric);
        let pos = colour(1.0, (-1.0, 1.0), Scale::Symmetric);
        assert!(neg.2 > neg.0 && pos.0 > pos.2, "negative blue, positive red: {neg:?} {pos:?}");
    }
}
