//! Cable routing: the channel centreline as a parametric cubic B-spline
//! (thesis §2.2, eq. 2.11–2.13; model-notes §2).
//!
//! The five control points sit at s_i = i·L/4 along the rod with lateral
//! offsets y_i. The curve is parametric in ζ ∈ [0, 1] with the clamped knot
//! vector [0,0,0,0,0.5,1,1,1,1]; y_c at an arc length s is found by inverting
//! s(ζ) = s. On each knot span the curve is a cubic polynomial in ζ, so the
//! basis is expanded once into power form and evaluation is a Horner sum.

use serde::{Deserialize, Serialize};

/// Number of control points of a routing (thesis: five).
pub const CONTROL_POINTS: usize = 5;

/// A routing's control-point offsets y_0..y_4 (mm) at s_i = i·L/4 (thesis
/// §2.2): what the sweep enumerates, the design varies and every record
/// stores as `routing_mm`. Serialised as a plain list of five numbers.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(transparent)]
pub struct ControlPoints(pub [f64; CONTROL_POINTS]);

impl ControlPoints {
    /// The offsets as an array, mm.
    pub fn as_array(&self) -> &[f64; CONTROL_POINTS] {
        &self.0
    }

    /// The offsets as a slice, mm.
    pub fn as_slice(&self) -> &[f64] {
        &self.0
    }

    /// The mirror image y_i → −y_i.
    pub fn mirrored(&self) -> Self {
        ControlPoints(self.0.map(|y| -y))
    }
}

impl From<[f64; CONTROL_POINTS]> for ControlPoints {
    fn from(y_mm: [f64; CONTROL_POINTS]) -> Self {
        ControlPoints(y_mm)
    }
}

impl TryFrom<&[f64]> for ControlPoints {
    type Error = RoutingError;

    /// Exactly [`CONTROL_POINTS`] values, else [`RoutingError::WrongCount`].
    fn try_from(y_mm: &[f64]) -> Result<Self, RoutingError> {
        <[f64; CONTROL_POINTS]>::try_from(y_mm).map(ControlPoints).map_err(|_| RoutingError::WrongCount(y_mm.len()))
    }
}

impl<'a> IntoIterator for &'a ControlPoints {
    type Item = &'a f64;
    type IntoIter = std::slice::Iter<'a, f64>;

    fn into_iter(self) -> Self::IntoIter {
        self.0.iter()
    }
}

impl PartialEq<[f64; CONTROL_POINTS]> for ControlPoints {
    fn eq(&self, other: &[f64; CONTROL_POINTS]) -> bool {
        self.0 == *other
    }
}

impl AsRef<[f64]> for ControlPoints {
    fn as_ref(&self) -> &[f64] {
        &self.0
    }
}

impl std::ops::Deref for ControlPoints {
    type Target = [f64; CONTROL_POINTS];

    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

impl std::ops::DerefMut for ControlPoints {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.0
    }
}

/// Why a routing was rejected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RoutingError {
    /// The routing needs exactly [`CONTROL_POINTS`] values.
    #[error("a routing needs exactly {CONTROL_POINTS} control points y0..y4 (mm), got {0}")]
    WrongCount(usize),
    /// A control point is NaN or infinite.
    #[error("control point y{index} is not a finite number ({value}); give finite offsets in mm")]
    NotFinite { index: usize, value: f64 },
    /// A control point lies on or outside the rod surface.
    #[error("control point y{index} = {} mm is outside the body: every |y_i| must be below the radius r = {} mm", crate::io::fmt_num(*value), crate::io::fmt_num(*radius_mm))]
    OutsideBody { index: usize, value: f64, radius_mm: f64 },
    /// The channel leaves a non-uniform body somewhere along s.
    #[error("the channel at s = {s_mm:.2} mm is at y_c = {y_mm:.3} mm, outside the body (radius r(s) = {radius_mm:.3} mm there): move the control points nearer the axis, or widen the radius profile there")]
    ChannelOutsideBody { s_mm: f64, y_mm: f64, radius_mm: f64 },
    /// The actuator's body (profile, segments, anchor) is invalid.
    #[error(transparent)]
    Body(#[from] super::body::BodyError),
    /// Rod length or radius is not positive and finite.
    #[error("rod length ({} mm) and radius ({} mm) must be positive and finite", crate::io::fmt_num(*length_mm), crate::io::fmt_num(*radius_mm))]
    BadGeometry { length_mm: f64, radius_mm: f64 },
}

/// Power-form coefficients c0 + c1 ζ + c2 ζ² + c3 ζ³ of the five basis
/// functions N_{i,3} on the two knot spans [0, 0.5) and [0.5, 1].
///
/// Expanded from the Cox–de Boor recursion (eq. 2.11) with the clamped knots
/// in exact rational arithmetic; checked against the recursion in the unit tests.
const BASIS: [[[f64; 4]; CONTROL_POINTS]; 2] = [
    // span 0: ζ ∈ [0, 0.5)
    [
        [1.0, -6.0, 12.0, -8.0],
        [0.0, 6.0, -18.0, 14.0],
        [0.0, 0.0, 6.0, -8.0],
        [0.0, 0.0, 0.0, 2.0],
        [0.0, 0.0, 0.0, 0.0],
    ],
    // span 1: ζ ∈ [0.5, 1]
    [
        [0.0, 0.0, 0.0, 0.0],
        [2.0, -6.0, 6.0, -2.0],
        [-2.0, 12.0, -18.0, 8.0],
        [2.0, -12.0, 24.0, -14.0],
        [-1.0, 6.0, -12.0, 8.0],
    ],
];

/// The routing of one actuator: five control-point offsets (mm) on a rod of
/// length `length_mm`, validated against the radius.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Routing {
    y_mm: [f64; CONTROL_POINTS],
    length_mm: f64,
    /// Power-form s(ζ) per span.
    s_poly: [[f64; 4]; 2],
    /// Power-form y_c(ζ) per span.
    y_poly: [[f64; 4]; 2],
    /// s at the interior knot ζ = 0.5.
    s_knot_mm: f64,
}

/// One routing spline's offset and its arc-length derivatives at one s
/// (a planar channel's y_c, or one coordinate of a 3-D channel).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoutingPoint {
    /// y_c(s), mm.
    pub y_mm: f64,
    /// dy_c/ds.
    pub dy_ds: f64,
    /// d²y_c/ds², 1/mm.
    pub d2y_ds2: f64,
}

/// Spacing of the channel CSV and drawing samples along the rod, mm.
pub const CHANNEL_STEP_MM: f64 = 0.25;

impl Routing {
    /// Channel centreline samples (s, y_c(s), dy_c/ds) from clamp to tip,
    /// every [`CHANNEL_STEP_MM`] or closer.
    pub fn channel_samples(&self) -> Vec<(f64, f64, f64)> {
        let length = self.length_mm();
        let n = (length / CHANNEL_STEP_MM).ceil() as usize;
        (0..=n)
            .map(|i| {
                let s = length * i as f64 / n as f64;
                let c = self.channel_at(s);
                (s, c.y_mm, c.dy_ds)
            })
            .collect()
    }

    /// The channel centreline as `channel.csv` (written by `design --out` and
    /// `mould`): columns `s_mm,y_mm,dy_ds`, s along the straight body from
    /// the clamp, y lateral from the body axis. This is the file's one writer.
    pub fn channel_csv(&self) -> String {
        use std::fmt::Write as _;
        let mut out = String::from("s_mm,y_mm,dy_ds\n");
        for (s, y, d) in self.channel_samples() {
            let _ = writeln!(out, "{s:.4},{y:.6},{d:.6}");
        }
        out
    }

    /// Builds a routing from control-point offsets `y_mm` (mm) for a rod of
    /// length `length_mm` and radius `radius_mm`. Every |y_i| must be below
    /// the radius so the channel (inside the control polygon's convex hull)
    /// stays inside the body.
    /// Takes a [`ControlPoints`], an array or a slice (a slice of the wrong
    /// length is [`RoutingError::WrongCount`]).
    pub fn new(y_mm: impl AsRef<[f64]>, length_mm: f64, radius_mm: f64) -> Result<Self, RoutingError> {
        let y_mm = y_mm.as_ref();
        if !(length_mm.is_finite() && radius_mm.is_finite() && length_mm > 0.0 && radius_mm > 0.0) {
            return Err(RoutingError::BadGeometry { length_mm, radius_mm });
        }
        if y_mm.len() != CONTROL_POINTS {
            return Err(RoutingError::WrongCount(y_mm.len()));
        }
        for (index, &value) in y_mm.iter().enumerate() {
            if !value.is_finite() {
                return Err(RoutingError::NotFinite { index, value });
            }
            if value.abs() >= radius_mm {
                return Err(RoutingError::OutsideBody { index, value, radius_mm });
            }
        }
        let mut y = [0.0; CONTROL_POINTS];
        y.copy_from_slice(y_mm);
        Ok(Self::from_points_unchecked(y, length_mm))
    }

    /// Builds the routing of actuator `a`: over the cable's length [0, s_k]
    /// (the anchor, or L), with the channel checked against r(s) along s
    /// for a non-uniform body. For the uniform body this is
    /// [`Routing::new`] with the actuator's length and radius.
    pub fn for_actuator(y_mm: impl AsRef<[f64]>, a: &super::Rod) -> Result<Self, RoutingError> {
        let body = a.body()?;
        let Some(body) = body else {
            if a.is_uniform_body() {
                return Routing::new(y_mm, a.length_mm, a.radius_mm);
            }
            // Uniform radius, cable knotted before the tip.
            return Routing::new(y_mm, a.cable_length_mm(), a.radius_mm);
        };
        let y_mm = y_mm.as_ref();
        if y_mm.len() != CONTROL_POINTS {
            return Err(RoutingError::WrongCount(y_mm.len()));
        }
        for (index, &value) in y_mm.iter().enumerate() {
            if !value.is_finite() {
                return Err(RoutingError::NotFinite { index, value });
            }
        }
        let mut y = [0.0; CONTROL_POINTS];
        y.copy_from_slice(y_mm);
        let routing = Self::from_points_unchecked(y, a.cable_length_mm());
        // The channel itself (not the control polygon) against r(s), on the
        // drawing grid and at the profile's points (where r has its kinks).
        let mut at: Vec<f64> = routing.channel_samples().iter().map(|p| p.0).collect();
        at.extend(body.breakpoints_mm().into_iter().filter(|&s| s <= routing.length_mm));
        for s in at {
            let y = routing.channel_at(s).y_mm;
            let r = body.radius_at(s);
            if !(y.abs() < r) {
                return Err(RoutingError::ChannelOutsideBody { s_mm: s, y_mm: y, radius_mm: r });
            }
        }
        Ok(routing)
    }

    /// Builds the spline without checking against a radius (used for the
    /// channel-offset effect, which shifts an already validated routing).
    pub(crate) fn from_points_unchecked(y_mm: [f64; CONTROL_POINTS], length_mm: f64) -> Self {
        let s_ctrl: [f64; CONTROL_POINTS] =
            std::array::from_fn(|i| i as f64 * length_mm / (CONTROL_POINTS - 1) as f64);
        let combine = |values: &[f64; CONTROL_POINTS]| -> [[f64; 4]; 2] {
            let mut out = [[0.0; 4]; 2];
            for (span, basis) in BASIS.iter().enumerate() {
                for (i, poly) in basis.iter().enumerate() {
                    for k in 0..4 {
                        out[span][k] += values[i] * poly[k];
                    }
                }
            }
            out
        };
        let s_poly = combine(&s_ctrl);
        let y_poly = combine(&y_mm);
        let s_knot_mm = horner(&s_poly[1], 0.5);
        Self { y_mm, length_mm, s_poly, y_poly, s_knot_mm }
    }

    /// The control-point offsets y0..y4, mm.
    pub fn control_points_mm(&self) -> ControlPoints {
        ControlPoints(self.y_mm)
    }

    /// Rod length the routing was built for, mm.
    pub fn length_mm(&self) -> f64 {
        self.length_mm
    }

    /// Arc length of the interior knot (ζ = 0.5), mm: the routing is a
    /// polynomial on each side of it, so integrators split there.
    pub fn knot_mm(&self) -> f64 {
        self.s_knot_mm
    }

    /// The same routing with every y_i shifted by `offset_mm` (channel
    /// offset effect, model-notes §6). Not re-checked against the radius:
    /// the offset models a manufacturing error of a valid design.
    pub fn shifted(&self, offset_mm: f64) -> Self {
        Self::from_points_unchecked(self.y_mm.map(|y| y + offset_mm), self.length_mm)
    }

    /// The mirror image (every y_i negated).
    pub fn mirrored(&self) -> Self {
        Self::from_points_unchecked(self.y_mm.map(|y| -y), self.length_mm)
    }

    /// Curve point at parameter ζ: (s, y_c), mm.
    pub fn at_parameter(&self, zeta: f64) -> (f64, f64) {
        let span = usize::from(zeta >= 0.5);
        (horner(&self.s_poly[span], zeta), horner(&self.y_poly[span], zeta))
    }

    /// Parameter ζ with s(ζ) = `s_mm` (Newton on the monotone cubic of the
    /// right span, started from linear interpolation within the span).
    pub fn parameter_at(&self, s_mm: f64) -> f64 {
        let s = s_mm.clamp(0.0, self.length_mm);
        let (span, z_lo, z_hi, s_lo, s_hi) = if s < self.s_knot_mm {
            (0, 0.0, 0.5, 0.0, self.s_knot_mm)
        } else {
            (1, 0.5, 1.0, self.s_knot_mm, self.length_mm)
        };
        let p = &self.s_poly[span];
        let mut z = z_lo + (z_hi - z_lo) * (s - s_lo) / (s_hi - s_lo);
        for _ in 0..50 {
            let f = horner(p, z) - s;
            let df = horner_d1(p, z);
            let step = f / df;
            z = (z - step).clamp(z_lo, z_hi);
            if step.abs() < 1e-15 {
                break;
            }
        }
        z
    }

    /// y_c and its first two arc-length derivatives at `s_mm` (eq. 2.13).
    pub fn channel_at(&self, s_mm: f64) -> RoutingPoint {
        let z = self.parameter_at(s_mm);
        let span = usize::from(z >= 0.5);
        let (sp, yp) = (&self.s_poly[span], &self.y_poly[span]);
        let s1 = horner_d1(sp, z);
        let s2 = horner_d2(sp, z);
        let y1 = horner_d1(yp, z);
        let y2 = horner_d2(yp, z);
        RoutingPoint {
            y_mm: horner(yp, z),
            dy_ds: y1 / s1,
            d2y_ds2: y2 / (s1 * s1) - y1 * s2 / (s1 * s1 * s1),
        }
    }
}

fn horner(c: &[f64; 4], z: f64) -> f64 {
    ((c[3] * z + c[2]) * z + c[1]) * z + c[0]
}

fn horner_d1(c: &[f64; 4], z: f64) -> f64 {
    (3.0 * c[3] * z + 2.0 * c[2]) * z + c[1]
}

fn horner_d2(c: &[f64; 4], z: f64) -> f64 {
    6.0 * c[3] * z + 2.0 * c[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Cox–de Boor recursion (eq. 2.11) evaluated directly.
    fn cox_de_boor(i: usize, p: usize, z: f64, knots: &[f64]) -> f64 {
        if p == 0 {
            let last = knots[i + 1] == 1.0 && z == 1.0 && knots[i] < knots[i + 1];
            return if (knots[i] <= z && z < knots[i + 1]) || last { 1.0 } else { 0.0 };
        }
        let mut out = 0.0;
        let d1 = knots[i + p] - knots[i];
        if d1 > 0.0 {
            out += (z - knots[i]) / d1 * cox_de_boor(i, p - 1, z, knots);
        }
        let d2 = knots[i + p + 1] - knots[i + 1];
        if d2 > 0.0 {
            out += (knots[i + p + 1] - z) / d2 * cox_de_boor(i + 1, p - 1, z, knots);
        }
        out
    }

    #[test]
    fn power_form_matches_cox_de_boor() {
        let knots = [0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0];
        for k in 0..=100 {
            let z = k as f64 / 100.0;
            let span = usize::from(z >= 0.5);
            for i in 0..CONTROL_POINTS {
                let a = cox_de_boor(i, 3, z, &knots);
                let b = horner(&BASIS[span][i], z);
                assert!((a - b).abs() < 1e-12, "N_{i},3({z}): {a} vs {b}");
            }
        }
    }

    #[test]
    fn inversion_and_derivatives_agree_with_finite_differences() {
        let r = Routing::new(&[1.0, -2.0, 4.0, 4.0, -4.0], 65.0, 5.0).unwrap();
        for k in 1..65 {
            let s = k as f64 + 0.3;
            let z = r.parameter_at(s);
            assert!((r.at_parameter(z).0 - s).abs() < 1e-10);
            let h = 1e-4;
            let c = r.channel_at(s);
            let (lo, hi) = (r.channel_at(s - h), r.channel_at(s + h));
            assert!((c.dy_ds - (hi.y_mm - lo.y_mm) / (2.0 * h)).abs() < 1e-6);
            assert!((c.d2y_ds2 - (hi.dy_ds - lo.dy_ds) / (2.0 * h)).abs() < 1e-6);
        }
        // Clamped ends pass through the first and last control points.
        assert!((r.channel_at(0.0).y_mm - 1.0).abs() < 1e-12);
        assert!((r.channel_at(65.0).y_mm + 4.0).abs() < 1e-12);
    }

    #[test]
    fn parametric_curve_is_not_the_naive_one() {
        // s(ζ) is not L·ζ: the knot sits away from L/2.
        let r = Routing::new(&[0.0; 5], 65.0, 5.0).unwrap();
        assert!((r.knot_mm() - 32.5).abs() < 1e-12); // symmetric control s → knot at L/2
        let z = r.parameter_at(10.0);
        assert!((z - 10.0 / 65.0).abs() > 1e-3);
    }

    #[test]
    fn bad_routings_are_rejected() {
        assert_eq!(Routing::new(&[0.0; 4], 65.0, 5.0), Err(RoutingError::WrongCount(4)));
        assert!(matches!(
            Routing::new(&[0.0, 5.0, 0.0, 0.0, 0.0], 65.0, 5.0),
            Err(RoutingError::OutsideBody { index: 1, .. })
        ));
        assert!(matches!(
            Routing::new(&[0.0, 0.0, f64::NAN, 0.0, 0.0], 65.0, 5.0),
            Err(RoutingError::NotFinite { index: 2, .. })
        ));
        assert!(matches!(
            Routing::new(&[0.0; 5], -1.0, 5.0),
            Err(RoutingError::BadGeometry { .. })
        ));
    }
}
