//! The one result of a solve, whichever backend served it: the tip pose
//! ([`TipPose`], `Copy` and fixed-size: what a sweep keeps of each solve),
//! the centreline ([`CentrelinePoint`], a node with its frame, strains and
//! every cable's channel, path and tension) and a single solve's
//! [`Simulation`] (pose, centreline, the three coefficient series). A
//! planar solve is the special case: z = 0, a frame turning about z only,
//! one cable, the out-of-plane and twist series zero.

use crate::model::cable::MAX_CABLES;
use crate::model::routing::ControlPoints;
use crate::solver::Backend;
use crate::model::Actuator;
use crate::shape::LengthBasis;

/// One value per cable, cables 1 … `len()` (at most [`MAX_CABLES`]): fixed
/// size, so that a pose and a node are `Copy` and never allocate. Reads as
/// a slice of the cables' values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerCable<T> {
    count: usize,
    values: [T; MAX_CABLES],
}

impl<T: Copy> PerCable<T> {
    /// `count` cables, each `value`.
    ///
    /// # Panics
    /// If `count` is above [`MAX_CABLES`].
    pub fn filled(count: usize, value: T) -> Self {
        assert!(count <= MAX_CABLES, "{count} cables: at most {MAX_CABLES}");
        Self { count, values: [value; MAX_CABLES] }
    }

    /// One cable with `value`.
    pub fn one(value: T) -> Self {
        Self::filled(1, value)
    }
}

impl<T> std::ops::Deref for PerCable<T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        &self.values[..self.count]
    }
}

impl<T> std::ops::DerefMut for PerCable<T> {
    fn deref_mut(&mut self) -> &mut [T] {
        &mut self.values[..self.count]
    }
}

/// The tip's frame of a solve that leaves the x–y plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipFrame {
    /// Unit tangent of the centreline at the tip, global: R v/|v|.
    pub tangent: [f64; 3],
    /// The tip cross-section's body y axis, global (column 2 of R).
    pub body_y_axis: [f64; 3],
}

/// The scalar results of one solve.
///
/// The angles are measured in the x–y plane: a planar solve integrates them
/// from the clamp (signed, continuous, not wrapped), the spatial backend
/// reports those of the projections on the plane (wrapped to (−π, π]).
/// The angle of the tip tangent from the clamp axis in 3-D is
/// [`TipPose::angle_from_clamp_axis_rad`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipPose {
    /// Each cable's tension at the base, N.
    pub tensions_n: PerCable<f64>,
    /// Each cable's displacement Δℓ at the base, mm: its path's shortening
    /// from the straight, unloaded rod's plus its own stretch ∫ τ(s)/EA dℓ
    /// (the length a motor pulled in); NaN from the RK4 references, which
    /// do not integrate the cables' paths.
    pub displacements_mm: PerCable<f64>,
    /// Tip position along the clamp axis, mm.
    pub tip_x_mm: f64,
    /// Tip position across the clamp axis, in the plane of a planar cable, mm.
    pub tip_y_mm: f64,
    /// Tip position out of that plane, mm (0 for a planar solve).
    pub tip_z_mm: f64,
    /// Tangent angle θ(L) of the centreline at the tip, from the clamp axis
    /// (+x) toward +y, rad (see the type's note on the plane).
    pub tip_angle_rad: f64,
    /// Angle φ(L) of the tip cross-section's axis (the frame angle), rad.
    pub tip_frame_angle_rad: f64,
    /// Tangent angle of the centreline at the clamp, rad (non-zero with shear).
    pub base_angle_rad: f64,
    /// Deformed arc length ℓ of the centreline, mm.
    pub length_mm: f64,
    /// Integration passes used (1 without distributed loads).
    pub iterations: u32,
    /// The tip frame of a spatial solve; `None` for a planar one, whose
    /// frame turns about z by the angles above.
    pub frame_3d: Option<TipFrame>,
}

impl TipPose {
    /// Cable 1's tension, N: the planar solve's one tension.
    pub fn tension_n(&self) -> f64 {
        self.tensions_n[0]
    }

    /// Cable 1's displacement, mm: the planar solve's one cable's.
    pub fn displacement_mm(&self) -> f64 {
        self.displacements_mm[0]
    }

    /// Tip position (x, y, z), mm.
    pub fn tip_mm(&self) -> [f64; 3] {
        [self.tip_x_mm, self.tip_y_mm, self.tip_z_mm]
    }

    /// Unit tangent of the centreline at the tip, global: (cos θ, sin θ, 0)
    /// for a planar solve.
    pub fn tip_tangent(&self) -> [f64; 3] {
        match &self.frame_3d {
            Some(f) => f.tangent,
            None => {
                let (s, c) = self.tip_angle_rad.sin_cos();
                [c, s, 0.0]
            }
        }
    }

    /// The tip cross-section's body y axis, global: (−sin φ, cos φ, 0) for a
    /// planar solve.
    pub fn tip_body_y_axis(&self) -> [f64; 3] {
        match &self.frame_3d {
            Some(f) => f.body_y_axis,
            None => {
                let (s, c) = self.tip_frame_angle_rad.sin_cos();
                [-s, c, 0.0]
            }
        }
    }

    /// The angle between the tip tangent and the clamp axis (+x) in space,
    /// rad, in [0, π] (unsigned: |θ(L)| for a planar solve bent by less than π).
    pub fn angle_from_clamp_axis_rad(&self) -> f64 {
        self.tip_tangent()[0].clamp(-1.0, 1.0).acos()
    }
}

/// A pose serialises as the planar record's pose fields (the top level of
/// `simulate --json` with `--routing`): tension, tip x and y, the three
/// angles, length and iterations.
impl serde::Serialize for TipPose {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut s = serializer.serialize_struct("TipPose", 8)?;
        s.serialize_field("tension_n", &self.tension_n())?;
        s.serialize_field("tip_x_mm", &self.tip_x_mm)?;
        s.serialize_field("tip_y_mm", &self.tip_y_mm)?;
        s.serialize_field("tip_angle_rad", &self.tip_angle_rad)?;
        s.serialize_field("tip_frame_angle_rad", &self.tip_frame_angle_rad)?;
        s.serialize_field("base_angle_rad", &self.base_angle_rad)?;
        s.serialize_field("length_mm", &self.length_mm)?;
        s.serialize_field("iterations", &self.iterations)?;
        s.end()
    }
}

/// One cable at one centreline node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CableAtNode {
    /// The channel's offset (y_c, z_c) in the body frame, mm; NaN beyond
    /// the cable's anchor (no channel there).
    pub channel_mm: [f64; 2],
    /// The cable's position, global, mm; NaN beyond the cable's anchor (the
    /// centreline has a node exactly at the anchor, where the cable ends).
    pub position_mm: [f64; 3],
    /// The cable's tension here, N (varies along s with friction; 0 beyond
    /// its anchor).
    pub tension_n: f64,
}

impl CableAtNode {
    /// No cable at this node (beyond its anchor).
    pub const NONE: CableAtNode = CableAtNode { channel_mm: [f64::NAN; 2], position_mm: [f64::NAN; 3], tension_n: 0.0 };

    /// Whether the cable runs through this node (not beyond its anchor).
    pub fn is_present(&self) -> bool {
        self.position_mm[0].is_finite()
    }
}

/// One node of a solved centreline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentrelinePoint {
    /// Reference arc length s, mm.
    pub s_mm: f64,
    /// Position along the clamp axis, mm.
    pub x_mm: f64,
    /// Position across it, mm.
    pub y_mm: f64,
    /// Position out of the x–y plane, mm (0 for a planar solve).
    pub z_mm: f64,
    /// Body frame R, by rows (`rotation[i][j]`; its columns are the body
    /// axes in the global frame).
    pub rotation: [[f64; 3]; 3],
    /// Frame angle φ in the x–y plane, rad (planar: continuous from the
    /// clamp; spatial: of the body x axis' projection, wrapped).
    pub frame_angle_rad: f64,
    /// Centreline tangent angle θ = φ + atan2(v2, v1) in the x–y plane, rad
    /// (spatial: of the tangent's projection, wrapped).
    pub tangent_angle_rad: f64,
    /// Deformed arc length from the clamp σ, mm.
    pub arc_length_mm: f64,
    /// Strains v (stretch v1, shears v2, v3) in the body frame.
    pub v: [f64; 3],
    /// Curvatures u (twist u1, bending u2 about body y, u3 about body z:
    /// the planar curvature) in the body frame, 1/mm.
    pub u_per_mm: [f64; 3],
    /// Each cable here.
    pub cables: PerCable<CableAtNode>,
}

impl CentrelinePoint {
    /// Position (x, y, z), mm.
    pub fn position_mm(&self) -> [f64; 3] {
        [self.x_mm, self.y_mm, self.z_mm]
    }

    /// Global position of a point at body offset (0, y, z), mm.
    pub fn body_point_mm(&self, y_mm: f64, z_mm: f64) -> [f64; 3] {
        let (r, p) = (&self.rotation, self.position_mm());
        std::array::from_fn(|i| p[i] + r[i][1] * y_mm + r[i][2] * z_mm)
    }
}

/// A node of a planar solve in its own terms; [`CentrelinePoint::from`]
/// turns it into the general node (frame about z, z = 0, one cable).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarPoint {
    /// Reference arc length s, mm.
    pub s_mm: f64,
    /// Position, mm.
    pub x_mm: f64,
    /// Position, mm.
    pub y_mm: f64,
    /// Frame angle φ, rad.
    pub frame_angle_rad: f64,
    /// (sin φ, cos φ).
    pub frame_sin_cos: (f64, f64),
    /// Tangent angle θ, rad.
    pub tangent_angle_rad: f64,
    /// Deformed arc length σ, mm.
    pub arc_length_mm: f64,
    /// Axial stretch v1.
    pub v1: f64,
    /// Shear v2.
    pub v2: f64,
    /// Curvature u, 1/mm.
    pub u_per_mm: f64,
    /// Channel offset y_c, mm; NaN beyond the cable's anchor.
    pub channel_y_mm: f64,
    /// Cable tension here, N.
    pub cable_tension_n: f64,
}

impl From<PlanarPoint> for CentrelinePoint {
    fn from(p: PlanarPoint) -> Self {
        let (sp, cp) = p.frame_sin_cos;
        let yc = p.channel_y_mm;
        // No channel beyond the anchor: NaN in every cable coordinate.
        let off_plane = if yc.is_nan() { f64::NAN } else { 0.0 };
        let cables = PerCable::one(CableAtNode {
            channel_mm: [yc, off_plane],
            position_mm: [p.x_mm - sp * yc, p.y_mm + cp * yc, off_plane],
            tension_n: p.cable_tension_n,
        });
        CentrelinePoint {
            s_mm: p.s_mm,
            x_mm: p.x_mm,
            y_mm: p.y_mm,
            z_mm: 0.0,
            rotation: [[cp, -sp, 0.0], [sp, cp, 0.0], [0.0, 0.0, 1.0]],
            frame_angle_rad: p.frame_angle_rad,
            tangent_angle_rad: p.tangent_angle_rad,
            arc_length_mm: p.arc_length_mm,
            v: [p.v1, p.v2, 0.0],
            u_per_mm: [0.0, 0.0, p.u_per_mm],
            cables,
        }
    }
}

/// Everything about one solved actuator, whichever backend solved it: the
/// pose, the coefficient series and the centreline. For single solves
/// (allocates); a planar solve has a_bend_y = a_twist = 0.
#[derive(Debug, Clone)]
pub struct Simulation {
    /// The actuator solved, as given (its cables' tensions the final ones).
    pub actuator: Actuator,
    /// The backend that solved it.
    pub backend: Backend,
    /// Tip pose and length.
    pub pose: TipPose,
    /// Legendre coefficients a_0 … a_n of the bending curvature about the
    /// body z axis (in the x–y plane; the planar a_i), mm⁻¹: κ = Σ a_i P_i(t)
    /// with dimensionless t, so every a_i is a curvature; in `length_basis`.
    pub a_bend_z: Vec<f64>,
    /// Of the bending curvature about the body y axis (out of the x–y plane).
    pub a_bend_y: Vec<f64>,
    /// Of the twist u_1.
    pub a_twist: Vec<f64>,
    /// The length the coefficients are per unit of.
    pub length_basis: LengthBasis,
    /// Centreline from clamp to tip.
    pub centreline: Vec<CentrelinePoint>,
}

impl Simulation {
    /// Cable 1's control points y_0 … y_4, mm: the planar routing.
    pub fn routing_mm(&self) -> ControlPoints {
        ControlPoints(self.actuator.cables[0].y_mm)
    }

    /// Each cable's path in the global frame at the centreline's nodes, from
    /// the clamp to where it is knotted, mm.
    pub fn cable_paths_mm(&self) -> Vec<Vec<[f64; 3]>> {
        (0..self.pose.tensions_n.len())
            .map(|i| self.centreline.iter().map(|n| n.cables[i]).filter(CableAtNode::is_present).map(|c| c.position_mm).collect())
            .collect()
    }
}
