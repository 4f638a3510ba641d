//! Pictures: PNG drawings of actuators, shared by `simulate`, reduce and
//! design. The font is compiled into the binary (DejaVu Sans, see
//! `assets/README.md`), so pictures never depend on the machine's fonts.

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
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
    pub fn of_body(sim: &crate::model::Simulation, actuator: &crate::model::Actuator, label: String, colour: RGBColor) -> Self {
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

/// Axis ranges (mm) enclosing every drawing with a margin, equal in scale.
fn bounds(bodies: &[BodyDrawing], extra: &[(f64, f64)]) -> ((f64, f64), (f64, f64)) {
    let mut xs = vec![0.0];
    let mut ys = vec![0.0];
    for b in bodies {
        let (l, r) = b.outline();
        for &(x, y) in l.iter().chain(&r) {
            xs.push(x);
            ys.push(y);
        }
    }
    for &(x, y) in extra {
        xs.push(x);
        ys.push(y);
    }
    let (x0, x1) = xs.iter().fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    let (y0, y1) = ys.iter().fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    let span = (x1 - x0).max(y1 - y0) + 10.0;
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    ((cx - span / 2.0, cx + span / 2.0), (cy - span / 2.0, cy + span / 2.0))
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
) -> Result<ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>, PlotError> {
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

/// Draws deformed actuators (body outline, channel/cable, tip marker) with
/// the clamp axis pointing down the page (the rod hangs), axes in mm.
/// `targets` adds crosses (e.g. target tips).
pub fn draw_bodies(path: &Path, title: &str, bodies: &[BodyDrawing], targets: &[(f64, f64)]) -> Result<(), PlotError> {
    register_fonts();
    let root = BitMapBackend::new(path, (800, 800)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let ((x0, x1), (y0, y1)) = bounds(bodies, targets);
    let mut chart = hanging_chart(&root, path, title, (y0, y1), (-x1, -x0))?;
    let page = |pts: &[(f64, f64)]| -> Vec<(f64, f64)> { pts.iter().map(|&(x, y)| (y, -x)).collect() };
    // The clamp.
    chart
        .draw_series(std::iter::once(Rectangle::new([(-8.0, 3.0), (8.0, 0.0)], BLACK.mix(0.5).filled())))
        .map_err(|e| PlotError::new(path, e))?;
    for b in bodies {
        let (left, right) = b.outline();
        let colour = b.colour;
        chart
            .draw_series(LineSeries::new(page(&left), colour.stroke_width(2)))
            .map_err(|e| PlotError::new(path, e))?
            .label(b.label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
        chart.draw_series(LineSeries::new(page(&right), colour.stroke_width(2))).map_err(|e| PlotError::new(path, e))?;
        // Tip cross-section closes the outline.
        if let (Some(&l), Some(&r)) = (left.last(), right.last()) {
            chart.draw_series(LineSeries::new(page(&[l, r]), colour.stroke_width(2))).map_err(|e| PlotError::new(path, e))?;
        }
        chart
            .draw_series(LineSeries::new(page(&b.centreline), colour.mix(0.4).stroke_width(1)))
            .map_err(|e| PlotError::new(path, e))?;
        for cable in std::iter::once(&b.cable).chain(&b.further_cables) {
            chart.draw_series(LineSeries::new(page(cable), RED.stroke_width(2))).map_err(|e| PlotError::new(path, e))?;
        }
        if let Some(&(x, y)) = b.centreline.last() {
            chart.draw_series(std::iter::once(Circle::new((y, -x), 5, colour.filled()))).map_err(|e| PlotError::new(path, e))?;
        }
    }
    if !targets.is_empty() {
        chart
            .draw_series(targets.iter().map(|&(x, y)| Cross::new((y, -x), 8, BLUE.stroke_width(3))))
            .map_err(|e| PlotError::new(path, e))?
            .label("target tip")
            .legend(|(x, y)| Cross::new((x + 10, y), 6, BLUE.stroke_width(3)));
    }
    chart
        .configure_series_labels()
        // Bodies hang down from the clamp at the top centre: the top corner is free.
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 14))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| PlotError::new(path, e))?;
    root.present().map_err(|e| PlotError::new(path, e))?;
    Ok(())
}

/// Two-view drawings of spatial (several-cable) actuators.
pub mod spatial;
