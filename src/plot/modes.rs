//! modes.png: the twelve characteristic-mode maps of a map, each with its
//! representative shape drawn beside it.

use super::body::{body_series, BodyDrawing};
use super::canvas::{png_backend, register_fonts, PlotError, FONT};
use super::map_frame::{draw_cells, draw_colour_bar, draw_page_axes, value_range, x_label_area, y_label_area, Area, MapFrame, Scale};
use super::series::{draw_series_on, series_points};
use crate::reduce::{MapCables, MapData, MapSummary, MODES};
use plotters::prelude::*;
use std::path::Path;

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
    for p in series_points(&series) {
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
    cables: Option<&MapCables>,
) -> Result<(u32, u32), PlotError> {
    register_fonts();
    let layout = ModesLayout::of(&map.summary);
    let frame = MapFrame::of(&map.summary);
    let root = png_backend(path, layout.size_px)?.into_drawing_area();
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
mod tests {
    use super::*;
    use crate::plot::map_frame::colour;
    use crate::plot::map_frame::tests::{bounding_box, cell, pixels_of, summary};
    use crate::reduce::{CellStats, ModeStats};

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
}
