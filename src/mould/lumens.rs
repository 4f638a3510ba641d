//! A printable body with lumens and its castable cores, for channels in
//! space (thesis Ch. 6: "if spatial channels … can be fabricated by 3D
//! printing").
//!
//! The two-part mould ([`super::Moulds`]) casts channels in one cutting
//! plane; a channel that leaves it cannot be cast in two halves. Here the
//! body itself is the print: the silicone body (clamp block and free
//! length) as one closed solid with a tube-shaped hole (lumen) of the tube's
//! diameter along each cable's channel, out through both end faces. And its
//! negative: the lumens' cores, one solid rod per cable reaching `wall_mm`
//! beyond both ends, to print in a soluble or flexible material and cast
//! the silicone around (then dissolve or pull them out).
//!
//! Frame as the moulds': x along the body (clamp face x = 0, tip x = L,
//! clamp block −c … 0), y and z the body frame's lateral axes, the channel
//! of a cable at (s, y_c(s), z_c(s)). Every surface is sampled on the same
//! x stations: the body's outline is the circle of radius r(x) (the radius
//! profile, so tapered bodies print too), a lumen's section the ellipse in
//! which the plane x = const cuts a tube of the tube's radius ρ about the
//! channel's tangent line — its centre is the channel point, exactly.

use super::mesh::{Mesh, MeshBuilder, Point};
use super::polygon::{self, P2};
use super::{MouldError, MouldParams, ParameterProblem, MAX_TRIANGLES};
use crate::model::cable::Channel;
use crate::model::routing::CONTROL_POINTS;
use crate::model::Actuator;
use serde::Serialize;

/// Corners of the body's outline in every x-section.
const OUTLINE_CORNERS: usize = 96;
/// Corners of a lumen's section.
const LUMEN_CORNERS: usize = 32;
/// Largest station spacing along the body, mm (the lumens' centres between
/// stations are then within about a micrometre of the channel).
const MAX_STATION_STEP_MM: f64 = 0.25;

/// The body with lumens of an actuator, checked and ready to mesh.
#[derive(Debug, Clone)]
pub struct Lumens {
    channels: Vec<Channel>,
    /// Each cable's control points (y0..y4, z0..z4), mm.
    control_points_mm: Vec<([f64; CONTROL_POINTS], [f64; CONTROL_POINTS])>,
    length_mm: f64,
    radius_mm: f64,
    /// Radius profile (s, r), piecewise linear; empty: uniform.
    profile_mm: Vec<(f64, f64)>,
    params: MouldParams,
    /// x stations from the clamp block's end to the tip, mm.
    stations: Vec<f64>,
}

/// What [`Lumens::write_all`] wrote (also saved as mould.json).
#[derive(Debug, Clone, Serialize)]
pub struct LumenSummary {
    /// "lumens": a printable body with lumens and its cores.
    pub style: &'static str,
    /// Every cable's channel, in cable order: control points y0..y4 and z0..z4, mm.
    pub channels: Vec<LumenChannel>,
    /// Body length L, mm.
    pub length_mm: f64,
    /// Body radius r (at the clamp), mm.
    pub radius_mm: f64,
    /// Radius profile (s, r) in mm; empty for a uniform body.
    pub radius_profile_mm: Vec<(f64, f64)>,
    /// Mould parameters (wall_mm is how far the cores reach beyond the body).
    pub params: MouldParams,
    /// The STL files.
    pub files: Vec<LumenFile>,
    /// The body's volume expected: the solid of revolution less π ρ² per mm of every channel, mm³.
    pub body_expected_mm3: f64,
    /// The cores' volume expected: π ρ² per mm of every core, mm³.
    pub core_expected_mm3: f64,
}

/// One cable's channel in [`LumenSummary`].
#[derive(Debug, Clone, Serialize)]
pub struct LumenChannel {
    /// Cable number (1-based, file order).
    pub cable: usize,
    /// Control points y0..y4, mm.
    pub y_mm: [f64; CONTROL_POINTS],
    /// Control points z0..z4, mm.
    pub z_mm: [f64; CONTROL_POINTS],
    /// Length of its lumen (clamp block + arc), mm.
    pub lumen_length_mm: f64,
    /// Its centreline file.
    pub file: String,
}

/// One STL file of the lumen style.
#[derive(Debug, Clone, Serialize)]
pub struct LumenFile {
    /// File name (body.stl, core.stl).
    pub file: String,
    /// Enclosed volume, mm³.
    pub volume_mm3: f64,
    /// Triangles.
    pub triangles: usize,
    /// Connected pieces (the body: 1; the cores: one per cable).
    pub shells: usize,
    /// Closed, 2-manifold, consistently oriented, positive volume.
    pub watertight: bool,
}

impl LumenSummary {
    /// The text `mould` prints once the files are written into `dir`.
    pub fn report(&self, dir: &std::path::Path) -> String {
        let mut out = format!(
            "printed body with {} lumen(s), L = {} mm, r = {} mm{}, clamp block {} mm, lumen Ø {} mm\n",
            self.channels.len(),
            self.length_mm,
            self.radius_mm,
            if self.radius_profile_mm.is_empty() { String::new() } else { " (radius profile)".into() },
            self.params.clamp_mm,
            self.params.tube_diameter_mm
        );
        for f in &self.files {
            out.push_str(&format!(
                "{:<12} {:.1} cm³, {} triangles, {} piece(s){}\n",
                f.file,
                f.volume_mm3 / 1000.0,
                f.triangles,
                f.shells,
                if f.watertight { "" } else { " NOT WATERTIGHT" }
            ));
        }
        out.push_str(&format!("expected     body {:.1} mm³, cores {:.1} mm³\n", self.body_expected_mm3, self.core_expected_mm3));
        let csv: Vec<&str> = self.channels.iter().map(|c| c.file.as_str()).collect();
        out.push_str(&format!("wrote body.stl, core.stl, {}, mould.json to {}\n", csv.join(", "), dir.display()));
        out
    }
}

impl Lumens {
    /// Checks the actuator, the parameters and every channel against the
    /// body (its radius profile) and each other: each lumen keeps
    /// `min_skin_mm` of silicone to the surface ([`MouldError::LumenTooClose`])
    /// and to every other lumen ([`MouldError::ChannelsTooClose`]). Every
    /// cable must be knotted at the tip and the body of one material
    /// ([`super::check_body`]).
    pub fn new(actuator: &Actuator, params: &MouldParams) -> Result<Self, MouldError> {
        let p = params;
        let bad = |name: &'static str, problem| Err(MouldError::BadParameter { name, problem });
        super::request::check_body(actuator, super::MouldStyle::Lumens)?;
        let channels = crate::model::cable::validate(&actuator.rod, &actuator.cables).map_err(crate::solver::spatial::SpatialError::from)?;
        actuator.rod.validate()?;
        let (length_mm, radius_mm) = (actuator.rod.length_mm, actuator.rod.radius_mm);
        let profile_mm = actuator.rod.radius_profile_mm.as_slice();
        super::params::check_sizes([
            ("wall_mm", p.wall_mm),
            ("tube_diameter_mm", p.tube_diameter_mm),
            ("clamp_mm", p.clamp_mm),
            ("min_skin_mm", p.min_skin_mm),
            ("station_step_mm", p.station_step_mm),
            ("radius_mm", radius_mm),
            ("length_mm", length_mm),
        ])?;
        if p.tube_diameter_mm <= 0.0 || p.tube_diameter_mm > radius_mm {
            return bad("tube_diameter_mm", ParameterProblem::Tube { tube_mm: p.tube_diameter_mm, radius_mm, pour: false });
        }
        if p.wall_mm <= 0.0 {
            return bad("wall_mm", ParameterProblem::WallNotPositive { wall_mm: p.wall_mm });
        }
        if p.clamp_mm < 0.0 {
            return bad("clamp_mm", ParameterProblem::Negative { value: p.clamp_mm });
        }
        if p.min_skin_mm < 0.0 {
            return bad("min_skin_mm", ParameterProblem::Negative { value: p.min_skin_mm });
        }
        if !(0.01..=2.0).contains(&p.station_step_mm) {
            return bad("station_step_mm", ParameterProblem::StationStep { step_mm: p.station_step_mm });
        }
        let step = p.station_step_mm.min(MAX_STATION_STEP_MM);
        // Stations: the clamp block's end, the clamp face, the body at the
        // step with every profile breakpoint, the tip.
        let mut marks: Vec<f64> = vec![0.0, length_mm];
        marks.extend(profile_mm.iter().map(|q| q.0).filter(|s| *s > 0.0 && *s < length_mm));
        marks.sort_by(f64::total_cmp);
        marks.dedup();
        let mut stations = if p.clamp_mm > 0.0 { vec![-p.clamp_mm] } else { Vec::new() };
        stations.push(0.0);
        for w in marks.windows(2) {
            let n = ((w[1] - w[0]) / step).ceil().max(1.0) as usize;
            stations.extend((1..=n).map(|k| if k == n { w[1] } else { w[0] + (w[1] - w[0]) * k as f64 / n as f64 }));
        }
        let lumens = Self {
            channels,
            control_points_mm: actuator.cables.iter().map(|c| (c.y_mm, c.z_mm)).collect(),
            length_mm, radius_mm, profile_mm: profile_mm.to_vec(), params: p.clone(), stations };
        let triangles = lumens.estimated_triangles();
        if triangles > MAX_TRIANGLES {
            return Err(MouldError::TooLarge { triangles, length_mm, radius_mm, wall_mm: p.wall_mm, clamp_mm: p.clamp_mm });
        }
        lumens.check_surface()?;
        lumens.check_gaps()?;
        Ok(lumens)
    }

    /// Body length L, mm.
    pub fn length_mm(&self) -> f64 {
        self.length_mm
    }

    /// The parameters.
    pub fn params(&self) -> &MouldParams {
        &self.params
    }

    /// The channels, in cable order.
    pub fn channels(&self) -> &[Channel] {
        &self.channels
    }

    /// Tube (lumen) radius ρ, mm.
    pub fn tube_radius_mm(&self) -> f64 {
        self.params.tube_diameter_mm / 2.0
    }

    /// Body radius r(x) (the clamp block has r(0)), mm.
    pub fn radius_at(&self, x_mm: f64) -> f64 {
        let s = x_mm.clamp(0.0, self.length_mm);
        let q = &self.profile_mm;
        if q.is_empty() {
            return self.radius_mm;
        }
        if s <= q[0].0 {
            return q[0].1;
        }
        for w in q.windows(2) {
            if s <= w[1].0 {
                let t = if w[1].0 > w[0].0 { (s - w[0].0) / (w[1].0 - w[0].0) } else { 1.0 };
                return w[0].1 + t * (w[1].1 - w[0].1);
            }
        }
        q[q.len() - 1].1
    }

    /// The centre (y, z) of lumen `k` at x and its slope (dy/dx, dz/dx):
    /// the channel on the body, straight along x (with the section of
    /// s = 0 or L) before the clamp face and beyond the tip, mm.
    pub fn lumen_at(&self, k: usize, x_mm: f64) -> ([f64; 2], [f64; 2]) {
        let c = self.channels[k].at(x_mm.clamp(0.0, self.length_mm));
        (c.r_mm, c.dr_ds)
    }

    /// A lumen's section at x: the plane x = const cuts the tube of radius
    /// ρ about the tangent line in an ellipse, ρ√(1 + m²) along the slope's
    /// direction and ρ across it (m = |slope|); counter-clockwise in (y, z).
    fn lumen_ring(&self, k: usize, x_mm: f64) -> Vec<P2> {
        let ([cy, cz], d) = self.lumen_at(k, x_mm);
        let rho = self.tube_radius_mm();
        let m2 = d[0] * d[0] + d[1] * d[1];
        // The map I + (√(1+m²) − 1) e eᵀ of the unit circle, e = d/|d|
        // (continuous as m → 0, so the rings do not twist between stations).
        let stretch = (1.0 + m2).sqrt() - 1.0;
        let (ey, ez) = if m2 > 0.0 { (d[0] / m2.sqrt(), d[1] / m2.sqrt()) } else { (1.0, 0.0) };
        (0..LUMEN_CORNERS)
            .map(|j| {
                let a = std::f64::consts::TAU * j as f64 / LUMEN_CORNERS as f64;
                let (u, v) = (a.cos(), a.sin());
                let along = stretch * (u * ey + v * ez);
                [cy + rho * (u + along * ey), cz + rho * (v + along * ez)]
            })
            .collect()
    }

    /// The body's outline at x, counter-clockwise in (y, z).
    fn outline_ring(&self, x_mm: f64) -> Vec<P2> {
        let r = self.radius_at(x_mm);
        (0..OUTLINE_CORNERS)
            .map(|j| {
                let a = std::f64::consts::TAU * j as f64 / OUTLINE_CORNERS as f64;
                [r * a.cos(), r * a.sin()]
            })
            .collect()
    }

    /// Every lumen keeps `min_skin_mm` to the surface; the meshed sections
    /// (ellipse inside the outline's polygon) leave room too.
    fn check_surface(&self) -> Result<(), MouldError> {
        let rho = self.tube_radius_mm();
        let n = (self.length_mm / 0.05).ceil() as usize;
        let inscribed = (std::f64::consts::PI / OUTLINE_CORNERS as f64).cos();
        for k in 0..self.channels.len() {
            for i in 0..=n {
                let s = self.length_mm * i as f64 / n as f64;
                let ([y, z], d) = self.lumen_at(k, s);
                let dist = y.hypot(z);
                let r = self.radius_at(s);
                let skin = r - dist - rho;
                let section = rho * (1.0 + d[0] * d[0] + d[1] * d[1]).sqrt();
                if skin < self.params.min_skin_mm || dist + section >= r * inscribed - 1e-3 {
                    return Err(MouldError::LumenTooClose {
                        cable: k + 1,
                        tube_mm: self.params.tube_diameter_mm,
                        skin_mm: skin,
                        s_mm: s,
                        distance_mm: dist,
                        radius_mm: r,
                        min_skin_mm: self.params.min_skin_mm.max(dist + section - r * inscribed + 1e-3 + skin),
                    });
                }
            }
        }
        Ok(())
    }

    /// Every pair of lumens keeps `min_skin_mm` between them: the least
    /// distance between their centrelines in space, less 2ρ (sampled every
    /// 0.02 mm, pairs within 2ρ + 3 mm in x compared); and their meshed
    /// sections stay apart at every station.
    fn check_gaps(&self) -> Result<(), MouldError> {
        let rho = self.tube_radius_mm();
        let l = self.length_mm;
        let n = (l / 0.02).ceil() as usize;
        let pts: Vec<Vec<[f64; 3]>> = (0..self.channels.len())
            .map(|k| (0..=n).map(|i| l * i as f64 / n as f64).map(|s| {
                let ([y, z], _) = self.lumen_at(k, s);
                [s, y, z]
            }).collect())
            .collect();
        let window = 2.0 * rho + 3.0;
        for a in 0..pts.len() {
            for b in a + 1..pts.len() {
                let mut best = (f64::INFINITY, 0.0);
                let mut lo = 0;
                for p in &pts[a] {
                    while pts[b][lo][0] < p[0] - window {
                        lo += 1;
                    }
                    for q in pts[b][lo..].iter().take_while(|q| q[0] <= p[0] + window) {
                        let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
                        if d < best.0 - 1e-9 {
                            best = (d, p[0]);
                        }
                    }
                }
                let gap = best.0.min(window) - 2.0 * rho;
                let refuse = |s_mm: f64, gap_mm: f64| MouldError::ChannelsTooClose {
                    first: a + 1,
                    second: b + 1,
                    s_mm,
                    gap_mm,
                    needed_mm: self.params.min_skin_mm,
                    tube_mm: self.params.tube_diameter_mm,
                };
                if gap < self.params.min_skin_mm {
                    return Err(refuse(best.1, gap));
                }
                // The sections as meshed: bounded by circles of their
                // largest semi-axis, which must not meet.
                for &x in &self.stations {
                    let (ca, da) = self.lumen_at(a, x);
                    let (cb, db) = self.lumen_at(b, x);
                    let reach = rho * ((1.0 + da[0] * da[0] + da[1] * da[1]).sqrt() + (1.0 + db[0] * db[0] + db[1] * db[1]).sqrt());
                    if (ca[0] - cb[0]).hypot(ca[1] - cb[1]) <= reach + 1e-3 {
                        return Err(refuse(x.max(0.0), gap));
                    }
                }
            }
        }
        Ok(())
    }

    /// At most how many triangles the body and the cores have.
    pub fn estimated_triangles(&self) -> f64 {
        let n = self.stations.len() as f64 + 2.0;
        let k = self.channels.len() as f64;
        let rings = OUTLINE_CORNERS as f64 + k * LUMEN_CORNERS as f64;
        2.0 * n * rings + 2.0 * (rings + 2.0 * k) + 2.0 * n * k * LUMEN_CORNERS as f64 + 2.0 * k * LUMEN_CORNERS as f64
    }

    /// The body with its lumens: one closed solid, mm.
    pub fn body(&self) -> Result<Mesh, MouldError> {
        let mut b = MeshBuilder::new();
        let at = |x: f64, q: P2| -> Point { [x, q[0], q[1]] };
        let outlines: Vec<Vec<P2>> = self.stations.iter().map(|&x| self.outline_ring(x)).collect();
        let lumens: Vec<Vec<Vec<P2>>> = (0..self.channels.len()).map(|k| self.stations.iter().map(|&x| self.lumen_ring(k, x)).collect()).collect();
        for i in 0..self.stations.len() - 1 {
            let (x0, x1) = (self.stations[i], self.stations[i + 1]);
            band(&mut b, x0, &outlines[i], x1, &outlines[i + 1], true);
            for rings in &lumens {
                band(&mut b, x0, &rings[i], x1, &rings[i + 1], false);
            }
        }
        // End faces: the outline with a hole per lumen.
        for (i, outward_x) in [(0, false), (self.stations.len() - 1, true)] {
            let x = self.stations[i];
            let holes: Vec<Vec<P2>> = lumens.iter().map(|rings| rings[i].clone()).collect();
            let tris = polygon::triangulate(&outlines[i], &holes).map_err(|source| MouldError::EndFace { x_mm: x, source })?;
            let mut pts = outlines[i].clone();
            holes.iter().for_each(|h| pts.extend_from_slice(h));
            for t in tris {
                let [p, q, r] = t.map(|v| at(x, pts[v]));
                // Counter-clockwise in (y, z) faces +x.
                if outward_x {
                    b.triangle(p, q, r);
                } else {
                    b.triangle(p, r, q);
                }
            }
        }
        Ok(b.finish())
    }

    /// The lumens' cores: one closed rod per cable along its lumen,
    /// reaching `wall_mm` beyond both ends of the body, mm.
    pub fn cores(&self) -> Mesh {
        let mut b = MeshBuilder::new();
        let e = self.params.wall_mm;
        let mut xs = vec![self.stations[0] - e];
        xs.extend_from_slice(&self.stations);
        xs.push(self.length_mm + e);
        for k in 0..self.channels.len() {
            let rings: Vec<Vec<P2>> = xs.iter().map(|&x| self.lumen_ring(k, x)).collect();
            for i in 0..xs.len() - 1 {
                band(&mut b, xs[i], &rings[i], xs[i + 1], &rings[i + 1], true);
            }
            // Caps: fans from the centre (the ellipse is convex).
            for (i, outward_x) in [(0, false), (xs.len() - 1, true)] {
                let (c, _) = self.lumen_at(k, xs[i]);
                let centre = [xs[i], c[0], c[1]];
                let ring = &rings[i];
                for j in 0..ring.len() {
                    let (p, q) = ([xs[i], ring[j][0], ring[j][1]], [xs[i], ring[(j + 1) % ring.len()][0], ring[(j + 1) % ring.len()][1]]);
                    if outward_x {
                        b.triangle(centre, p, q);
                    } else {
                        b.triangle(centre, q, p);
                    }
                }
            }
        }
        b.finish()
    }

    /// Length of lumen `k` (clamp block + arc of the channel), mm.
    pub fn lumen_length_mm(&self, k: usize) -> f64 {
        self.params.clamp_mm + self.channels[k].rest_length_mm(self.length_mm)
    }

    /// √(1 + m²) of lumen `k` at x: its section's area over π ρ².
    fn stretch(&self, k: usize, x_mm: f64) -> f64 {
        let (_, d) = self.lumen_at(k, x_mm);
        (1.0 + d[0] * d[0] + d[1] * d[1]).sqrt()
    }

    /// Volume of lumen `k` in the body: π ρ² per mm of channel arc, and in
    /// the clamp block the prism of the section at s = 0, mm³.
    pub fn lumen_volume_mm3(&self, k: usize) -> f64 {
        let a = std::f64::consts::PI * self.tube_radius_mm().powi(2);
        a * (self.channels[k].rest_length_mm(self.length_mm) + self.params.clamp_mm * self.stretch(k, 0.0))
    }

    /// The body's volume: ∫ π r(x)² dx over the clamp block and the body,
    /// less every lumen's volume, mm³.
    pub fn body_expected_mm3(&self) -> f64 {
        let pi = std::f64::consts::PI;
        let n = 4000;
        let h = self.length_mm / n as f64;
        // r is piecewise linear: the midpoint rule is exact but for r'² h²/12 per step.
        let solid: f64 = (0..n).map(|i| pi * self.radius_at((i as f64 + 0.5) * h).powi(2) * h).sum::<f64>() + pi * self.radius_at(0.0).powi(2) * self.params.clamp_mm;
        solid - (0..self.channels.len()).map(|k| self.lumen_volume_mm3(k)).sum::<f64>()
    }

    /// The cores' volume: every lumen's, plus the prisms beyond both ends
    /// (the sections of s = 0 and L, `wall_mm` long), mm³.
    pub fn core_expected_mm3(&self) -> f64 {
        let a = std::f64::consts::PI * self.tube_radius_mm().powi(2);
        let e = self.params.wall_mm;
        (0..self.channels.len()).map(|k| self.lumen_volume_mm3(k) + a * e * (self.stretch(k, 0.0) + self.stretch(k, self.length_mm))).sum()
    }

    /// Writes body.stl, core.stl, the channels' CSV files and mould.json
    /// into `dir` (created if missing), in place.
    pub fn write_all(&self, dir: &std::path::Path) -> Result<LumenSummary, MouldError> {
        use crate::io::FileError;
        std::fs::create_dir_all(dir).map_err(FileError::on("creating", dir))?;
        let title = |what: &str| format!("cablemap {what}, units mm, L={} r={} {} lumens", self.length_mm, self.radius_mm, self.channels.len());
        let mut files = Vec::new();
        for (name, mesh) in [("body.stl", self.body()?), ("core.stl", self.cores())] {
            let path = dir.join(name);
            crate::io::write_atomic(&path, &super::stl::to_bytes(&mesh, &title(&name[..name.len() - 4]))).map_err(FileError::on("writing", &path))?;
            let report = mesh.check();
            files.push(LumenFile {
                file: name.to_string(),
                volume_mm3: report.volume_mm3,
                triangles: report.triangles,
                shells: report.shell_volumes_mm3.len(),
                watertight: report.is_watertight(),
            });
        }
        let mut channels = Vec::new();
        for k in 0..self.channels.len() {
            let name = crate::model::cable::channel_file_name(k);
            let path = dir.join(&name);
            crate::io::write_atomic(&path, self.channels[k].csv(self.length_mm).as_bytes()).map_err(FileError::on("writing", &path))?;
            let (y_mm, z_mm) = self.control_points_mm[k];
            channels.push(LumenChannel { cable: k + 1, y_mm, z_mm, lumen_length_mm: self.lumen_length_mm(k), file: name });
        }
        let summary = LumenSummary {
            style: "lumens",
            channels,
            length_mm: self.length_mm,
            radius_mm: self.radius_mm,
            radius_profile_mm: self.profile_mm.clone(),
            params: self.params.clone(),
            files,
            body_expected_mm3: self.body_expected_mm3(),
            core_expected_mm3: self.core_expected_mm3(),
        };
        let path = dir.join(super::SUMMARY_FILE);
        let json = serde_json::to_string_pretty(&summary).expect("summary serialises") + "\n";
        crate::io::write_atomic(&path, json.as_bytes()).map_err(FileError::on("writing", &path))?;
        Ok(summary)
    }
}

/// The surface between two rings at x0 < x1 (same corner count): facing
/// away from the axis with `outward`, towards it otherwise (a lumen's wall).
fn band(b: &mut MeshBuilder, x0: f64, r0: &[P2], x1: f64, r1: &[P2], outward: bool) {
    let n = r0.len();
    for j in 0..n {
        let k = (j + 1) % n;
        let (a, bb, c, d) = ([x0, r0[j][0], r0[j][1]], [x0, r0[k][0], r0[k][1]], [x1, r1[k][0], r1[k][1]], [x1, r1[j][0], r1[j][1]]);
        if outward {
            b.quad(a, bb, c, d);
        } else {
            b.quad(a, d, c, bb);
        }
    }
}

#[cfg(test)]
#[path = "lumens_tests.rs"]
mod tests;
