//! The axes of a study (`[[study.axis]]`): what a study may vary and how
//! each value of an axis changes a variant's sweep spec. The rod's numbers
//! ([`NUMBER_AXES`]), the tension range (`tension_n`), tables of
//! `[actuator.effects]` settings (`effects`), and every effect parameter of
//! the registry by its path ([`crate::model::effects::REGISTRY`]:
//! `effects.KEY`, `gravity.scale`, …), set through the registry's
//! own setter.

use crate::model::effects::Section;
use crate::model::{EffectInfo, Rod, REGISTRY};
use serde::Deserialize;

/// Axes whose values are numbers at `[actuator] NAME`.
pub const NUMBER_AXES: [&str; 6] = ["length_mm", "radius_mm", "ei_n_mm2", "ea_n", "ga_n", "density_g_cm3"];

/// The axis of the tension range: pairs [min_n, max_n].
const TENSION_AXIS: &str = "tension_n";

/// The axis of tables of `[actuator.effects]` settings, laid over the base spec's.
fn effects_axis() -> &'static str {
    Section::Effects.key()
}

/// The axes of the registry's effect parameters, by path.
fn effect_paths() -> String {
    REGISTRY.iter().map(|e| e.path).collect::<Vec<_>>().join(", ")
}

/// One `[[study.axis]]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct AxisSection {
    /// The axis.
    pub name: String,
    /// Its values.
    pub values: Option<Vec<toml::Value>>,
    /// Or factors on the base spec's value.
    pub scale: Option<Vec<f64>>,
}

/// What is wrong with one axis, and what to write instead.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AxisError {
    /// An axis with neither values nor scale.
    #[error("give values = [...] or scale = [...]")]
    NoValues,
    /// An axis with values and scale.
    #[error("give either values or scale, not both")]
    ValuesAndScale,
    /// A value that must be a number.
    #[error("value {value} is not a number")]
    NotANumber {
        /// The value as written.
        value: String,
    },
    /// A scale factor that is not positive.
    #[error("scale {0} must be a positive factor")]
    BadFactor(f64),
    /// A scale on an effect parameter.
    #[error("give values = [...] (numbers; an effect parameter has no scale)")]
    EffectScale,
    /// A scale on the tension axis.
    #[error("give values = [[min_n, max_n], ...] (no scale)")]
    TensionScale,
    /// A tension value that is not a pair.
    #[error("value {value} is not a pair [min_n, max_n] of tensions")]
    NotAPair {
        /// The value as written.
        value: String,
    },
    /// A scale on the effects axis.
    #[error("give values = [{{...}}, ...] (tables of [actuator.effects] settings; no scale)")]
    EffectsScale,
    /// An effects value that is not a table.
    #[error("value {value} is not a table of [actuator.effects] settings")]
    NotATable {
        /// The value as written.
        value: String,
    },
    /// A table of settings that has no JSON form (a TOML date, say).
    #[error("value {value} holds a setting that is not a number, a string or a table")]
    Settings {
        /// The value as written.
        value: String,
    },
    /// An axis of no known name.
    #[error("unknown axis '{name}': use one of {}, {TENSION_AXIS}, {}, or an effect parameter ({})", NUMBER_AXES.join(", "), effects_axis(), effect_paths())]
    Unknown {
        /// The name given.
        name: String,
    },
    /// An axis without a value.
    #[error("no values")]
    Empty,
}

/// How one value of an axis changes the spec (as JSON, the spec's canonical form).
#[derive(Debug, Clone)]
pub(super) enum Change {
    /// `[actuator] KEY = value`.
    Number { key: &'static str, value: f64 },
    /// `[actuator] KEY` times `factor`.
    Scale { key: &'static str, factor: f64 },
    /// A registry effect parameter, set by its entry.
    Effect { info: &'static EffectInfo, value: f64 },
    /// `[tension] min_n, max_n`.
    Tension { min_n: f64, max_n: f64 },
    /// `[actuator.effects]` settings laid over the base spec's.
    Effects(serde_json::Map<String, serde_json::Value>),
}

/// An axis value as a number (TOML integers count).
fn number(v: &toml::Value) -> Result<f64, AxisError> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64)).ok_or_else(|| AxisError::NotANumber { value: v.to_string() })
}

fn fmt(v: f64) -> String {
    crate::io::fmt_num(v)
}

/// The values of `a` when it may have no scale (`error` names what to write).
fn values_only(a: &AxisSection, error: AxisError) -> Result<&[toml::Value], AxisError> {
    a.values.as_deref().filter(|_| a.scale.is_none()).ok_or(error)
}

impl AxisSection {
    /// Each value's label (e.g. `55`, `×0.8`, `1–3 N`) and change, in order.
    pub fn changes(&self) -> Result<Vec<(String, Change)>, AxisError> {
        let changes = self.changes_of_kind()?;
        if changes.is_empty() {
            return Err(AxisError::Empty);
        }
        Ok(changes)
    }

    fn changes_of_kind(&self) -> Result<Vec<(String, Change)>, AxisError> {
        if let Some(key) = NUMBER_AXES.iter().copied().find(|k| *k == self.name) {
            return match (&self.values, &self.scale) {
                (Some(values), None) => values.iter().map(|v| number(v).map(|x| (fmt(x), Change::Number { key, value: x }))).collect(),
                (None, Some(scale)) => scale
                    .iter()
                    .map(|&f| {
                        if f.is_finite() && f > 0.0 {
                            Ok((format!("×{}", fmt(f)), Change::Scale { key, factor: f }))
                        } else {
                            Err(AxisError::BadFactor(f))
                        }
                    })
                    .collect(),
                (Some(_), Some(_)) => Err(AxisError::ValuesAndScale),
                (None, None) => Err(AxisError::NoValues),
            };
        }
        if let Some(info) = REGISTRY.iter().copied().find(|e| e.path == self.name) {
            return values_only(self, AxisError::EffectScale)?
                .iter()
                .map(|v| number(v).map(|x| (fmt(x), Change::Effect { info, value: x })))
                .collect();
        }
        if self.name == TENSION_AXIS {
            return values_only(self, AxisError::TensionScale)?.iter().map(tension_pair).collect();
        }
        if self.name == effects_axis() {
            return values_only(self, AxisError::EffectsScale)?.iter().map(effect_settings).collect();
        }
        Err(AxisError::Unknown { name: self.name.clone() })
    }
}

/// A tension axis value: `[min_n, max_n]`.
fn tension_pair(v: &toml::Value) -> Result<(String, Change), AxisError> {
    let pair: Option<Vec<f64>> =
        v.as_array().map(|p| p.iter().filter_map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64))).collect());
    match pair.as_deref() {
        Some(&[lo, hi]) if v.as_array().is_some_and(|p| p.len() == 2) => {
            Ok((format!("{}–{} N", fmt(lo), fmt(hi)), Change::Tension { min_n: lo, max_n: hi }))
        }
        _ => Err(AxisError::NotAPair { value: v.to_string() }),
    }
}

/// An effects axis value: a table of `[actuator.effects]` settings.
fn effect_settings(v: &toml::Value) -> Result<(String, Change), AxisError> {
    let t = v.as_table().ok_or_else(|| AxisError::NotATable { value: v.to_string() })?;
    let json = serde_json::to_value(t).map_err(|_| AxisError::Settings { value: v.to_string() })?;
    let label = if t.is_empty() { "none".to_string() } else { t.iter().map(|(k, v)| format!("{k}:{v}")).collect::<Vec<_>>().join(" ") };
    Ok((format!("{{{label}}}"), Change::Effects(json.as_object().cloned().unwrap_or_default())))
}

impl Change {
    /// Sets this change in the spec's JSON.
    pub fn apply(&self, json: &mut serde_json::Value) {
        let actuator = &mut json["actuator"];
        match self {
            Change::Number { key, value } => actuator[*key] = serde_json::json!(value),
            Change::Scale { key, factor } => {
                let base = actuator[*key].as_f64().expect("actuator numbers are numbers");
                actuator[*key] = serde_json::json!(base * factor);
            }
            Change::Tension { min_n, max_n } => {
                json["tension"]["min_n"] = serde_json::json!(min_n);
                json["tension"]["max_n"] = serde_json::json!(max_n);
            }
            Change::Effect { info, value } => {
                // Through the rod's own serde form, so that the parameter's
                // field (an optional one: the clamp) is written as the rod writes it.
                let mut rod: Rod = serde_json::from_value(actuator.clone()).expect("the spec's actuator reads back");
                (info.set)(&mut rod, *value);
                let section = info.section.key();
                actuator[section] = serde_json::to_value(rod).expect("a rod serialises")[section].take();
            }
            Change::Effects(settings) => {
                let section = &mut actuator[Section::Effects.key()];
                for (k, v) in settings {
                    section[k] = v.clone();
                }
            }
        }
    }
}
