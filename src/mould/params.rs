//! The moulds' parameters and the bodies they can cast.

use super::{BodyFeature, MouldError, ParameterProblem};
use serde::{Deserialize, Serialize};

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

/// The moulds' parameters a user sets (`--wall-mm`, …; `cablemap.design`'s
/// keywords), each [`MouldParams::default`]'s when not given.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MouldSettings {
    /// [`MouldParams::wall_mm`].
    pub wall_mm: Option<f64>,
    /// [`MouldParams::tube_diameter_mm`].
    pub tube_diameter_mm: Option<f64>,
    /// [`MouldParams::clearance_mm`].
    pub clearance_mm: Option<f64>,
    /// [`MouldParams::clamp_mm`].
    pub clamp_mm: Option<f64>,
    /// [`MouldParams::min_skin_mm`].
    pub min_skin_mm: Option<f64>,
}

impl MouldSettings {
    /// The parameters: those given, the defaults elsewhere.
    pub fn params(&self) -> MouldParams {
        let d = MouldParams::default();
        MouldParams {
            wall_mm: self.wall_mm.unwrap_or(d.wall_mm),
            tube_diameter_mm: self.tube_diameter_mm.unwrap_or(d.tube_diameter_mm),
            clearance_mm: self.clearance_mm.unwrap_or(d.clearance_mm),
            clamp_mm: self.clamp_mm.unwrap_or(d.clamp_mm),
            min_skin_mm: self.min_skin_mm.unwrap_or(d.min_skin_mm),
            ..d
        }
    }

    /// A request's parameters from its `mould` object (for
    /// `#[serde(deserialize_with = …)]`).
    pub fn deserialize_params<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<MouldParams, D::Error> {
        Self::deserialize(deserializer).map(|s| s.params())
    }
}

/// Refuses a size (a parameter or the body's) that is not finite or is
/// beyond any printer's bed (the meshes of such moulds would not fit in
/// memory), named by its key.
pub(super) fn check_sizes(sizes: impl IntoIterator<Item = (&'static str, f64)>) -> Result<(), MouldError> {
    for (name, value) in sizes {
        if !value.is_finite() {
            return Err(MouldError::BadParameter { name, problem: ParameterProblem::NotFinite { value } });
        }
        if value.abs() > MAX_SIZE_MM {
            return Err(MouldError::BadParameter { name, problem: ParameterProblem::TooLarge { value } });
        }
    }
    Ok(())
}

impl MouldParams {
    /// The largest channel offset |y_c| these moulds can cast in a body of
    /// radius `radius_mm`: the tube's outer radius and `min_skin_mm` of
    /// silicone must fit between the channel's centreline and the surface, mm.
    /// [`Moulds::new`] refuses a channel beyond it; `design --moulds` bounds
    /// its search by it.
    pub fn max_castable_offset_mm(&self, radius_mm: f64) -> f64 {
        radius_mm - self.tube_diameter_mm / 2.0 - self.min_skin_mm
    }
}

/// Largest size accepted for any mould dimension (body length and radius,
/// wall, clamp block, tube), mm.
pub const MAX_SIZE_MM: f64 = 10_000.0;

/// Most triangles of the three parts together (about 50 bytes each in the
/// STL files, several times that in memory while they are built).
pub const MAX_TRIANGLES: f64 = 4e6;

/// Refuses a body the moulds cannot cast: a radius profile, segments or a
/// cable knotted before the tip ([`MouldError::NonUniformBody`]).
pub fn check_uniform_body(rod: &crate::model::Rod) -> Result<(), MouldError> {
    let mut features = Vec::new();
    if !rod.radius_profile_mm.is_empty() {
        features.push(BodyFeature::RadiusProfile { lumens: false });
    }
    if !rod.segments.is_empty() {
        features.push(BodyFeature::Segments);
    }
    if rod.cable_length_mm() < rod.length_mm {
        features.push(BodyFeature::CableAnchored);
    }
    if features.is_empty() {
        Ok(())
    } else {
        Err(MouldError::NonUniformBody { features })
    }
}

