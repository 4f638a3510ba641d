//! The two-part moulds of one or more planar channels: the geometry of
//! tray, lid and cover, and each part's heightfield mesh in its print frame.

use super::font::{text_pixels, text_width_mm};
use super::mesh::{heightfield_solid, sided, Mesh, Sided};
use super::{MouldError, MouldParams, ParameterProblem, MAX_TRIANGLES};
use crate::model::Routing;
use serde::Serialize;

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
    pub fn letter(self) -> &'static str {
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
/// Marks: engraving depth, mm (the pixel size is the font's, [`super::font::PIXEL_MM`]).
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

/// The moulds of one or more planar channels (all in the cutting plane):
/// geometry and meshes.
#[derive(Debug, Clone)]
pub struct Moulds {
    /// The channels, in the actuator's cable order.
    channels: Vec<Routing>,
    /// Channel indices in increasing y (the same at every x: channels
    /// closer than the tube are refused, so they never cross).
    order: Vec<usize>,
    length_mm: f64,
    radius_mm: f64,
    params: MouldParams,
    /// Tube radius ρ, mm.
    pub(super) tube_radius_mm: f64,
    /// Widest x-section half-width of each channel's protrusion, ρ·max √(1 + y_c′²), mm.
    ridge_half_width_max_mm: Vec<f64>,
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
    /// Checks the parameters and the routing's channel against the body
    /// (one channel: the thesis's actuator).
    pub fn new(routing: &Routing, radius_mm: f64, params: &MouldParams) -> Result<Self, MouldError> {
        Self::planar(std::slice::from_ref(routing), radius_mm, params)
    }

    /// Checks the parameters and every channel against the body and each
    /// other: each keeps `min_skin_mm` of silicone to the surface
    /// ([`MouldError::ChannelTooClose`]) and to every other channel's tube
    /// ([`MouldError::ChannelsTooClose`]). The channels are the cables'
    /// y_c(s) in the cutting plane, in cable order, all of one length.
    pub fn planar(channels: &[Routing], radius_mm: f64, params: &MouldParams) -> Result<Self, MouldError> {
        let p = params;
        let bad = |name: &'static str, problem| Err(MouldError::BadParameter { name, problem });
        let Some(first) = channels.first() else {
            return bad("channels", ParameterProblem::NoChannel);
        };
        let length = first.length_mm();
        if let Some(k) = channels.iter().position(|c| c.length_mm() != length) {
            return bad("channels", ParameterProblem::ChannelLengths { cable: k + 1, length_mm: channels[k].length_mm(), first_mm: length });
        }
        super::params::check_sizes([
            ("wall_mm", p.wall_mm),
            ("tube_diameter_mm", p.tube_diameter_mm),
            ("clearance_mm", p.clearance_mm),
            ("clamp_mm", p.clamp_mm),
            ("min_skin_mm", p.min_skin_mm),
            ("station_step_mm", p.station_step_mm),
            ("radius_mm", radius_mm),
            ("length_mm", length),
        ])?;
        if p.tube_diameter_mm <= 0.0 || p.tube_diameter_mm > radius_mm {
            return bad("tube_diameter_mm", ParameterProblem::Tube { tube_mm: p.tube_diameter_mm, radius_mm, pour: true });
        }
        if !(0.0..=0.5).contains(&p.clearance_mm) {
            return bad("clearance_mm", ParameterProblem::Clearance { clearance_mm: p.clearance_mm });
        }
        if p.wall_mm < PIN_HEIGHT_MM + p.clearance_mm + 0.8 {
            return bad(
                "wall_mm",
                ParameterProblem::WallTooThin {
                    wall_mm: p.wall_mm,
                    holes_mm: PIN_HEIGHT_MM + p.clearance_mm,
                    least_mm: PIN_HEIGHT_MM + p.clearance_mm + 0.8,
                },
            );
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
        let text_mm = text_width_mm("CL ^+Y");
        if length + p.clamp_mm < text_mm + 12.0 {
            return bad("clamp_mm", ParameterProblem::ClampTooShort { length_mm: length, clamp_mm: p.clamp_mm, needed_mm: text_mm + 12.0 });
        }
        let rho = p.tube_diameter_mm / 2.0;
        // The channel must keep min_skin of silicone to the surface everywhere.
        let limit = p.max_castable_offset_mm(radius_mm);
        let n = (length / 0.05).ceil() as usize;
        let mut widest = vec![1.0_f64; channels.len()];
        for (k, routing) in channels.iter().enumerate() {
            for i in 0..=n {
                let s = length * i as f64 / n as f64;
                let c = routing.channel_at(s);
                widest[k] = widest[k].max((1.0 + c.dy_ds * c.dy_ds).sqrt());
                if c.y_mm.abs() > limit {
                    return Err(MouldError::ChannelTooClose {
                        cable: k + 1,
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
        }
        check_channel_gaps(channels, rho, p.min_skin_mm)?;
        let mut order: Vec<usize> = (0..channels.len()).collect();
        order.sort_by(|a, b| channels[*a].channel_at(0.0).y_mm.total_cmp(&channels[*b].channel_at(0.0).y_mm));
        let moulds = Self {
            channels: channels.to_vec(),
            order,
            length_mm: length,
            radius_mm,
            params: p.clone(),
            tube_radius_mm: rho,
            ridge_half_width_max_mm: widest.iter().map(|w| rho * w).collect(),
            x_range_mm: [-p.clamp_mm - p.wall_mm, length + p.wall_mm],
            y_half_mm: radius_mm + p.wall_mm + BAND_MM,
            sprue_depth_mm: radius_mm / 2.0,
        };
        let triangles = moulds.estimated_triangles();
        if triangles > MAX_TRIANGLES {
            return Err(MouldError::TooLarge { triangles, length_mm: length, radius_mm, wall_mm: p.wall_mm, clamp_mm: p.clamp_mm });
        }
        // The samples across each channel must lie inside the trough, and
        // neighbouring channels' sample blocks (protrusion, tip notch) must
        // not overlap.
        let notch = rho + p.clearance_mm;
        for i in 0..=n {
            let s = length * i as f64 / n as f64;
            let mut prev: Option<(usize, f64, f64, f64)> = None;
            for &k in &moulds.order {
                let w = moulds.ridge_half_width_max_mm[k].max(notch);
                let y = channels[k].channel_at(s).y_mm;
                if y.abs() + w >= radius_mm {
                    return bad(
                        "tube_diameter_mm",
                        ParameterProblem::Protrusion { cable: k + 1, half_width_mm: w, y_mm: y.abs(), radius_mm, s_mm: s },
                    );
                }
                if let Some((j, yj, wj, _)) = prev {
                    if y - w <= yj + wj {
                        let gap = channel_gap_mm(&channels[j], &channels[k], rho);
                        return Err(MouldError::ChannelsTooClose {
                            first: j.min(k) + 1,
                            second: j.max(k) + 1,
                            s_mm: s,
                            gap_mm: gap.0.min(y - yj - 2.0 * rho),
                            needed_mm: (w + wj - 2.0 * rho).max(p.min_skin_mm),
                            tube_mm: p.tube_diameter_mm,
                        });
                    }
                }
                prev = Some((k, y, w, s));
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

    /// The channels the moulds are for, in cable order.
    pub fn channels(&self) -> &[Routing] {
        &self.channels
    }

    /// Body length L, mm.
    pub fn length_mm(&self) -> f64 {
        self.length_mm
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
        [-self.params.clamp_mm, self.length_mm]
    }

    /// Centreline y of channel `k` (cable order, from 0) at x (assembly
    /// frame): y_c(x) on the body, straight along x in the clamp block and
    /// beyond the tip, mm.
    pub fn channel_y_mm(&self, k: usize, x_mm: f64) -> f64 {
        self.channels[k].channel_at(x_mm.clamp(0.0, self.length_mm)).y_mm
    }

    /// dy/dx of the channel at a station: the spline's slope on the body, 0
    /// on the straight ends; at x = 0 and x = L the side picks the limit.
    /// Evaluated at the station itself (not the sided offset) so both sides of
    /// a step elsewhere give bit-identical points.
    fn channel_slope(&self, k: usize, x: Sided) -> f64 {
        let l = self.length_mm;
        let on_body = (x.0 > 0.0 && x.0 < l) || (x.0 == 0.0 && x.1 > 0) || (x.0 == l && x.1 < 0);
        if on_body {
            self.channels[k].channel_at(x.0).dy_ds
        } else {
            0.0
        }
    }

    /// Length of channel `k` inside the cavity (clamp block + arc of y_c), mm.
    pub fn channel_length_mm(&self, k: usize) -> f64 {
        let l = self.length_mm;
        let n = 4000;
        let arc: f64 = (0..n)
            .map(|i| {
                let s = l * (i as f64 + 0.5) / n as f64;
                (1.0 + self.channels[k].channel_at(s).dy_ds.powi(2)).sqrt() * l / n as f64
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
                    // Tip-end wall: a notch per tube (mould 2) or protrusion (mould 1).
                    let rn = self.tube_radius_mm + self.params.clearance_mm;
                    let notch = (0..self.channels.len())
                        .map(|k| {
                            let u = ye - s * self.channel_y_mm(k, c1);
                            if u.abs() < rn {
                                -(rn * rn - u * u).sqrt()
                            } else {
                                0.0
                            }
                        })
                        .fold(0.0, f64::min);
                    notch.max(trough(r, ye))
                }
            }
            PartKind::Lid => {
                // The protrusions: in an x-section the half tube of radius ρ
                // about a channel is a half ellipse ρ·√(1 + y_c′²) wide;
                // the channels' are disjoint (checked in `planar`).
                let rho = self.tube_radius_mm;
                (0..self.channels.len())
                    .map(|k| {
                        let w = rho * (1.0 + self.channel_slope(k, x).powi(2)).sqrt();
                        let u = ye - s * self.channel_y_mm(k, x.0);
                        if u.abs() < w {
                            rho * (1.0 - (u / w).powi(2)).sqrt()
                        } else {
                            0.0
                        }
                    })
                    .fold(0.0, f64::max)
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
    /// each channel that moves with it (so each crest is a grid line). The
    /// count is the same at every station.
    fn samples(&self, kind: PartKind, features: &[Feature], x: Sided) -> Vec<Sided> {
        let s = kind.frame_sign();
        let r = self.radius_mm;
        let mut edges: Vec<f64> = features.iter().flat_map(|f| f.y_mm).collect();
        edges.sort_by(f64::total_cmp);
        edges.dedup();
        // Blocks (centre, half-width) in increasing print-frame y.
        let mut blocks: Vec<(f64, f64)> = self
            .order
            .iter()
            .map(|&k| match kind {
                PartKind::Lid => (s * self.channel_y_mm(k, x.0), self.ridge_half_width_max_mm[k]),
                PartKind::Tray | PartKind::Cover => (s * self.channel_y_mm(k, self.length_mm), self.tube_radius_mm + self.params.clearance_mm),
            })
            .collect();
        if s < 0.0 {
            blocks.reverse();
        }
        let n_side = match kind {
            PartKind::Lid => 4,
            PartKind::Tray | PartKind::Cover => TROUGH_SAMPLES,
        };
        let pi = std::f64::consts::PI;
        let mut out: Vec<Sided> = vec![(-self.y_half_mm, 0)];
        out.extend(edges.iter().filter(|e| **e < -r).flat_map(|e| [(*e, -1), (*e, 1)]));
        // Trough left of the first block: y = r cos φ, φ from π down to φ_a.
        let (c, w) = blocks[0];
        let phi_a = ((c - w) / r).clamp(-1.0, 1.0).acos();
        out.extend((0..n_side).map(|k| (r * (pi - (pi - phi_a) * k as f64 / n_side as f64).cos(), 0)));
        for (i, &(c, w)) in blocks.iter().enumerate() {
            if i > 0 {
                // Trough between two blocks, both ends excluded.
                let (cp, wp) = blocks[i - 1];
                let phi_b = ((cp + wp) / r).clamp(-1.0, 1.0).acos();
                let phi_a = ((c - w) / r).clamp(-1.0, 1.0).acos();
                out.extend((1..n_side).map(|k| (r * (phi_b + (phi_a - phi_b) * k as f64 / n_side as f64).cos(), 0)));
            }
            out.extend((0..=CHANNEL_SAMPLES).map(|k| {
                let theta = pi * (1.0 - k as f64 / CHANNEL_SAMPLES as f64);
                (c + w * theta.cos(), 0)
            }));
        }
        let (c, w) = blocks[blocks.len() - 1];
        let phi_b = ((c + w) / r).clamp(-1.0, 1.0).acos();
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

#[cfg(test)]
#[path = "tests.rs"]
mod tests;

/// The smallest silicone gap between the tubes (diameter 2ρ) of two planar
/// channels, mm, and the arc length s on `a` where it occurs: the least
/// distance between the centrelines (x = s, y = y_c(s)) less 2ρ. Sampled
/// every 0.02 mm along both; only pairs within 2ρ + 3 mm in x are compared
/// (farther pairs are farther apart than that anyway).
pub(super) fn channel_gap_mm(a: &Routing, b: &Routing, rho: f64) -> (f64, f64) {
    let pts = |r: &Routing| -> Vec<[f64; 2]> {
        let l = r.length_mm();
        let n = (l / 0.02).ceil() as usize;
        (0..=n).map(|i| l * i as f64 / n as f64).map(|s| [s, r.channel_at(s).y_mm]).collect()
    };
    let (pa, pb) = (pts(a), pts(b));
    let window = 2.0 * rho + 3.0;
    let mut best = (f64::INFINITY, 0.0);
    let mut lo = 0;
    for p in &pa {
        while lo < pb.len() && pb[lo][0] < p[0] - window {
            lo += 1;
        }
        for q in pb[lo..].iter().take_while(|q| q[0] <= p[0] + window) {
            let d = (p[0] - q[0]).hypot(p[1] - q[1]);
            if d < best.0 - 1e-9 {
                best = (d, p[0]);
            }
        }
    }
    (best.0.min(window) - 2.0 * rho, best.1)
}

/// Refuses two channels whose tubes keep less than `min_skin_mm` of
/// silicone between them ([`MouldError::ChannelsTooClose`]).
fn check_channel_gaps(channels: &[Routing], rho: f64, min_skin_mm: f64) -> Result<(), MouldError> {
    for (i, a) in channels.iter().enumerate() {
        for (j, b) in channels.iter().enumerate().skip(i + 1) {
            let (gap, s) = channel_gap_mm(a, b, rho);
            if gap < min_skin_mm {
                return Err(MouldError::ChannelsTooClose { first: i + 1, second: j + 1, s_mm: s, gap_mm: gap, needed_mm: min_skin_mm, tube_mm: 2.0 * rho });
            }
        }
    }
    Ok(())
}
