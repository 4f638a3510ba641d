//! Pictures: PNG drawings of actuators, shared by `simulate`, reduce and
//! design. The font is compiled into the binary (DejaVu Sans, see
//! `assets/README.md`), so pictures never depend on the machine's fonts.

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;
use std::path::Path;
use std::sync::Once;

/// Font family name every figure uses.
pub const FONT: &str = "sans-serif";

static FONT_BYTES: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Registers the bundled font with plotters (idempotent).
pub fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        for style in [FontStyle::Normal, FontStyle::Bold, FontStyle::Italic, FontStyle::Oblique] {
            if plotters::style::register_font(FONT, style, FONT_BYTES).is_err() {
                panic!("the bundled font assets/DejaVuSans.ttf is not valid TrueType");
            }
        }
    });
}

/// Error of a drawing backend, as text (plotters' errors are generic).
#[derive(Debug, thiserror::Error)]
#[error("drawing {path}: {message}")]
pub struct PlotError {
    /// File being drawn.
    pub path: String,
    /// What went wrong.
    pub message: String,
}

impl PlotError {
    /// Wraps any displayable backend error for `path`.
    pub fn new(path: &Path, e: impl std::fmt::Display) -> Self {
        Self { path: path.display().to_string(), message: e.to_string() }
    }
}

/// The bitmap a PNG is drawn into at `path`, after the checks every output
/// file gets ([`crate::io::write_atomic`]'s): never over a symbolic link,
/// FIFO, device or directory, never inside a sweep run directory. plotters
/// writes the file itself when the drawing is presented, so the checks
/// come first here.
pub fn png_backend(path: &Path, size_px: (u32, u32)) -> Result<BitMapBackend<'_>, PlotError> {
    crate::io::check_regular_or_new(path).map_err(|e| PlotError::new(path, e))?;
    crate::io::check_outside_run_dir(path, "the picture").map_err(|e| PlotError::new(path, e))?;
    Ok(BitMapBackend::new(path, size_px))
}

/// One deformed actuator to draw.
#[derive(Debug, Clone)]
pub struct BodyDrawing {
    /// Centreline points (x, y), mm, clamp first.
    pub centreline: Vec<(f64, f64)>,
    /// Frame angle φ at each centreline point, rad (cross-sections ⊥ frame axis).
    pub frame_angle_rad: Vec<f64>,
    /// Cable path (x, y), mm, from the clamp to where the cable is knotted.
    pub cable: Vec<(f64, f64)>,
    /// Paths of the further cables of a several-cable actuator (x, y), mm,
    /// drawn like `cable` (empty for one cable).
    pub further_cables: Vec<Vec<(f64, f64)>>,
    /// Rod radius, mm.
    pub radius_mm: f64,
    /// Radius r(s) at each centreline point, mm, for a non-uniform body;
    /// empty: `radius_mm` everywhere.
    pub radii_mm: Vec<f64>,
    /// Legend label.
    pub label: String,
    /// Line colour.
    pub colour: RGBColor,
}

impl BodyDrawing {
    /// The drawing of a simulated body: its centreline, outline at ±`radius_mm`
    /// about it and the cable path.
    pub fn of_simulation(sim: &crate::model::Simulation, radius_mm: f64, label: String, colour: RGBColor) -> Self {
        BodyDrawing {
            centreline: sim.centreline.iter().map(|c| (c.x_mm, c.y_mm)).collect(),
            frame_angle_rad: sim.centreline.iter().map(|c| c.frame_angle_rad).collect(),
            // The cable ends at its anchor: the solver leaves the points beyond it NaN.
            cable: sim.centreline.iter().filter(|c| c.cable_x_mm.is_finite()).map(|c| (c.cable_x_mm, c.cable_y_mm)).collect(),
            further_cables: Vec::new(),
            radius_mm,
            radii_mm: Vec::new(),
            label,
            colour,
        }
    }

    /// The drawing of a simulated `actuator`: the outline follows its
    /// radius r(s) (a tapered or segmented body), else ±`radius_mm`.
    pub fn of_body(sim: &crate::model::Simulation, actuator: &crate::model::Rod, label: String, colour: RGBColor) -> Self {
        let mut d = Self::of_simulation(sim, actuator.radius_mm, label, colour);
        if let Ok(Some(body)) = crate::model::Body::of(actuator) {
            d.radii_mm = sim.centreline.iter().map(|c| body.radius_at(c.s_mm)).collect();
        }
        d
    }

    /// The body outline at ±r(s) about the centreline, as two polylines.
    pub fn outline(&self) -> (Vec<(f64, f64)>, Vec<(f64, f64)>) {
        let side = |sign: f64| -> Vec<(f64, f64)> {
            self.centreline
                .iter()
                .zip(&self.frame_angle_rad)
                .enumerate()
                .map(|(i, (&(x, y), &phi))| {
                    let r = self.radii_mm.get(i).copied().unwrap_or(self.radius_mm);
                    (x - sign * r * phi.sin(), y + sign * r * phi.cos())
                })
                .collect()
        };
        (side(1.0), side(-1.0))
    }
}

/// The drawn clamp's half-width per unit of the body's radius at the clamp
/// r(0): the clamp grips the whole base with a margin of 0.6·r(0) on each
/// side (16 mm for the thesis's r = 5 mm rod, as before).
pub const CLAMP_HALF_WIDTH_PER_RADIUS: f64 = 1.6;

/// Half the width of the drawn clamp, mm, for a body of radius
/// `base_radius_mm` at the clamp, so that a thick base is never drawn
/// wider than the clamp holding it.
pub fn clamp_half_width_mm(base_radius_mm: f64) -> f64 {
    CLAMP_HALF_WIDTH_PER_RADIUS * base_radius_mm
}

/// Depth of the drawn clamp bar above the clamp face, mm.
const CLAMP_DEPTH_MM: f64 = 3.0;

impl BodyDrawing {
    /// The radius at the clamp r(0), mm.
    pub fn base_radius_mm(&self) -> f64 {
        self.radii_mm.first().copied().unwrap_or(self.radius_mm)
    }

    /// Whether the body is drawn as a line (no radius anywhere, e.g. a
    /// target shape): its outline would coincide with its centreline.
    fn is_line(&self) -> bool {
        self.radius_mm == 0.0 && self.radii_mm.iter().all(|&r| r == 0.0)
    }

    /// The body's name in the legend: its label up to the first
    /// parenthesis or comma ("achieved body (outline at ±r), …" → "achieved body").
    fn name(&self) -> &str {
        let name = self.label[..self.label.find([',', '(']).unwrap_or(self.label.len())].trim();
        if name.is_empty() {
            "body"
        } else {
            name
        }
    }
}

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

/// Every series a picture of `bodies` and `targets` (tip crosses) draws,
/// each with its legend entry: the clamp (sized by the first body's
/// r(0)), then per body its outline, centreline, cable(s) and tip dot,
/// then the targets. Empty paths are left out, so every series listed is
/// drawn and every drawn series is listed.
pub fn body_series(bodies: &[BodyDrawing], targets: &[(f64, f64)]) -> Vec<PictureSeries> {
    let mut series = vec![clamp_series(bodies.first().map_or(0.0, BodyDrawing::base_radius_mm))];
    for b in bodies {
        let colour = b.colour.to_rgba();
        let name = b.name();
        if !b.is_line() {
            let (left, right) = b.outline();
            // The tip cross-section closes the outline.
            let tip: Vec<(f64, f64)> = left.last().into_iter().chain(right.last()).copied().collect();
            let paths: Vec<Vec<(f64, f64)>> = [left, right, tip].into_iter().filter(|p| p.len() > 1).collect();
            if !paths.is_empty() {
                series.push(PictureSeries { legend: b.label.clone(), colour, mark: Mark::Lines { paths, width_px: 2 } });
            }
        }
        if b.centreline.len() > 1 {
            // A line body is its centreline: it carries the body's label.
            let (legend, colour, width_px) =
                if b.is_line() { (b.label.clone(), colour, 2) } else { (format!("{name}: centreline"), b.colour.mix(0.4), 1) };
            series.push(PictureSeries { legend, colour, mark: Mark::Lines { paths: vec![b.centreline.clone()], width_px } });
        }
        let cables: Vec<&Vec<(f64, f64)>> = std::iter::once(&b.cable).chain(&b.further_cables).filter(|c| c.len() > 1).collect();
        let several = cables.len() > 1;
        for (i, cable) in cables.into_iter().enumerate() {
            let legend = if several { format!("{name}: cable {}", i + 1) } else { format!("{name}: cable") };
            series.push(PictureSeries { legend, colour: RED.to_rgba(), mark: Mark::Lines { paths: vec![cable.clone()], width_px: 2 } });
        }
        if let Some(&at) = b.centreline.last() {
            series.push(PictureSeries { legend: format!("{name}: tip"), colour, mark: Mark::Dot { at, radius_px: 5 } });
        }
    }
    if !targets.is_empty() {
        series.push(PictureSeries { legend: "target tip".into(), colour: BLUE.to_rgba(), mark: Mark::Crosses { at: targets.to_vec() } });
    }
    series
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
fn bounds(points: &[(f64, f64)]) -> ((f64, f64), (f64, f64)) {
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
const LEGEND_ROW_PX: i32 = 20;
/// Font size of legend text, pixels.
const LEGEND_FONT_PX: u32 = 14;
/// Padding inside the legend's box, pixels.
const LEGEND_PAD_PX: i32 = 8;
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
    let mut chart = ChartBuilder::on(root)
        .caption(title, (FONT, 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(55)
        .build_cartesian_2d(lateral_mm.0..lateral_mm.1, page_vertical_mm.0..page_vertical_mm.1)
        .map_err(|e| PlotError::new(path, e))?;
    chart
        .configure_mesh()
        .x_desc("y (mm, lateral)")
        .y_desc("x (mm, along the clamp axis, downward)")
        .y_label_formatter(&|v| format!("{:.0}", -v + 0.0))
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 16))
        .draw()
        .map_err(|e| PlotError::new(path, e))?;
    Ok(chart)
}

/// Draws deformed actuators (body outline, centreline, cable, tip dot,
/// clamp sized by the body's radius at the clamp) with the clamp axis
/// pointing down the page (the rod hangs), axes in mm, and under the chart
/// a legend of every series ([`body_series`]). `targets` adds crosses
/// (e.g. target tips).
pub fn draw_bodies(path: &Path, title: &str, bodies: &[BodyDrawing], targets: &[(f64, f64)]) -> Result<(), PlotError> {
    register_fonts();
    let series = body_series(bodies, targets);
    // The legend goes under the chart, where it covers nothing.
    let legend_h = LEGEND_ROW_PX as u32 * series.len() as u32 + 2 * LEGEND_PAD_PX as u32 + 10;
    let root = png_backend(path, (800, 800 + legend_h))?.into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let (plot, below) = root.split_vertically(800);
    let ((x0, x1), (y0, y1)) = bounds(&series_points(&series));
    let mut chart = hanging_chart(&plot, path, title, (y0, y1), (-x1, -x0))?;
    for s in &series {
        draw_series_on(&mut chart, path, s)?;
    }
    // Left-aligned with the chart's plot (its y label area is 55 px after a 15 px margin).
    draw_legend(&below, path, &series, (70, 0))?;
    root.present().map_err(|e| PlotError::new(path, e))?;
    Ok(())
}

/// Two-view drawings of spatial (several-cable) actuators.
pub mod spatial;

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A straight body hanging 60 mm with a cable beside its centreline.
    pub(crate) fn hanging(radii_mm: Vec<f64>, colour: RGBColor) -> BodyDrawing {
        let n = 13;
        let xs: Vec<f64> = (0..n).map(|i| 60.0 * i as f64 / (n - 1) as f64).collect();
        BodyDrawing {
            centreline: xs.iter().map(|&x| (x, 0.0)).collect(),
            frame_angle_rad: vec![0.0; n],
            cable: xs.iter().map(|&x| (x, 2.0)).collect(),
            further_cables: Vec::new(),
            radius_mm: 5.0,
            radii_mm,
            label: "body (outline at ±r)".into(),
            colour,
        }
    }

    #[test]
    fn every_drawn_series_has_a_legend_entry_centreline_and_tip_included() {
        let series = body_series(&[hanging(Vec::new(), BLUE)], &[(50.0, 3.0)]);
        let legends: Vec<&str> = series.iter().map(|s| s.legend.as_str()).collect();
        assert_eq!(legends, ["clamp", "body (outline at ±r)", "body: centreline", "body: cable", "body: tip", "target tip"]);
        assert!(matches!(series[4].mark, Mark::Dot { at: (x, _), .. } if x == 60.0), "the tip dot sits at the tip");
        // A body without a cable lists none (nothing drawn, nothing listed).
        let mut bare = hanging(Vec::new(), BLUE);
        bare.cable.clear();
        assert!(body_series(&[bare], &[]).iter().all(|s| !s.legend.contains("cable")));
    }

    #[test]
    fn the_legend_under_the_picture_shows_the_tip_dot() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("body.png");
        let colour = RGBColor(10, 160, 20);
        draw_bodies(&path, "t", &[hanging(Vec::new(), colour)], &[]).unwrap();
        let img = image::open(&path).unwrap().to_rgb8();
        // The legend lies under the 800 px chart, covering none of it. A
        // line glyph is 2 px tall, the tip dot 10.
        assert!(img.height() >= 800 + 5 * 20, "no room under the chart for the five legend rows");
        let tallest = (0..img.width())
            .map(|x| (800..img.height()).filter(|&y| img.get_pixel(x, y).0 == [colour.0, colour.1, colour.2]).count())
            .max()
            .unwrap_or(0);
        assert!(tallest >= 8, "no tip dot in the legend: tallest run of the body colour {tallest} px");
    }

    #[test]
    fn the_clamp_is_as_wide_as_the_body_base_and_a_margin() {
        let tapered = hanging(vec![15.4; 13], BLUE);
        let Mark::Bar { corners: [(_, y0), (_, y1)] } = body_series(&[tapered], &[])[0].mark else { panic!("the clamp is a bar") };
        assert!((y1 - y0 - 2.0 * 1.6 * 15.4).abs() < 1e-9, "clamp {} mm wide for r(0) = 15.4 mm", y1 - y0);
        assert_eq!(clamp_half_width_mm(5.0), 8.0, "the thesis rod keeps its 16 mm clamp");
    }
}
