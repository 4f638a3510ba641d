//! Printable moulds for a designed actuator (thesis §5.2, Fig. 5.2).
//!
//! The thesis casts the silicone body in two steps: half of it in a first
//! mould whose inner surface carries a protrusion along the cable routing
//! (leaving a groove), then, with a PTFE tube laid in the groove, the other
//! half in a second mould; pulling the tube out leaves the channel.
//!
//! Here every part is an open tray or plate, printable face up without
//! supports and free of undercuts, built as a heightfield solid
//! ([`mesh::heightfield_solid`]). Frame: x along the body (the clamp face at
//! x = 0, the tip at x = L, the clamp block at −c … 0), y the model's lateral
//! axis (the bending plane), z normal to the cutting plane z = 0 that holds
//! the channel centreline y = y_c(x).
//!
//! - **Tray** (`T`): the half-cylinder trough z = −√(r² − y²) over −c < x < L,
//!   three registration pins, a pour opening (sprue) through the clamp-end
//!   wall and a notch for the tube through the tip-end wall. Used in both castings.
//! - **Lid 1** (`1`): a plate with the channel's protrusion, a half tube of
//!   the tube's radius whose centreline follows y_c(s) in the cutting plane
//!   (straight along x in the clamp block and beyond the ends). Tray + lid
//!   are mould 1: the cavity is the half body with its groove.
//! - **Cover 2** (`2`): a second half-cylinder trough with pin holes, the same
//!   sprue and notch. Tray + cover are mould 2: the full cylinder cavity that
//!   takes the half body (still in the tray) with the tube in its groove.
//!
//! Lid and cover are printed mating face up, i.e. turned 180° about the x axis
//! from their place in the assembly: their print frame has y and z negated.
//! Orientation marks are engraved in each part's mating face: "CL" at the
//! clamp end, an arrow and "+Y" in the margin on the +y side, and the part's
//! letter; a mirrored print reads backwards.
//!
//! Only the uniform planar body with one cable exists in cablemap today, so
//! only its moulds are made: no tapered/segmented or spatial-channel variants.

pub mod mesh;
pub mod preview;
pub mod stl;

use crate::model::Routing;
use mesh::{heightfield_solid, sided, Mesh, Sided};
use serde::Serialize;
use std::path::Path;

/// Parameters of the moulds, mm.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MouldParams {
    /// Wall (and floor) thickness around the cavity, mm.
    pub wall_mm: f64,
    /// Outer diameter of the PTFE tube that forms the channel, mm (thesis: 1).
    pub tube_diameter_mm: f64,
    /// Play between mating printed features (pins, tube notches), mm.
    pub clearance_mm: f64,
    /// Length of the clamp block cast before the clamp face (x from −c to 0), mm.
    pub clamp_mm: f64,
    /// Least silicone between the channel and the body surface, mm.
    pub min_skin_mm: f64,
    /// Largest spacing of mesh stations along the channel, mm.
    pub station_step_mm: f64,
}

impl Default for MouldParams {
    fn default() -> Self {
        Self { wall_mm: 3.0, tube_diameter_mm: 1.0, clearance_mm: 0.15, clamp_mm: 10.0, min_skin_mm: 0.3, station_step_mm: 0.5 }
    }
}

impl MouldParams {
    /// The largest channel offset |y_c| these moulds can cast in a body of
    /// radius `radius_mm`: the tube's outer radius and `min_skin_mm` of
    /// silicone must fit between the channel's centreline and the surface, mm.
    /// [`Moulds::new`] refuses a channel beyond it; `design --moulds` bounds
    /// its search by it.
    pub fn max_channel_offset_mm(&self, radius_mm: f64) -> f64 {
        radius_mm - self.tube_diameter_mm / 2.0 - self.min_skin_mm
    }
}

/// Largest size accepted for any mould dimension (body length and radius,
/// wall, clamp block, tube), mm.
pub const MAX_SIZE_MM: f64 = 10_000.0;

/// Most triangles of the three parts together (about 50 bytes each in the
/// STL files, several times that in memory while they are built).
pub const MAX_TRIANGLES: f64 = 4e6;

/// The file every mould directory holds: an output directory that has it
/// (or is new or empty) may be replaced.
pub const SUMMARY_FILE: &str = "mould.json";

/// Why moulds could not be made or written.
#[derive(Debug, thiserror::Error)]
pub enum MouldError {
    /// The meshes would be too large to build or print.
    #[error(
        "the moulds would have about {} triangles, more than {} (about {} MB of STL): the body ({} mm long, r = {} mm) with wall {} mm and clamp block {} mm is too large to mesh at the station step; give the sizes in mm, and mould a body of printable size",
        crate::io::fmt_sig(*triangles, 3),
        crate::io::fmt_sig(MAX_TRIANGLES, 3),
        crate::io::fmt_sig(*triangles * 50.0 / 1e6, 3),
        crate::io::fmt_num(*length_mm),
        crate::io::fmt_num(*radius_mm),
        crate::io::fmt_num(*wall_mm),
        crate::io::fmt_num(*clamp_mm)
    )]
    TooLarge { triangles: f64, length_mm: f64, radius_mm: f64, wall_mm: f64, clamp_mm: f64 },
    /// The output directory holds other files.
    #[error("{}: the directory exists and is not a mould directory (it has files but no {SUMMARY_FILE}); give a new or empty directory, or one written by cablemap mould", path.display())]
    NotAMouldDir { path: std::path::PathBuf },
    /// The output directory has no name (".", "/").
    #[error("{}: give the moulds a directory of their own by name (e.g. --out moulds)", path.display())]
    OutUnnamed { path: std::path::PathBuf },
    /// A parameter is out of range.
    #[error("bad mould parameter {name}: {message}")]
    BadParameter {
        /// The parameter's name in [`MouldParams`].
        name: &'static str,
        /// Its value and what it must be.
        message: String,
    },
    /// The channel comes too close to the body surface to be cast.
    #[error(
        "the channel (tube Ø {tube_mm} mm) comes within {skin_mm:.3} mm of the body surface at s = {s_mm:.2} mm \
         (|y_c| = {y_mm:.3} mm, r = {radius_mm} mm); it needs at least {min_skin_mm} mm of silicone: \
         use a routing with |y_c| ≤ {limit_mm:.3} mm (design --max-offset-mm), a thinner tube, or --min-skin-mm"
    )]
    ChannelTooClose { tube_mm: f64, skin_mm: f64, s_mm: f64, y_mm: f64, radius_mm: f64, min_skin_mm: f64, limit_mm: f64 },
    /// The actuator is not a uniform cylinder with the cable knotted at the tip.
    #[error("moulds are made for uniform cylinders only, but this actuator has {0}: the two-part mould's tray and plate assume one radius and a channel to the tip; cast a tapered or segmented body in a mould of your own (channel.csv gives the channel)")]
    NonUniformBody(String),
    /// Writing a file.
    #[error("{context}: {source}")]
    Io { context: String, source: std::io::Error },
    /// Drawing the preview.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
}

/// Refuses a body the moulds cannot cast: a radius profile, segments or a
/// cable knotted before the tip ([`MouldError::NonUniformBody`]).
pub fn check_uniform_body(a: &crate::model::Rod) -> Result<(), MouldError> {
    let mut what = Vec::new();
    if !a.radius_profile_mm.is_empty() {
        what.push("a radius profile (radius_profile_mm)");
    }
    if !a.segments.is_empty() {
        what.push("segments of their own material");
    }
    if a.cable_length_mm() < a.length_mm {
        what.push("a cable anchored before the tip (cable_anchor_mm)");
    }
    if what.is_empty() {
        Ok(())
    } else {
        Err(MouldError::NonUniformBody(what.join(" and ")))
    }
}

/// One printed part.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PartKind {
    /// The lower half trough (both castings).
    Tray,
    /// The plate with the channel's protrusion (mould 1).
    Lid,
    /// The upper half trough (mould 2).
    Cover,
}

impl PartKind {
    /// Name used in files and reports.
    pub fn name(self) -> &'static str {
        match self {
            PartKind::Tray => "tray",
            PartKind::Lid => "lid",
            PartKind::Cover => "cover",
        }
    }

    /// +1 when the print frame is the assembly frame, −1 when the part is
    /// printed turned 180° about x (y and z negated).
    pub fn frame_sign(self) -> f64 {
        match self {
            PartKind::Tray => 1.0,
            PartKind::Lid | PartKind::Cover => -1.0,
        }
    }

    /// The letter engraved on the part.
    fn letter(self) -> &'static str {
        match self {
            PartKind::Tray => "T",
            PartKind::Lid => "1",
            PartKind::Cover => "2",
        }
    }
}

/// Registration pin: side, height (mm).
const PIN_MM: f64 = 3.0;
const PIN_HEIGHT_MM: f64 = 1.5;
/// Margin band beside the wall that holds pins and marks, mm.
const BAND_MM: f64 = 8.0;
/// Marks: pixel size and engraving depth, mm.
const PIXEL_MM: f64 = 0.8;
const MARK_DEPTH_MM: f64 = 0.6;
/// Trough samples per side of the channel block, and samples across the channel.
const TROUGH_SAMPLES: usize = 48;
const CHANNEL_SAMPLES: usize = 32;

/// A rectangle of the mating face raised (dz > 0) or sunk (dz < 0), print frame.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Feature {
    x_mm: [f64; 2],
    y_mm: [f64; 2],
    dz_mm: f64,
}

/// The moulds of one routing: geometry and meshes.
#[derive(Debug, Clone)]
pub struct Moulds {
    routing: Routing,
    radius_mm: f64,
    params: MouldParams,
    /// Tube radius ρ, mm.
    tube_radius_mm: f64,
    /// Widest x-section half-width of the protrusion, ρ·max √(1 + y_c′²), mm.
    ridge_half_width_max_mm: f64,
    x_range_mm: [f64; 2],
    y_half_mm: f64,
    sprue_depth_mm: f64,
}

/// A built part: its kind and mesh in its print frame.
#[derive(Debug, Clone)]
pub struct Part {
    /// Which part.
    pub kind: PartKind,
    /// Mesh in the print frame (mating face up; see [`PartKind::frame_sign`]), mm.
    pub mesh: Mesh,
}

fn trough(r: f64, y: f64) -> f64 {
    if y.abs() < r {
        -(r * r - y * y).sqrt()
    } else {
        0.0
    }
}

impl Moulds {
    /// Checks the parameters and the routing's channel against the body.
    pub fn new(routing: &Routing, radius_mm: f64, params: &MouldParams) -> Result<Self, MouldError> {
        let p = params;
        let bad = |name: &'static str, message: String| Err(MouldError::BadParameter { name, message });
        let sizes = [
            ("wall_mm", p.wall_mm),
            ("tube_diameter_mm", p.tube_diameter_mm),
            ("clearance_mm", p.clearance_mm),
            ("clamp_mm", p.clamp_mm),
            ("min_skin_mm", p.min_skin_mm),
            ("station_step_mm", p.station_step_mm),
            ("radius_mm", radius_mm),
            ("length_mm", routing.length_mm()),
        ];
        for (name, value) in sizes {
            if !value.is_finite() {
                return bad(name, format!("{value} is not a number of mm: give a finite size"));
            }
            // Beyond any printer's bed; the meshes of such moulds would not fit in memory.
            if value.abs() > MAX_SIZE_MM {
                return bad(name, format!("{} mm is larger than {MAX_SIZE_MM} mm, beyond any printer: give the size in mm", crate::io::fmt_num(value)));
            }
        }
        if p.tube_diameter_mm <= 0.0 || p.tube_diameter_mm > radius_mm {
            return bad("tube_diameter_mm", format!(
                "{} mm must be positive and at most the radius {radius_mm} mm (the pour opening is r/2 deep)",
                p.tube_diameter_mm
            ));
        }
        if !(0.0..=0.5).contains(&p.clearance_mm) {
            return bad("clearance_mm", format!("{} mm must be between 0 and 0.5", p.clearance_mm));
        }
        if p.wall_mm < PIN_HEIGHT_MM + p.clearance_mm + 0.8 {
            return bad("wall_mm", format!(
                "{} mm is too thin: the lid's pin holes are {} mm deep; use at least {} mm",
                p.wall_mm,
                PIN_HEIGHT_MM + p.clearance_mm,
                PIN_HEIGHT_MM + p.clearance_mm + 0.8
            ));
        }
        if p.clamp_mm < 0.0 {
            return bad("clamp_mm", format!("{} mm must be ≥ 0", p.clamp_mm));
        }
        if p.min_skin_mm < 0.0 {
            return bad("min_skin_mm", format!("{} mm must be ≥ 0", p.min_skin_mm));
        }
        if !(0.01..=2.0).contains(&p.station_step_mm) {
            return bad("station_step_mm", format!("{} mm must be between 0.01 and 2", p.station_step_mm));
        }
        let length = routing.length_mm();
        let text_mm = text_width_mm("CL ^+Y");
        if length + p.clamp_mm < text_mm + 12.0 {
            return bad("clamp_mm", format!(
                "body of {length} mm plus clamp block {} mm is too short for the marks and pins (needs {} mm)",
                p.clamp_mm,
                text_mm + 12.0
            ));
        }
        let rho = p.tube_diameter_mm / 2.0;
        // The channel must keep min_skin of silicone to the surface everywhere.
        let limit = p.max_channel_offset_mm(radius_mm);
        let n = (length / 0.05).ceil() as usize;
        let mut widest = 1.0_f64;
        for i in 0..=n {
            let s = length * i as f64 / n as f64;
            let c = routing.channel_at(s);
            widest = widest.max((1.0 + c.dy_ds * c.dy_ds).sqrt());
            if c.y_mm.abs() > limit {
                return Err(MouldError::ChannelTooClose {
                    tube_mm: p.tube_diameter_mm,
                    skin_mm: radius_mm - rho - c.y_mm.abs(),
                    s_mm: s,
                    y_mm: c.y_mm.abs(),
                    radius_mm,
                    min_skin_mm: p.min_skin_mm,
                    limit_mm: limit,
                });
            }
        }
        let moulds = Self {
            routing: routing.clone(),
            radius_mm,
            params: p.clone(),
            tube_radius_mm: rho,
            ridge_half_width_max_mm: rho * widest,
            x_range_mm: [-p.clamp_mm - p.wall_mm, length + p.wall_mm],
            y_half_mm: radius_mm + p.wall_mm + BAND_MM,
            sprue_depth_mm: radius_mm / 2.0,
        };
        let triangles = moulds.estimated_triangles();
        if triangles > MAX_TRIANGLES {
            return Err(MouldError::TooLarge { triangles, length_mm: length, radius_mm, wall_mm: p.wall_mm, clamp_mm: p.clamp_mm });
        }
        // The samples across the channel must lie inside the trough.
        let w = moulds.ridge_half_width_max_mm.max(rho + p.clearance_mm);
        for i in 0..=n {
            let y = routing.channel_at(length * i as f64 / n as f64).y_mm.abs();
            if y + w >= radius_mm {
                return bad("tube_diameter_mm", format!(
                    "the protrusion (half-width {w:.3} mm in x-sections) at |y_c| = {y:.3} mm reaches the body surface r = {radius_mm} mm; \
                     use a routing further from the surface or a thinner tube"
                ));
            }
        }
        Ok(moulds)
    }

    /// At most how many triangles the three parts' meshes have (about
    /// 1.7 times as many as they do: steps of zero height weld away),
    /// counted from their stations and samples before any is built (see
    /// [`mesh::heightfield_solid`]: a grid, four walls and a bottom fan).
    pub fn estimated_triangles(&self) -> f64 {
        [PartKind::Tray, PartKind::Lid, PartKind::Cover]
            .into_iter()
            .map(|kind| {
                let features = self.features(kind);
                let marks = self.station_marks(&features);
                // The lid's stations fill the gaps between the marks (as
                // `stations` does, counted without building them).
                let n = match kind {
                    PartKind::Lid => {
                        let step = self.params.station_step_mm;
                        1.0 + marks.windows(2).map(|w| if w[1].0 > w[0].0 { ((w[1].0 - w[0].0) / step).ceil() } else { 1.0 }).sum::<f64>()
                    }
                    PartKind::Tray | PartKind::Cover => marks.len() as f64,
                };
                let m = self.samples(kind, &features, marks[0]).len() as f64;
                2.0 * (n - 1.0) * (m - 1.0) + 4.0 * (n + m) + 2.0 * (n + m)
            })
            .sum()
    }

    /// The routing the moulds are for.
    pub fn routing(&self) -> &Routing {
        &self.routing
    }

    /// Body radius r, mm.
    pub fn radius_mm(&self) -> f64 {
        self.radius_mm
    }

    /// The parameters.
    pub fn params(&self) -> &MouldParams {
        &self.params
    }

    /// x extent of every part, mm (clamp-end wall to tip-end wall).
    pub fn x_range_mm(&self) -> [f64; 2] {
        self.x_range_mm
    }

    /// Half-width of every part in y, mm.
    pub fn y_half_mm(&self) -> f64 {
        self.y_half_mm
    }

    /// The cavity's x range: the clamp block's end to the tip, mm.
    pub fn cavity_x_mm(&self) -> [f64; 2] {
        [-self.params.clamp_mm, self.routing.length_mm()]
    }

    /// Channel centreline y at x (assembly frame): y_c(x) on the body,
    /// straight along x in the clamp block and beyond the tip, mm.
    pub fn channel_y_mm(&self, x_mm: f64) -> f64 {
        self.routing.channel_at(x_mm.clamp(0.0, self.routing.length_mm())).y_mm
    }

    /// dy/dx of the channel at a station: the spline's slope on the body, 0
    /// on the straight ends; at x = 0 and x = L the side picks the limit.
    /// Evaluated at the station itself (not the sided offset) so both sides of
    /// a step elsewhere give bit-identical points.
    fn channel_slope(&self, x: Sided) -> f64 {
        let l = self.routing.length_mm();
        let on_body = (x.0 > 0.0 && x.0 < l) || (x.0 == 0.0 && x.1 > 0) || (x.0 == l && x.1 < 0);
        if on_body {
            self.routing.channel_at(x.0).dy_ds
        } else {
            0.0
        }
    }

    /// Length of the channel inside the cavity (clamp block + arc of y_c), mm.
    pub fn channel_length_mm(&self) -> f64 {
        let l = self.routing.length_mm();
        let n = 4000;
        let arc: f64 = (0..n)
            .map(|i| {
                let s = l * (i as f64 + 0.5) / n as f64;
                (1.0 + self.routing.channel_at(s).dy_ds.powi(2)).sqrt() * l / n as f64
            })
            .sum();
        self.params.clamp_mm + arc
    }

    /// Bottom of a part in its print frame, mm.
    pub fn z_bottom_mm(&self, kind: PartKind) -> f64 {
        match kind {
            PartKind::Tray | PartKind::Cover => -(self.radius_mm + self.params.wall_mm),
            PartKind::Lid => -self.params.wall_mm,
        }
    }

    /// The engraved text of a part: (text, left x, baseline band centre y), print frame.
    fn texts(&self, kind: PartKind) -> Vec<(String, f64, f64)> {
        let s = kind.frame_sign();
        let yb = self.radius_mm + self.params.wall_mm + BAND_MM / 2.0;
        // The arrow points to the assembly's +y side as seen in the print frame.
        let arrow = if s > 0.0 { '^' } else { 'v' };
        let [x0, x1] = self.x_range_mm;
        let id = kind.letter();
        vec![
            (format!("CL {arrow}+Y"), x0 + 2.0, s * yb),
            (id.to_string(), (x0 + x1) / 2.0 - text_width_mm(id) / 2.0, -s * yb),
        ]
    }

    fn features(&self, kind: PartKind) -> Vec<Feature> {
        let s = kind.frame_sign();
        let yb = self.radius_mm + self.params.wall_mm + BAND_MM / 2.0;
        let [x0, x1] = self.x_range_mm;
        let cl = self.params.clearance_mm;
        let (half, dz) = match kind {
            PartKind::Tray => (PIN_MM / 2.0, PIN_HEIGHT_MM),
            PartKind::Lid | PartKind::Cover => (PIN_MM / 2.0 + cl, -(PIN_HEIGHT_MM + cl)),
        };
        // Three pins, two on the −y side: the halves only fit one way round.
        let mut out: Vec<Feature> = [(x0 + 4.0, -yb), (x1 - 4.0, -yb), (x1 - 4.0, yb)]
            .into_iter()
            .map(|(x, y)| Feature { x_mm: [x - half, x + half], y_mm: [s * y - half, s * y + half], dz_mm: dz })
            .collect();
        for (text, x_left, y_centre) in self.texts(kind) {
            out.extend(text_pixels(&text, x_left, y_centre).into_iter().map(|(x, y)| Feature { x_mm: x, y_mm: y, dz_mm: -MARK_DEPTH_MM }));
        }
        out
    }

    /// Height of a part's mating face (print frame) at sided (x, y), mm.
    fn height(&self, kind: PartKind, features: &[Feature], x: Sided, y: Sided) -> f64 {
        let (xe, ye) = (sided(x), sided(y));
        let s = kind.frame_sign();
        let r = self.radius_mm;
        let [c0, c1] = self.cavity_x_mm();
        let mut z = match kind {
            PartKind::Tray | PartKind::Cover => {
                if xe > c0 && xe < c1 {
                    trough(r, ye)
                } else if xe <= c0 {
                    // Pour opening: the trough continues through the clamp-end
                    // wall down to r/2 (the tube passes through it too).
                    trough(r, ye).max(-self.sprue_depth_mm)
                } else {
                    // Tip-end wall: a notch for the tube (mould 2) or the lid's protrusion (mould 1).
                    let rn = self.tube_radius_mm + self.params.clearance_mm;
                    let u = ye - s * self.channel_y_mm(c1);
                    let notch = if u.abs() < rn { -(rn * rn - u * u).sqrt() } else { 0.0 };
                    notch.max(trough(r, ye))
                }
            }
            PartKind::Lid => {
                // The protrusion: in an x-section the half tube of radius ρ
                // about the channel is a half ellipse ρ·√(1 + y_c′²) wide.
                let rho = self.tube_radius_mm;
                let w = rho * (1.0 + self.channel_slope(x).powi(2)).sqrt();
                let u = ye - s * self.channel_y_mm(x.0);
                if u.abs() < w {
                    rho * (1.0 - (u / w).powi(2)).sqrt()
                } else {
                    0.0
                }
            }
        };
        for f in features {
            if f.x_mm[0] < xe && xe < f.x_mm[1] && f.y_mm[0] < ye && ye < f.y_mm[1] {
                z += f.dz_mm;
            }
        }
        z
    }

    /// y samples of a part at station x (print frame): the margins with
    /// every feature edge twice, the trough by angle, and a block across
    /// the channel that moves with it (so the crest is a grid line).
    fn samples(&self, kind: PartKind, features: &[Feature], x: Sided) -> Vec<Sided> {
        let s = kind.frame_sign();
        let r = self.radius_mm;
        let mut edges: Vec<f64> = features.iter().flat_map(|f| f.y_mm).collect();
        edges.sort_by(f64::total_cmp);
        edges.dedup();
        let (centre, w, n_side) = match kind {
            PartKind::Lid => (s * self.channel_y_mm(x.0), self.ridge_half_width_max_mm, 4),
            PartKind::Tray | PartKind::Cover => {
                (s * self.channel_y_mm(self.routing.length_mm()), self.tube_radius_mm + self.params.clearance_mm, TROUGH_SAMPLES)
            }
        };
        let mut out: Vec<Sided> = vec![(-self.y_half_mm, 0)];
        out.extend(edges.iter().filter(|e| **e < -r).flat_map(|e| [(*e, -1), (*e, 1)]));
        // Trough left of the channel block: y = r cos φ, φ from π down to φ_a.
        let phi_a = ((centre - w) / r).clamp(-1.0, 1.0).acos();
        out.extend((0..n_side).map(|k| (r * (std::f64::consts::PI - (std::f64::consts::PI - phi_a) * k as f64 / n_side as f64).cos(), 0)));
        out.extend((0..=CHANNEL_SAMPLES).map(|k| {
            let theta = std::f64::consts::PI * (1.0 - k as f64 / CHANNEL_SAMPLES as f64);
            (centre + w * theta.cos(), 0)
        }));
        let phi_b = ((centre + w) / r).clamp(-1.0, 1.0).acos();
        out.extend((1..=n_side).map(|k| (r * (phi_b * (1.0 - k as f64 / n_side as f64)).cos(), 0)));
        out.extend(edges.iter().filter(|e| **e > r).flat_map(|e| [(*e, -1), (*e, 1)]));
        out.push((self.y_half_mm, 0));
        out
    }

    /// x stations of a part: ends, steps (twice), and for the lid a fill
    /// no wider than the station step so the crest follows y_c(s).
    fn stations(&self, kind: PartKind, features: &[Feature]) -> Vec<Sided> {
        let marks = self.station_marks(features);
        if kind != PartKind::Lid {
            return marks;
        }
        let mut out = vec![marks[0]];
        for pair in marks.windows(2) {
            let (a, b) = (pair[0].0, pair[1].0);
            if b > a {
                let n = ((b - a) / self.params.station_step_mm).ceil() as usize;
                out.extend((1..n).map(|k| (a + (b - a) * k as f64 / n as f64, 0)));
            }
            out.push(pair[1]);
        }
        out
    }

    /// The stations every part has: the ends and every step (twice).
    fn station_marks(&self, features: &[Feature]) -> Vec<Sided> {
        let [x0, x1] = self.x_range_mm;
        let [c0, c1] = self.cavity_x_mm();
        let mut steps: Vec<f64> = vec![c0, 0.0, c1];
        steps.extend(features.iter().flat_map(|f| f.x_mm));
        steps.sort_by(f64::total_cmp);
        steps.dedup();
        let mut marks: Vec<Sided> = vec![(x0, 0)];
        marks.extend(steps.iter().flat_map(|x| [(*x, -1), (*x, 1)]));
        marks.push((x1, 0));
        marks
    }

    /// Builds one part in its print frame.
    pub fn part(&self, kind: PartKind) -> Part {
        let features = self.features(kind);
        let stations = self.stations(kind, &features);
        let mesh = heightfield_solid(
            &stations,
            &|x| self.samples(kind, &features, x),
            &|x, y| self.height(kind, &features, x, y),
            self.z_bottom_mm(kind),
        );
        Part { kind, mesh }
    }

    /// Height of a part's mating face at (x, y) in its print frame (for drawings), mm.
    pub fn height_mm(&self, kind: PartKind, x_mm: f64, y_mm: f64) -> f64 {
        self.height(kind, &self.features(kind), (x_mm, 0), (y_mm, 0))
    }

    /// The part's cross-section profile at x in the assembly frame: (y, z)
    /// points of its mating face, mm (for drawings).
    pub fn section_mm(&self, kind: PartKind, x_mm: f64) -> Vec<(f64, f64)> {
        let features = self.features(kind);
        let s = kind.frame_sign();
        let mut pts: Vec<(f64, f64)> = self
            .samples(kind, &features, (x_mm, 0))
            .into_iter()
            .map(|y| (s * y.0, s * self.height(kind, &features, (x_mm, 0), y)))
            .collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        pts
    }
}

/// Volume between the plane z = 0 and a part's mating face over the cavity's
/// footprint (−c < x < L, |y| < r), from the mesh: Σ over upward-facing
/// triangles with their centroid in the footprint of projected area × −mean z.
/// Positive for a trough (below the plane), negative for a protrusion.
pub fn volume_below_face_mm3(mesh: &Mesh, cavity_x_mm: [f64; 2], radius_mm: f64) -> f64 {
    let mut v = 0.0;
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        let area_xy = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
        if area_xy <= 0.0 {
            continue;
        }
        let (cx, cy) = ((a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0);
        if cx > cavity_x_mm[0] && cx < cavity_x_mm[1] && cy.abs() < radius_mm {
            v += area_xy * -(a[2] + b[2] + c[2]) / 3.0;
        }
    }
    v
}

/// The pixel font of the marks (rows top to bottom, '#' engraved; 3 wide,
/// the arrows 5). No two pixels touch only at a corner, so the engraving
/// stays 2-manifold.
fn glyph(c: char) -> &'static [&'static str] {
    match c {
        'C' => &["###", "#..", "#..", "#..", "###"],
        'L' => &["#..", "#..", "#..", "#..", "###"],
        'T' => &["###", ".#.", ".#.", ".#.", ".#."],
        'Y' => &["#.#", "#.#", "###", ".#.", ".#."],
        '+' => &["...", ".#.", "###", ".#.", "..."],
        '1' => &["##.", ".#.", ".#.", ".#.", "###"],
        '2' => &["###", "..#", "###", "#..", "###"],
        '^' => &["..#..", ".###.", "#####", "..#..", "..#.."],
        'v' => &["..#..", "..#..", "#####", ".###.", "..#.."],
        _ => &["...", "...", "...", "...", "..."],
    }
}

/// Width of `text` in the mark font, mm.
fn text_width_mm(text: &str) -> f64 {
    text.chars().map(|c| (glyph(c)[0].len() + 1) as f64 * PIXEL_MM).sum::<f64>() - PIXEL_MM
}

/// Pixel rectangles ([x0, x1], [y0, y1]) of `text` from `x_left`, centred on
/// `y_centre`, read left to right with the glyphs' tops towards +y.
fn text_pixels(text: &str, x_left: f64, y_centre: f64) -> Vec<([f64; 2], [f64; 2])> {
    let p = PIXEL_MM;
    let top = y_centre + 2.5 * p;
    let mut out = Vec::new();
    let mut x = x_left;
    for c in text.chars() {
        for (row, line) in glyph(c).iter().enumerate() {
            // Runs of pixels in a row become one rectangle.
            let cells: Vec<bool> = line.chars().map(|ch| ch == '#').collect();
            let mut k = 0;
            while k < cells.len() {
                if cells[k] {
                    let start = k;
                    while k < cells.len() && cells[k] {
                        k += 1;
                    }
                    out.push(([x + start as f64 * p, x + k as f64 * p], [top - (row + 1) as f64 * p, top - row as f64 * p]));
                } else {
                    k += 1;
                }
            }
        }
        x += (glyph(c)[0].len() + 1) as f64 * p;
    }
    out
}

/// Gap between the two parts of one print plate, mm.
const PLATE_GAP_MM: f64 = 6.0;

/// The three parts of a routing's moulds, built once.
#[derive(Debug, Clone)]
pub struct MouldSet {
    /// The geometry they were built from.
    pub moulds: Moulds,
    /// Lower half trough (both castings).
    pub tray: Part,
    /// Plate with the protrusion (mould 1).
    pub lid: Part,
    /// Upper half trough (mould 2).
    pub cover: Part,
}

/// One part as placed in an STL file.
#[derive(Debug, Clone, Serialize)]
pub struct PlacedPart {
    /// Part name (tray, lid, cover).
    pub part: PartKind,
    /// Engraved letter.
    pub letter: &'static str,
    /// Translation from the part's print frame to the file, mm.
    pub offset_mm: [f64; 3],
    /// Enclosed volume (print material), mm³.
    pub volume_mm3: f64,
    /// Triangles.
    pub triangles: usize,
    /// Closed, 2-manifold, consistently oriented, positive volume.
    pub watertight: bool,
}

/// One STL file: its name and the parts on its plate.
#[derive(Debug, Clone, Serialize)]
pub struct MouldFile {
    /// File name (mould1.stl, mould2.stl).
    pub file: String,
    /// The parts, in file order.
    pub parts: Vec<PlacedPart>,
}

/// What `write_all` wrote (also saved as mould.json).
#[derive(Debug, Clone, Serialize)]
pub struct MouldSummary {
    /// Control points y0..y4, mm.
    pub routing_mm: crate::model::routing::ControlPoints,
    /// Body length L and radius r, mm.
    pub length_mm: f64,
    /// Body radius r, mm.
    pub radius_mm: f64,
    /// Mould parameters.
    pub params: MouldParams,
    /// Channel length inside the body (clamp block + arc), mm.
    pub channel_length_mm: f64,
    /// The STL files with their parts.
    pub files: Vec<MouldFile>,
    /// Cavity of mould 1 measured on the meshes (half body minus half channel), mm³.
    pub mould1_cavity_mm3: f64,
    /// The half body with its groove, π r² (L + c)/2 − π ρ²/2 · channel length, mm³.
    pub mould1_body_mm3: f64,
    /// Cavity of mould 2 measured on the meshes, mm³.
    pub mould2_cavity_mm3: f64,
    /// The full body, π r² (L + c), mm³ (the tube takes π ρ² · channel length of it).
    pub mould2_body_mm3: f64,
}

impl MouldSet {
    /// Builds the tray, lid and cover.
    pub fn build(moulds: Moulds) -> Self {
        let tray = moulds.part(PartKind::Tray);
        let lid = moulds.part(PartKind::Lid);
        let cover = moulds.part(PartKind::Cover);
        Self { moulds, tray, lid, cover }
    }

    /// Checks and builds the moulds of `routing` on a body of radius `radius_mm`.
    pub fn new(routing: &Routing, radius_mm: f64, params: &MouldParams) -> Result<Self, MouldError> {
        Ok(Self::build(Moulds::new(routing, radius_mm, params)?))
    }

    /// The part of a kind.
    pub fn part(&self, kind: PartKind) -> &Part {
        match kind {
            PartKind::Tray => &self.tray,
            PartKind::Lid => &self.lid,
            PartKind::Cover => &self.cover,
        }
    }

    /// The parts of mould 1 (tray, lid) or 2 (tray, cover).
    pub fn kinds(number: u8) -> [PartKind; 2] {
        if number == 1 {
            [PartKind::Tray, PartKind::Lid]
        } else {
            [PartKind::Tray, PartKind::Cover]
        }
    }

    /// The print plate of mould `number`: both parts on z = 0, side by side in y.
    pub fn plate(&self, number: u8) -> (Mesh, Vec<PlacedPart>) {
        let mut mesh = Mesh::default();
        let mut placed = Vec::new();
        for (k, kind) in Self::kinds(number).into_iter().enumerate() {
            let m = &self.moulds;
            let offset = [0.0, k as f64 * (2.0 * m.y_half_mm() + PLATE_GAP_MM), -m.z_bottom_mm(kind)];
            let part = self.part(kind).mesh.translated(offset);
            let report = part.check();
            placed.push(PlacedPart {
                part: kind,
                letter: kind.letter(),
                offset_mm: offset,
                volume_mm3: report.volume_mm3,
                triangles: report.triangles,
                watertight: report.is_watertight(),
            });
            mesh.append(&part);
        }
        (mesh, placed)
    }

    /// Cavity volume of mould `number` measured on the part meshes, mm³.
    pub fn cavity_volume_mm3(&self, number: u8) -> f64 {
        let (x, r) = (self.moulds.cavity_x_mm(), self.moulds.radius_mm());
        Self::kinds(number).iter().map(|k| volume_below_face_mm3(&self.part(*k).mesh, x, r)).sum()
    }

    /// The body volume the cavity of mould `number` should have, mm³.
    pub fn body_volume_mm3(&self, number: u8) -> f64 {
        let m = &self.moulds;
        let [c0, c1] = m.cavity_x_mm();
        let full = std::f64::consts::PI * m.radius_mm().powi(2) * (c1 - c0);
        if number == 1 {
            full / 2.0 - std::f64::consts::PI * m.tube_radius_mm.powi(2) / 2.0 * m.channel_length_mm()
        } else {
            full
        }
    }

    /// Writes the mould directory `dir` as a whole: its files are written
    /// into a staging directory beside it, which then replaces `dir`
    /// ([`crate::io::write_dir_replacing`]), so a killed run leaves no
    /// partial `dir` (and an earlier one whole). `dir` must be new, empty or
    /// an earlier mould directory (it has [`SUMMARY_FILE`]).
    pub fn write_dir(&self, dir: &Path) -> Result<MouldSummary, MouldError> {
        let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).filter(|n| n != "." && n != "..");
        let Some(name) = name else {
            return Err(MouldError::OutUnnamed { path: dir.to_path_buf() });
        };
        let holds_files = std::fs::read_dir(dir).is_ok_and(|mut entries| entries.next().is_some());
        if holds_files && !dir.join(SUMMARY_FILE).is_file() {
            return Err(MouldError::NotAMouldDir { path: dir.to_path_buf() });
        }
        crate::io::write_dir_replacing(dir, &name, |staging| self.write_all(staging), |step, path, source| {
            let what = match step {
                crate::io::DirStep::Create => "creating",
                crate::io::DirStep::Replace => "putting the new moulds in place at",
            };
            MouldError::Io { context: format!("{what} {}", path.display()), source }
        })
    }

    /// Writes mould1.stl, mould2.stl, mould1.png, mould2.png, channel.csv and
    /// mould.json into `dir` (created if missing), in place: [`MouldSet::write_dir`]
    /// is what `cablemap mould` uses; `design --moulds` writes them among
    /// its own files.
    pub fn write_all(&self, dir: &Path) -> Result<MouldSummary, MouldError> {
        let io = |context: String| move |source| MouldError::Io { context, source };
        std::fs::create_dir_all(dir).map_err(io(format!("creating {}", dir.display())))?;
        let m = &self.moulds;
        let routing = m.routing();
        let ys = routing.control_points_mm().iter().map(|y| format!("{y:.3}")).collect::<Vec<_>>().join(",");
        let mut files = Vec::new();
        for number in [1u8, 2] {
            let (mesh, placed) = self.plate(number);
            let title = format!("cablemap mould{number}, units mm, L={} r={} y=[{ys}]", routing.length_mm(), m.radius_mm());
            let name = format!("mould{number}.stl");
            let path = dir.join(&name);
            crate::io::write_atomic(&path, &stl::to_bytes(&mesh, &title)).map_err(io(format!("writing {}", path.display())))?;
            preview::write_png(&dir.join(format!("mould{number}.png")), self, number)?;
            files.push(MouldFile { file: name, parts: placed });
        }
        let path = dir.join("channel.csv");
        crate::io::write_atomic(&path, routing.channel_csv().as_bytes())
            .map_err(io(format!("writing {}", path.display())))?;
        let summary = MouldSummary {
            routing_mm: routing.control_points_mm(),
            length_mm: routing.length_mm(),
            radius_mm: m.radius_mm(),
            params: m.params().clone(),
            channel_length_mm: m.channel_length_mm(),
            files,
            mould1_cavity_mm3: self.cavity_volume_mm3(1),
            mould1_body_mm3: self.body_volume_mm3(1),
            mould2_cavity_mm3: self.cavity_volume_mm3(2),
            mould2_body_mm3: self.body_volume_mm3(2),
        };
        let path = dir.join(SUMMARY_FILE);
        let json = serde_json::to_string_pretty(&summary).expect("summary serialises") + "\n";
        crate::io::write_atomic(&path, json.as_bytes()).map_err(io(format!("writing {}", path.display())))?;
        Ok(summary)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ROUTINGS: [[f64; 5]; 4] = [[1.0, -2.0, 3.0, 0.5, -3.0], [0.0; 5], [4.0, 4.0, -4.0, 4.0, 4.0], [-4.1, 0.0, 4.1, -2.0, 0.0]];

    fn set(y: &[f64; 5], params: &MouldParams) -> MouldSet {
        MouldSet::new(&Routing::new(y, 65.0, 5.0).unwrap(), 5.0, params).unwrap()
    }

    fn variants() -> Vec<MouldParams> {
        let d = MouldParams::default();
        vec![
            d.clone(),
            MouldParams { clamp_mm: 0.0, ..d.clone() },
            MouldParams { wall_mm: 5.0, clearance_mm: 0.3, ..d.clone() },
            MouldParams { tube_diameter_mm: 0.6, clearance_mm: 0.0, min_skin_mm: 0.2, ..d },
        ]
    }

    /// Segments where the plane x = `x` cuts the mesh's triangles, as (y, z) pairs.
    pub(crate) fn slice(mesh: &Mesh, x: f64) -> Vec<[(f64, f64); 2]> {
        let mut out = Vec::new();
        for t in &mesh.triangles {
            let mut pts = Vec::new();
            for k in 0..3 {
                let (a, b) = (mesh.vertices[t[k] as usize], mesh.vertices[t[(k + 1) % 3] as usize]);
                if (a[0] - x) * (b[0] - x) < 0.0 {
                    let f = (x - a[0]) / (b[0] - a[0]);
                    pts.push((a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])));
                }
            }
            if pts.len() == 2 {
                out.push([pts[0], pts[1]]);
            }
        }
        out
    }

    #[test]
    fn every_part_is_watertight_also_after_stl() {
        for y in &ROUTINGS {
            for p in variants() {
                let s = set(y, &p);
                for kind in [PartKind::Tray, PartKind::Lid, PartKind::Cover] {
                    let mesh = &s.part(kind).mesh;
                    let r = mesh.check();
                    assert!(r.is_watertight(), "{kind:?} {y:?} {p:?}: {r:?}");
                    assert_eq!(r.shell_volumes_mm3.len(), 1, "{kind:?}: one piece");
                    // The file stores f32: it must stay closed after that rounding.
                    let (_, back) = stl::read(&stl::to_bytes(mesh, "t")).unwrap();
                    let rb = back.check();
                    assert!(rb.is_watertight(), "{kind:?} {y:?} {p:?} as STL: {rb:?}");
                    assert!((rb.volume_mm3 - r.volume_mm3).abs() < 1e-4 * r.volume_mm3);
                }
                for number in [1, 2] {
                    let (plate, placed) = s.plate(number);
                    let r = plate.check();
                    assert!(r.is_watertight() && r.shell_volumes_mm3.len() == 2, "{r:?}");
                    assert!(placed.iter().all(|p| p.watertight));
                    // Every part sits on the bed.
                    assert!(plate.bounds_mm().0[2].abs() < 1e-9);
                }
            }
        }
    }

    #[test]
    fn the_protrusion_follows_the_routing_with_the_tube_diameter() {
        for y in &ROUTINGS {
            for p in variants() {
                let s = set(y, &p);
                let lid = &s.lid.mesh;
                let rho = p.tube_diameter_mm / 2.0;
                let routing = s.moulds.routing();
                let mut x = -p.clamp_mm + 0.137;
                while x < 65.0 {
                    let yc = s.moulds.channel_y_mm(x);
                    // Print frame: the lid is turned over, its protrusion at −y_c.
                    let near = |q: &(f64, f64)| (q.0 + yc).abs() < 3.0 * rho;
                    let segs: Vec<[(f64, f64); 2]> = slice(lid, x).into_iter().filter(|g| near(&g[0]) && near(&g[1])).collect();
                    let crest = segs.iter().flatten().copied().fold((0.0, f64::NEG_INFINITY), |a, q| if q.1 > a.1 { q } else { a });
                    assert!((-crest.0 - yc).abs() < 0.02, "x = {x}: crest at y = {} vs y_c = {yc}", -crest.0);
                    assert!((crest.1 - rho).abs() < 0.02, "x = {x}: crest height {} vs ρ = {rho}", crest.1);
                    // Width at half height across the channel: √3 ρ for a half tube of radius ρ.
                    let crossings: Vec<f64> = segs
                        .iter()
                        .filter(|g| (g[0].1 - rho / 2.0) * (g[1].1 - rho / 2.0) < 0.0)
                        .map(|g| g[0].0 + (rho / 2.0 - g[0].1) / (g[1].1 - g[0].1) * (g[1].0 - g[0].0))
                        .collect();
                    let (lo, hi) = crossings.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), y| (l.min(*y), h.max(*y)));
                    let slope = if x > 0.0 { routing.channel_at(x).dy_ds } else { 0.0 };
                    let width = (hi - lo) / (1.0 + slope * slope).sqrt();
                    assert!((width - 3f64.sqrt() * rho).abs() < 0.02, "x = {x}: half-height width {width} vs √3 ρ = {}", 3f64.sqrt() * rho);
                    x += 0.731;
                }
            }
        }
    }

    #[test]
    fn cavities_hold_the_body() {
        for y in &ROUTINGS {
            for p in variants() {
                let s = set(y, &p);
                for number in [1, 2] {
                    let (cavity, body) = (s.cavity_volume_mm3(number), s.body_volume_mm3(number));
                    assert!(((cavity - body) / body).abs() < 0.005, "mould {number} {y:?} {p:?}: cavity {cavity} vs body {body}");
                }
                // The groove is really there: the protrusion inside the cavity is half the tube.
                let ridge = -volume_below_face_mm3(&s.lid.mesh, s.moulds.cavity_x_mm(), 5.0);
                let channel = std::f64::consts::PI * (p.tube_diameter_mm / 2.0).powi(2) / 2.0 * s.moulds.channel_length_mm();
                assert!((ridge - channel).abs() < 0.02 * channel, "protrusion {ridge} mm³ vs half tube {channel} mm³");
            }
        }
    }

    /// Triangles with every corner in |y| ≤ `y_max`, as canonical
    /// (rotation-normalised, rounded) corner lists.
    fn region(mesh: &Mesh, y_lo: f64, y_hi: f64) -> Vec<[[i64; 3]; 3]> {
        let mut out: Vec<[[i64; 3]; 3]> = mesh
            .triangles
            .iter()
            .filter_map(|t| {
                let c = t.map(|i| mesh.vertices[i as usize]);
                if !c.iter().all(|p| p[1] >= y_lo && p[1] <= y_hi) {
                    return None;
                }
                let q = c.map(|p| p.map(|v| (v * 1e5).round() as i64));
                let k = (0..3).min_by_key(|&k| q[k]).unwrap();
                Some([q[k], q[(k + 1) % 3], q[(k + 2) % 3]])
            })
            .collect();
        out.sort();
        out
    }

    #[test]
    fn a_mirrored_routing_gives_mirrored_moulds_but_not_mirrored_marks() {
        let p = MouldParams::default();
        for y in &ROUTINGS[..1] {
            let a = set(y, &p);
            let b = set(&y.map(|v| -v), &p);
            let r = 5.0;
            let yb = a.moulds.y_half_mm();
            for kind in [PartKind::Tray, PartKind::Lid, PartKind::Cover] {
                let (ma, mb) = (a.part(kind).mesh.mirrored_y(), &b.part(kind).mesh);
                // Channel, trough, openings: mirror images of each other.
                let (ra, rb) = (region(&ma, -r, r), region(mb, -r, r));
                assert!(ra.len() > 1000);
                assert_eq!(ra, rb, "{kind:?}: the cavity regions are not mirror images");
                // The marks are not mirrored: the mirrored print shows them backwards.
                let band = |m: &Mesh| [region(m, -yb, -r - 1.0), region(m, r + 1.0, yb)];
                assert_ne!(band(&ma), band(mb), "{kind:?}: the marks do not tell the mirrored print apart");
                // Marks, pins and channel together: the mirrored print is not the mirror routing's mould.
                assert_ne!(region(&ma, -yb, yb), region(mb, -yb, yb));
            }
        }
    }

    #[test]
    fn the_marks_read_differently_when_mirrored() {
        for text in ["CL ^+Y", "CL v+Y", "T", "1", "2"] {
            let px = text_pixels(text, 0.0, 0.0);
            let flip_y: Vec<_> = px.iter().map(|(x, y)| (*x, [-y[1], -y[0]])).collect();
            let w = text_width_mm(text);
            let flip_x: Vec<_> = px.iter().map(|(x, y)| ([w - x[1], w - x[0]], *y)).collect();
            let key = |v: &[([f64; 2], [f64; 2])]| {
                let mut k: Vec<[i64; 4]> = v.iter().map(|(x, y)| [x[0], x[1], y[0], y[1]].map(|c| (c * 1e6).round() as i64)).collect();
                k.sort();
                k
            };
            assert_ne!(key(&px), key(&flip_y), "{text} reads the same mirrored in y");
            if text.len() > 1 {
                assert_ne!(key(&px), key(&flip_x), "{text} reads the same mirrored in x");
            }
        }
    }

    #[test]
    fn pins_fit_their_holes_one_way_only() {
        let s = set(&ROUTINGS[0], &MouldParams::default());
        let m = &s.moulds;
        let pins: Vec<Feature> = m.features(PartKind::Tray).into_iter().filter(|f| f.dz_mm > 0.0).collect();
        assert_eq!(pins.len(), 3);
        for f in &pins {
            let (x, y) = ((f.x_mm[0] + f.x_mm[1]) / 2.0, (f.y_mm[0] + f.y_mm[1]) / 2.0);
            assert!(m.height_mm(PartKind::Tray, x, y) > 1.0);
            for kind in [PartKind::Lid, PartKind::Cover] {
                // Turned over onto the tray, (x, y) of the tray is (x, −y) of the part.
                let edge = PIN_MM / 2.0 + 0.05;
                for (dx, dy) in [(0.0, 0.0), (edge, 0.0), (-edge, 0.0), (0.0, edge), (0.0, -edge)] {
                    assert!(m.height_mm(kind, x + dx, -(y + dy)) < -PIN_HEIGHT_MM, "{kind:?}: no hole for the pin at {x},{y}");
                }
            }
        }
        // Turning a half end for end (180° about z) puts a pin where there is no hole.
        let [x0, x1] = m.x_range_mm();
        let turned = pins.iter().any(|f| {
            let (x, y) = ((f.x_mm[0] + f.x_mm[1]) / 2.0, (f.y_mm[0] + f.y_mm[1]) / 2.0);
            m.height_mm(PartKind::Lid, x0 + x1 - x, y) > -PIN_HEIGHT_MM
        });
        assert!(turned);
    }

    #[test]
    fn channels_near_the_surface_and_bad_parameters_are_refused() {
        let p = MouldParams::default();
        let near = Routing::new(&[4.5, 0.0, 0.0, 0.0, 0.0], 65.0, 5.0).unwrap();
        let e = Moulds::new(&near, 5.0, &p).unwrap_err();
        assert!(matches!(e, MouldError::ChannelTooClose { .. }), "{e}");
        assert!(e.to_string().contains("--max-offset-mm"), "{e}");
        let ok = Routing::new(&[1.0, 0.0, 0.0, 0.0, 0.0], 65.0, 5.0).unwrap();
        for bad in [
            MouldParams { tube_diameter_mm: 0.0, ..p.clone() },
            MouldParams { tube_diameter_mm: 6.0, ..p.clone() },
            MouldParams { clearance_mm: -0.1, ..p.clone() },
            MouldParams { wall_mm: 1.0, ..p.clone() },
            MouldParams { clamp_mm: f64::NAN, ..p.clone() },
        ] {
            let e = Moulds::new(&ok, 5.0, &bad).unwrap_err();
            assert!(matches!(e, MouldError::BadParameter { .. }), "{bad:?}: {e}");
        }
        let short = Routing::new(&[0.0; 5], 10.0, 5.0).unwrap();
        assert!(Moulds::new(&short, 5.0, &MouldParams { clamp_mm: 0.0, ..p.clone() }).is_err());
        // A size that is not a number or beyond any printer is refused by name.
        for (bad, name) in [
            (MouldParams { wall_mm: f64::NAN, ..p.clone() }, "wall_mm"),
            (MouldParams { wall_mm: 1e308, ..p.clone() }, "wall_mm"),
            (MouldParams { clamp_mm: 1e7, ..p.clone() }, "clamp_mm"),
        ] {
            match Moulds::new(&ok, 5.0, &bad).unwrap_err() {
                MouldError::BadParameter { name: got, message } => assert_eq!(got, name, "{message}"),
                e => panic!("{e}"),
            }
        }
    }

    /// The size check counts the triangles before meshing: an upper bound
    /// within twice the built meshes' (steps of zero height weld away), so
    /// the limit means about what it says; and a
    /// mould within every size limit but too large to mesh is refused.
    #[test]
    fn the_triangle_estimate_matches_the_meshes_and_bounds_them() {
        for (length, wall) in [(65.0, 3.0), (300.0, 3.0), (65.0, 40.0)] {
            let routing = Routing::new(&[1.0, -2.0, 3.0, 0.5, -3.0], length, 5.0).unwrap();
            let params = MouldParams { wall_mm: wall, ..MouldParams::default() };
            let set = MouldSet::new(&routing, 5.0, &params).unwrap();
            let built: usize = [PartKind::Tray, PartKind::Lid, PartKind::Cover].iter().map(|k| set.part(*k).mesh.check().triangles).sum();
            let estimate = set.moulds.estimated_triangles();
            assert!(estimate >= built as f64 && estimate < 2.0 * built as f64, "L {length}, wall {wall}: {estimate} vs {built}");
        }
        let long = Routing::new(&[1.0, -2.0, 3.0, 0.5, -3.0], 9000.0, 5.0).unwrap();
        let e = Moulds::new(&long, 5.0, &MouldParams { wall_mm: 2000.0, ..MouldParams::default() }).unwrap_err();
        assert!(matches!(e, MouldError::TooLarge { .. }) && e.to_string().contains("triangles"), "{e}");
    }
}
