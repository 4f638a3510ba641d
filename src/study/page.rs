//! The study page, `index.html`: the comparison table, then every
//! variant's reach on common axes and modes at one scale, side by side.

use super::comparison::Comparison;
use super::error::StudyError;
use crate::reduce::{CellStats, MapSummary, MODES};
use std::path::Path;

/// The page showing the variants' maps side by side.
pub const PAGE_FILE: &str = "index.html";

/// Width of the plot of every reach picture on the study page, pixels (for
/// the lateral extent common to all variants).
pub const STUDY_REACH_PLOT_W: u32 = 400;
/// Display width of the widest variant's modes.png on the study page, pixels.
pub const MODES_SHOWN_MAX_W: u32 = 720;

/// The study page's reach picture of variant `index`, in the study directory.
pub fn reach_picture_file(index: usize) -> String {
    format!("reach-v{index}.png")
}

/// A picture on the study page: its file (relative to the study
/// directory) and the size it is shown at, pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct PagePicture {
    /// File, relative to the study directory.
    pub file: String,
    /// Display size (width, height), pixels.
    pub shown_px: (u32, u32),
}

/// The pictures of the study page, one per variant in each list.
#[derive(Debug, Clone, PartialEq)]
pub struct PagePictures {
    /// Reach on common axes (shown at their own size).
    pub reach: Vec<PagePicture>,
    /// Pixels per mm of every reach picture.
    pub reach_px_per_mm: f64,
    /// The variants' modes.png, sized to one scale.
    pub modes: Vec<PagePicture>,
    /// Pixels per mm of every modes panel as shown.
    pub modes_px_per_mm: f64,
}

/// A scale in px per mm as the page states it.
fn px(px_per_mm: f64) -> String {
    format!("{px_per_mm:.2}")
}


impl Comparison {
    /// The side-by-side page: the table, then each variant's reach (on
    /// common axes) and mode pictures (at one scale) in a row, linking to
    /// its map explorer.
    pub fn html(&self, pictures: &PagePictures) -> String {
        let esc = |t: &str| {
            t.replace('&', "&amp;")
                .replace('<', "&lt;")
                .replace('>', "&gt;")
                .replace('"', "&quot;")
        };
        let mut h = format!(
            "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Study: {name}</title>\n<style>\
             body{{font-family:sans-serif;margin:1.5em}} table{{border-collapse:collapse}} td,th{{border:1px solid #ccc;padding:3px 6px;text-align:right}}\
             td.l{{text-align:left}} .row{{display:flex;flex-wrap:wrap;gap:1em;align-items:flex-start}} .v{{flex:0 0 auto}} .v img{{border:1px solid #ddd}}\
             </style></head><body>\n<h1>Study: {name}</h1>\n<p>{n} variants, each a sweep and its feasibility map (<code>cablemap study</code>). \
             Areas are non-empty cells × cell area; mode areas count the cells where the mode occurs; a<sub>0</sub>, a<sub>1</sub> in mm⁻¹.</p>\n",
            name = esc(&self.name),
            n = self.variants.len()
        );
        h.push_str("<table><tr><th>variant</th><th>settings</th><th>reach mm²</th>");
        for m in 0..MODES {
            h.push_str(&format!("<th>mode {m} mm²</th>"));
        }
        h.push_str("<th>a0 range</th><th>a1 range</th><th>failed</th></tr>\n");
        for r in &self.variants {
            h.push_str(&format!(
                "<tr><td><a href=\"{}/index.html\">v{}</a></td><td class=\"l\">{}</td><td>{:.0}</td>",
                r.map,
                r.index,
                esc(&r.label),
                r.reach_area_mm2
            ));
            for a in r.mode_area_mm2 {
                h.push_str(&format!("<td>{a:.0}</td>"));
            }
            h.push_str(&format!(
                "<td>{:.4} … {:.4}</td><td>{:.4} … {:.4}</td><td>{} of {}</td></tr>\n",
                r.a0_range[0], r.a0_range[1], r.a1_range[0], r.a1_range[1], r.rows_failed, r.rows_total
            ));
        }
        h.push_str("</table>\n");
        let sections = [
            (
                "Reach (simulations per cell)",
                format!(
                    "Every variant on the same axes ({} px per mm) and the same log colour scale, so a smaller reach looks smaller; \
                     below each, its own map's reach.png.",
                    px(pictures.reach_px_per_mm)
                ),
                &pictures.reach,
            ),
            (
                "Characteristic modes",
                format!(
                    "Each variant's modes.png shown at one scale ({} px per mm in every map panel), so panel sizes compare; click for full size.",
                    px(pictures.modes_px_per_mm)
                ),
                &pictures.modes,
            ),
        ];
        for (k, (title, caption, shown)) in sections.into_iter().enumerate() {
            let is_reach = k == 0;
            h.push_str(&format!("<h2>{title}</h2>\n<p>{caption}</p>\n<div class=\"row\">\n"));
            for (r, p) in self.variants.iter().zip(shown.iter()) {
                // Reach: the picture opens the explorer, its own reach.png is linked below; modes: opens at full size.
                let (link, own) = if is_reach {
                    (format!("{}/index.html", r.map), format!(" · <a href=\"{}/reach.png\">own axes</a>", r.map))
                } else {
                    (p.file.clone(), String::new())
                };
                h.push_str(&format!(
                    "<div class=\"v\" style=\"width:{w}px\"><a href=\"{link}\"><img src=\"{file}\" width=\"{w}\" height=\"{ht}\" alt=\"{file} of variant {i}\"></a>\
                     <br>v{i}: {label}{own}</div>\n",
                    file = p.file,
                    w = p.shown_px.0,
                    ht = p.shown_px.1,
                    i = r.index,
                    label = esc(&r.label)
                ));
            }
            h.push_str("</div>\n");
        }
        h.push_str("</body></html>\n");
        h
    }

    /// Draws the page's reach pictures into `dir` from the variants' maps
    /// `maps` (summary and cells, in the order of the rows): every variant
    /// on common axes (the union of their frames at one mm per pixel) and
    /// one colour scale; and sizes their modes.png to one scale.
    pub fn draw_pictures(&self, dir: &Path, maps: &[(MapSummary, Vec<CellStats>)]) -> Result<PagePictures, StudyError> {
        use crate::plot::{draw_heatmap_laid_out, HeatmapLayout, MapFrame, ModesLayout, Scale};
        let frame = maps.iter().map(|(s, _)| MapFrame::of(s)).reduce(MapFrame::union);
        let most = maps.iter().flat_map(|(_, cells)| cells.iter().map(|c| c.count)).max().unwrap_or(1);
        let mut reach = Vec::new();
        let mut reach_px_per_mm = 0.0;
        if let Some(frame) = frame {
            let layout = HeatmapLayout { frame, plot_w_px: STUDY_REACH_PLOT_W, value_range: Some((1.0, most as f64)) };
            reach_px_per_mm = frame.px_per_mm(STUDY_REACH_PLOT_W);
            for (r, (summary, cells)) in self.variants.iter().zip(maps) {
                let file = reach_picture_file(r.index);
                let counts: Vec<(i32, i32, f64)> = cells.iter().map(|c| (c.ix, c.iy, c.count as f64)).collect();
                let title = format!("v{}: simulations per cell", r.index);
                let label = "simulations per cell (log scale, all variants)";
                let size = draw_heatmap_laid_out(&dir.join(&file), summary, &layout, &title, label, &counts, Scale::Log)?;
                reach.push(PagePicture { file, shown_px: size });
            }
        }
        // modes.png keeps each map's own frame: shown at k px per mm, its
        // display width is its width × k / (its own px per mm); k puts the
        // widest at MODES_SHOWN_MAX_W.
        let layouts: Vec<ModesLayout> = maps.iter().map(|(s, _)| ModesLayout::of(s)).collect();
        let widest_mm = layouts.iter().map(|l| f64::from(l.size_px.0) / l.px_per_mm).fold(0.0, f64::max);
        let modes_px_per_mm = if widest_mm > 0.0 { f64::from(MODES_SHOWN_MAX_W) / widest_mm } else { 0.0 };
        let modes = self
            .variants
            .iter()
            .zip(&layouts)
            .map(|(r, l)| {
                let k = modes_px_per_mm / l.px_per_mm;
                let shown = |n: u32| (f64::from(n) * k).round() as u32;
                PagePicture { file: format!("{}/modes.png", r.map), shown_px: (shown(l.size_px.0), shown(l.size_px.1)) }
            })
            .collect();
        Ok(PagePictures { reach, reach_px_per_mm, modes, modes_px_per_mm })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::comparison::VariantRow;

    #[test]
    fn the_page_draws_every_reach_on_common_axes_and_modes_at_one_scale() {
        use crate::plot::map_frame::tests::{bounding_box, cell, pixels_of, summary};
        let small = summary();
        // A reach twice as large each way, from a rod twice as long.
        let large = MapSummary { nx: 20, ny: 32, y_min_mm: -80.0, length_mm: 130.0, ..summary() };
        let busiest = |ix, iy| cell(ix, iy, 50, 0);
        let maps = vec![(small, vec![cell(0, 0, 1, 0), busiest(3, 4)]), (large, vec![cell(0, 0, 1, 0), busiest(12, 20)])];
        let row = |index: usize| VariantRow {
            index,
            label: format!("length_mm={}", maps[index].0.length_mm),
            reach_area_mm2: 50.0,
            mode_area_mm2: [0.0; MODES],
            a0_range: [0.0, 0.0],
            a1_range: [0.0, 0.0],
            rows_total: 51,
            rows_failed: 0,
            cell_mm: 5.0,
            map: format!("v{index}/map"),
        };
        let comparison = Comparison { name: "t".into(), variants: vec![row(0), row(1)] };
        let dir = tempfile::tempdir().unwrap();
        let pictures = comparison.draw_pictures(dir.path(), &maps).unwrap();
        // Same axes: the same image size, and a 5 mm cell takes as many pixels in both.
        assert_eq!(pictures.reach[0].shown_px, pictures.reach[1].shown_px);
        use plotters::prelude::ColorMap;
        let top = plotters::style::colors::colormaps::ViridisRGB.get_color_normalized(1.0, 0.0, 1.0);
        let cell_px: Vec<(u32, u32)> = pictures
            .reach
            .iter()
            .map(|p| {
                let img = image::open(dir.path().join(&p.file)).unwrap().to_rgb8();
                let ((x0, x1), (y0, y1)) = bounding_box(&pixels_of(&img, top, 80));
                (x1 - x0 + 1, y1 - y0 + 1)
            })
            .collect();
        // (Cell edges round to whole pixels: ±1 px.)
        let expected = (5.0 * pictures.reach_px_per_mm).round() as u32;
        for (w, h) in &cell_px {
            assert!(w.abs_diff(expected) <= 1 && h.abs_diff(expected) <= 1, "busiest cells {cell_px:?} px, {expected} px expected in both");
        }
        // modes.png keeps each map's frame: shown widths follow the maps' mm extents.
        let layouts: Vec<_> = maps.iter().map(|(s, _)| crate::plot::ModesLayout::of(s)).collect();
        for (p, l) in pictures.modes.iter().zip(&layouts) {
            let shown_px_per_mm = f64::from(p.shown_px.0) / f64::from(l.size_px.0) * l.px_per_mm;
            assert!((shown_px_per_mm - pictures.modes_px_per_mm).abs() < 0.01, "{p:?}");
        }
        assert!(pictures.modes[1].shown_px.0 > pictures.modes[0].shown_px.0);
        // The page shows them at those sizes and states the scales.
        let page = comparison.html(&pictures);
        for p in pictures.reach.iter().chain(&pictures.modes) {
            assert!(page.contains(&format!("src=\"{}\" width=\"{}\" height=\"{}\"", p.file, p.shown_px.0, p.shown_px.1)), "{p:?}");
        }
        assert!(page.contains(&format!("same axes ({:.2} px per mm)", pictures.reach_px_per_mm)), "{page}");
    }
}
