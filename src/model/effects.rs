//! The effect registry: every physical effect beyond the thesis model
//! (model-notes §6), each parameter described once — its spec key, unit,
//! default, valid and plausible ranges, command-line flag, whether
//! and how calibrate and diagnose fit it. Which backends model an effect
//! is declared with the backends, in the solver layer.
//!
//! Everything else that knows an effect reads it from here: the command
//! line's effect flags are generated from [`REGISTRY`], [`Rod::validate`]
//! checks each entry's [`Bounds`], the calibration candidates
//! (`calibrate::Effect`) are a view of the entries with a [`Fit`], the
//! solvers' capability check walks the entries, and tests check
//! docs/model.md's effects table against it. The spec keys are spelled
//! here and in the [`Effects`] struct only (`effect_parameters.rs`;
//! tests/layering.rs checks it).
//!
//! To add an effect: a field in [`Effects`] (or a parameter of the rod), an
//! entry in [`REGISTRY`] and a row in docs/model.md's table; then its term
//! in the solver backends that model it.

use super::effect_parameters::DEFAULT_CREEP_TIME_S;
use super::parameter::{ParameterError, PlausibleRange};
use super::rod::Rod;
#[cfg(doc)]
use super::Effects;

/// Scale on the weight.
pub const PLAUSIBLE_GRAVITY_SCALE: PlausibleRange =
    PlausibleRange { min: 0.0, max: 1e6, expected: "0, or a scale up to 1e6 on the nominal weight (1 is the rod's own)" };
/// Friction coefficient.
pub const PLAUSIBLE_FRICTION_MU: PlausibleRange =
    PlausibleRange { min: 0.0, max: 100.0, expected: "0, or a friction coefficient up to 100 (PTFE on silicone: about 0.1–0.5)" };
/// Material stiffening α.
pub const PLAUSIBLE_STIFFENING_ALPHA: PlausibleRange =
    PlausibleRange { min: 0.0, max: 1e6, expected: "0, or a stiffening up to 1e6" };
/// Clamp stiffness, N·mm/rad.
pub const PLAUSIBLE_CLAMP_STIFFNESS: PlausibleRange =
    PlausibleRange { min: 1e-9, max: 1e18, expected: "a clamp stiffness from 1e-9 to 1e18 N·mm/rad" };

/// The table of the rod a parameter sits in (`[actuator.effects]`,
/// `[actuator.gravity]` in a sweep spec; `[rod.…]` in a cable spec).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Section {
    /// [`Effects`].
    Effects,
    /// [`super::rod::Gravity`].
    Gravity,
}

impl Section {
    /// The table's key under the rod.
    pub fn key(self) -> &'static str {
        match self {
            Section::Effects => "effects",
            Section::Gravity => "gravity",
        }
    }
}

/// The values a parameter may take ([`Rod::validate`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Bounds {
    /// Finite and ≥ 0, then within the plausible range.
    NonNegative(PlausibleRange),
    /// Finite and > 0, then within the plausible range if one is given.
    Positive(Option<PlausibleRange>),
    /// Finite and within [min, max] (or [min, max) when `max_open`).
    Within {
        /// Smallest value.
        min: f64,
        /// Largest value (excluded when `max_open`).
        max: f64,
        /// Whether `max` itself is refused.
        max_open: bool,
        /// The range in words, for the error.
        expected: &'static str,
    },
    /// Finite with |v| below the rod's radius.
    BelowRadius {
        /// The range in words, for the error.
        expected: &'static str,
    },
}

/// How a fit parameterises a value so that its search is unconstrained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Domain {
    /// v > 0, fitted as ln v.
    Positive,
    /// 0 < v < 1, fitted as logit v.
    Fraction,
    /// Any finite v, fitted as itself.
    Signed,
}

impl Domain {
    /// Whether `v` lies in the domain.
    pub fn contains(self, v: f64) -> bool {
        match self {
            Domain::Positive => v > 0.0 && v.is_finite(),
            Domain::Fraction => v > 0.0 && v < 1.0,
            Domain::Signed => v.is_finite(),
        }
    }
}

/// How calibrate and diagnose fit an effect's parameter.
#[derive(Debug, Clone, Copy)]
pub struct Fit {
    /// The candidate's name in reports, JSON and on the command line
    /// (`--effects friction`, `synth --effect friction`).
    pub name: &'static str,
    /// Starting value of the fit.
    pub start: f64,
    /// The fitted coordinate.
    pub domain: Domain,
    /// Values a real rod, clamp and cable can have (closed, within the
    /// domain); a fit outside them points at another cause.
    pub plausible: (f64, f64),
    /// The plausible range in words, for reports.
    pub plausible_text: &'static str,
    /// Whether the effect is switched on at all on a rod (gravity can be
    /// off whatever its scale).
    pub switched_on: fn(&Rod) -> bool,
    /// Switches the effect on before its parameter is set.
    pub switch_on: fn(&mut Rod),
}

impl Fit {
    /// A fit of an effect that is on wherever its parameter is set.
    pub const fn new(name: &'static str, start: f64, domain: Domain, plausible: (f64, f64), plausible_text: &'static str) -> Fit {
        Fit { name, start, domain, plausible, plausible_text, switched_on: always_on, switch_on: nothing_to_switch }
    }

    /// Whether `value` is plausible for a real rod.
    pub fn is_plausible(&self, value: f64) -> bool {
        self.domain.contains(value) && (self.plausible.0..=self.plausible.1).contains(&value)
    }
}

/// One parameter of an effect.
#[derive(Debug, Clone, Copy)]
pub struct EffectInfo {
    /// The effect in words (docs/model.md's "effect" column).
    pub effect: &'static str,
    /// Its spec key in [`EffectInfo::section`] (the serde field name).
    pub key: &'static str,
    /// Its path under the rod, as errors and docs name it
    /// (`effects.friction_mu`, `gravity.scale`).
    pub path: &'static str,
    /// Its name with its unit, unique over the rod's parameters (the spec
    /// key, or with its table's name where the key alone says little:
    /// `gravity_scale`): fit reports and `--hold NAME=V` use it, and the
    /// flag is `--` and it in kebab case.
    pub name: &'static str,
    /// The table of the rod holding it.
    pub section: Section,
    /// Its symbol in the model notes.
    pub symbol: &'static str,
    /// Its unit ("1" for a plain number).
    pub unit: &'static str,
    /// The value that leaves the effect out (the thesis model); ∞ for the
    /// rigid clamp.
    pub default: f64,
    /// The default in words, for help texts and docs.
    pub default_text: &'static str,
    /// The values accepted.
    pub bounds: Bounds,
    /// The command-line flag setting it.
    pub flag: &'static str,
    /// Older names of the flag, still accepted.
    pub flag_aliases: &'static [&'static str],
    /// The flag's value name in help texts.
    pub value_name: &'static str,
    /// The flag's help text, before "[default: …]".
    pub help: &'static str,
    /// How calibrate and diagnose fit it; `None`: not a fit candidate.
    pub fit: Option<Fit>,
    /// The parameter it qualifies (creep's time constant acts only when
    /// creep's fraction does); `None` for a main parameter.
    pub qualifies: Option<&'static EffectInfo>,
    /// Reads the parameter from a rod (∞ for a rigid clamp).
    pub get: fn(&Rod) -> f64,
    /// Sets the parameter on a rod (∞ gives the rigid clamp).
    pub set: fn(&mut Rod, f64),
}

fn always_on(_: &Rod) -> bool {
    true
}

fn nothing_to_switch(_: &mut Rod) {}

/// Registry entry: gravity direction (clamp tilt).
pub static GRAVITY_DIRECTION: EffectInfo = EffectInfo {
    effect: "gravity direction (clamp tilt)",
    key: "direction_rad",
    path: "gravity.direction_rad",
    name: "gravity_direction_rad",
    section: Section::Gravity,
    symbol: "β",
    unit: "rad",
    default: 0.0,
    default_text: "0",
    bounds: Bounds::Within {
        min: -std::f64::consts::TAU,
        max: std::f64::consts::TAU,
        max_open: false,
        expected: "an angle in rad with |θ| ≤ 2π (was it given in degrees?)",
    },
    flag: "--gravity-direction-rad",
    flag_aliases: &[],
    value_name: "RAD",
    help: "Gravity direction from the clamp axis, rad (clamp tilt)",
    fit: None,
    qualifies: None,
    get: |a| a.gravity.direction_rad,
    set: |a, v| a.gravity.direction_rad = v,
    
};

/// Registry entry: gravity scale.
pub static GRAVITY_SCALE: EffectInfo = EffectInfo {
    effect: "gravity scale",
    key: "scale",
    path: "gravity.scale",
    name: "gravity_scale",
    section: Section::Gravity,
    symbol: "k",
    unit: "1",
    default: 1.0,
    default_text: "1",
    bounds: Bounds::NonNegative(PLAUSIBLE_GRAVITY_SCALE),
    flag: "--gravity-scale",
    flag_aliases: &[],
    value_name: "K",
    help: "Scale on the nominal self-weight",
    fit: Some(Fit {
        // Gravity can be off whatever its scale: fitting its scale turns it on.
        switched_on: |a| a.gravity.enabled,
        switch_on: |a| a.gravity.enabled = true,
        ..Fit::new("gravity", 1.0, Domain::Positive, (0.0, 10.0), "0 < k ≤ 10")
    }),
    qualifies: None,
    get: |a| a.gravity.scale,
    set: |a, v| a.gravity.scale = v,
    
};

/// Registry entry: material stiffening.
pub static STIFFENING: EffectInfo = EffectInfo {
    effect: "material stiffening",
    key: "stiffening_alpha",
    path: "effects.stiffening_alpha",
    name: "stiffening_alpha",
    section: Section::Effects,
    symbol: "α",
    unit: "1",
    default: 0.0,
    default_text: "0",
    bounds: Bounds::NonNegative(PLAUSIBLE_STIFFENING_ALPHA),
    flag: "--stiffening-alpha",
    flag_aliases: &[],
    value_name: "ALPHA",
    help: "Material stiffening α: moment EI·u·(1 + α (r u)²)",
    fit: Some(Fit::new("stiffening", 0.2, Domain::Positive, (0.0, 100.0), "0 < α ≤ 100")),
    qualifies: None,
    get: |a| a.effects.stiffening_alpha,
    set: |a, v| a.effects.stiffening_alpha = v,
    
};

/// Registry entry: clamp compliance.
pub static CLAMP_COMPLIANCE: EffectInfo = EffectInfo {
    effect: "clamp compliance",
    key: "clamp_stiffness_n_mm_per_rad",
    path: "effects.clamp_stiffness_n_mm_per_rad",
    name: "clamp_stiffness_n_mm_per_rad",
    section: Section::Effects,
    symbol: "k_θ",
    unit: "N·mm/rad",
    default: f64::INFINITY,
    default_text: "rigid clamp",
    bounds: Bounds::Positive(Some(PLAUSIBLE_CLAMP_STIFFNESS)),
    flag: "--clamp-stiffness-n-mm-per-rad",
    flag_aliases: &["--clamp-stiffness"],
    value_name: "N_MM_PER_RAD",
    help: "Clamp rotational stiffness k_θ, N·mm/rad: the effect `clamp_compliance` (`--clamp-stiffness` is the old name)",
    fit: Some(Fit::new("clamp_compliance", 300.0, Domain::Positive, (1.0, 1e5), "1 ≤ k_θ ≤ 1e5 N·mm/rad")),
    qualifies: None,
    get: |a| a.effects.clamp_stiffness_n_mm_per_rad.unwrap_or(f64::INFINITY),
    set: |a, v| a.effects.clamp_stiffness_n_mm_per_rad = (v != f64::INFINITY).then_some(v),
    
};

/// Registry entry: channel offset.
pub static CHANNEL_OFFSET: EffectInfo = EffectInfo {
    effect: "channel offset",
    key: "channel_offset_mm",
    path: "effects.channel_offset_mm",
    name: "channel_offset_mm",
    section: Section::Effects,
    symbol: "δ",
    unit: "mm",
    default: 0.0,
    default_text: "0",
    bounds: Bounds::BelowRadius { expected: "|δ| below the radius" },
    flag: "--channel-offset-mm",
    flag_aliases: &[],
    value_name: "MM",
    help: "Channel offset δ added to every y_i, mm",
    fit: Some(Fit::new("channel_offset", 0.0, Domain::Signed, (-2.0, 2.0), "|δ| ≤ 2 mm")),
    qualifies: None,
    get: |a| a.effects.channel_offset_mm,
    set: |a, v| a.effects.channel_offset_mm = v,
    
};

/// Registry entry: stiffness gradient.
pub static STIFFNESS_GRADIENT: EffectInfo = EffectInfo {
    effect: "stiffness gradient",
    key: "stiffness_gradient_beta",
    path: "effects.stiffness_gradient_beta",
    name: "stiffness_gradient_beta",
    section: Section::Effects,
    symbol: "β",
    unit: "1",
    default: 0.0,
    default_text: "0",
    bounds: Bounds::Within { min: -20.0, max: 20.0, max_open: false, expected: "|β| ≤ 20 (β = ln(EI(L)/EI(0)))" },
    flag: "--stiffness-gradient-beta",
    flag_aliases: &[],
    value_name: "BETA",
    help: "Stiffness gradient β: EI(s) = EI·exp(β (s/L − ½)), β = ln(EI(L)/EI(0))",
    fit: Some(Fit::new("stiffness_gradient", 0.0, Domain::Signed, (-5.0, 5.0), "|β| ≤ 5 (EI(L)/EI(0) between 1/150 and 150)")),
    qualifies: None,
    get: |a| a.effects.stiffness_gradient_beta,
    set: |a, v| a.effects.stiffness_gradient_beta = v,
    
};

/// Registry entry: cable–channel friction.
pub static FRICTION: EffectInfo = EffectInfo {
    effect: "cable–channel friction",
    key: "friction_mu",
    path: "effects.friction_mu",
    name: "friction_mu",
    section: Section::Effects,
    symbol: "μ",
    unit: "1",
    default: 0.0,
    default_text: "0",
    bounds: Bounds::NonNegative(PLAUSIBLE_FRICTION_MU),
    flag: "--friction-mu",
    flag_aliases: &[],
    value_name: "MU",
    help: "Cable–channel friction coefficient μ (capstan law)",
    fit: Some(Fit::new("friction", 0.02, Domain::Positive, (0.0, 1.0), "0 < μ ≤ 1")),
    qualifies: None,
    get: |a| a.effects.friction_mu,
    set: |a, v| a.effects.friction_mu = v,
    
};

/// Registry entry: creep in bending.
pub static CREEP_FRACTION: EffectInfo = EffectInfo {
    effect: "creep in bending",
    key: "creep_fraction",
    path: "effects.creep_fraction",
    name: "creep_fraction",
    section: Section::Effects,
    symbol: "f",
    unit: "1",
    default: 0.0,
    default_text: "0",
    bounds: Bounds::Within {
        min: 0.0,
        max: 1.0,
        max_open: true,
        expected: "0 ≤ f < 1 (the fraction of the bending rigidity that relaxes)",
    },
    flag: "--creep-fraction",
    flag_aliases: &[],
    value_name: "F",
    help: "Creep: fraction f of the bending rigidity that relaxes (0 ≤ f < 1)",
    fit: Some(Fit::new("creep", 0.05, Domain::Fraction, (0.0, 0.9), "0 < f ≤ 0.9")),
    qualifies: None,
    get: |a| a.effects.creep_fraction,
    set: |a, v| a.effects.creep_fraction = v,
    
};

/// Registry entry: creep time constant.
pub static CREEP_TIME: EffectInfo = EffectInfo {
    effect: "creep time constant",
    key: "creep_time_s",
    path: "effects.creep_time_s",
    name: "creep_time_s",
    section: Section::Effects,
    symbol: "T",
    unit: "s",
    default: DEFAULT_CREEP_TIME_S,
    default_text: "10",
    bounds: Bounds::Positive(None),
    flag: "--creep-time-s",
    flag_aliases: &[],
    value_name: "S",
    help: "Creep time constant T, s",
    fit: None,
    qualifies: Some(&CREEP_FRACTION),
    get: |a| a.effects.creep_time_s,
    set: |a, v| a.effects.creep_time_s = v,
    
};

/// Registry entry: creep hold.
pub static CREEP_HOLD: EffectInfo = EffectInfo {
    effect: "creep hold",
    key: "creep_hold_s",
    path: "effects.creep_hold_s",
    name: "creep_hold_s",
    section: Section::Effects,
    symbol: "d",
    unit: "s",
    default: 0.0,
    default_text: "0",
    bounds: Bounds::Within { min: 0.0, max: f64::INFINITY, max_open: true, expected: "a finite time ≥ 0 s" },
    flag: "--creep-hold-s",
    flag_aliases: &[],
    value_name: "S",
    help: "Creep: seconds each tension is held on a fresh rod in sweeps and design",
    fit: None,
    qualifies: Some(&CREEP_FRACTION),
    get: |a| a.effects.creep_hold_s,
    set: |a, v| a.effects.creep_hold_s = v,
    
};

/// Every effect parameter, in the order of the command line's flags.
pub static REGISTRY: [&EffectInfo; 10] = [
    &GRAVITY_DIRECTION,
    &GRAVITY_SCALE,
    &STIFFENING,
    &CLAMP_COMPLIANCE,
    &CHANNEL_OFFSET,
    &STIFFNESS_GRADIENT,
    &FRICTION,
    &CREEP_FRACTION,
    &CREEP_TIME,
    &CREEP_HOLD,
];

impl EffectInfo {
    /// The flag's help text with its default.
    pub fn flag_help(&self) -> String {
        format!("{} [default: {}]", self.help, self.default_text)
    }

    /// Whether the parameter differs from the thesis model's value on `rod`.
    pub fn is_set(&self, rod: &Rod) -> bool {
        (self.get)(rod) != self.default
    }

    /// Whether the parameter changes what a solver computes on `rod`: set,
    /// and, for a qualifying parameter (creep's time constant), its main
    /// parameter set too.
    pub fn acts(&self, rod: &Rod) -> bool {
        self.is_set(rod) && self.qualifies.is_none_or(|main| main.is_set(rod))
    }

    /// Refuses a value outside [`EffectInfo::bounds`] for `rod` (whose
    /// radius bounds the channel offset). ∞ is the rigid clamp's "absent".
    pub fn check(&self, rod: &Rod) -> Result<(), ParameterError> {
        let value = (self.get)(rod);
        let name = self.path;
        match self.bounds {
            Bounds::NonNegative(range) => {
                if !(value.is_finite() && value >= 0.0) {
                    return Err(ParameterError::OutOfRange { name, value, expected: "a finite number ≥ 0" });
                }
                range.check(name, value)
            }
            Bounds::Positive(range) => {
                if value == self.default && self.default == f64::INFINITY {
                    return Ok(());
                }
                if !(value.is_finite() && value > 0.0) {
                    return Err(ParameterError::NotPositive { name, value });
                }
                range.map_or(Ok(()), |r| r.check(name, value))
            }
            Bounds::Within { min, max, max_open, expected } => {
                let below_max = if max_open { value < max } else { value <= max };
                if value.is_finite() && value >= min && below_max {
                    Ok(())
                } else {
                    Err(ParameterError::OutOfRange { name, value, expected })
                }
            }
            Bounds::BelowRadius { expected } => {
                if value.is_finite() && value.abs() < rod.radius_mm {
                    Ok(())
                } else {
                    Err(ParameterError::OutOfRange { name, value, expected })
                }
            }
        }
    }
}

/// The entry of spec key `key` (the key alone, `friction_mu`, or its path,
/// `effects.friction_mu`, `gravity.scale`).
pub fn find(key: &str) -> Option<&'static EffectInfo> {
    REGISTRY.iter().copied().find(|e| e.key == key || e.path == key)
}

/// The entry whose flag is `flag` (`--friction-mu`, or an alias).
pub fn find_flag(flag: &str) -> Option<&'static EffectInfo> {
    REGISTRY.iter().copied().find(|e| e.flag == flag || e.flag_aliases.contains(&flag))
}

/// The entries calibrate and diagnose can fit, in registry order.
pub fn fittable() -> impl Iterator<Item = (&'static EffectInfo, &'static Fit)> {
    REGISTRY.iter().copied().filter_map(|e| e.fit.as_ref().map(|f| (e, f)))
}

/// Checks every effect parameter of `rod` against its bounds.
pub fn validate(rod: &Rod) -> Result<(), ParameterError> {
    REGISTRY.iter().try_for_each(|e| e.check(rod))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_flags_and_candidate_names_are_unique_and_accessors_round_trip() {
        let mut seen = std::collections::BTreeSet::new();
        for e in REGISTRY {
            assert!(seen.insert(e.path.to_string()), "{} twice", e.path);
            assert_eq!(e.path, format!("{}.{}", e.section.key(), e.key));
            assert_eq!(e.flag, format!("--{}", e.name.replace('_', "-")), "the flag is the parameter's name");
            assert!(seen.insert(e.flag.to_string()), "{} twice", e.flag);
            if let Some(f) = &e.fit {
                assert!(seen.insert(f.name.to_string()), "{} twice", f.name);
                assert!(f.domain.contains(f.start) || f.domain == Domain::Signed, "{}: start outside the domain", f.name);
            }
            let d = Rod::default();
            assert_eq!((e.get)(&d), e.default, "{}: the default rod has the registry's default", e.key);
            assert!(!e.acts(&d) && e.check(&d).is_ok());
            let mut a = d.clone();
            let v = if e.default == 0.0 { 0.25 } else if e.default.is_finite() { e.default * 0.5 } else { 40.0 };
            (e.set)(&mut a, v);
            assert_eq!((e.get)(&a), v, "{}", e.key);
            assert!(e.is_set(&a) && e.check(&a).is_ok(), "{}", e.key);
            assert_eq!(find(e.key).map(|f| f.key), Some(e.key));
            assert_eq!(find(e.path).map(|f| f.key), Some(e.key));
            assert_eq!(find_flag(e.flag).map(|f| f.key), Some(e.key));
        }
    }

    #[test]
    fn bounds_refuse_with_the_parameters_path() {
        let mut a = Rod::default();
        a.effects.friction_mu = -1.0;
        assert!(validate(&a).unwrap_err().to_string().contains("effects.friction_mu"));
        let mut a = Rod::default();
        a.effects.creep_fraction = 1.0;
        assert!(validate(&a).unwrap_err().to_string().contains("0 ≤ f < 1"));
        let mut a = Rod::default();
        a.effects.channel_offset_mm = 5.0;
        assert!(validate(&a).unwrap_err().to_string().contains("effects.channel_offset_mm"));
        let mut a = Rod::default();
        a.effects.clamp_stiffness_n_mm_per_rad = Some(0.0);
        assert!(validate(&a).unwrap_err().to_string().contains("must be a positive"));
        let mut a = Rod::default();
        a.gravity.direction_rad = 1e300;
        assert!(validate(&a).unwrap_err().to_string().contains("gravity.direction_rad"));
    }
}
