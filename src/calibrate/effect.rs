//! The candidate effects of model-notes §6 as fit parameters: how each sets
//! the actuator, how it is parameterised for the fit (positivity by logs,
//! a fraction by a logit) and what values are physically plausible.

use crate::model::Rod;
use serde::Serialize;

/// An effect the thesis model leaves out, with one fitted parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Effect {
    /// Cable–channel friction, μ.
    Friction,
    /// Gravity scale k on the nominal self-weight.
    Gravity,
    /// Material stiffening α.
    Stiffening,
    /// Clamp compliance, k_θ in N·mm/rad.
    ClampCompliance,
    /// Channel offset δ, mm.
    ChannelOffset,
    /// Viscoelastic creep in bending, fraction f (time constant held fixed).
    Creep,
    /// Stiffness gradient β: EI(s) = EI·exp(β (s/L − ½)), EA and GA unchanged.
    StiffnessGradient,
}

impl Effect {
    /// Every candidate, in a fixed order.
    pub const ALL: [Effect; 7] = [
        Effect::Friction,
        Effect::Gravity,
        Effect::Stiffening,
        Effect::ClampCompliance,
        Effect::ChannelOffset,
        Effect::Creep,
        Effect::StiffnessGradient,
    ];

    /// The name used in reports, JSON and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Effect::Friction => "friction",
            Effect::Gravity => "gravity",
            Effect::Stiffening => "stiffening",
            Effect::ClampCompliance => "clamp_compliance",
            Effect::ChannelOffset => "channel_offset",
            Effect::Creep => "creep",
            Effect::StiffnessGradient => "stiffness_gradient",
        }
    }

    /// Parses a name of [`Effect::name`].
    pub fn parse(name: &str) -> Option<Effect> {
        Effect::ALL.into_iter().find(|e| e.name() == name)
    }

    /// The parameter's name with its unit.
    pub fn parameter_name(self) -> &'static str {
        match self {
            Effect::Friction => "friction_mu",
            Effect::Gravity => "gravity_scale",
            Effect::Stiffening => "stiffening_alpha",
            Effect::ClampCompliance => "clamp_stiffness_n_mm_per_rad",
            Effect::ChannelOffset => "channel_offset_mm",
            Effect::Creep => "creep_fraction",
            Effect::StiffnessGradient => "stiffness_gradient_beta",
        }
    }

    /// Sets the effect's parameter on `a`.
    pub fn apply(self, a: &mut Rod, value: f64) {
        match self {
            Effect::Friction => a.effects.friction_mu = value,
            Effect::Gravity => {
                a.gravity.enabled = true;
                a.gravity.scale = value;
            }
            Effect::Stiffening => a.effects.stiffening_alpha = value,
            Effect::ClampCompliance => a.effects.clamp_stiffness_n_mm_per_rad = Some(value),
            Effect::ChannelOffset => a.effects.channel_offset_mm = value,
            Effect::Creep => a.effects.creep_fraction = value,
            Effect::StiffnessGradient => a.effects.stiffness_gradient_beta = value,
        }
    }

    /// The effect's value on `a` if it is switched on there (a fit then
    /// starts from it), `None` if `a` has the thesis model's value.
    pub fn current(self, a: &Rod) -> Option<f64> {
        let v = match self {
            Effect::Friction => a.effects.friction_mu,
            Effect::Gravity => return (a.gravity.enabled && a.gravity.scale != 1.0 && a.gravity.scale > 0.0).then_some(a.gravity.scale),
            Effect::Stiffening => a.effects.stiffening_alpha,
            Effect::ClampCompliance => return a.effects.clamp_stiffness_n_mm_per_rad,
            Effect::ChannelOffset => a.effects.channel_offset_mm,
            Effect::Creep => a.effects.creep_fraction,
            Effect::StiffnessGradient => a.effects.stiffness_gradient_beta,
        };
        (v != 0.0).then_some(v)
    }

    /// Starting value of the fit.
    pub fn start(self) -> f64 {
        match self {
            Effect::Friction => 0.02,
            Effect::Gravity => 1.0,
            Effect::Stiffening => 0.2,
            Effect::ClampCompliance => 300.0,
            Effect::ChannelOffset => 0.0,
            Effect::Creep => 0.05,
            Effect::StiffnessGradient => 0.0,
        }
    }

    /// Values a real rod, clamp and cable can have; a fit outside them
    /// points at another cause.
    pub fn plausible(self, value: f64) -> bool {
        match self {
            Effect::Friction => value > 0.0 && value <= 1.0,
            Effect::Gravity => value > 0.0 && value <= 10.0,
            Effect::Stiffening => value > 0.0 && value <= 100.0,
            Effect::ClampCompliance => (1.0..=1e5).contains(&value),
            Effect::ChannelOffset => value.abs() <= 2.0,
            Effect::Creep => value > 0.0 && value <= 0.9,
            Effect::StiffnessGradient => value.abs() <= 5.0,
        }
    }

    /// The plausible range in words, for reports.
    pub fn plausible_text(self) -> &'static str {
        match self {
            Effect::Friction => "0 < μ ≤ 1",
            Effect::Gravity => "0 < k ≤ 10",
            Effect::Stiffening => "0 < α ≤ 100",
            Effect::ClampCompliance => "1 ≤ k_θ ≤ 1e5 N·mm/rad",
            Effect::ChannelOffset => "|δ| ≤ 2 mm",
            Effect::Creep => "0 < f ≤ 0.9",
            Effect::StiffnessGradient => "|β| ≤ 5 (EI(L)/EI(0) between 1/150 and 150)",
        }
    }

    /// Maps a parameter value to the fit's unconstrained coordinate.
    pub fn to_internal(self, value: f64) -> f64 {
        match self {
            Effect::ChannelOffset | Effect::StiffnessGradient => value,
            Effect::Creep => (value / (1.0 - value)).ln(),
            _ => value.ln(),
        }
    }

    /// Inverse of [`Effect::to_internal`].
    pub fn from_internal(self, x: f64) -> f64 {
        match self {
            Effect::ChannelOffset | Effect::StiffnessGradient => x,
            Effect::Creep => 1.0 / (1.0 + (-x).exp()),
            _ => x.exp(),
        }
    }

    /// d value / d internal coordinate at internal `x` (for standard errors).
    pub fn derivative(self, x: f64) -> f64 {
        match self {
            Effect::ChannelOffset | Effect::StiffnessGradient => 1.0,
            Effect::Creep => {
                let f = self.from_internal(x);
                f * (1.0 - f)
            }
            _ => x.exp(),
        }
    }

    /// Which extra measurement separates this effect from `other`.
    pub fn separating_measurement(self, other: Effect) -> &'static str {
        use Effect::*;
        let mut pair = [self, other];
        pair.sort();
        match (pair[0], pair[1]) {
            (StiffnessGradient, _) | (_, StiffnessGradient) => "measure the centreline shape (curvature along the rod) on a straight routing: a stiffness gradient spreads the curvature unevenly along s (κ ∝ 1/EI(s)), the other effects do not",
            (Friction, Creep) => "repeat the load/unload protocol with two very different dwell times (e.g. 1 s and 60 s per step): a creep loop changes with dwell, a friction loop does not",
            (Gravity, _) | (_, Gravity) => "repeat a routing with the clamp tilted (clamp_tilt_rad ≠ 0, e.g. 0.5 rad): only the self-weight's effect changes with the tilt",
            (ClampCompliance, ChannelOffset) | (Stiffening, ClampCompliance) => "add a routing with y_c(0) = 0 (y0 = 0): clamp compliance vanishes there; also measure the centreline near the clamp (a rigid rotation at s = 0)",
            (Friction, _) | (_, Friction) => "load and unload through the same tensions in small steps: friction opens a loop between the two directions",
            (Creep, _) | (_, Creep) => "hold the top tension for a long dwell and record the rest state after unloading: creep leaves a residual bend",
            (Stiffening, ChannelOffset) => "add a straight routing measured at many tensions: stiffening makes the curvature sublinear in tension, an offset does not",
            _ => "measure the centreline shape (curvature along the rod) as well as the tip",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_round_trip_and_names_parse() {
        for e in Effect::ALL {
            let v = e.start() + 0.1;
            assert!((e.from_internal(e.to_internal(v)) - v).abs() < 1e-12 * v.abs().max(1.0));
            let x = e.to_internal(v);
            let h = 1e-6;
            let fd = (e.from_internal(x + h) - e.from_internal(x - h)) / (2.0 * h);
            assert!((fd - e.derivative(x)).abs() < 1e-6 * fd.abs().max(1.0));
            assert_eq!(Effect::parse(e.name()), Some(e));
        }
    }
}
