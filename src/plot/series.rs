//! What a picture of hanging rods is made of: series (lines, dots, bars,
//! crosses in the body frame, mm) with their legend entries, the clamp, and
//! the page chart they are drawn on (the clamp axis down the page).

use super::canvas::{PlotError, FONT};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// The drawn clamp's half-width per unit of the body's radius at the clamp
/// r(0): the clamp grips the whole base with a margin of 0.6·r(0) on each
/// side (16 mm for the thesis's r = 5 mm rod).
pub const CLAMP_HALF_WIDTH_PER_RADIUS: f64 = 1.6;

/// Half the width of the drawn clamp, mm, for a body of radius
/// `base_radius_mm` at the clamp, so that a thick base is never drawn
/// wider than the clamp holding it.
pub fn clamp_half_width_mm(base_radius_mm: f64) -> f64 {
    CLAMP_HALF_WIDTH_PER_RADIUS * base_radius_mm
}

/// Depth of the drawn clamp bar above the clamp face, mm.
const CLAMP_DEPTH_MM: f64 = 3.0;

/// What one series of a body picture draws, in the body frame (x along
/// the clamp axis, y lateral), mm.
#[derive(Debug, Clone, PartialEq)]
pub enum Mark {
    /// Polylines `width_px` wide (one legend entry for all of them).
    Lines {
        /// The polylines, (x, y) mm each.
        paths: Vec<Vec<(f64, f64)>>,
        /// Stroke width, pixels.
        width_px: u32,
    },
    /// A filled dot of `radius_px` at (x, y) mm.
    Dot {
        /// Centre (x, y), mm.
        at: (f64, f64),
        /// Radius, pixels.
        radius_px: u32,
    },
    /// A filled bar between two corners (x, y), mm.
    Bar {
        /// Opposite corners (x, y), mm.
        corners: [(f64, f64); 2],
    },
    /// Crosses at points (x, y), mm.
    Crosses {
        /// The points, mm.
        at: Vec<(f64, f64)>,
    },
}

/// One series of a body picture: what it draws and its legend entry
/// ([`body_series`]; [`draw_bodies`] draws exactly these).
#[derive(Debug, Clone, PartialEq)]
pub struct PictureSeries {
    /// Legend text.
    pub legend: String,
    /// Colour.
    pub colour: RGBAColor,
    /// What is drawn.
    pub mark: Mark,
}

/// The clamp of a body of radius `base_radius_mm` at the clamp, as a series.
pub fn clamp_series(base_radius_mm: f64) -> PictureSeries {
    let w = clamp_half_width_mm(base_radius_mm);
    PictureSeries {
        legend: "clamp".into(),
        colour: BLACK.mix(0.5),
        mark: Mark::Bar { corners: [(-CLAMP_DEPTH_MM, -w), (0.0, w)] },
    }
}

/// The points of `series` (mm), for a picture's bounds.
pub fn series_points(series: &[PictureSeries]) -> Vec<(f64, f64)> {
    let mut pts = Vec::new();
    for s in series {
        match &s.mark {
            Mark::Lines { paths, .. } => pts.extend(paths.iter().flatten().copied()),
            Mark::Dot { at, .. } => pts.push(*at),
            Mark::Bar { corners } => pts.extend(corners),
            Mark::Crosses { at } => pts.extend(at),
        }
    }
    pts
}

/// Axis ranges (mm) enclosing `points` and the clamp at the origin with a
/// margin, equal in scale.
pub(super) fn bounds(points: &[(f64, f64)]) -> ((f64, f64), (f64, f64)) {
    let (mut x0, mut x1, mut y0, mut y1) = (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
    for &(x, y) in points {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    let span = (x1 - x0).max(y1 - y0) + 10.0;
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    ((cx - span / 2.0, cx + span / 2.0), (cy - span / 2.0, cy + span / 2.0))
}

/// A chart of the page: lateral y across, −x down, in mm.
pub type PageChart<'a, 'b> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Draws one series on a page chart (x down the page); its legend entry
/// is [`draw_legend`]'s.
pub fn draw_series_on(chart: &mut PageChart, path: &Path, s: &PictureSeries) -> Result<(), PlotError> {
    let err = |e| PlotError::new(path, e);
    let page = |&(x, y): &(f64, f64)| (y, -x);
    let colour = s.colour;
    match &s.mark {
        Mark::Lines { paths, width_px } => {
            for p in paths {
                chart.draw_series(LineSeries::new(p.iter().map(page), colour.stroke_width(*width_px))).map_err(err)?;
            }
        }
        Mark::Dot { at, radius_px } => {
            chart.draw_series(std::iter::once(Circle::new(page(at), *radius_px, colour.filled()))).map_err(err)?;
        }
        Mark::Bar { corners } => {
            chart.draw_series(std::iter::once(Rectangle::new([page(&corners[0]), page(&corners[1])], colour.filled()))).map_err(err)?;
        }
        Mark::Crosses { at } => {
            chart.draw_series(at.iter().map(|p| Cross::new(page(p), 8, colour.stroke_width(3)))).map_err(err)?;
        }
    }
    Ok(())
}

/// Height of one legend row, pixels.
pub(super) const LEGEND_ROW_PX: i32 = 20;
/// Font size of legend text, pixels.
const LEGEND_FONT_PX: u32 = 14;
/// Padding inside the legend's box, pixels.
pub(super) const LEGEND_PAD_PX: i32 = 8;
/// Width of a legend glyph, pixels.
const LEGEND_GLYPH_PX: i32 = 24;

fn legend_text_style() -> TextStyle<'static> {
    TextStyle::from((FONT, LEGEND_FONT_PX).into_font())
}

/// The size (w, h) in pixels of [`draw_legend`]'s box for `series` on `area`.
pub fn legend_size(area: &DrawingArea<BitMapBackend, plotters::coord::Shift>, series: &[PictureSeries]) -> (i32, i32) {
    let font = legend_text_style();
    let text_w = series.iter().map(|s| area.estimate_text_size(&s.legend, &font).map_or(0, |(w, _)| w as i32)).max().unwrap_or(0);
    (2 * LEGEND_PAD_PX + LEGEND_GLYPH_PX + 8 + text_w, 2 * LEGEND_PAD_PX + LEGEND_ROW_PX * series.len() as i32)
}

/// Draws the legend of `series` on `area`, a white box with its top-left
/// corner at `at` (pixels): one row per series, its glyph and its text.
pub fn draw_legend(
    area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    path: &Path,
    series: &[PictureSeries],
    at: (i32, i32),
) -> Result<(), PlotError> {
    let err = |e| PlotError::new(path, e);
    let (w, h) = legend_size(area, series);
    let (x0, y0) = at;
    area.draw(&Rectangle::new([(x0, y0), (x0 + w, y0 + h)], WHITE.filled())).map_err(err)?;
    area.draw(&Rectangle::new([(x0, y0), (x0 + w, y0 + h)], BLACK.stroke_width(1))).map_err(err)?;
    for (i, s) in series.iter().enumerate() {
        let (gx, y) = (x0 + LEGEND_PAD_PX, y0 + LEGEND_PAD_PX + LEGEND_ROW_PX * i as i32 + LEGEND_ROW_PX / 2);
        let mid = gx + LEGEND_GLYPH_PX / 2;
        let c = s.colour;
        match &s.mark {
            Mark::Lines { width_px, .. } => {
                area.draw(&PathElement::new(vec![(gx, y), (gx + LEGEND_GLYPH_PX, y)], c.stroke_width((*width_px).max(2))))
            }
            Mark::Dot { radius_px, .. } => area.draw(&Circle::new((mid, y), *radius_px, c.filled())),
            Mark::Bar { .. } => area.draw(&Rectangle::new([(gx, y - 3), (gx + LEGEND_GLYPH_PX, y + 3)], c.filled())),
            Mark::Crosses { .. } => area.draw(&Cross::new((mid, y), 6, c.stroke_width(3))),
        }
        .map_err(err)?;
        let text = Text::new(s.legend.clone(), (gx + LEGEND_GLYPH_PX + 8, y), legend_text_style().pos(Pos::new(HPos::Left, VPos::Center)));
        area.draw(&text).map_err(err)?;
    }
    Ok(())
}

/// A chart of a hanging rod in page coordinates: horizontal = y (lateral,
/// `lateral_mm`), vertical = −x (the clamp axis pointing down the page,
/// `page_vertical_mm` = range of −x), axes labelled in mm.
pub fn hanging_chart<'a, 'b>(
    root: &'a DrawingArea<BitMapBackend<'b>, plotters::coord::Shift>,
    path: &Path,
    title: &str,
    lateral_mm: (f64, f64),
    page_vertical_mm: (f64, f64),
) -> Result<PageChart<'a, 'b>, PlotError> {
    page_chart(root, path, (title, 22), ("y (mm, lateral)", lateral_mm), page_vertical_mm)
}

/// [`hanging_chart`] with its caption `(text, size in px)` and its lateral
/// axis `(label, range in mm)`.
pub(super) fn page_chart<'a, 'b>(
    root: &'a DrawingArea<BitMapBackend<'b>, plotters::coord::Shift>,
    path: &Path,
    (caption, caption_px): (&str, u32),
    (lateral_label, lateral_mm): (&str, (f64, f64)),
    page_vertical_mm: (f64, f64),
) -> Result<PageChart<'a, 'b>, PlotError> {
    let mut chart = ChartBuilder::on(root)
        .caption(caption, (FONT, caption_px))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(55)
        .build_cartesian_2d(lateral_mm.0..lateral_mm.1, page_vertical_mm.0..page_vertical_mm.1)
        .map_err(|e| PlotError::new(path, e))?;
    chart
        .configure_mesh()
        .x_desc(lateral_label)
        .y_desc("x (mm, along the clamp axis, downward)")
        .y_label_formatter(&|v| format!("{:.0}", -v + 0.0))
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 16))
        .draw()
        .map_err(|e| PlotError::new(path, e))?;
    Ok(chart)
}

/// Draws the series legend plotters keeps for `chart` at `position` in `font_size` points.
pub fn draw_series_labels<'a, 'b: 'a>(chart: &mut PageChart<'a, 'b>, path: &Path, position: SeriesLabelPosition, font_size: u32) -> Result<(), PlotError> {
    chart
        .configure_series_labels()
        .position(position)
        .label_font((FONT, font_size))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| PlotError::new(path, e))
}
