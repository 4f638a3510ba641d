//! PNG pictures of the maps (for papers; the explorer page draws its own).
//!
//! Axes follow the actuator drawings: the lateral tip coordinate y runs
//! across the page, the clamp axis x runs down (the rod hangs), both in mm,
//! at equal aspect: one mm across is one mm down.

use super::{CellStats, MapData, MapSummary, MODES};
use crate::plot::{body_series, clamp_half_width_mm, draw_series_on, register_fonts, BodyDrawing, PageChart, PlotError, FONT};
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
    fn area_size(&self, plot_w: u32, label_size: u32) -> (u32, u32) {
        let plot_h = (self.px_per_mm(plot_w) * (self.x_mm.1 - self.x_mm.0)).round() as u32;
        (plot_w + y_label_area(label_size) + 2 * MAP_MARGIN, plot_h + x_label_area(label_size) + 2 * MAP_MARGIN)
    }
}

/// The body's radius at the clamp r(0), mm: the radius profile's first
/// point (profiles start at s = 0), else the uniform radius.
fn base_radius_mm(summary: &MapSummary) -> f64 {
    summary.body.radius_profile_mm.first().map_or(summary.radius_mm, |p| p.1)
}

fn x_label_area(label_size: u32) -> u32 {
    label_size * 3
}

fn y_label_area(label_size: u32) -> u32 {
    label_size * 3 + 8
}

/// Draws cells coloured by value on `area` (sized by [`MapFrame::area_size`]
/// for `frame`), the clamp (as wide as the body's base and a margin) and
/// the rest tip. Nothing is drawn over the cells but these two marks.
#[allow(clippy::too_many_arguments)]
fn draw_cells(
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
fn draw_page_axes(chart: &mut PageChart, path: &Path, descs: (&str, &str), label_size: u32, ticks: (usize, usize)) -> Result<(), PlotError> {
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

/// Pixels around a thumbnail's plot area.
const THUMB_MARGIN: u32 = 4;

/// Ranges (lateral, clamp axis; mm) that hold `y_mm` and `x_mm` and fill a
/// plot of `w_px` × `h_px` at equal aspect (1 mm across = 1 mm down).
fn equal_aspect(y_mm: (f64, f64), x_mm: (f64, f64), w_px: f64, h_px: f64) -> ((f64, f64), (f64, f64)) {
    let px_per_mm = (w_px / (y_mm.1 - y_mm.0)).min(h_px / (x_mm.1 - x_mm.0));
    let grow = |(lo, hi): (f64, f64), px: f64| {
        let (mid, half) = (0.5 * (lo + hi), 0.5 * px / px_per_mm);
        (mid - half, mid + half)
    };
    (grow(y_mm, w_px), grow(x_mm, h_px))
}

/// Draws `body` as a thumbnail filling `area` (beside a map, never over it):
/// clamp, outline, centreline, cable and tip at equal aspect on its own
/// mm axes.
fn draw_thumbnail(area: &Area, path: &Path, body: &BodyDrawing, label_size: u32) -> Result<(), PlotError> {
    let series = body_series(std::slice::from_ref(body), &[]);
    let (mut x, mut y) = ((0.0_f64, 0.0_f64), (0.0_f64, 0.0_f64));
    for p in crate::plot::series_points(&series) {
        (x, y) = ((x.0.min(p.0), x.1.max(p.0)), (y.0.min(p.1), y.1.max(p.1)));
    }
    // A little room around the body.
    let pad = 0.04 * (x.1 - x.0).max(y.1 - y.0) + 1.0;
    let (x, y) = ((x.0 - pad, x.1 + pad), (y.0 - pad, y.1 + pad));
    let (w, h) = area.dim_in_pixel();
    let (plot_w, plot_h) = (
        f64::from(w.saturating_sub(2 * THUMB_MARGIN + y_label_area(label_size)).max(1)),
        f64::from(h.saturating_sub(2 * THUMB_MARGIN + x_label_area(label_size)).max(1)),
    );
    let (y, x) = equal_aspect(y, x, plot_w, plot_h);
    let mut chart = ChartBuilder::on(area)
        .margin(THUMB_MARGIN)
        .x_label_area_size(x_label_area(label_size))
        .y_label_area_size(y_label_area(label_size))
        .build_cartesian_2d(y.0..y.1, -x.1..-x.0)
        .map_err(|e| PlotError::new(path, e))?;
    draw_page_axes(&mut chart, path, ("y (mm)", "x (mm, down)"), label_size, (4, 6))?;
    for s in &series {
        draw_series_on(&mut chart, path, s)?;
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

/// How a heat map is laid out: the extent it shows, the width of its plot
/// and its colour range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeatmapLayout {
    /// The mm extent drawn (a map's own, or one common to several maps).
    pub frame: MapFrame,
    /// Width of the plot area, pixels (its height follows at equal aspect).
    pub plot_w_px: u32,
    /// The values at the ends of the colour scale, as given to the map
    /// (counts for a log scale); None: the cells' own range.
    pub value_range: Option<(f64, f64)>,
}

impl HeatmapLayout {
    /// A map's own layout: its frame, [`HEATMAP_PLOT_W`] wide, its own range.
    pub fn of(summary: &MapSummary) -> Self {
        Self { frame: MapFrame::of(summary), plot_w_px: HEATMAP_PLOT_W, value_range: None }
    }
}

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
    draw_heatmap_laid_out(path, summary, &HeatmapLayout::of(summary), title, colour_label, cells, scale)
}

/// [`draw_heatmap`] in a given layout (e.g. common axes and colour range
/// for several maps). Returns the image size in pixels.
pub fn draw_heatmap_laid_out(
    path: &Path,
    summary: &MapSummary,
    layout: &HeatmapLayout,
    title: &str,
    colour_label: &str,
    cells: &[(i32, i32, f64)],
    scale: Scale,
) -> Result<(u32, u32), PlotError> {
    register_fonts();
    let label_size = 17;
    let (map_w, map_h) = layout.frame.area_size(layout.plot_w_px, label_size);
    let size = (map_w, TITLE_H + map_h + BAR_H);
    let root = crate::plot::png_backend(path, size)?.into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let shown_value = |v: f64| if scale == Scale::Log { v.max(1.0).log10() } else { v };
    let shown: Vec<(i32, i32, f64)> = cells.iter().map(|&(i, j, v)| (i, j, shown_value(v))).collect();
    let values: Vec<f64> = match layout.value_range {
        Some((lo, hi)) => vec![shown_value(lo), shown_value(hi)],
        None => shown.iter().map(|c| c.2).collect(),
    };
    let range = value_range(&values, scale);
    let (head, body) = root.split_vertically(TITLE_H);
    head.draw(&Text::new(title.to_string(), (12, 12), (FONT, 22))).map_err(|e| PlotError::new(path, e))?;
    let (map_area, bar) = body.split_vertically(map_h);
    draw_cells(&map_area, path, summary, &layout.frame, &shown, range, scale, label_size)?;
    draw_colour_bar(&bar, path, range, colour_label, scale, 15)?;
    root.present().map_err(|e| PlotError::new(path, e))?;
    Ok(size)
}

/// Above this share of reached cells holding a single simulation, a map
/// reads as speckle rather than regions.
pub const SPARSE_SINGLE_SHARE: f64 = 0.5;
/// Below this share of the reach's bounding box reached, a map reads as
/// scattered dots.
pub const SPARSE_FILLED_SHARE: f64 = 0.1;
/// Largest cell size a sparse map's note suggests, in multiples of its own.
const MAX_SUGGESTED_FACTOR: i64 = 20;

/// How densely a map's cells are reached: a map whose cells mostly hold
/// one simulation, or fill little of the reach's bounding box, shows
/// speckle (e.g. 1 mm cells over a tapered 360 mm body's reach) and wants
/// larger cells (`--cell-mm`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Density {
    /// Cell size, mm.
    pub cell_mm: f64,
    /// Reached cells.
    pub cells: usize,
    /// Share of the reached cells holding one simulation.
    pub single_share: f64,
    /// Reached cells over the cells of the reach's bounding box.
    pub filled_share: f64,
}

impl Density {
    /// The density of the map with `summary` and `cells`.
    pub fn of(summary: &MapSummary, cells: &[CellStats]) -> Self {
        Self::coarsened(summary, cells, 1)
    }

    /// The density the map would have with cells `factor` times larger,
    /// from its own cells: grids lie on multiples of the cell size, so a
    /// cell of `factor`·c is the union of `factor`² cells of c.
    fn coarsened(summary: &MapSummary, cells: &[CellStats], factor: i64) -> Self {
        let c = summary.cell_mm;
        // The grid's origin in cells (a multiple of the cell size).
        let (ox, oy) = ((summary.x_min_mm / c).round() as i64, (summary.y_min_mm / c).round() as i64);
        let mut merged: std::collections::HashMap<(i64, i64), i64> = std::collections::HashMap::new();
        for cell in cells.iter().filter(|cell| cell.count > 0) {
            let key = ((ox + i64::from(cell.ix)).div_euclid(factor), (oy + i64::from(cell.iy)).div_euclid(factor));
            *merged.entry(key).or_default() += cell.count;
        }
        let singles = merged.values().filter(|&&n| n == 1).count();
        let extent = |f: fn(&(i64, i64)) -> i64| merged.keys().map(f).fold((i64::MAX, i64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let ((x0, x1), (y0, y1)) = (extent(|k| k.0), extent(|k| k.1));
        let boxed = if merged.is_empty() { 1.0 } else { ((x1 - x0 + 1) * (y1 - y0 + 1)) as f64 };
        let n = merged.len();
        Self {
            cell_mm: c * factor as f64,
            cells: n,
            single_share: if n == 0 { 0.0 } else { singles as f64 / n as f64 },
            filled_share: n as f64 / boxed,
        }
    }

    /// Whether the map shows speckle rather than regions.
    pub fn is_sparse(&self) -> bool {
        self.cells > 0 && (self.single_share > SPARSE_SINGLE_SHARE || self.filled_share < SPARSE_FILLED_SHARE)
    }

    /// The smallest cell size, a whole multiple of the map's, at which the
    /// map would no longer be sparse (None: not within 20 times its cell).
    pub fn suggested_cell_mm(summary: &MapSummary, cells: &[CellStats]) -> Option<f64> {
        let found = (2..=MAX_SUGGESTED_FACTOR).map(|f| Self::coarsened(summary, cells, f)).find(|d| !d.is_sparse());
        // Rounded, so that 3 × 0.1 mm reads 0.3.
        found.map(|d| (d.cell_mm * 1e6).round() / 1e6)
    }

    /// A sentence saying that the map with `summary` and `cells` is sparse
    /// and which `--cell-mm` to reduce again with; None when it is not sparse.
    pub fn sparse_note(summary: &MapSummary, cells: &[CellStats]) -> Option<String> {
        let d = Self::of(summary, cells);
        if !d.is_sparse() {
            return None;
        }
        let advice = match Self::suggested_cell_mm(summary, cells) {
            Some(mm) => format!("reduce again with --cell-mm {} for regions instead of speckle", crate::io::fmt_num(mm)),
            None => format!(
                "even {} mm cells stay sparse: sweep more levels or tensions, or reduce again with a much larger --cell-mm",
                crate::io::fmt_num(d.cell_mm * MAX_SUGGESTED_FACTOR as f64)
            ),
        };
        Some(format!(
            "sparse map: at {} mm cells {:.0} % of the {} reached cells hold a single simulation and they fill {:.0} % of the reach's bounding box; {advice}",
            crate::io::fmt_num(d.cell_mm),
            100.0 * d.single_share,
            d.cells,
            100.0 * d.filled_share
        ))
    }
}

/// Width of one mode panel's map plot in modes.png, pixels.
const MODE_MAP_PLOT_W: u32 = 340;
/// Width of the representative's thumbnail beside each mode map, pixels.
const MODE_THUMB_W: u32 = 170;
/// Tick-label size in modes.png.
const MODE_LABEL_SIZE: u32 = 14;
/// Tick-label size of the thumbnails.
const THUMB_LABEL_SIZE: u32 = 11;
/// Height of a mode panel's title strip, pixels.
const MODE_TITLE_H: u32 = 46;
/// Gap right of each panel, pixels.
const MODE_GAP: u32 = 10;
/// Heights of the header and of the colour-bar strip of modes.png, pixels.
const MODES_HEAD_H: u32 = 56;
const MODES_BAR_H: u32 = 80;

/// The layout of modes.png for a map: 4 × 3 panels, each a title strip
/// over the mode's map with the representative's thumbnail beside it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModesLayout {
    /// Size of one map area (plot and its labels), pixels.
    map_px: (u32, u32),
    /// Size of one panel, pixels.
    panel_px: (u32, u32),
    /// Size of the whole image, pixels.
    pub size_px: (u32, u32),
    /// Pixels per mm of every panel's map.
    pub px_per_mm: f64,
}

impl ModesLayout {
    /// The layout of modes.png of the map with `summary`.
    pub fn of(summary: &MapSummary) -> Self {
        let frame = MapFrame::of(summary);
        let map_px = frame.area_size(MODE_MAP_PLOT_W, MODE_LABEL_SIZE);
        let panel_px = (map_px.0 + MODE_THUMB_W + MODE_GAP, map_px.1 + MODE_TITLE_H);
        Self {
            map_px,
            panel_px,
            size_px: (3 * panel_px.0, MODES_HEAD_H + 4 * panel_px.1 + MODES_BAR_H),
            px_per_mm: frame.px_per_mm(MODE_MAP_PLOT_W),
        }
    }
}

/// The 12 characteristic-mode maps in one figure (a_0 ranges down, a_1
/// ranges across), all at equal aspect in the map's frame on one log
/// colour scale. Each mode's representative shape is drawn as a thumbnail
/// beside its map, on its own mm axes: drawn over the map it would hide
/// the very cells it explains (its tip lies in them, and a long body such
/// as the tentacle crosses much of its reach). A map of several cables
/// (`cables`) captions each shape with every cable's tension. Returns the
/// image size.
pub fn draw_modes(
    path: &Path,
    map: &MapData,
    shapes: &[Option<BodyDrawing>],
    cables: Option<&super::MapCables>,
) -> Result<(u32, u32), PlotError> {
    register_fonts();
    let layout = ModesLayout::of(&map.summary);
    let frame = MapFrame::of(&map.summary);
    let root = crate::plot::png_backend(path, layout.size_px)?.into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let (head, rest) = root.split_vertically(MODES_HEAD_H);
    let (body, bar) = rest.split_vertically(4 * layout.panel_px.1);
    head.draw(&Text::new(
        "Characteristic modes: a0 in 4 ranges (rows) × a1 in 3 (columns); colour = simulations of the mode per cell",
        (12, 8),
        (FONT, 20),
    ))
    .map_err(|e| PlotError::new(path, e))?;
    head.draw(&Text::new(
        format!(
            "beside each map, on its own mm axes: the simulation nearest the mode's median (a0, a1), body blue, cable red, clamp grey; a_i in mm⁻¹, {}",
            map.summary.length_basis.describe()
        ),
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
        let (title, area) = panel.split_vertically(MODE_TITLE_H);
        title
            .draw(&Text::new(format!("mode {m}  (n = {})", mode.count), (10, 4), (FONT, 17)))
            .map_err(|e| PlotError::new(path, e))?;
        let tension = mode.representative.as_ref().map_or(String::new(), |r| {
            let tensions = cables.map_or_else(|| format!("{:.2} N", r.tension_n), |c| c.tensions_text(r.routing_id));
            format!(", shape at τ = {tensions}")
        });
        title
            .draw(&Text::new(format!("a0 {}, a1 {}{tension}", fmt(mode.a0_bounds), fmt(mode.a1_bounds)), (10, 25), (FONT, 13)))
            .map_err(|e| PlotError::new(path, e))?;
        let (map_area, beside) = area.split_horizontally(layout.map_px.0);
        let (thumb, _gap) = beside.split_horizontally(MODE_THUMB_W);
        let cells: Vec<(i32, i32, f64)> =
            map.cells.iter().filter(|c| c.modes[m] > 0).map(|c| (c.ix, c.iy, (c.modes[m] as f64).log10())).collect();
        draw_cells(&map_area, path, &map.summary, &frame, &cells, range, Scale::Log, MODE_LABEL_SIZE)?;
        if let Some(shape) = shapes.get(m).and_then(Option::as_ref) {
            draw_thumbnail(&thumb, path, shape, THUMB_LABEL_SIZE)?;
        }
    }
    draw_colour_bar(&bar, path, range, "simulations of the mode per cell (log scale, all panels)", Scale::Log, 15)?;
    root.present().map_err(|e| PlotError::new(path, e))?;
    Ok(layout.size_px)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::reduce::{CoefficientStats, ModeBoundaries, ModeStats};
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
        let hits = pixels_of(&img, RGBColor(top.0, top.1, top.2), BAR_H);
        assert!(hits.len() > 400, "cell of {} px", hits.len());
        let (x, y) = bounding_box(&hits);
        let (cw, ch) = (x.1 - x.0 + 1, y.1 - y.0 + 1);
        assert!(cw.abs_diff(ch) <= 1, "cell drawn {cw}×{ch} px: not square");
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
    fn the_clamp_of_a_tapered_body_is_drawn_from_its_base_radius() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("map.png");
        let mut s = summary();
        s.body.radius_profile_mm = vec![(0.0, 15.4), (65.0, 6.4)];
        draw_heatmap(&path, &s, "test", "v", &[(8, 2, 1.0)], Scale::Linear).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        // The clamp is the longest black run across a row short of the
        // x axis (which spans the whole plot).
        let plot_w = HEATMAP_PLOT_W as usize;
        let clamp_px = (0..img.height() / 2)
            .flat_map(|y| {
                let row: Vec<bool> = (0..img.width()).map(|x| img.get_pixel(x, y).0 == [0, 0, 0]).collect();
                row.split(|black| !black).map(<[bool]>::len).collect::<Vec<_>>()
            })
            .filter(|&run| run < plot_w * 9 / 10)
            .max()
            .unwrap();
        let px_per_mm = MapFrame::of(&s).px_per_mm(HEATMAP_PLOT_W);
        let expected = 2.0 * clamp_half_width_mm(15.4) * px_per_mm;
        assert!((clamp_px as f64 - expected).abs() <= 3.0, "clamp {clamp_px} px wide, r(0) = 15.4 mm wants {expected:.0} px");
    }

    #[test]
    fn mode_thumbnails_never_cover_the_map_cells() {
        let s = summary();
        // Mode 0 reaches every cell, under where a hanging body would be drawn in the map's frame.
        let cells: Vec<CellStats> = (0..10).flat_map(|ix| (0..16).map(move |iy| cell(ix, iy, 2, 0))).collect();
        let modes: Vec<ModeStats> = (0..MODES)
            .map(|m| ModeStats {
                mode: m,
                a0_range: m / 3,
                a1_range: m % 3,
                a0_bounds: (f64::NEG_INFINITY, 0.0),
                a1_bounds: (0.0, f64::INFINITY),
                count: if m == 0 { 320 } else { 0 },
                cells: if m == 0 { 160 } else { 0 },
                representative: None,
            })
            .collect();
        let map = MapData { summary: s, cells, modes, designs: Vec::new() };
        let body_colour = RGBColor(10, 160, 20);
        let mut shapes = vec![None; MODES];
        shapes[0] = Some(crate::plot::tests::hanging(Vec::new(), body_colour));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("modes.png");
        draw_modes(&path, &map, &shapes, None).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        let cell_colour = colour(2f64.log10(), (0.0, 2f64.log10()), Scale::Log);
        let ((x0, x1), (y0, y1)) = bounding_box(&pixels_of(&img, cell_colour, MODES_BAR_H));
        let body = pixels_of(&img, body_colour, MODES_BAR_H);
        assert!(body.len() > 100, "the thumbnail is drawn ({} px)", body.len());
        let covering = body.iter().filter(|&&(x, y)| (x0..=x1).contains(&x) && (y0..=y1).contains(&y)).count();
        assert_eq!(covering, 0, "{covering} px of the body drawn over the cells ({x0}…{x1} × {y0}…{y1})");
    }

    #[test]
    fn a_sparse_map_says_so_and_suggests_a_cell_size() {
        let s = summary();
        // One simulation in each cell: speckle; merged by 2 (10 mm cells) every cell holds 4.
        let speckle: Vec<CellStats> = (0..10).flat_map(|ix| (0..16).map(move |iy| cell(ix, iy, 1, 0))).collect();
        let d = Density::of(&s, &speckle);
        assert!(d.is_sparse() && d.single_share == 1.0 && d.filled_share == 1.0, "{d:?}");
        assert_eq!(Density::suggested_cell_mm(&s, &speckle), Some(10.0));
        let note = Density::sparse_note(&s, &speckle).unwrap();
        assert!(note.contains("100 % of the 160 reached cells hold a single simulation") && note.contains("--cell-mm 10"), "{note}");
        // Two busy cells at opposite corners fill 1 % of their box.
        let scattered = [cell(0, 0, 50, 0), cell(9, 15, 50, 0)];
        assert!(Density::of(&s, &scattered).filled_share < SPARSE_FILLED_SHARE);
        assert!(Density::sparse_note(&s, &scattered).is_some_and(|n| n.contains("fill 1 %")));
        // Three simulations per cell everywhere: no note.
        let dense: Vec<CellStats> = (0..10).flat_map(|ix| (0..16).map(move |iy| cell(ix, iy, 3, 0))).collect();
        assert_eq!(Density::sparse_note(&s, &dense), None);
    }

    #[test]
    fn zero_is_white_on_the_signed_scale() {
        assert_eq!(colour(0.0, (-1.0, 1.0), Scale::Symmetric), RGBColor(247, 247, 247));
        let neg = colour(-1.0, (-1.0, 1.0), Scale::Symmetric);
        let pos = colour(1.0, (-1.0, 1.0), Scale::Symmetric);
        assert!(neg.2 > neg.0 && pos.0 > pos.2, "negative blue, positive red: {neg:?} {pos:?}");
    }
}
