//! Pictures of deformed actuators in the x–y plane (the rod hangs: the
//! clamp axis points down the page): body outline, centreline, every
//! cable, tip; shared by `simulate`, reduce and design.

use super::canvas::{png_backend, register_fonts, PlotError};
use super::series::{bounds, clamp_series, draw_legend, draw_series_on, hanging_chart, series_points, Mark, PictureSeries, LEGEND_PAD_PX, LEGEND_ROW_PX};
use crate::model::Rod;
use crate::solver::Simulation;
use plotters::prelude::*;
use std::path::Path;

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
    /// The drawing of a simulation in the x–y plane: its centreline,
    /// outline at ±`radius_mm` about it and every cable's path, each up to
    /// where it is knotted.
    pub fn of_simulation(sim: &Simulation, radius_mm: f64, label: String, colour: RGBColor) -> Self {
        let mut paths = sim.cable_paths_mm().into_iter().map(|p| p.iter().map(|q| (q[0], q[1])).collect::<Vec<_>>());
        BodyDrawing {
            centreline: sim.centreline.iter().map(|c| (c.x_mm, c.y_mm)).collect(),
            frame_angle_rad: sim.centreline.iter().map(|c| c.frame_angle_rad).collect(),
            cable: paths.next().unwrap_or_default(),
            further_cables: paths.collect(),
            radius_mm,
            radii_mm: Vec::new(),
            label,
            colour,
        }
    }

    /// The drawing of a simulation of a body `rod`: the outline follows its
    /// radius r(s) (a tapered or segmented body), else ±`radius_mm`.
    pub fn of_body(sim: &Simulation, rod: &Rod, label: String, colour: RGBColor) -> Self {
        let mut d = Self::of_simulation(sim, rod.radius_mm, label, colour);
        if let Ok(Some(body)) = rod.body() {
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

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::plot::clamp_half_width_mm;

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
