//! The effect parameters a rod carries (its `[effects]` table,
//! model-notes §6): the values only. What each parameter means, its bounds,
//! flag and fit are the registry's ([`crate::model::effects`]), which reads and
//! sets these fields; this file and the registry are the only places the
//! `[effects]` keys are spelled (tests/layering.rs).

use serde::{Deserialize, Serialize};

/// Default creep time constant T, s.
pub const DEFAULT_CREEP_TIME_S: f64 = 10.0;

/// Direction of the last tension change, which decides the sign of friction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum LoadDirection {
    /// Tension rising: friction opposes the cable sliding toward the base.
    #[default]
    Load,
    /// Tension falling: friction acts the other way.
    Unload,
}

impl LoadDirection {
    /// The slip sign η in friction's capstan law dτ/ds = −η μ τ |ψ'|:
    /// +1 loading, −1 unloading.
    pub fn slip_sign(self) -> f64 {
        match self {
            LoadDirection::Load => 1.0,
            LoadDirection::Unload => -1.0,
        }
    }
}

/// Physical effects beyond the thesis model, each with one parameter
/// (model-notes §6; described in [`REGISTRY`]). All default to "off" (the
/// thesis model).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Effects {
    /// Cable–channel friction coefficient μ (capstan law along the channel).
    pub friction_mu: f64,
    /// Whether the tension was last rising or falling (sign of friction).
    pub load_direction: LoadDirection,
    /// Material stiffening α: bending moment EI·u·(1 + α (r u)²).
    pub stiffening_alpha: f64,
    /// Rotational stiffness of the clamp k_θ, N·mm/rad; `None` is a rigid clamp.
    pub clamp_stiffness_n_mm_per_rad: Option<f64>,
    /// Channel offset δ: the built channel sits at y_c + δ, mm.
    pub channel_offset_mm: f64,
    /// Viscoelastic creep in bending (standard linear solid): the fraction f
    /// of the instantaneous bending rigidity that relaxes, 0 ≤ f < 1. Held
    /// long enough at a moment m, the curvature creeps from m/EI to
    /// m/(EI (1 − f)).
    pub creep_fraction: f64,
    /// Time constant T of the creep's dashpot, s (the curvature relaxes
    /// like exp(−(1 − f) t / T) at a held moment).
    pub creep_time_s: f64,
    /// For solves outside a measured protocol (simulate, sweep, design):
    /// how long each tension is held on a rod with no load history before
    /// the shape is taken, s. 0 gives the instantaneous (elastic) shape.
    pub creep_hold_s: f64,
    /// Stiffness gradient β: EI(s) = EI·exp(β (s/L − ½)) with EA, GA
    /// unchanged (uneven curing, an unmodelled taper); β = ln(EI(L)/EI(0)),
    /// β < 0 is softer toward the tip. Not written when 0, so existing specs
    /// and metadata are unchanged.
    #[serde(skip_serializing_if = "is_zero")]
    pub stiffness_gradient_beta: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl Default for Effects {
    fn default() -> Self {
        Self {
            friction_mu: 0.0,
            load_direction: LoadDirection::Load,
            stiffening_alpha: 0.0,
            clamp_stiffness_n_mm_per_rad: None,
            channel_offset_mm: 0.0,
            creep_fraction: 0.0,
            creep_time_s: DEFAULT_CREEP_TIME_S,
            creep_hold_s: 0.0,
            stiffness_gradient_beta: 0.0,
        }
    }
}
