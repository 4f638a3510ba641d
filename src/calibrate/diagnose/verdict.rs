//! What a diagnosis concludes, as one value from the criterion to the JSON.

use crate::calibrate::effect::Effect;
use serde::{Serialize, Serializer};

/// The verdict of a diagnosis. In JSON and reports it is one word: `none`,
/// the (first) named effect's name, `ambiguous`, `unexplained` or
/// `inconclusive`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// The thesis model (with any held effects) is consistent with the
    /// noise and no candidate effect is warranted: `none`.
    Consistent,
    /// This effect (the first one added; a second may follow it) explains
    /// the data: its name.
    Named(Effect),
    /// The data cannot tell these two effects apart: `ambiguous`.
    Ambiguous(Effect, Effect),
    /// Even the best model with one or two library effects stays above the
    /// noise: `unexplained`.
    Unexplained,
    /// Nothing can be concluded (the thesis-model fit did not converge, or
    /// no candidate fit did): `inconclusive`.
    Inconclusive,
}

impl Verdict {
    /// The verdict's word, as in the JSON.
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Consistent => "none",
            Verdict::Named(e) => e.name(),
            Verdict::Ambiguous(..) => "ambiguous",
            Verdict::Unexplained => "unexplained",
            Verdict::Inconclusive => "inconclusive",
        }
    }
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label())
    }
}

impl Serialize for Verdict {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.label())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verdicts_serialise_to_their_words() {
        let json = |v: Verdict| serde_json::to_value(v).unwrap();
        assert_eq!(json(Verdict::Consistent), "none");
        assert_eq!(json(Verdict::Named(Effect::ClampCompliance)), "clamp_compliance");
        assert_eq!(json(Verdict::Ambiguous(Effect::Friction, Effect::Creep)), "ambiguous");
        assert_eq!(json(Verdict::Unexplained), "unexplained");
        assert_eq!(Verdict::Inconclusive.to_string(), "inconclusive");
    }
}
