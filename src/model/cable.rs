//! Cables of an actuator: routing (y and z channels), tension and anchor,
//! checked against the body; a cable's `--cable` text form.
//!
//! Each coordinate of the channel is the thesis's parametric cubic B-spline
//! ([`Routing`], model-notes §2): y_c(s) and z_c(s) share s(ζ), so the pair
//! is one parametric space curve r_c(s) = (0, y_c(s), z_c(s)) in the body
//! frame. z ≡ 0 is today's planar routing.

use crate::model::{ActuatorError, CableSpecProblem, DisplacementProblem};
use crate::model::routing::{RoutingPoint, Routing, CHANNEL_STEP_MM, CONTROL_POINTS};
use crate::model::Rod;
use serde::{Deserialize, Serialize};

/// Most cables an actuator may have.
pub const MAX_CABLES: usize = 8;

/// The file of cable `k`'s channel (from 0): `channel_{k+1}.csv`, written by
/// [`Channel::csv`] wherever an actuator's channels are written.
pub fn channel_file_name(k: usize) -> String {
    format!("channel_{}.csv", k + 1)
}

/// Points per knot span at which the channel is checked against the radius.
const RADIUS_CHECK_POINTS_PER_SPAN: usize = 512;

/// One cable: its channel's control points, its actuation (a tension, or a
/// displacement), its stiffness and where it is knotted.
///
/// In a file (TOML `[[cable]]`) a cable gives exactly one of `tension_n`
/// and `displacement_mm`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "CableFile", into = "CableFile")]
pub struct Cable {
    /// Lateral (body y) control points y_0 … y_4, mm.
    pub y_mm: [f64; CONTROL_POINTS],
    /// Out-of-plane (body z) control points z_0 … z_4, mm; all zero for a planar cable.
    pub z_mm: [f64; CONTROL_POINTS],
    /// Tension pulled at the base, N (≥ 0): the actuation of a
    /// tension-driven cable; of a displacement-driven one, the tension the
    /// solve found (the start of the next solve).
    pub tension_n: f64,
    /// The displacement Δℓ pulled in at the base, mm, when the cable is
    /// driven by displacement (a motor's position) rather than by tension:
    /// the change of its path length from the straight, unloaded rod's, plus
    /// its own stretch under tension ([`Cable::cable_ea_n`]). A cable pulled
    /// in less than its path needs carries no tension (slack).
    pub displacement_mm: Option<f64>,
    /// The cable's axial stiffness EA, N (its stretch under tension τ is
    /// τ/EA per unit length); `None` is inextensible.
    pub cable_ea_n: Option<f64>,
    /// Arc length s_k of the knot, mm (0 < s_k ≤ L); `None` is the tip.
    /// The five control points span the cable, [0, s_k] (as the planar
    /// `cable_anchor_mm`); beyond s_k the cable is slack and carries no load.
    pub anchor_mm: Option<f64>,
}

/// How a cable is driven at the base: the one actuation type of every
/// solve, ladder, capture and sweep row.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Actuation {
    /// Pulled with this tension, N.
    Tension(f64),
    /// Pulled in by this length, mm (its tension is found by the solve).
    Displacement(f64),
}

impl Actuation {
    /// The same actuation scaled by `fraction` (a continuation ladder's rung).
    pub fn scaled(self, fraction: f64) -> Actuation {
        match self {
            Actuation::Tension(t) => Actuation::Tension(t * fraction),
            Actuation::Displacement(d) => Actuation::Displacement(d * fraction),
        }
    }
}

/// A cable as the actuator file writes it (exactly one actuation).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CableFile {
    y_mm: [f64; CONTROL_POINTS],
    #[serde(default)]
    z_mm: [f64; CONTROL_POINTS],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    tension_n: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    displacement_mm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    cable_ea_n: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    anchor_mm: Option<f64>,
}

/// A `[[cable]]` table without exactly one actuation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ActuationError {
    /// Neither a tension nor a displacement.
    #[error("a cable needs its actuation: tension_n = … (N) or displacement_mm = … (mm)")]
    Missing,
    /// Both.
    #[error("a cable is driven either by tension_n or by displacement_mm, not both: give one")]
    Both,
}

impl TryFrom<CableFile> for Cable {
    type Error = ActuationError;
    fn try_from(f: CableFile) -> Result<Self, ActuationError> {
        let tension_n = match (f.tension_n, f.displacement_mm) {
            (Some(_), Some(_)) => return Err(ActuationError::Both),
            (None, None) => return Err(ActuationError::Missing),
            (t, _) => t.unwrap_or(0.0),
        };
        Ok(Cable { y_mm: f.y_mm, z_mm: f.z_mm, tension_n, displacement_mm: f.displacement_mm, cable_ea_n: f.cable_ea_n, anchor_mm: f.anchor_mm })
    }
}

impl From<Cable> for CableFile {
    fn from(c: Cable) -> Self {
        let driven = c.displacement_mm.is_some();
        CableFile {
            y_mm: c.y_mm,
            z_mm: c.z_mm,
            tension_n: (!driven).then_some(c.tension_n),
            displacement_mm: c.displacement_mm,
            cable_ea_n: c.cable_ea_n,
            anchor_mm: c.anchor_mm,
        }
    }
}

impl Cable {
    /// A planar cable (z ≡ 0) knotted at the tip.
    pub fn planar(y_mm: [f64; CONTROL_POINTS], tension_n: f64) -> Self {
        Self::spatial(y_mm, [0.0; CONTROL_POINTS], tension_n)
    }

    /// A spatial cable knotted at the tip.
    pub fn spatial(y_mm: [f64; CONTROL_POINTS], z_mm: [f64; CONTROL_POINTS], tension_n: f64) -> Self {
        Self { y_mm, z_mm, tension_n, displacement_mm: None, cable_ea_n: None, anchor_mm: None }
    }

    /// Whether the cable is driven by its displacement (else by its tension).
    pub fn is_displacement_driven(&self) -> bool {
        self.displacement_mm.is_some()
    }

    /// How the cable is driven: its displacement if it has one, else its tension.
    pub fn actuation(&self) -> Actuation {
        match self.displacement_mm {
            Some(d) => Actuation::Displacement(d),
            None => Actuation::Tension(self.tension_n),
        }
    }

    /// The cable driven by `actuation` (a displacement-driven cable's
    /// tension starts at zero).
    pub fn actuated(&self, actuation: Actuation) -> Cable {
        match actuation {
            Actuation::Tension(t) => Cable { tension_n: t, displacement_mm: None, ..self.clone() },
            Actuation::Displacement(d) => Cable { tension_n: 0.0, displacement_mm: Some(d), ..self.clone() },
        }
    }


    /// Whether the channel lies in the body's x–y plane (every z_i = 0).
    pub fn is_planar(&self) -> bool {
        self.z_mm.iter().all(|&z| z == 0.0)
    }

    /// The knot position s_k on a rod of length `length_mm`.
    pub fn anchor_or_tip_mm(&self, length_mm: f64) -> f64 {
        self.anchor_mm.unwrap_or(length_mm)
    }
}

/// A validated cable's channel: the two coordinate splines.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    y: Routing,
    z: Routing,
}

/// The channel's body-frame offset and its first two arc-length derivatives at one s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelPoint {
    /// (y_c, z_c), mm.
    pub r_mm: [f64; 2],
    /// (dy_c/ds, dz_c/ds).
    pub dr_ds: [f64; 2],
    /// (d²y_c/ds², d²z_c/ds²), 1/mm.
    pub d2r_ds2: [f64; 2],
}

impl Channel {
    /// Channel offset and derivatives at `s_mm`.
    pub fn at(&self, s_mm: f64) -> ChannelPoint {
        let (a, b): (RoutingPoint, RoutingPoint) = (self.y.channel_at(s_mm), self.z.channel_at(s_mm));
        ChannelPoint { r_mm: [a.y_mm, b.y_mm], dr_ds: [a.dy_ds, b.dy_ds], d2r_ds2: [a.d2y_ds2, b.d2y_ds2] }
    }

    /// Arc length of the routing's interior knot, mm.
    pub fn knot_mm(&self) -> f64 {
        self.y.knot_mm()
    }

    /// The channel's distance from the rod axis at parameter ζ, mm.
    /// The channel's length in the straight, unloaded rod, ∫ √(1 + y'² + z'²) ds
    /// over [0, `end_mm`], mm (Simpson's rule on 1024 intervals; the bound
    /// of a displacement).
    pub fn rest_length_mm(&self, end_mm: f64) -> f64 {
        let n = 1024;
        let h = end_mm / n as f64;
        let f = |s: f64| {
            let p = self.at(s);
            (1.0 + p.dr_ds[0] * p.dr_ds[0] + p.dr_ds[1] * p.dr_ds[1]).sqrt()
        };
        (0..=n).map(|k| f(k as f64 * h) * if k == 0 || k == n { 1.0 } else if k % 2 == 1 { 4.0 } else { 2.0 }).sum::<f64>() * h / 3.0
    }

    /// The channel of a routing in the bending plane (z ≡ 0), as a cable
    /// with every z_i = 0 has.
    pub fn in_plane(y: &Routing) -> Self {
        Self { y: y.clone(), z: Routing::from_points_unchecked([0.0; CONTROL_POINTS], y.length_mm()) }
    }

    /// The channel as `channel_K.csv` (cable K of an actuator, written by
    /// `design --targets --out` and by `mould` for several channels or a
    /// printed body): `s_mm,y_mm,z_mm,dy_ds,dz_ds` over [0, `end_mm`]
    /// every [`CHANNEL_STEP_MM`] or closer. This is the file's one writer
    /// (the one planar channel's `channel.csv` is [`Routing::channel_csv`]).
    pub fn csv(&self, end_mm: f64) -> String {
        use std::fmt::Write as _;
        let mut out = String::from("s_mm,y_mm,z_mm,dy_ds,dz_ds\n");
        let n = (end_mm / CHANNEL_STEP_MM).ceil().max(1.0) as usize;
        for k in 0..=n {
            let s = end_mm * k as f64 / n as f64;
            let p = self.at(s);
            let _ = writeln!(out, "{s:.4},{:.6},{:.6},{:.6},{:.6}", p.r_mm[0], p.r_mm[1], p.dr_ds[0], p.dr_ds[1]);
        }
        out
    }

    fn radius_at_parameter(&self, zeta: f64) -> (f64, f64) {
        let (s, y) = self.y.at_parameter(zeta);
        let (_, z) = self.z.at_parameter(zeta);
        // √(y² + z²) rather than hypot (libm's is several times slower;
        // millimetre offsets neither overflow nor underflow).
        (s, (y * y + z * z).sqrt())
    }
}

/// Checks every cable against the actuator and builds the channels.
///
/// Errors: no cables or more than [`MAX_CABLES`]; a tension that is negative
/// or not finite; a control point that is not finite or not below the radius;
/// a channel that reaches |r_c| ≥ r anywhere along s (none can when every
/// control point (y_i, z_i) lies inside the disc: the convex hull of the
/// control points holds the channel; otherwise checked at 2·512 + 1
/// points); an anchor outside (0, L]; two cables on
/// the same path (identical control points: the spline is linear in them, so
/// this is exactly "the same curve").
pub fn validate(rod: &Rod, cables: &[Cable]) -> Result<Vec<Channel>, ActuatorError> {
    if cables.is_empty() || cables.len() > MAX_CABLES {
        return Err(ActuatorError::CableCount { count: cables.len(), max: MAX_CABLES });
    }
    let (length, radius) = (rod.length_mm, rod.radius_mm);
    let mut channels = Vec::with_capacity(cables.len());
    for (index, cable) in cables.iter().enumerate() {
        let cable_no = index + 1;
        if !(cable.tension_n.is_finite() && cable.tension_n >= 0.0) {
            return Err(ActuatorError::Tension { cable: cable_no, tension_n: cable.tension_n });
        }
        if let Some(anchor) = cable.anchor_mm {
            if !(anchor.is_finite() && anchor > 0.0 && anchor <= length) {
                return Err(ActuatorError::Anchor { cable: cable_no, anchor_mm: anchor, length_mm: length });
            }
        }
        // The control points span the cable, [0, anchor] (docs/model.md,
        // "Cables"), as the planar solver's `cable_anchor_mm` does.
        let span = cable.anchor_or_tip_mm(length);
        let y = Routing::new(&cable.y_mm, span, radius)
            .map_err(|source| ActuatorError::Routing { cable: cable_no, axis: 'y', source })?;
        let z = Routing::new(&cable.z_mm, span, radius)
            .map_err(|source| ActuatorError::Routing { cable: cable_no, axis: 'z', source })?;
        let channel = Channel { y, z };
        // y and z share the parameter ζ and the basis (non-negative, summing
        // to one), so the channel lies in the convex hull of its control
        // points (y_i, z_i): with all of them inside the disc of radius r,
        // so is every point of it, and the samples are not needed.
        let hull_inside = cable.y_mm.iter().zip(&cable.z_mm).all(|(y, z)| y * y + z * z < radius * radius);
        if !hull_inside {
            let n = 2 * RADIUS_CHECK_POINTS_PER_SPAN;
            for k in 0..=n {
                let (s, dist) = channel.radius_at_parameter(k as f64 / n as f64);
                if dist >= radius {
                    return Err(ActuatorError::OutsideBody { cable: cable_no, s_mm: s, distance_mm: dist, radius_mm: radius });
                }
            }
        }
        if let Some(ea) = cable.cable_ea_n {
            if !(ea.is_finite() && ea > 0.0) {
                return Err(ActuatorError::CableStiffness { cable: cable_no, cable_ea_n: ea });
            }
        }
        if let Some(d) = cable.displacement_mm {
            let bad = |problem| Err(ActuatorError::Displacement { cable: cable_no, displacement_mm: d, problem });
            if !d.is_finite() {
                return bad(DisplacementProblem::NotFinite);
            }
            if d < 0.0 {
                return bad(DisplacementProblem::Negative);
            }
            let rest = channel.rest_length_mm(span);
            if d >= rest {
                return bad(DisplacementProblem::LongerThanCable { rest_length_mm: rest });
            }
        }
        for (other, earlier) in cables[..index].iter().enumerate() {
            if earlier.y_mm == cable.y_mm && earlier.z_mm == cable.z_mm {
                return Err(ActuatorError::SamePath { first: other + 1, second: cable_no });
            }
        }
        channels.push(channel);
    }
    Ok(channels)
}

/// Parses the `--cable` form: `y=Y0,Y1,Y2,Y3,Y4 z=Z0,Z1,Z2,Z3,Z4 tension=T`
/// (whitespace-separated `key=value` fields; `z=` may be left out for a
/// planar cable; `anchor=S` knots it at s = S mm instead of the tip).
impl std::str::FromStr for Cable {
    type Err = ActuatorError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let bad = |problem| ActuatorError::CableSpec { given: text.to_string(), problem };
        let points = |key: &str, value: &str| -> Result<[f64; CONTROL_POINTS], ActuatorError> {
            let v: Vec<f64> = value
                .split(',')
                .map(|x| x.trim().parse::<f64>().map_err(|_| bad(CableSpecProblem::NotANumber { key: key.into(), value: x.trim().into() })))
                .collect::<Result<_, _>>()?;
            v.try_into().map_err(|v: Vec<f64>| bad(CableSpecProblem::ControlPointCount { key: key.into(), expected: CONTROL_POINTS, got: v.len() }))
        };
        let number = |key: &str, value: &str| -> Result<f64, ActuatorError> {
            value.trim().parse::<f64>().map_err(|_| bad(CableSpecProblem::NotANumber { key: key.into(), value: value.into() }))
        };
        let (mut y, mut z, mut tension, mut anchor, mut displacement, mut ea) = (None, None, None, None, None, None);
        for field in text.split_whitespace() {
            let (key, value) = field.split_once('=').ok_or_else(|| bad(CableSpecProblem::NotKeyValue { field: field.into() }))?;
            let slot_taken = |taken: bool| if taken { Err(bad(CableSpecProblem::GivenTwice { key: key.into() })) } else { Ok(()) };
            match key {
                "y" => {
                    slot_taken(y.is_some())?;
                    y = Some(points(key, value)?);
                }
                "z" => {
                    slot_taken(z.is_some())?;
                    z = Some(points(key, value)?);
                }
                "tension" => {
                    slot_taken(tension.is_some())?;
                    tension = Some(number(key, value)?);
                }
                "anchor" => {
                    slot_taken(anchor.is_some())?;
                    anchor = Some(number(key, value)?);
                }
                "displacement" => {
                    slot_taken(displacement.is_some())?;
                    displacement = Some(number(key, value)?);
                }
                "ea" => {
                    slot_taken(ea.is_some())?;
                    ea = Some(number(key, value)?);
                }
                other => return Err(bad(CableSpecProblem::UnknownField { key: other.into() })),
            }
        }
        let y_mm = y.ok_or_else(|| bad(CableSpecProblem::MissingY))?;
        let tension_n = match (tension, displacement) {
            (Some(_), Some(_)) => return Err(bad(CableSpecProblem::TensionAndDisplacement)),
            (None, None) => return Err(bad(CableSpecProblem::NoActuation)),
            (t, _) => t.unwrap_or(0.0),
        };
        Ok(Cable { y_mm, z_mm: z.unwrap_or([0.0; CONTROL_POINTS]), tension_n, displacement_mm: displacement, cable_ea_n: ea, anchor_mm: anchor })
    }
}

/// The `--cable` form that [`Cable`]'s `FromStr` reads back to the same
/// cable bit for bit: `y=…` always, `z=…` only when out of plane, then
/// `tension=…` and `anchor=…` when knotted before the tip. Numbers are
/// Rust's shortest round-trip form.
impl std::fmt::Display for Cable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let list = |v: &[f64]| v.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(",");
        write!(f, "y={}", list(&self.y_mm))?;
        if !self.is_planar() {
            write!(f, " z={}", list(&self.z_mm))?;
        }
        match self.displacement_mm {
            Some(d) => write!(f, " displacement={d}")?,
            None => write!(f, " tension={}", self.tension_n)?,
        }
        if let Some(ea) = self.cable_ea_n {
            write!(f, " ea={ea}")?;
        }
        if let Some(anchor) = self.anchor_mm {
            write!(f, " anchor={anchor}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rod() -> Rod {
        Rod::default()
    }

    #[test]
    fn planar_channel_matches_the_planar_routing() {
        let y = [1.0, -2.0, 3.0, 0.5, -4.0];
        let ch = validate(&rod(), &[Cable::planar(y, 1.0)]).unwrap().remove(0);
        let r = Routing::new(&y, 65.0, 5.0).unwrap();
        for k in 0..=65 {
            let s = k as f64;
            let (a, b) = (ch.at(s), r.channel_at(s));
            assert_eq!(a.r_mm, [b.y_mm, 0.0]);
            assert_eq!(a.dr_ds, [b.dy_ds, 0.0]);
        }
    }

    #[test]
    fn a_channel_whose_control_points_lie_inside_the_disc_lies_inside_everywhere() {
        // The convex hull property that lets validate skip its samples.
        let r = rod().radius_mm;
        let k = 0.99 * r / 2f64.sqrt();
        for (y, z) in [([k, -k, k, -k, k], [k, k, -k, -k, k]), ([0.0, 4.9, -4.9, 0.0, 3.0], [4.9, 0.0, 0.0, -4.9, 3.9])] {
            let channels = validate(&rod(), &[Cable::spatial(y, z, 1.0)]).unwrap();
            for k in 0..=4096 {
                let (s, d) = channels[0].radius_at_parameter(k as f64 / 4096.0);
                assert!(d < r, "{y:?} {z:?}: {d} mm from the axis at s = {s} mm");
            }
        }
        // A control point outside the disc, the channel inside: the samples accept it.
        assert!(validate(&rod(), &[Cable::spatial([0.0, 4.0, 0.0, 0.0, 0.0], [0.0, 3.5, 0.0, 0.0, 0.0], 1.0)]).is_ok());
    }

    #[test]
    fn bad_cables_get_named_errors() {
        let ok = Cable::spatial([1.0; 5], [1.0; 5], 1.0);
        let e = validate(&rod(), &[]).unwrap_err();
        assert!(matches!(e, ActuatorError::CableCount { count: 0, .. }), "{e}");
        let e = validate(&rod(), &vec![ok.clone(); 9]).unwrap_err();
        assert!(matches!(e, ActuatorError::CableCount { count: 9, .. }), "{e}");
        let mut neg = ok.clone();
        neg.tension_n = -0.1;
        let e = validate(&rod(), &[neg]).unwrap_err();
        assert!(matches!(e, ActuatorError::Tension { cable: 1, .. }), "{e}");
        assert!(e.to_string().contains("cable 1"), "{e}");
        // Each coordinate inside, the distance outside: (4, 4) is 5.66 mm from the axis.
        let e = validate(&rod(), &[Cable::spatial([4.0; 5], [4.0; 5], 1.0)]).unwrap_err();
        assert!(matches!(e, ActuatorError::OutsideBody { cable: 1, .. }), "{e}");
        assert!(e.to_string().contains("radius"), "{e}");
        let e = validate(&rod(), &[Cable::spatial([1.0; 5], [0.0, 0.0, 5.5, 0.0, 0.0], 1.0)]).unwrap_err();
        assert!(matches!(e, ActuatorError::Routing { cable: 1, axis: 'z', .. }), "{e}");
        assert!(e.to_string().contains("z"), "{e}");
        let e = validate(&rod(), &[ok.clone(), Cable::planar([-1.0; 5], 1.0), ok.clone()]).unwrap_err();
        assert!(matches!(e, ActuatorError::SamePath { first: 1, second: 3 }), "{e}");
        let mut anchored = ok.clone();
        anchored.anchor_mm = Some(70.0);
        let e = validate(&rod(), &[anchored]).unwrap_err();
        assert!(matches!(e, ActuatorError::Anchor { cable: 1, .. }), "{e}");
    }

    #[test]
    fn cable_text_form_parses_and_names_its_problems() {
        let c: Cable = "y=1,2,3,2,1 z=0,-1,-2,-1,0 tension=1.5".parse().unwrap();
        assert_eq!(c.y_mm, [1.0, 2.0, 3.0, 2.0, 1.0]);
        assert_eq!(c.z_mm, [0.0, -1.0, -2.0, -1.0, 0.0]);
        assert_eq!(c.tension_n, 1.5);
        assert_eq!(c.anchor_mm, None);
        let planar: Cable = "tension=2 y=-1,-1,-1,-1,-1 anchor=40".parse().unwrap();
        assert!(planar.is_planar());
        assert_eq!(planar.anchor_mm, Some(40.0));
        for (text, needle) in [
            ("y=1,2,3 tension=1", "5 control points, got 3"),
            ("y=1,2,3,4,5", "tension= (N) or displacement= (mm) is missing"),
            ("y=1,2,3,4,5 tension=1 displacement=2", "not both"),
            ("z=1,2,3,4,5 tension=1", "y= is missing"),
            ("y=1,2,x,4,5 tension=1", "'x' is not a number"),
            ("y=1,2,3,4,5 tension=1 colour=red", "unknown field 'colour'"),
            ("y=1,2,3,4,5 tension=1 tension=2", "given twice"),
            ("y=1,2,3,4,5 tension", "not key=value"),
        ] {
            let e = text.parse::<Cable>().unwrap_err().to_string();
            assert!(e.contains(needle), "{text}: {e}");
            assert!(e.contains("cable \""), "{e}");
        }
    }

    #[test]
    fn a_cables_text_form_reads_back_to_the_same_cable() {
        for c in [
            Cable::planar([3.0, 1.0, 2.5, 1.0, 3.0], 1.8000000000000003),
            Cable { y_mm: [0.1, -0.2, 0.3, 1e-7, 4.0], z_mm: [0.0, 1.0, -1.5, 0.0, 2.0], tension_n: 0.6, displacement_mm: None, cable_ea_n: None, anchor_mm: Some(40.25) },
            Cable { y_mm: [0.1, -0.2, 0.3, 1e-7, 4.0], z_mm: [0.0; 5], tension_n: 0.0, displacement_mm: Some(1.25), cable_ea_n: Some(800.0), anchor_mm: None },
        ] {
            assert_eq!(c.to_string().parse::<Cable>().unwrap(), c, "{c}");
        }
        assert_eq!(Cable::planar([3.0, 1.0, 1.0, 1.0, 3.0], 1.8).to_string(), "y=3,1,1,1,3 tension=1.8");
    }
}
