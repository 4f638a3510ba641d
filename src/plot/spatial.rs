//! The PNG of an actuator's simulation: two orthogonal views of the hanging
//! rod, x–y (looking along z) and x–z (looking along y), on one scale, with
//! the body's silhouette, the centreline, every cable's path (up to where
//! it is knotted) and the tip; with [`draw_spatial_with_points`], points in
//! 3-D besides (a capture's measured and simulated markers).

use super::canvas::{png_backend, register_fonts, PlotError, FONT};
use super::series::{clamp_series, draw_legend, draw_series_on, legend_size, page_chart, Mark, PictureSeries};
use crate::solver::Simulation;
use plotters::prelude::*;
use plotters::style::full_palette::{BLUE_800, BROWN, ORANGE, PURPLE};
use std::path::Path;

/// Colours of cables 1–8.
const CABLE_COLOURS: [RGBColor; 8] = [RED, ORANGE, PURPLE, GREEN, MAGENTA, CYAN, BROWN, BLACK];

/// One view: the lateral coordinate (1 = y, 2 = z) and its name.
struct View {
    axis: usize,
    name: &'static str,
}

/// The two views every spatial picture shows: x–y (looking along z) and x–z (looking along y).
const VIEWS: [View; 2] = [View { axis: 1, name: "y" }, View { axis: 2, name: "z" }];

/// Points in the clamp frame drawn in both views, with one legend entry.
#[derive(Debug, Clone, PartialEq)]
pub struct SpatialPoints {
    /// Legend text.
    pub legend: String,
    /// Colour.
    pub colour: RGBAColor,
    /// The points (x, y, z), mm.
    pub points_mm: Vec<[f64; 3]>,
    /// Crosses (measured points) or dots (simulated ones).
    pub crosses: bool,
}

/// Draws `sim` as two side-by-side views into `path` (PNG, 1400 × 760 px).
pub fn draw_spatial(path: &Path, title: &str, sim: &Simulation) -> Result<(), PlotError> {
    draw_spatial_with_points(path, title, sim, &[])
}

/// [`draw_spatial`] with `points` in both views (the views' scale covers them).
pub fn draw_spatial_with_points(path: &Path, title: &str, sim: &Simulation, points: &[SpatialPoints]) -> Result<(), PlotError> {
    let radius = sim.actuator.rod.radius_mm;
    let paths = sim.cable_paths_mm();
    // One scale for both views: the range of x and of both lateral coordinates.
    let (mut lo, mut hi) = ([0.0f64; 3], [0.0f64; 3]);
    for n in &sim.centreline {
        let p = n.position_mm();
        for i in 0..3 {
            lo[i] = lo[i].min(p[i] - radius);
            hi[i] = hi[i].max(p[i] + radius);
        }
    }
    for p in points.iter().flat_map(|p| &p.points_mm) {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i] - 2.0);
            hi[i] = hi[i].max(p[i] + 2.0);
        }
    }
    draw_views(path, title, (lo, hi), |view| {
        let a = view.axis;
        // Series in the view's body frame (x, lateral), as the planar pictures.
        let in_view = |p: [f64; 3]| (p[0], p[a]);
        let (left, right) = silhouette(sim, a, radius);
        let tip: Vec<(f64, f64)> = left.last().into_iter().chain(right.last()).copied().collect();
        let mut series = vec![clamp_series(radius)];
        series.push(PictureSeries {
            legend: "body (silhouette of radius r)".into(),
            colour: BLUE_800.to_rgba(),
            mark: Mark::Lines { paths: [left, right, tip].into_iter().filter(|p| p.len() > 1).collect(), width_px: 2 },
        });
        series.push(PictureSeries {
            legend: "centreline".into(),
            colour: BLUE_800.mix(0.4),
            mark: Mark::Lines { paths: vec![sim.centreline.iter().map(|n| in_view(n.position_mm())).collect()], width_px: 1 },
        });
        for (i, cable) in paths.iter().enumerate() {
            series.push(PictureSeries {
                legend: format!("cable {} ({:.2} N)", i + 1, sim.actuator.cables[i].tension_n),
                colour: CABLE_COLOURS[i % CABLE_COLOURS.len()].to_rgba(),
                mark: Mark::Lines { paths: vec![cable.iter().map(|&p| in_view(p)).collect()], width_px: 2 },
            });
        }
        if let Some(n) = sim.centreline.last() {
            let mark = Mark::Dot { at: in_view(n.position_mm()), radius_px: 5 };
            series.push(PictureSeries { legend: "tip".into(), colour: BLUE_800.to_rgba(), mark });
        }
        for p in points {
            let at: Vec<(f64, f64)> = p.points_mm.iter().map(|&q| in_view(q)).collect();
            if p.crosses {
                series.push(PictureSeries { legend: p.legend.clone(), colour: p.colour, mark: Mark::Crosses { at } });
            } else {
                // One legend entry: the first dot carries it, the others none.
                for (k, q) in at.into_iter().enumerate() {
                    let legend = if k == 0 { p.legend.clone() } else { String::new() };
                    series.push(PictureSeries { legend, colour: p.colour, mark: Mark::Dot { at: q, radius_px: 5 } });
                }
            }
        }
        series
    })
}

/// A tip trajectory to draw: its waypoints and, per leg, the tip at each
/// sample (`None` where the sample's solve failed), mm.
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectoryDrawing {
    /// The waypoints as asked (x, y, z; NaN for a component not asked).
    pub waypoints: Vec<[f64; 3]>,
    /// Per leg (waypoint k to k + 1), the sampled tips in order.
    pub legs: Vec<Vec<Option<[f64; 3]>>>,
    /// The body's radius at the clamp, mm (the drawn clamp's size).
    pub base_radius_mm: f64,
}

/// Colour of the sampled tip path.
pub const TRAJECTORY_PATH_COLOUR: RGBColor = RED;

impl TrajectoryDrawing {
    /// The series of the view whose lateral coordinate is `axis` (1 = y,
    /// 2 = z), in the body frame (x, lateral): the clamp, the straight
    /// legs between waypoints, the sampled tip path through every solved
    /// sample (one polyline per run of solved samples: one per leg when
    /// none failed) and the waypoints.
    pub fn series(&self, axis: usize) -> Vec<PictureSeries> {
        let in_view = |p: &[f64; 3]| (p[0], p[axis]);
        let finite = |p: &&[f64; 3]| p.iter().all(|v| v.is_finite());
        let legs: Vec<Vec<(f64, f64)>> = self.waypoints.windows(2).filter(|w| w.iter().all(|p| finite(&p))).map(|w| vec![in_view(&w[0]), in_view(&w[1])]).collect();
        let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
        for leg in &self.legs {
            let mut run = Vec::new();
            for tip in leg {
                match tip {
                    Some(p) => run.push(in_view(p)),
                    None => runs.extend((run.len() > 1).then(|| std::mem::take(&mut run))),
                }
            }
            runs.extend((run.len() > 1).then_some(run));
        }
        vec![
            clamp_series(self.base_radius_mm),
            PictureSeries { legend: "straight legs between the waypoints".into(), colour: BLACK.mix(0.35), mark: Mark::Lines { paths: legs, width_px: 1 } },
            PictureSeries { legend: "tip path (actuation linear in each leg)".into(), colour: TRAJECTORY_PATH_COLOUR.to_rgba(), mark: Mark::Lines { paths: runs, width_px: 2 } },
            PictureSeries { legend: "waypoints".into(), colour: BLACK.to_rgba(), mark: Mark::Crosses { at: self.waypoints.iter().filter(finite).map(in_view).collect() } },
        ]
    }

    /// Draws the trajectory as [`draw_spatial`] draws a rod: x–y and x–z
    /// views side by side on one scale, into `path` (PNG, 1400 × 760 px).
    pub fn draw(&self, path: &Path, title: &str) -> Result<(), PlotError> {
        let (mut lo, mut hi) = ([0.0f64; 3], [0.0f64; 3]);
        let points = self.waypoints.iter().chain(self.legs.iter().flatten().flatten());
        for p in points.filter(|p| p.iter().all(|v| v.is_finite())) {
            for i in 0..3 {
                lo[i] = lo[i].min(p[i]);
                hi[i] = hi[i].max(p[i]);
            }
        }
        draw_views(path, title, (lo, hi), |view| self.series(view.axis))
    }
}

/// Draws the two [`VIEWS`] side by side into `path` (PNG, 1400 × 760 px),
/// on one scale covering `(lo, hi)` (x, y, z, mm) with a margin; each
/// view's series come from `series_of`, its legend in the upper right.
fn draw_views(path: &Path, title: &str, (lo, hi): ([f64; 3], [f64; 3]), series_of: impl Fn(&View) -> Vec<PictureSeries>) -> Result<(), PlotError> {
    register_fonts();
    let root = png_backend(path, (1400, 760))?.into_drawing_area();
    root.fill(&WHITE).map_err(|e| PlotError::new(path, e))?;
    let root = root.titled(title, (FONT, 22)).map_err(|e| PlotError::new(path, e))?;
    let panels = root.split_evenly((1, 2));
    let lat_lo = lo[1].min(lo[2]);
    let lat_hi = hi[1].max(hi[2]);
    let span = (hi[0] - lo[0]).max(lat_hi - lat_lo) + 10.0;
    let (cx, cl) = (0.5 * (lo[0] + hi[0]), 0.5 * (lat_lo + lat_hi));
    let x_range = (cx - span / 2.0, cx + span / 2.0);
    let lat_range = (cl - span / 2.0, cl + span / 2.0);
    for (panel, view) in panels.iter().zip(&VIEWS) {
        let caption = format!("x–{} view (looking along {})", view.name, if view.axis == 1 { "z" } else { "y" });
        let lateral = format!("{} (mm)", view.name);
        let mut chart = page_chart(panel, path, (&caption, 18), (&lateral, lat_range), (-x_range.1, -x_range.0))?;
        let series = series_of(view);
        for s in &series {
            draw_series_on(&mut chart, path, s)?;
        }
        // The legend in the plot's upper right corner (the rod hangs from the top centre).
        let plot = chart.plotting_area().strip_coord_spec();
        let legend: Vec<PictureSeries> = series.iter().filter(|s| !s.legend.is_empty()).cloned().collect();
        let (w, _) = legend_size(&plot, &legend);
        draw_legend(&plot, path, &legend, (plot.dim_in_pixel().0 as i32 - w - 10, 10))?;
    }
    root.present().map_err(|e| PlotError::new(path, e))?;
    Ok(())
}

/// Points (x, lateral) of one side of a body outline, mm.
type Outline = Vec<(f64, f64)>;

/// The body's outline in the view plane (x, lateral axis `a`), mm: at each node the cross-section (a disc of radius r spanned by
/// the body y and z axes) reaches r·|(b_y·N, b_z·N)| along the in-view
/// normal N of the projected centreline.
fn silhouette(sim: &Simulation, a: usize, radius: f64) -> (Outline, Outline) {
    let nodes = &sim.centreline;
    let mut left = Vec::with_capacity(nodes.len());
    let mut right = Vec::with_capacity(nodes.len());
    for (k, n) in nodes.iter().enumerate() {
        let (prev, next) = (&nodes[k.saturating_sub(1)], &nodes[(k + 1).min(nodes.len() - 1)]);
        let (p, prev, next) = (n.position_mm(), prev.position_mm(), next.position_mm());
        let (tx, tl) = (next[0] - prev[0], next[a] - prev[a]);
        let norm = tx.hypot(tl);
        if norm == 0.0 {
            continue;
        }
        // In-view normal (x, lateral) = (−t_lat, t_x)/|t|.
        let (nx, nl) = (-tl / norm, tx / norm);
        let r = n.rotation;
        let dot = |col: usize| r[0][col] * nx + r[a][col] * nl;
        let reach = radius * dot(1).hypot(dot(2));
        left.push((p[0] + reach * nx, p[a] + reach * nl));
        right.push((p[0] - reach * nx, p[a] - reach * nl));
    }
    (left, right)
}


#[cfg(test)]
mod tests {
    use super::*;

    fn lines(s: &PictureSeries) -> &Vec<Vec<(f64, f64)>> {
        match &s.mark {
            Mark::Lines { paths, .. } => paths,
            other => panic!("{}: not lines: {other:?}", s.legend),
        }
    }

    /// Four waypoints, three legs of 21 samples: one straight line and one
    /// sampled polyline per leg in each view, through the samples' (x, lateral);
    /// a failed sample splits its leg's polyline.
    #[test]
    fn a_trajectory_draws_one_polyline_per_leg_through_its_samples() {
        let waypoints = vec![[40.0, -30.0, 1.0], [60.0, 0.0, 2.0], [45.0, 30.0, -1.0], [50.0, 25.0, 0.0]];
        let legs: Vec<Vec<Option<[f64; 3]>>> = waypoints
            .windows(2)
            .map(|w| (0..=20).map(|j| {
                let f = j as f64 / 20.0;
                Some([0, 1, 2].map(|i| w[0][i] + f * (w[1][i] - w[0][i]) + 3.0 * (std::f64::consts::PI * f).sin()))
            }).collect())
            .collect();
        let mut drawing = TrajectoryDrawing { waypoints: waypoints.clone(), legs, base_radius_mm: 5.0 };
        for axis in [1, 2] {
            let series = drawing.series(axis);
            let straight = lines(&series[1]);
            assert_eq!(straight.len(), 3);
            assert_eq!(straight[2], vec![(45.0, waypoints[2][axis]), (50.0, waypoints[3][axis])]);
            let path = lines(&series[2]);
            assert_eq!(path.len(), 3, "one polyline per leg");
            for (leg, line) in drawing.legs.iter().zip(path) {
                let want: Vec<(f64, f64)> = leg.iter().flatten().map(|p| (p[0], p[axis])).collect();
                assert_eq!(line, &want);
            }
            assert!(matches!(&series[3].mark, Mark::Crosses { at } if at.len() == 4));
        }
        drawing.legs[1][7] = None;
        let series = drawing.series(1);
        let path = lines(&series[2]);
        assert_eq!(path.iter().map(Vec::len).collect::<Vec<_>>(), [21, 7, 13, 21], "the failed sample splits leg 2");
        // Drawn: a PNG of the two views with the path's colour on it.
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("trajectory.png");
        drawing.draw(&file, "test").unwrap();
        let png = image::open(&file).unwrap().to_rgb8();
        assert_eq!(png.dimensions(), (1400, 760));
        let c = TRAJECTORY_PATH_COLOUR;
        let red = png.pixels().filter(|p| p.0 == [c.0, c.1, c.2]).count();
        assert!(red > 500, "{red} pixels of the path's colour");
    }
}
