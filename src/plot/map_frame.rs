//! What every map picture shares: the frame (the mm extent a map shows at
//! equal aspect), the cells coloured by value on a scale, the page axes
//! and the colour bar.
//!
//! Axes follow the actuator drawings: the lateral tip coordinate y runs
//! across the page, the clamp axis x runs down (the rod hangs), both in mm,
//! at equal aspect: one mm across is one mm down.

use super::canvas::{PlotError, FONT};
use super::series::{clamp_half_width_mm, PageChart};
use crate::reduce::MapSummary;
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

pub(super) fn value_range(values: &[f64], scale: Scale) -> (f64, f64) {
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
pub(super) const DIVERGING: [(u8, u8, u8); 11] = [
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
pub(super) fn colour(v: f64, (lo, hi): (f64, f64), scale: Scale) -> RGBColor {
    match scale {
        Scale::Symmetric => diverging((v - lo) / (hi - lo)),
        _ => ViridisRGB.get_color_normalized(v.clamp(lo, hi) as f32, lo as f32, hi as f32),
    }
}

pub(super) type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// The mm extent a map shows (the grid, the clamp at the origin and the
/// rest tip at (L, 0)) and the pixels a map of it takes at equal aspect:
/// one mm across is one mm down.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapFrame {
    /// Clamp-axis range (down the page), mm.
    pub x_mm: (f64, f64),
    /// Lateral range (across the page), mm.
    pub y_mm: (f64, f64),
}

/// Pixels around a map's plot area: tick labels left and below.
const MAP_MARGIN: u32 = 8;

impl MapFrame {
    /// The frame of one map.
    pub fn of(summary: &MapSummary) -> Self {
        let c = summary.cell_mm;
        let (x0, y0) = (summary.x_min_mm, summary.y_min_mm);
        let (x1, y1) = (x0 + summary.nx as f64 * c, y0 + summary.ny as f64 * c);
        Self { x_mm: (x0.min(-2.0), x1.max(summary.length_mm + 2.0)), y_mm: (y0.min(-2.0), y1.max(2.0)) }
    }

    /// The smallest frame holding both (common axes for several maps).
    pub fn union(self, other: Self) -> Self {
        Self {
            x_mm: (self.x_mm.0.min(other.x_mm.0), self.x_mm.1.max(other.x_mm.1)),
            y_mm: (self.y_mm.0.min(other.y_mm.0), self.y_mm.1.max(other.y_mm.1)),
        }
    }

    /// Pixels per mm of a map whose plot is `plot_w` pixels wide.
    pub fn px_per_mm(&self, plot_w: u32) -> f64 {
        f64::from(plot_w) / (self.y_mm.1 - self.y_mm.0)
    }

    /// Size of a map area (plot plus label areas) whose plot is `plot_w`
    /// pixels wide.
    pub(super) fn area_size(&self, plot_w: u32, label_size: u32) -> (u32, u32) {
        let plot_h = (self.px_per_mm(plot_w) * (self.x_mm.1 - self.x_mm.0)).round() as u32;
        (plot_w + y_label_area(label_size) + 2 * MAP_MARGIN, plot_h + x_label_area(label_size) + 2 * MAP_MARGIN)
    }
}

/// The body's radius at the clamp r(0), mm: the radius profile's first
/// point (profiles start at s = 0), else the uniform radius.
fn base_radius_mm(summary: &MapSummary) -> f64 {
    summary.body.radius_profile_mm.first().map_or(summary.radius_mm, |p| p.1)
}

pub(super) fn x_label_area(label_size: u32) -> u32 {
    label_size * 3
}

pub(super) fn y_label_area(label_size: u32) -> u32 {
    label_size * 3 + 8
}

/// Draws cells coloured by value on `area` (sized by [`MapFrame::area_size`]
/// for `frame`), the clamp (as wide as the body's base and a margin) and
/// the rest tip. Nothing is drawn over the cells but these two marks.
#[allow(clippy::too_many_arguments)]
pub(super) fn draw_cells(
    area: &Area,
    path: &Path,
    summary: &MapSummary,
    frame: &MapFrame,
    cells: &[(i32, i32, f64)],
    range: (f64, f64),
    scale: Scale,
    label_size: u32,
) -> Result<(), PlotError> {
    let (x0, y0, c) = (summary.x_min_mm, summary.y_min_mm, summary.cell_mm);
    let mut chart = ChartBuilder::on(area)
        .margin(MAP_MARGIN)
        .x_label_area_size(x_label_area(label_size))
        .y_label_area_size(y_label_area(label_size))
        .build_cartesian_2d(frame.y_mm.0..frame.y_mm.1, -frame.x_mm.1..-frame.x_mm.0)
        .map_err(|e| PlotError::new(path, e))?;
    draw_page_axes(&mut chart, path, ("tip y (mm)", "tip x (mm, down)"), label_size, (10, 10))?;
    chart
        .draw_series(cells.iter().map(|&(ix, iy, v)| {
            let (xa, ya) = (x0 + ix as f64 * c, y0 + iy as f64 * c);
            Rectangle::new([(ya, -xa), (ya + c, -(xa + c))], colour(v, range, scale).filled())
        }))
        .map_err(|e| PlotError::new(path, e))?;
    // The clamp (a bar at the origin) and the rest tip (a circle at (L, 0)).
    let w = clamp_half_width_mm(base_radius_mm(summary));
    chart.draw_series(std::iter::once(Rectangle::new([(-w, 0.6), (w, 0.0)], BLACK.filled()))).map_err(|e| PlotError::new(path, e))?;
    chart
        .draw_series(std::iter::once(Circle::new((0.0, -summary.length_mm), 4, BLACK.stroke_width(1))))
        .map_err(|e| PlotError::new(path, e))?;
    Ok(())
}

/// Draws the axes of a page chart without grid lines: whole-mm tick labels
/// (`ticks` across and down; the clamp axis counted downward) and the axis
/// descriptions `descs` (across, down), all at `label_size`.
pub(super) fn draw_page_axes(chart: &mut PageChart, path: &Path, descs: (&str, &str), label_size: u32, ticks: (usize, usize)) -> Result<(), PlotError> {
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(ticks.0)
        .y_labels(ticks.1)
        .x_desc(descs.0)
        .y_desc(descs.1)
        .y_label_formatter(&|v| format!("{:.0}", -v + 0.0))
        .x_label_formatter(&|v| format!("{v:.0}"))
        .label_style((FONT, label_size))
        .axis_desc_style((FONT, label_size))
        .draw()
        .map_err(|e| PlotError::new(path, e))
}

/// Draws a horizontal colour bar for `range` labelled `label` (under a map
/// or a figure of maps).
pub(super) fn draw_colour_bar(area: &Area, path: &Path, range: (f64, f64), label: &str, scale: Scale, font: u32) -> Result<(), PlotError> {
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

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::reduce::{CellStats, CoefficientStats, ModeBoundaries, MODES};
    use crate::shape::LengthBasis;

    /// A map of 10 × 16 cells of 5 mm for a 65 mm rod of r = 5 mm.
    pub(crate) fn summary() -> MapSummary {
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

    /// The pixels (x, y) of exactly `colour` above the bottom `bar_h` rows
    /// (a colour bar holds every colour of the scale).
    pub(crate) fn pixels_of(img: &image::RgbImage, colour: RGBColor, bar_h: u32) -> Vec<(u32, u32)> {
        let wanted = [colour.0, colour.1, colour.2];
        img.enumerate_pixels().filter(|p| p.2 .0 == wanted && p.1 < img.height() - bar_h).map(|p| (p.0, p.1)).collect()
    }

    /// The smallest and largest x and y of `pixels`.
    pub(crate) fn bounding_box(pixels: &[(u32, u32)]) -> ((u32, u32), (u32, u32)) {
        pixels.iter().fold(((u32::MAX, 0), (u32::MAX, 0)), |((x0, x1), (y0, y1)), &(x, y)| ((x0.min(x), x1.max(x)), (y0.min(y), y1.max(y))))
    }

    /// A reached cell holding `count` simulations, all of mode `mode`.
    pub(crate) fn cell(ix: i32, iy: i32, count: i64, mode: usize) -> CellStats {
        let mut modes = [0; MODES];
        modes[mode] = count;
        let stats = CoefficientStats { p10: 0.0, p90: 0.0, min: 0.0, max: 0.0 };
        CellStats { ix, iy, x_mm: 0.0, y_mm: 0.0, count, coefficients: vec![stats; 3], modes }
    }

    #[test]
    fn zero_is_white_on_the_signed_scale() {
        assert_eq!(colour(0.0, (-1.0, 1.0), Scale::Symmetric), RGBColor(247, 247, 247));
        let neg = colour(-1.0, (-1.0, 1.0), Scale::Symmetric);
        let pos = colour(1.0, (-1.0, 1.0), Scale::Symmetric);
        assert!(neg.2 > neg.0 && pos.0 > pos.2, "negative blue, positive red: {neg:?} {pos:?}");
    }
}
