//! A rod as a command describes it: a base rod and the values set on it.
//! The base is a rod file's, else the rod a measurement file gives, else
//! the thesis's; the workflows that read measurements (calibrate,
//! diagnose) resolve it only once they have read them, so that the values
//! asked for apply on top of the data's rod.

use crate::model::rod::ActuatorFileError;
use crate::model::{EffectInfo, Rod};
use std::path::PathBuf;

/// Values set on a base rod, and the rod file to start from.
#[derive(Debug, Clone, Default)]
pub struct RodOverrides {
    /// Rod TOML file to start from (the fields of a sweep spec's
    /// `[actuator]` section, docs/model.md).
    pub file: Option<PathBuf>,
    /// Rod length L, mm.
    pub length_mm: Option<f64>,
    /// Rod radius r, mm.
    pub radius_mm: Option<f64>,
    /// Axial rigidity EA, N.
    pub ea_n: Option<f64>,
    /// Shear rigidity GA, N.
    pub ga_n: Option<f64>,
    /// Bending rigidity EI, N·mm².
    pub ei_n_mm2: Option<f64>,
    /// Material density, g/cm³.
    pub density_g_cm3: Option<f64>,
    /// Self-weight off.
    pub no_gravity: bool,
    /// Effect parameters, by registry entry, set in order.
    pub effects: Vec<(&'static EffectInfo, f64)>,
    /// Radius profile r(s): points (s, r) in mm.
    pub radius_profile_mm: Option<Vec<(f64, f64)>>,
    /// Where the cable is knotted, mm.
    pub cable_anchor_mm: Option<f64>,
}

impl RodOverrides {
    /// Whether nothing is set: no file, no value, gravity on, no effect.
    pub fn is_empty(&self) -> bool {
        self.file.is_none()
            && [self.length_mm, self.radius_mm, self.ea_n, self.ga_n, self.ei_n_mm2, self.density_g_cm3, self.cable_anchor_mm].iter().all(Option::is_none)
            && !self.no_gravity
            && self.effects.is_empty()
            && self.radius_profile_mm.is_none()
    }

    /// `base` with these values set (the file is not read: `base` is the base).
    pub fn apply(&self, base: &Rod) -> Rod {
        let mut rod = base.clone();
        let set = |slot: &mut f64, v: Option<f64>| {
            if let Some(v) = v {
                *slot = v;
            }
        };
        set(&mut rod.length_mm, self.length_mm);
        set(&mut rod.radius_mm, self.radius_mm);
        set(&mut rod.ea_n, self.ea_n);
        set(&mut rod.ga_n, self.ga_n);
        set(&mut rod.ei_n_mm2, self.ei_n_mm2);
        set(&mut rod.density_g_cm3, self.density_g_cm3);
        for (info, value) in &self.effects {
            (info.set)(&mut rod, *value);
        }
        if self.no_gravity {
            rod.gravity.enabled = false;
        }
        if let Some(profile) = &self.radius_profile_mm {
            rod.radius_profile_mm = profile.clone();
        }
        if self.cable_anchor_mm.is_some() {
            rod.cable_anchor_mm = self.cable_anchor_mm;
        }
        rod
    }

    /// The rod: the file's if one is given, else `from_data` (the rod a
    /// measurement file gives), else the thesis's; with the values set.
    pub fn resolve(&self, from_data: Option<&Rod>) -> Result<Rod, ActuatorFileError> {
        let base = match (&self.file, from_data) {
            (Some(path), _) => Rod::from_toml_file(path)?,
            (None, Some(rod)) => rod.clone(),
            (None, None) => Rod::default(),
        };
        Ok(self.apply(&base))
    }
}

/// The fields a [`RodOverrides`] deserialises from, besides the effects by
/// their registry names: the rod flags of a command by their names
/// (`gravity = false` for `--no-gravity`, `actuator_file` for
/// `--actuator-file`), as the Python keywords say them.
const OVERRIDE_FIELDS: [&str; 10] =
    ["actuator_file", "length_mm", "radius_mm", "ea_n", "ga_n", "ei_n_mm2", "density_g_cm3", "gravity", "radius_profile_mm", "cable_anchor_mm"];

impl<'de> serde::Deserialize<'de> for RodOverrides {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Fields;
        impl<'de> serde::de::Visitor<'de> for Fields {
            type Value = RodOverrides;

            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("the rod's fields by their names")
            }

            fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<RodOverrides, A::Error> {
                use serde::de::Error;
                let mut o = RodOverrides::default();
                while let Some(key) = map.next_key::<String>()? {
                    let slot = match key.as_str() {
                        "length_mm" => &mut o.length_mm,
                        "radius_mm" => &mut o.radius_mm,
                        "ea_n" => &mut o.ea_n,
                        "ga_n" => &mut o.ga_n,
                        "ei_n_mm2" => &mut o.ei_n_mm2,
                        "density_g_cm3" => &mut o.density_g_cm3,
                        "cable_anchor_mm" => &mut o.cable_anchor_mm,
                        "actuator_file" => {
                            o.file = Some(map.next_value()?);
                            continue;
                        }
                        "gravity" => {
                            o.no_gravity = !map.next_value::<bool>()?;
                            continue;
                        }
                        "radius_profile_mm" => {
                            o.radius_profile_mm = Some(map.next_value()?);
                            continue;
                        }
                        _ => match crate::model::REGISTRY.iter().find(|i| i.name == key) {
                            Some(info) => {
                                o.effects.push((*info, map.next_value()?));
                                continue;
                            }
                            None => {
                                let known: Vec<&str> = OVERRIDE_FIELDS.iter().copied().chain(crate::model::REGISTRY.iter().map(|i| i.name)).collect();
                                return Err(A::Error::custom(format!("unknown rod field {key:?}: the fields are {}", known.join(", "))));
                            }
                        },
                    };
                    *slot = Some(map.next_value()?);
                }
                Ok(o)
            }
        }
        deserializer.deserialize_map(Fields)
    }
}
