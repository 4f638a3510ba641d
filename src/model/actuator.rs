//! The actuator: a rod ([`Rod`]: body along s, materials, effects,
//! gravity) and 1–8 cables ([`Cable`]: channel y(s), z(s), anchor and
//! actuation). The thesis's planar single-cable actuator is this type with
//! one cable and z ≡ 0. This is the `--actuator FILE.toml` format
//! (docs/schema.md).

use crate::model::cable::{self, Cable};
use crate::model::ActuatorError;
use crate::model::{ParameterError, Rod};
use serde::{Deserialize, Serialize};

/// GJ = EI / this factor when not given: for an isotropic material
/// GJ/EI = G/E·(J/I) = 2/(2(1 + ν)) = 1/1.5 with ν = 0.5.
pub const EI_OVER_GJ: f64 = 1.5;

/// A whole spatial actuator: rod, torsion, gravity direction and cables.
/// This is the `--actuator FILE.toml` format (see docs/schema.md).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Actuator {
    /// Rod parameters (thesis defaults); `rod.gravity.direction_rad` is
    /// ignored when `gravity_direction` is given.
    #[serde(default)]
    pub rod: Rod,
    /// Torsional rigidity GJ, N·mm²; `None` is EI/1.5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gj_n_mm2: Option<f64>,
    /// Gravity direction in the global frame (any length, normalised);
    /// `None` takes the planar rod's in-plane direction (cos d, sin d, 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity_direction: Option<[f64; 3]>,
    /// The cables (TOML: `[[cable]]` tables).
    #[serde(rename = "cable")]
    pub cables: Vec<Cable>,
}

impl Actuator {
    /// The thesis rod with `cables`.
    pub fn with_cables(rod: Rod, cables: Vec<Cable>) -> Self {
        Self { rod, gj_n_mm2: None, gravity_direction: None, cables }
    }

    /// Whether this is a rod alone: no cables, torsion or gravity
    /// direction, so a routing on it is one planar cable.
    pub fn is_rod_alone(&self) -> bool {
        self.cables.is_empty() && self.gj_n_mm2.is_none() && self.gravity_direction.is_none()
    }

    /// GJ in use, N·mm².
    pub fn torsional_rigidity_n_mm2(&self) -> f64 {
        self.gj_n_mm2.unwrap_or(self.rod.ei_n_mm2 / EI_OVER_GJ)
    }

    /// Unit gravity direction (global).
    pub fn gravity_unit(&self) -> Result<[f64; 3], ActuatorError> {
        let g = match self.gravity_direction {
            Some(g) => g,
            None => {
                let d = self.rod.gravity.direction_rad;
                [d.cos(), d.sin(), 0.0]
            }
        };
        let n = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
        if !(n.is_finite() && n > 0.0) {
            return Err(ActuatorError::GravityDirection(g));
        }
        Ok(g.map(|c| c / n))
    }

    /// Checks the actuator itself, whichever backend solves it (the rod's
    /// parameters, torsion, gravity and cables), and builds the cables' channels.
    pub fn channels(&self) -> Result<Vec<cable::Channel>, ActuatorError> {
        self.rod.validate()?;
        if let Some(gj) = self.gj_n_mm2 {
            if !(gj.is_finite() && gj > 0.0) {
                return Err(ParameterError::NotPositive { name: "gj_n_mm2", value: gj }.into());
            }
            crate::model::rod::PLAUSIBLE_EI_N_MM2.check("gj_n_mm2", gj)?;
        }
        self.gravity_unit()?;
        cable::validate(&self.rod, &self.cables)
    }

    /// Reads the TOML format (docs/schema.md); `source` names the file in errors.
    pub fn from_toml(text: &str, source: &str) -> Result<Self, ActuatorError> {
        toml::from_str(text).map_err(|e| ActuatorError::Toml { source_name: source.to_string(), source: e })
    }

    /// Reads and checks an actuator file ([`Actuator::channels`]; which
    /// backend serves it is decided when it is solved).
    pub fn read(path: &std::path::Path) -> Result<Self, ActuatorError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| ActuatorError::Read { path: path.to_path_buf(), source: e.into() })?;
        let a = Self::from_toml(&text, &path.display().to_string())?;
        a.channels()?;
        Ok(a)
    }
}

