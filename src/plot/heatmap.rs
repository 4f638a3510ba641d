//! A map of one value per cell with a colour bar (the map directory's
//! count, coefficient and spread pictures; the study page's reach maps).

use super::canvas::{png_backend, register_fonts, PlotError, FONT};
use super::map_frame::{draw_cells, draw_colour_bar, value_range, MapFrame, Scale};
use crate::reduce::MapSummary;
use plotters::prelude::*;
use std::path::Path;

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
    let root = png_backend(path, size)?.into_drawing_area();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::clamp_half_width_mm;
    use crate::plot::map_frame::tests::{bounding_box, pixels_of, summary};
    use crate::plot::map_frame::DIVERGING;

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
}
