//! The candidate effects of model-notes §6 as fit parameters: a view of the
//! effect registry ([`crate::model::effects`]), whose entries with a
//! [`Fit`] are the candidates. The registry says how each sets the
//! actuator, how it is parameterised for the fit (positivity by logs, a
//! fraction by a logit) and what values are physically plausible; this
//! module adds only what separates two candidates.

use crate::model::effects::{self, Domain, EffectInfo, Fit};
use crate::model::Rod;
use serde::Serialize;

/// An effect the thesis model leaves out, with one fitted parameter: one
/// per registry entry with a [`Fit`], in registry order (a test checks it).
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
    /// Every candidate, in a fixed order (reports and fits list them so).
    pub const ALL: [Effect; 7] = [
        Effect::Friction,
        Effect::Gravity,
        Effect::Stiffening,
        Effect::ClampCompliance,
        Effect::ChannelOffset,
        Effect::Creep,
        Effect::StiffnessGradient,
    ];

    /// The candidate's registry entry.
    pub fn info(self) -> &'static EffectInfo {
        match self {
            Effect::Friction => &effects::FRICTION,
            Effect::Gravity => &effects::GRAVITY_SCALE,
            Effect::Stiffening => &effects::STIFFENING,
            Effect::ClampCompliance => &effects::CLAMP_COMPLIANCE,
            Effect::ChannelOffset => &effects::CHANNEL_OFFSET,
            Effect::Creep => &effects::CREEP_FRACTION,
            Effect::StiffnessGradient => &effects::STIFFNESS_GRADIENT,
        }
    }

    /// How the candidate is fitted.
    pub fn fit(self) -> &'static Fit {
        self.info().fit.as_ref().expect("a candidate's entry has a fit")
    }

    /// The name used in reports, JSON and on the command line.
    pub fn name(self) -> &'static str {
        self.fit().name
    }

    /// Parses a name of [`Effect::name`].
    pub fn parse(name: &str) -> Option<Effect> {
        Effect::ALL.into_iter().find(|e| e.name() == name)
    }

    /// The parameter's name with its unit.
    pub fn parameter_name(self) -> &'static str {
        self.info().name
    }

    /// Sets the effect's parameter on `a` (switching the effect on).
    pub fn apply(self, a: &mut Rod, value: f64) {
        (self.fit().switch_on)(a);
        (self.info().set)(a, value);
    }

    /// The effect's value on `a` if it is switched on there and can start
    /// a fit (a fit then starts from it), `None` if `a` has the thesis
    /// model's value.
    pub fn current(self, a: &Rod) -> Option<f64> {
        let (info, fit) = (self.info(), self.fit());
        let v = (info.get)(a);
        ((fit.switched_on)(a) && info.is_set(a) && fit.domain.contains(v)).then_some(v)
    }

    /// Starting value of the fit.
    pub fn start(self) -> f64 {
        self.fit().start
    }

    /// Values a real rod, clamp and cable can have; a fit outside them
    /// points at another cause.
    pub fn plausible(self, value: f64) -> bool {
        self.fit().is_plausible(value)
    }

    /// The plausible range in words, for reports.
    pub fn plausible_text(self) -> &'static str {
        self.fit().plausible_text
    }

    /// Maps a parameter value to the fit's unconstrained coordinate.
    pub fn to_internal(self, value: f64) -> f64 {
        match self.fit().domain {
            Domain::Signed => value,
            Domain::Fraction => (value / (1.0 - value)).ln(),
            Domain::Positive => value.ln(),
        }
    }

    /// Inverse of [`Effect::to_internal`].
    pub fn from_internal(self, x: f64) -> f64 {
        match self.fit().domain {
            Domain::Signed => x,
            Domain::Fraction => 1.0 / (1.0 + (-x).exp()),
            Domain::Positive => x.exp(),
        }
    }

    /// d value / d internal coordinate at internal `x` (for standard errors).
    pub fn derivative(self, x: f64) -> f64 {
        match self.fit().domain {
            Domain::Signed => 1.0,
            Domain::Fraction => {
                let f = self.from_internal(x);
                f * (1.0 - f)
            }
            Domain::Positive => x.exp(),
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

    #[test]
    fn the_candidates_are_the_registrys_fittable_entries_in_order() {
        let fittable: Vec<&str> = crate::model::effects::fittable().map(|(e, _)| e.name).collect();
        let candidates: Vec<&str> = Effect::ALL.iter().map(|e| e.parameter_name()).collect();
        let mut sorted = candidates.clone();
        sorted.sort_by_key(|k| fittable.iter().position(|f| f == k));
        assert_eq!(sorted, fittable, "every fittable registry entry is a candidate, and only those");
    }

    #[test]
    fn current_reads_a_switched_on_effect_only() {
        let mut a = Rod::default();
        assert!(Effect::ALL.iter().all(|e| e.current(&a).is_none()));
        Effect::Gravity.apply(&mut a, 2.0);
        Effect::ClampCompliance.apply(&mut a, 300.0);
        assert_eq!((Effect::Gravity.current(&a), Effect::ClampCompliance.current(&a)), (Some(2.0), Some(300.0)));
        a.gravity.enabled = false;
        assert_eq!(Effect::Gravity.current(&a), None);
    }
}
