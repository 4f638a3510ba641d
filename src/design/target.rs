//! Design targets and weights of eq. 3.17: tip position (x_e, y_e) and
//! Legendre curvature coefficients a_0 … a_n, any of them optional.

pub use super::targets::{error_pct, Quantity, MAX_ORDER};
use super::DesignError;
use serde::Serialize;

/// A design target: the requested components, in the order x, y, a_0, a_1, ….
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Target {
    /// (quantity, target value) pairs, sorted, each quantity at most once:
    /// the tip in the plane and the in-plane bending coefficients.
    pub components: Vec<(Quantity, f64)>,
}

/// The `--target` key of a quantity a target holds.
pub(super) fn target_key(q: Quantity) -> String {
    q.planar_key().expect("a --target asks for quantities in the plane only")
}

impl Target {
    /// Parses `x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015` (any subset, any order).
    pub fn parse(text: &str) -> Result<Self, DesignError> {
        let mut components = Vec::new();
        let bad = |problem| DesignError::BadTarget { problem };
        for (key, component, value) in parse_pairs(text, List::Target).map_err(bad)? {
            if !value.is_finite() {
                return Err(bad(ListProblem::NotFinite { key, value }));
            }
            if components.iter().any(|(c, _)| *c == component) {
                return Err(bad(ListProblem::Twice { key }));
            }
            components.push((component, value));
        }
        if components.is_empty() {
            return Err(bad(ListProblem::EmptyTarget));
        }
        components.sort_by_key(|c| c.0);
        Ok(Self { components })
    }

    /// Highest coefficient order asked for, if any coefficient is.
    pub fn highest_order(&self) -> Option<usize> {
        self.components.iter().filter_map(|(c, _)| if let Quantity::BendZ(k) = c { Some(*k) } else { None }).max()
    }

    /// The order to compute and report: the highest coefficient given, or the
    /// thesis's order 2 for a tip-only target (so the shape is still reported).
    pub fn order(&self) -> usize {
        self.highest_order().unwrap_or(2)
    }

    /// The target value of `component`, if requested.
    pub fn get(&self, component: Quantity) -> Option<f64> {
        self.components.iter().find(|(c, _)| *c == component).map(|(_, v)| *v)
    }

    /// The target as a `{"x": …, "a0": …}` JSON object.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::Value::Object(self.components.iter().map(|(c, v)| (target_key(*c), serde_json::json!(v))).collect())
    }
}

/// Weights λ of eq. 3.17, one per target component.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Weights {
    /// (component, λ) pairs for components whose weight was given explicitly.
    overrides: Vec<(Quantity, f64)>,
}

impl Weights {
    /// Parses `x=1,y=1,a0=100,a1=50,a2=25` (any subset; others keep the
    /// thesis defaults). Weights must be finite and ≥ 0.
    pub fn parse(text: &str) -> Result<Self, DesignError> {
        let mut overrides: Vec<(Quantity, f64)> = Vec::new();
        let bad = |problem| DesignError::BadWeights { problem };
        for (key, component, value) in parse_pairs(text, List::Weights).map_err(bad)? {
            if !(value.is_finite() && value >= 0.0) {
                return Err(bad(ListProblem::NotAWeight { key, value }));
            }
            overrides.retain(|(c, _)| *c != component);
            overrides.push((component, value));
        }
        Ok(Self { overrides })
    }

    /// λ for `component`: the override, else the thesis default.
    pub fn get(&self, component: Quantity) -> f64 {
        let default = component.thesis_weight().expect("a --target asks for the tip and coefficients only");
        self.overrides.iter().find(|(c, _)| *c == component).map_or(default, |(_, w)| *w)
    }

    /// Checks that a weight was not given for a component the target omits
    /// (almost always a typo) and that some weight is positive.
    pub fn check_against(&self, target: &Target) -> Result<(), DesignError> {
        for (c, _) in &self.overrides {
            if target.get(*c).is_none() {
                return Err(DesignError::BadWeights { problem: ListProblem::NotInTarget { key: target_key(*c) } });
            }
        }
        if target.components.iter().all(|(c, _)| self.get(*c) == 0.0) {
            return Err(DesignError::BadWeights { problem: ListProblem::AllZero });
        }
        Ok(())
    }
}

/// Which list of `KEY=VALUE` pairs: a target or its weights.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum List {
    /// `--target`.
    Target,
    /// `--weights`.
    Weights,
}

impl List {
    /// An example of the list, completing the error messages.
    pub fn example(self) -> &'static str {
        match self {
            List::Target => "e.g. --target x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015",
            List::Weights => "e.g. --weights x=1,y=1,a0=100,a1=50,a2=25",
        }
    }
}

/// What is wrong with a target's or its weights' list.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ListProblem {
    /// An item without `=`.
    #[error("'{item}' is not KEY=VALUE; write {}", list.example())]
    NotKeyValue {
        /// The item.
        item: String,
        /// Which list.
        list: List,
    },
    /// A key that names no component.
    #[error("unknown component '{key}'; use x, y (tip, mm) or a0 … a{MAX_ORDER} (curvature coefficients, 1/mm)")]
    UnknownComponent {
        /// The key.
        key: String,
    },
    /// A value that is no number.
    #[error("{key}: '{value}' is not a finite number; {}{}", if value.contains(['=', ' ', ';', '\t']) { "separate components with commas, " } else { "" }, list.example())]
    NotANumber {
        /// The key.
        key: String,
        /// The value as written.
        value: String,
        /// Which list.
        list: List,
    },
    /// A target value that is not finite.
    #[error("{key}: '{value}' is not a finite number")]
    NotFinite {
        /// The key.
        key: String,
        /// The value.
        value: f64,
    },
    /// A component given twice.
    #[error("{key} is given twice")]
    Twice {
        /// The key.
        key: String,
    },
    /// No component.
    #[error("the target is empty; give at least one of x, y, a0, a1, … e.g. --target x=50,y=5")]
    EmptyTarget,
    /// A weight that is negative or not finite.
    #[error("{key}: '{value}' is not a finite weight ≥ 0")]
    NotAWeight {
        /// The key.
        key: String,
        /// The value.
        value: f64,
    },
    /// A weight for a component the target does not ask for.
    #[error("a weight is given for {key} but the target does not ask for it; add {key}=… to --target or drop the weight")]
    NotInTarget {
        /// The component's key.
        key: String,
    },
    /// Every weight zero.
    #[error("every weight is zero: nothing to fit")]
    AllZero,
}

/// Splits `KEY=VALUE,…` into (key, component, number).
fn parse_pairs(text: &str, list: List) -> Result<Vec<(String, Quantity, f64)>, ListProblem> {
    text.split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|item| {
            let (key, value) = item.split_once('=').ok_or_else(|| ListProblem::NotKeyValue { item: item.to_string(), list })?;
            let key = key.trim();
            let component = Quantity::parse_planar_key(key).ok_or_else(|| ListProblem::UnknownComponent { key: key.to_string() })?;
            let number: f64 = value.trim().parse().map_err(|_| ListProblem::NotANumber { key: key.to_string(), value: value.trim().to_string(), list })?;
            Ok((key.to_string(), component, number))
        })
        .collect()
}


#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_thesis_target() {
        let t = Target::parse("x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015").unwrap();
        assert_eq!(t.components.len(), 5);
        assert_eq!(t.get(Quantity::TipX), Some(50.0));
        assert_eq!(t.get(Quantity::BendZ(2)), Some(0.015));
        assert_eq!(t.order(), 2);
    }

    #[test]
    fn any_subset_and_order() {
        let t = Target::parse("a1=-0.06, x=3").unwrap();
        assert_eq!(t.components, vec![(Quantity::TipX, 3.0), (Quantity::BendZ(1), -0.06)]);
        assert_eq!(t.order(), 1);
        assert_eq!(Target::parse("x=1,y=2").unwrap().order(), 2);
    }

    #[test]
    fn rejects_bad_targets() {
        for bad in ["", "x", "x=abc", "z=1", "x=1,x=2", "a=1", "a99=1", "y=nan"] {
            assert!(Target::parse(bad).is_err(), "{bad} should be rejected");
        }
    }

    #[test]
    fn components_run_together_are_told_to_use_commas() {
        for bad in ["x=50 y=5", "x=50;y=5"] {
            let e = Target::parse(bad).unwrap_err().to_string();
            assert!(e.contains("'50") && e.contains("separate components with commas") && e.contains("x=50,y=5"), "{bad}: {e}");
        }
        let e = Target::parse("x=abc").unwrap_err().to_string();
        assert!(e.contains("'abc' is not a finite number") && !e.contains("commas"), "{e}");
    }

    #[test]
    fn weights_default_and_override() {
        let t = Target::parse("x=1,a0=0.01,a3=0.001").unwrap();
        let w = Weights::parse("a0=7").unwrap();
        w.check_against(&t).unwrap();
        assert_eq!(w.get(Quantity::BendZ(0)), 7.0);
        assert_eq!(w.get(Quantity::TipX), 1.0);
        assert_eq!(w.get(Quantity::BendZ(1)), 50.0);
        assert_eq!(w.get(Quantity::BendZ(3)), 25.0);
        assert!(Weights::parse("y=2").unwrap().check_against(&t).is_err());
        assert!(Weights::parse("x=-1").is_err());
        assert!(Weights::parse("x=0,a0=0,a3=0").unwrap().check_against(&t).is_err());
    }

    #[test]
    fn error_convention_matches_table_5_1() {
        // Target I, a_0: −0.0244 vs −0.0250 is +2.40 %; a_2: 0.0131 vs 0.015 is −12.7 %.
        assert!((error_pct(-0.0244, -0.025).unwrap() - 2.4).abs() < 1e-9);
        assert!((error_pct(0.0131, 0.015).unwrap() + 12.666_666).abs() < 1e-3);
        assert_eq!(error_pct(1.0, 0.0), None);
    }
}
