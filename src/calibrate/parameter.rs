//! The parameters of a fit: the rigidities, the weight and the effects of
//! the registry, each with the coordinate the fit moves it in.

use super::{Effect, HeldError, HeldItem};
use crate::model::Actuator;
use serde::Serialize;

/// A parameter a fit can fit or hold (`--fix NAME=VALUE`): a rigidity, the
/// weight, or a registry effect's parameter. Planar measurements fit EA,
/// GA, EI and effects; captures with 3-D markers the torsion and the
/// density too.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Parameter {
    /// Bending rigidity EI (of the section of radius `radius_mm`), N·mm².
    Ei,
    /// Axial rigidity EA, N.
    Ea,
    /// Shear rigidity GA, N.
    Ga,
    /// Torsional rigidity GJ, N·mm² (set explicitly once fitted).
    Gj,
    /// Material density, g/cm³: the weight.
    Density,
    /// A registry effect's parameter.
    Effect(Effect),
}

impl Parameter {
    /// The rigidities and the weight of a fit on captures, in report order.
    pub const BODY: [Parameter; 5] = [Parameter::Ei, Parameter::Ea, Parameter::Ga, Parameter::Gj, Parameter::Density];

    /// The name with its unit, as in the actuator file.
    pub fn name(self) -> &'static str {
        match self {
            Parameter::Ei => "ei_n_mm2",
            Parameter::Ea => "ea_n",
            Parameter::Ga => "ga_n",
            Parameter::Gj => "gj_n_mm2",
            Parameter::Density => "density_g_cm3",
            Parameter::Effect(e) => e.parameter_name(),
        }
    }

    /// Parses `EI`, `ei_n_mm2`, `GJ`, `density`, an effect's name or its
    /// parameter's name (any case).
    pub fn parse(name: &str) -> Option<Parameter> {
        let lower = name.trim().to_ascii_lowercase();
        let body = match lower.as_str() {
            "ei" | "ei_n_mm2" => Some(Parameter::Ei),
            "ea" | "ea_n" => Some(Parameter::Ea),
            "ga" | "ga_n" => Some(Parameter::Ga),
            "gj" | "gj_n_mm2" => Some(Parameter::Gj),
            "density" | "density_g_cm3" => Some(Parameter::Density),
            _ => None,
        };
        body.or_else(|| Effect::ALL.into_iter().find(|e| e.name() == lower || e.parameter_name() == lower).map(Parameter::Effect))
    }

    /// The value on `a`.
    pub fn get(self, a: &Actuator) -> f64 {
        match self {
            Parameter::Ei => a.rod.ei_n_mm2,
            Parameter::Ea => a.rod.ea_n,
            Parameter::Ga => a.rod.ga_n,
            Parameter::Gj => a.torsional_rigidity_n_mm2(),
            Parameter::Density => a.rod.density_g_cm3,
            Parameter::Effect(e) => e.current(&a.rod).unwrap_or_else(|| e.start()),
        }
    }

    /// Sets the value on `a` (an effect is switched on).
    pub fn set(self, a: &mut Actuator, v: f64) {
        match self {
            Parameter::Ei => a.rod.ei_n_mm2 = v,
            Parameter::Ea => a.rod.ea_n = v,
            Parameter::Ga => a.rod.ga_n = v,
            Parameter::Gj => a.gj_n_mm2 = Some(v),
            Parameter::Density => a.rod.density_g_cm3 = v,
            Parameter::Effect(e) => e.apply(&mut a.rod, v),
        }
    }

    /// The coordinate the fit moves: the log of a rigidity or the density,
    /// an effect's registry coordinate.
    pub(crate) fn to_internal(self, v: f64) -> f64 {
        match self {
            Parameter::Effect(e) => e.to_internal(v),
            _ => v.ln(),
        }
    }

    /// Inverse of [`Parameter::to_internal`].
    pub(crate) fn from_internal(self, x: f64) -> f64 {
        match self {
            Parameter::Effect(e) => e.from_internal(x),
            _ => x.exp(),
        }
    }

    /// d value / d internal coordinate.
    pub(crate) fn derivative(self, x: f64) -> f64 {
        match self {
            Parameter::Effect(e) => e.derivative(x),
            _ => x.exp(),
        }
    }

    /// Whether a planar fit (one in-plane cable, tip readings) can fit or
    /// hold it: EA, GA, EI and the effects; a planar rod has no torsion,
    /// and its weight is not fitted.
    pub fn is_planar(self) -> bool {
        !matches!(self, Parameter::Gj | Parameter::Density)
    }

    /// Parses `--fix NAME=VALUE` (`item`): the parameter and its value.
    pub fn parse_held(item: &str) -> Result<(Parameter, f64), HeldError> {
        let bad = |reason: HeldItem| HeldError::Item { item: item.to_string(), reason };
        let (name, value) = item.split_once('=').ok_or_else(|| bad(HeldItem::NoValue))?;
        let p = Parameter::parse(name).ok_or_else(|| bad(HeldItem::Unknown { name: name.to_string() }))?;
        let v = value.trim().parse::<f64>().map_err(|_| bad(HeldItem::NotANumber { value: value.to_string() }))?;
        Ok((p, v))
    }
}
