//! Rod parameters (thesis Table 2.1, model-notes §1) and the optional
//! physical effects the thesis model leaves out (model-notes §6).

use super::body::{Body, Segment};
use serde::{Deserialize, Serialize};

// The effects and their registry live in `effects`; re-exported here, where
// the rod's other parameters are.
pub use super::effects::{
    Effects, LoadDirection, Unmodelled, DEFAULT_CREEP_TIME_S, PLAUSIBLE_CLAMP_STIFFNESS, PLAUSIBLE_FRICTION_MU,
    PLAUSIBLE_GRAVITY_SCALE, PLAUSIBLE_STIFFENING_ALPHA,
};

/// Standard gravity, m/s².
pub const STANDARD_GRAVITY_M_S2: f64 = 9.81;

/// A plausible range of a parameter: far beyond any rod cablemap models,
/// yet refusing values whose products in the solver overflow or vanish.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlausibleRange {
    /// Smallest value accepted.
    pub min: f64,
    /// Largest value accepted.
    pub max: f64,
    /// The range and an example in words, for the error.
    pub expected: &'static str,
}

impl PlausibleRange {
    /// Refuses `value` of parameter `name` outside the range.
    pub fn check(&self, name: &'static str, value: f64) -> Result<(), ParameterError> {
        if (self.min..=self.max).contains(&value) {
            Ok(())
        } else {
            Err(ParameterError::OutOfRange { name, value, expected: self.expected })
        }
    }
}

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

/// Why a parameter set was rejected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParameterError {
    /// A parameter that must be positive and finite is not.
    #[error("parameter {name} = {} must be a positive, finite number", crate::io::fmt_num(*value))]
    NotPositive { name: &'static str, value: f64 },
    /// A parameter that must be finite is not, or lies outside its range.
    #[error("parameter {name} = {} is out of range: {expected}", crate::io::fmt_num(*value))]
    OutOfRange { name: &'static str, value: f64, expected: &'static str },
    /// A coefficient order the discretisation does not resolve
    /// ([`crate::model::resolution`]).
    #[error("{0}")]
    Unresolved(String),
    /// The body along s (radius profile, segments, cable anchor) is invalid
    /// ([`crate::model::body::BodyError`]).
    #[error("{0}")]
    Body(String),
    /// The solver backend asked for does not model this rod
    /// ([`crate::model::solver::Backend::check`]).
    #[error(transparent)]
    Unsupported(#[from] crate::model::solver::Unsupported),
}

/// Why an actuator file could not be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("actuator file {path}: {message} (an actuator file holds the [actuator] fields of docs/model.md: length_mm, radius_mm, radius_profile_mm, segments, cable_anchor_mm, ...)")]
pub struct ActuatorFileError {
    /// The file.
    pub path: String,
    /// What is wrong.
    pub message: String,
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

    /// Radius r(s), mm (the profile's, or `radius_mm`). Assumes a valid body.
    pub fn radius_at(&self, s_mm: f64) -> f64 {
        match Body::of(self) {
            Ok(Some(b)) => b.radius_at(s_mm),
            _ => self.radius_mm,
        }
    }

    /// The smallest radius along the cable's length [0, s_k], mm: bounds on
    /// the control points below it keep the channel inside the body (the
    /// spline stays in its control polygon's hull). `radius_mm` for the
    /// uniform cylinder.
    pub fn channel_radius_mm(&self) -> f64 {
        match Body::of(self) {
            Ok(Some(b)) => b.min_radius_mm(0.0, self.cable_length_mm()),
            _ => self.radius_mm,
        }
    }

    /// The largest radius along the rod, mm.
    pub fn max_radius_mm(&self) -> f64 {
        self.radius_profile_mm.iter().map(|p| p.1).fold(if self.radius_profile_mm.is_empty() { self.radius_mm } else { 0.0 }, f64::max)
    }

    /// Reads an actuator TOML file (the fields of [`Rod`], as in a sweep
    /// spec's `[actuator]` section; missing fields are the thesis's), checked
    /// with [`Rod::validate`]. This module owns the actuator file format.
    pub fn from_toml_file(path: &std::path::Path) -> Result<Rod, ActuatorFileError> {
        let text = std::fs::read_to_string(path).map_err(|e| ActuatorFileError { path: path.display().to_string(), message: e.to_string() })?;
        Rod::from_toml_str(&text).map_err(|message| ActuatorFileError { path: path.display().to_string(), message })
    }

    /// Parses actuator TOML text (see [`Rod::from_toml_file`]).
    pub fn from_toml_str(text: &str) -> Result<Rod, String> {
        let a: Rod = toml::from_str(text).map_err(|e| e.to_string().trim_end().to_string())?;
        a.validate().map_err(|e| e.to_string())?;
        Ok(a)
    }

    /// Checks every parameter; the solver calls this before it starts.
    pub fn validate(&self) -> Result<(), ParameterError> {
        let positive = [
            ("length_mm", self.length_mm),
            ("radius_mm", self.radius_mm),
            ("ea_n", self.ea_n),
            ("ga_n", self.ga_n),
            ("ei_n_mm2", self.ei_n_mm2),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(ParameterError::NotPositive { name, value });
            }
        }
        // Absurd sizes (a subnormal rigidity, a kilometre-long rod) are
        // refused here with a plausible range: the solver's products of them
        // would overflow or vanish into non-finite results. Within these
        // ranges every product the solver forms stays finite.
        for (name, value, range) in [
            ("length_mm", self.length_mm, PLAUSIBLE_LENGTH_MM),
            ("radius_mm", self.radius_mm, PLAUSIBLE_RADIUS_MM),
            ("ea_n", self.ea_n, PLAUSIBLE_FORCE_N),
            ("ga_n", self.ga_n, PLAUSIBLE_FORCE_N),
            ("ei_n_mm2", self.ei_n_mm2, PLAUSIBLE_EI_N_MM2),
        ] {
            range.check(name, value)?;
        }
        for (name, value, range) in [
            ("density_g_cm3", self.density_g_cm3, PLAUSIBLE_DENSITY_G_CM3),
            ("gravity.g_m_s2", self.gravity.g_m_s2, PLAUSIBLE_G_M_S2),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(ParameterError::OutOfRange { name, value, expected: "a finite number ≥ 0" });
            }
            range.check(name, value)?;
        }
        // Every effect parameter by its registry entry.
        super::effects::validate(self)?;
        Body::of(self)?;
        Ok(())
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
