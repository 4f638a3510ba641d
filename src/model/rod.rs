//! Rod parameters (thesis Table 2.1, model-notes §1): geometry, rigidities,
//! density, gravity, the effects it carries, the body along s (radius
//! profile, segments, rest curvature) and the cable's anchor; the actuator
//! file format. Checking a rod is [`Rod::validate`] (`validation.rs`).

use super::body::{Body, BodyError, BodyParts, Segment};
use super::parameter::{ParameterError, PlausibleRange};
use serde::{Deserialize, Serialize};

pub use super::effect_parameters::{Effects, LoadDirection, DEFAULT_CREEP_TIME_S};

/// Standard gravity, m/s².
pub const STANDARD_GRAVITY_M_S2: f64 = 9.81;

/// Rod length, mm.
pub const PLAUSIBLE_LENGTH_MM: PlausibleRange =
    PlausibleRange { min: 1e-3, max: 1e6, expected: "a length from 1e-3 to 1e6 mm (the thesis rod: 65 mm)" };
/// Rod radius, mm.
pub const PLAUSIBLE_RADIUS_MM: PlausibleRange =
    PlausibleRange { min: 1e-4, max: 1e4, expected: "a radius from 1e-4 to 1e4 mm (the thesis rod: 5 mm)" };
/// Axial and shear rigidity, N.
pub const PLAUSIBLE_FORCE_N: PlausibleRange =
    PlausibleRange { min: 1e-9, max: 1e12, expected: "a rigidity from 1e-9 to 1e12 N (the thesis rod: EA 26.7 N, GA 1.71 N)" };
/// Bending rigidity, N·mm².
pub const PLAUSIBLE_EI_N_MM2: PlausibleRange =
    PlausibleRange { min: 1e-9, max: 1e18, expected: "a bending rigidity from 1e-9 to 1e18 N·mm² (the thesis rod: 115 N·mm²)" };
/// Density, g/cm³.
pub const PLAUSIBLE_DENSITY_G_CM3: PlausibleRange =
    PlausibleRange { min: 0.0, max: 100.0, expected: "0, or a density up to 100 g/cm³ (silicone: 1.07; osmium, the densest element: 22.6)" };
/// Acceleration of gravity, m/s².
pub const PLAUSIBLE_G_M_S2: PlausibleRange =
    PlausibleRange { min: 0.0, max: 1e4, expected: "0, or an acceleration up to 1e4 m/s² (Earth: 9.81)" };

/// What is wrong with an actuator's TOML text.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RodTextError {
    /// The file could not be read.
    #[error(transparent)]
    Read(crate::io::SharedIoError),
    /// Not TOML, or a field unknown or of the wrong type.
    #[error("{}", .0.to_string().trim_end())]
    Toml(toml::de::Error),
    /// A parameter is invalid.
    #[error(transparent)]
    Parameter(#[from] ParameterError),
}

/// Why an actuator file could not be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("actuator file {path}: {problem} (an actuator file holds the [actuator] fields of docs/model.md: length_mm, radius_mm, radius_profile_mm, segments, cable_anchor_mm, ...)")]
pub struct ActuatorFileError {
    /// The file.
    pub path: String,
    /// What is wrong.
    pub problem: RodTextError,
}

/// Self-weight of the rod.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Gravity {
    /// Whether self-weight acts at all (the thesis's rod hangs: on by default).
    pub enabled: bool,
    /// Direction of gravity in the plane, measured from the clamp axis (+x)
    /// toward +y, rad. 0 is a rod hanging straight down from its clamp; a
    /// tilted clamp turns the rod against gravity.
    pub direction_rad: f64,
    /// Scale k on the nominal weight ρ·π r²·g (model-notes §6: gravity effect).
    pub scale: f64,
    /// Acceleration of gravity, m/s².
    pub g_m_s2: f64,
}

impl Default for Gravity {
    fn default() -> Self {
        Self { enabled: true, direction_rad: 0.0, scale: 1.0, g_m_s2: STANDARD_GRAVITY_M_S2 }
    }
}

/// The actuator: geometry, rigidities, material and effects. Defaults are
/// the thesis's fitted values (Table 2.1) for Dragon Skin 10 Medium.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Rod {
    /// Rod length L, mm.
    pub length_mm: f64,
    /// Rod radius r, mm.
    pub radius_mm: f64,
    /// Axial rigidity EA, N.
    pub ea_n: f64,
    /// Shear rigidity GA, N.
    pub ga_n: f64,
    /// Bending rigidity EI, N·mm².
    pub ei_n_mm2: f64,
    /// Material density, g/cm³.
    pub density_g_cm3: f64,
    /// Self-weight.
    pub gravity: Gravity,
    /// Effects beyond the thesis model.
    pub effects: Effects,
    /// Radius profile r(s): points (s, r) in mm, piecewise linear, from s = 0
    /// to L (a cone is two points). Empty: the uniform radius `radius_mm`.
    /// EA, GA, EI (and the weight) are those of a section of radius
    /// `radius_mm`, scaled by (r/radius_mm)², ², ⁴ (and ²). Not written when
    /// empty, so existing files are unchanged.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub radius_profile_mm: Vec<(f64, f64)>,
    /// Segments of their own material, clamp to tip ([`Segment`]); empty:
    /// one material.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub segments: Vec<Segment>,
    /// Where the cable is knotted, s_k ≤ L (mm); `None` is the tip. The
    /// routing's five control points span [0, s_k]; beyond the knot the rod
    /// carries no cable load, only its weight.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cable_anchor_mm: Option<f64>,
    /// Rest curvature u* of a rod cured bent, 1/mm: the curvature of the
    /// unloaded rod in the x–y plane (about the body z axis), constant
    /// along s; the bending law is m = EI (u − u*) (Rucker–Webster's u*).
    /// A body property calibrate does not fit. Not written when 0, so
    /// existing files are unchanged.
    #[serde(skip_serializing_if = "is_zero")]
    pub rest_curvature_per_mm: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl Default for Rod {
    fn default() -> Self {
        Self {
            length_mm: 65.0,
            radius_mm: 5.0,
            ea_n: 26.6964,
            ga_n: 1.70866,
            ei_n_mm2: 115.117,
            density_g_cm3: 1.07,
            gravity: Gravity::default(),
            effects: Effects::default(),
            radius_profile_mm: Vec::new(),
            segments: Vec::new(),
            cable_anchor_mm: None,
            rest_curvature_per_mm: 0.0,
        }
    }
}

impl Rod {
    /// Weight per unit length along the gravity direction, N/mm, including
    /// the gravity scale; 0 when gravity is off.
    pub fn weight_n_per_mm(&self) -> f64 {
        if !self.gravity.enabled {
            return 0.0;
        }
        // ρ [g/cm³] = ρ·1e-6 kg/mm³; area π r² mm²; g m/s² → N/mm.
        let mass_kg_per_mm = self.density_g_cm3 * 1e-6 * std::f64::consts::PI * self.radius_mm.powi(2);
        self.gravity.scale * mass_kg_per_mm * self.gravity.g_m_s2
    }

    /// Whether the body is the uniform cylinder with the cable knotted at
    /// the tip (the thesis's rod, solved on the fast path).
    pub fn is_uniform_body(&self) -> bool {
        self.radius_profile_mm.is_empty() && self.segments.is_empty() && self.cable_anchor_mm.is_none_or(|k| k == self.length_mm)
    }

    /// The cable's length along the rod, s_k (mm): the anchor, or L.
    pub fn cable_length_mm(&self) -> f64 {
        self.cable_anchor_mm.unwrap_or(self.length_mm)
    }

    /// The body along s (radius profile, segments), resolved and checked;
    /// `None` for the uniform cylinder, solved on the fast path.
    pub fn body(&self) -> Result<Option<Body>, BodyError> {
        Body::new(&BodyParts {
            length_mm: self.length_mm,
            radius_mm: self.radius_mm,
            ea_n: self.ea_n,
            ga_n: self.ga_n,
            ei_n_mm2: self.ei_n_mm2,
            density_g_cm3: self.density_g_cm3,
            radius_profile_mm: &self.radius_profile_mm,
            segments: &self.segments,
            cable_anchor_mm: self.cable_anchor_mm,
        })
    }

    /// Radius r(s), mm (the profile's, or `radius_mm`). Assumes a valid body.
    pub fn radius_at(&self, s_mm: f64) -> f64 {
        match self.body() {
            Ok(Some(b)) => b.radius_at(s_mm),
            _ => self.radius_mm,
        }
    }

    /// The smallest radius along the cable's length [0, s_k], mm: bounds on
    /// the control points below it keep the channel inside the body (the
    /// spline stays in its control polygon's hull). `radius_mm` for the
    /// uniform cylinder.
    pub fn channel_radius_mm(&self) -> f64 {
        match self.body() {
            Ok(Some(b)) => b.min_radius_mm(0.0, self.cable_length_mm()),
            _ => self.radius_mm,
        }
    }

    /// Reads an actuator TOML file (the fields of [`Rod`], as in a sweep
    /// spec's `[actuator]` section; missing fields are the thesis's), checked
    /// with [`Rod::validate`]. This module owns the actuator file format.
    pub fn from_toml_file(path: &std::path::Path) -> Result<Rod, ActuatorFileError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| ActuatorFileError { path: path.display().to_string(), problem: RodTextError::Read(e.into()) })?;
        Rod::from_toml_str(&text).map_err(|problem| ActuatorFileError { path: path.display().to_string(), problem })
    }

    /// Parses actuator TOML text (see [`Rod::from_toml_file`]).
    pub fn from_toml_str(text: &str) -> Result<Rod, RodTextError> {
        let a: Rod = toml::from_str(text).map_err(RodTextError::Toml)?;
        a.validate()?;
        Ok(a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_weight_matches_model_notes() {
        let w = Rod::default().weight_n_per_mm();
        assert!((w - 8.244088901733995e-4).abs() < 1e-15, "{w}");
        let mut off = Rod::default();
        off.gravity.enabled = false;
        assert_eq!(off.weight_n_per_mm(), 0.0);
    }

    #[test]
    fn validation_names_the_parameter() {
        let mut a = Rod::default();
        a.ei_n_mm2 = -1.0;
        let e = a.validate().unwrap_err().to_string();
        assert!(e.contains("ei_n_mm2"), "{e}");
    }
}
