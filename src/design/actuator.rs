//! The actuator of a several-cable design: the `--actuator FILE.toml` of
//! `simulate` (docs/schema.md) whose `[[cable]]` tables may also say what
//! the design may change. A cable without `y_mm`/`z_mm` has a free channel;
//! one with them is fixed unless it says `free = ["y"]`, `["z"]` or
//! `["y", "z"]`. Its actuation is designed per target within
//! `tension_min_n`/`tension_max_n` (default 0 … 2 N, the thesis's upper
//! bound; 1 … 2 N, the thesis's and `design --target`'s, for an actuator
//! of one cable: [`default_tension_min_n`]) or, for a displacement-driven cable (`displacement_mm` or
//! `displacement_max_mm` given), within 0 … `displacement_max_mm`.
//! A free coordinate stays within `max_offset_mm` of the axis (default the
//! thesis's 0.999 r: the radius less a skin of 0.1 %).

use super::objective::Bounds;
use super::DesignError;
use crate::model::{Actuator, Rod};
use serde::Serialize;
use std::path::Path;

/// Default upper tension bound of a designed cable, N (the thesis's τ_u).
/// Tension bounds without a map, N (the thesis's design range, §5).
pub const DEFAULT_TENSION_RANGE_N: [f64; 2] = [1.0, 2.0];

pub const DEFAULT_TENSION_MAX_N: f64 = 2.0;

/// Default lower tension bound of a designed cable of an actuator with
/// `cables` cables, N: for one cable the thesis's τ_l = 1 N, the default of
/// `design --target` (whose search, the thesis's, serves one planar cable
/// and needs τ_l > 0), so the thesis's design through `--targets` gives
/// its answers; for several, 0 N (an antagonist must be able to go slack).
pub fn default_tension_min_n(cables: usize) -> f64 {
    if cables == 1 {
        DEFAULT_TENSION_RANGE_N[0]
    } else {
        0.0
    }
}

/// Default upper displacement bound of a displacement-driven cable, mm
/// (the thesis rod's ≈ 2.5 mm/N at its 2 N).
pub const DEFAULT_DISPLACEMENT_MAX_MM: f64 = 5.0;

/// How a cable is actuated, and the bounds of its actuation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ActuationBounds {
    /// Tension-driven: τ_min ≤ τ ≤ τ_max, N.
    Tension {
        /// Lower bound, N.
        min_n: f64,
        /// Upper bound, N.
        max_n: f64,
    },
    /// Displacement-driven: d_min ≤ Δℓ ≤ d_max, mm.
    Displacement {
        /// Lower bound, mm.
        min_mm: f64,
        /// Upper bound, mm.
        max_mm: f64,
    },
}

impl ActuationBounds {
    /// (lower, upper).
    pub fn range(&self) -> (f64, f64) {
        match *self {
            ActuationBounds::Tension { min_n, max_n } => (min_n, max_n),
            ActuationBounds::Displacement { min_mm, max_mm } => (min_mm, max_mm),
        }
    }
}

/// What the design may change of one cable.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CableFreedom {
    /// Its y control points are designed.
    pub free_y: bool,
    /// Its z control points are designed.
    pub free_z: bool,
    /// The largest distance of a free control point from the axis, mm.
    pub max_offset_mm: f64,
    /// Its actuation's kind and bounds.
    pub actuation: ActuationBounds,
}

impl CableFreedom {
    /// The names of the free coordinates (`["y", "z"]`, …).
    pub fn free(&self) -> Vec<&'static str> {
        [("y", self.free_y), ("z", self.free_z)].into_iter().filter(|f| f.1).map(|f| f.0).collect()
    }
}

/// The actuator to design for: the actuator (the fixed cables' channels as
/// given, the free ones' as placeholders) and each cable's freedom.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DesignActuator {
    /// Rod, torsion, gravity and cables.
    pub actuator: Actuator,
    /// One per cable, in file order.
    pub freedom: Vec<CableFreedom>,
}

/// Keys a `[[cable]]` of a design's actuator file may add to the actuator format.
const DESIGN_KEYS: [&str; 6] = ["free", "tension_min_n", "tension_max_n", "displacement_max_mm", "max_offset_mm", "displacement_min_mm"];

fn bad(source: &str, message: String) -> DesignError {
    DesignError::ActuatorFile { file: source.to_string(), message }
}

impl DesignActuator {
    /// Reads an actuator file with design keys; `rod_overrides` applies the
    /// command line's rod flags to its `[rod]`.
    pub fn read(path: &Path, rod_overrides: impl Fn(&Rod) -> Rod) -> Result<Self, DesignError> {
        let text = std::fs::read_to_string(path).map_err(|e| bad(&path.display().to_string(), e.to_string()))?;
        Self::parse(&text, &path.display().to_string(), rod_overrides)
    }

    /// One free planar cable (y free, z ≡ 0) in `rod`: the thesis's design.
    pub fn planar(rod: Rod, tension_min_n: f64, tension_max_n: f64, max_offset_mm: Option<f64>) -> Self {
        let max_offset_mm = max_offset_mm.unwrap_or_else(|| Bounds::thesis_max_offset_mm(rod.channel_radius_mm()));
        let freedom = CableFreedom {
            free_y: true,
            free_z: false,
            max_offset_mm,
            actuation: ActuationBounds::Tension { min_n: tension_min_n, max_n: tension_max_n },
        };
        Self { actuator: Actuator::with_cables(rod, vec![crate::model::Cable::planar([0.0; 5], tension_min_n)]), freedom: vec![freedom] }
    }

    /// Parses the TOML text (`source` names it in errors).
    pub fn parse(text: &str, source: &str, rod_overrides: impl Fn(&Rod) -> Rod) -> Result<Self, DesignError> {
        let mut doc: toml::Table = text.parse().map_err(|e: toml::de::Error| bad(source, e.to_string()))?;
        let cables = match doc.get_mut("cable") {
            Some(toml::Value::Array(cables)) => cables,
            _ => return Err(bad(source, "no [[cable]] tables: a design needs 1 to 8 cables (a [[cable]] without y_mm/z_mm has a free channel)".into())),
        };
        let mut pending = Vec::with_capacity(cables.len());
        let tension_min_n = default_tension_min_n(cables.len());
        for (i, cable) in cables.iter_mut().enumerate() {
            let no = i + 1;
            let toml::Value::Table(t) = cable else { return Err(bad(source, format!("cable {no} is not a table"))) };
            let mut keys = std::collections::BTreeMap::new();
            for k in DESIGN_KEYS {
                if let Some(v) = t.remove(k) {
                    keys.insert(k, v);
                }
            }
            let has_channel = t.contains_key("y_mm") || t.contains_key("z_mm");
            let (free_y, free_z) = match keys.get("free") {
                None => (!has_channel, !has_channel),
                Some(toml::Value::Array(list)) => {
                    let mut f = (false, false);
                    for v in list {
                        match v.as_str() {
                            Some("y") => f.0 = true,
                            Some("z") => f.1 = true,
                            _ => return Err(bad(source, format!("cable {no}: free = {list:?}: list the free coordinates, \"y\" and/or \"z\" (free = [] for a fixed channel)"))),
                        }
                    }
                    f
                }
                Some(v) => return Err(bad(source, format!("cable {no}: free = {v}: give a list, e.g. free = [\"y\", \"z\"]"))),
            };
            for axis in ["y_mm", "z_mm"] {
                t.entry(axis).or_insert_with(|| toml::Value::Array(vec![toml::Value::Float(0.0); 5]));
            }
            let number = |k: &str| -> Result<Option<f64>, DesignError> {
                match keys.get(k) {
                    None => Ok(None),
                    Some(v) => v
                        .as_float()
                        .or_else(|| v.as_integer().map(|i| i as f64))
                        .filter(|x| x.is_finite())
                        .map(Some)
                        .ok_or_else(|| bad(source, format!("cable {no}: {k} = {v} is not a finite number"))),
                }
            };
            let displaced = t.contains_key("displacement_mm") || keys.contains_key("displacement_max_mm");
            let actuation = if displaced {
                if t.contains_key("tension_n") || keys.contains_key("tension_max_n") || keys.contains_key("tension_min_n") {
                    return Err(bad(source, format!("cable {no} is displacement-driven (displacement_mm/displacement_max_mm) and has tension bounds: give one kind")));
                }
                t.insert("displacement_mm".into(), toml::Value::Float(0.0));
                ActuationBounds::Displacement {
                    min_mm: number("displacement_min_mm")?.unwrap_or(0.0),
                    max_mm: number("displacement_max_mm")?.unwrap_or(DEFAULT_DISPLACEMENT_MAX_MM),
                }
            } else {
                t.insert("tension_n".into(), toml::Value::Float(0.0));
                ActuationBounds::Tension {
                    min_n: number("tension_min_n")?.unwrap_or(tension_min_n),
                    max_n: number("tension_max_n")?.unwrap_or(DEFAULT_TENSION_MAX_N),
                }
            };
            let (lo, hi) = actuation.range();
            if !(lo >= 0.0 && lo <= hi && hi <= crate::solver::simulate::MAX_LADDER_TENSION_N) {
                return Err(bad(source, format!("cable {no}: actuation bounds {lo} … {hi} must satisfy 0 ≤ min ≤ max")));
            }
            pending.push((free_y, free_z, number("max_offset_mm")?, actuation));
        }
        let mut actuator = Actuator::from_toml(&toml::to_string(&doc).expect("a parsed table serialises"), source)
            .map_err(|e| bad(source, e.to_string()))?;
        actuator.rod = rod_overrides(&actuator.rod);
        actuator.rod.validate()?;
        actuator.gravity_unit().map_err(|e| bad(source, e.to_string()))?;
        if actuator.cables.len() > crate::model::MAX_CABLES {
            return Err(bad(source, format!("{} cables: an actuator has 1 to {}", actuator.cables.len(), crate::model::MAX_CABLES)));
        }
        let radius = actuator.rod.channel_radius_mm();
        let freedom = pending
            .into_iter()
            .enumerate()
            .map(|(i, (free_y, free_z, max_offset, actuation))| {
                let max_offset_mm = max_offset.unwrap_or_else(|| Bounds::thesis_max_offset_mm(radius));
                if !(max_offset_mm > 0.0 && max_offset_mm < radius) {
                    return Err(bad(source, format!("cable {}: max_offset_mm = {max_offset_mm} must lie in (0, r = {radius}) mm", i + 1)));
                }
                let c = &actuator.cables[i];
                // A fixed coordinate must leave the free one room.
                for k in 0..5 {
                    let fixed = match (free_y, free_z) {
                        (true, false) => c.z_mm[k],
                        (false, true) => c.y_mm[k],
                        _ => 0.0,
                    };
                    if fixed.abs() >= max_offset_mm {
                        return Err(bad(source, format!("cable {}: the fixed control point {k} ({fixed} mm) leaves the free coordinate no room inside max_offset_mm = {max_offset_mm} mm", i + 1)));
                    }
                }
                Ok(CableFreedom { free_y, free_z, max_offset_mm, actuation })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self { actuator, freedom })
    }

    /// Number of cables.
    pub fn cables(&self) -> usize {
        self.freedom.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_fixed_and_bounds_are_read() {
        let text = "gravity_direction = [1, 0, 0]\n[[cable]]\ntension_max_n = 1.5\n\n[[cable]]\ny_mm = [-2, -2, -2, -2, -2]\nfree = [\"z\"]\nmax_offset_mm = 4\n\n[[cable]]\ny_mm = [1, 1, 1, 1, 1]\nz_mm = [1, 1, 1, 1, 1]\ntension_n = 0.3\n\n[[cable]]\ndisplacement_max_mm = 3\n";
        let d = DesignActuator::parse(text, "test", |r| r.clone()).unwrap();
        assert_eq!(d.cables(), 4);
        let f = &d.freedom;
        assert_eq!((f[0].free_y, f[0].free_z, f[0].actuation), (true, true, ActuationBounds::Tension { min_n: 0.0, max_n: 1.5 }));
        assert!((f[0].max_offset_mm - 4.995).abs() < 1e-12);
        assert_eq!((f[1].free_y, f[1].free_z, f[1].max_offset_mm), (false, true, 4.0));
        assert_eq!((f[2].free_y, f[2].free_z), (false, false));
        assert_eq!(f[3].actuation, ActuationBounds::Displacement { min_mm: 0.0, max_mm: 3.0 });
        assert_eq!(d.actuator.cables[1].y_mm, [-2.0; 5]);
        // One cable: the thesis's 1 … 2 N of `design --target`, unless given.
        let one = DesignActuator::parse("[[cable]]\n", "test", |r| r.clone()).unwrap();
        assert_eq!(one.freedom[0].actuation, ActuationBounds::Tension { min_n: 1.0, max_n: 2.0 });
        let zero = DesignActuator::parse("[[cable]]\ntension_min_n = 0\n", "test", |r| r.clone()).unwrap();
        assert_eq!(zero.freedom[0].actuation, ActuationBounds::Tension { min_n: 0.0, max_n: 2.0 });
    }

    #[test]
    fn bad_design_keys_are_named() {
        for (text, says) in [
            ("[[cable]]\nfree = [\"x\"]\n", "free"),
            ("[[cable]]\ntension_max_n = -1\n", "0 ≤ min ≤ max"),
            ("[[cable]]\nmax_offset_mm = 9\n", "max_offset_mm"),
            ("[[cable]]\ndisplacement_max_mm = 2\ntension_max_n = 1\n", "one kind"),
            ("[rod]\n", "no [[cable]]"),
            ("[[cable]]\ncolour = 1\n", "colour"),
        ] {
            let e = DesignActuator::parse(text, "t.toml", |r| r.clone()).unwrap_err().to_string();
            assert!(e.contains(says), "{text:?}: {e}");
        }
    }
}
