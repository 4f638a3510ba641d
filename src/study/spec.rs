//! A study spec: a sweep spec with a `[study]` section of axes, and its
//! variants (every combination of the axes' values, first axis slowest),
//! each with its complete sweep spec.

use super::axes::{AxisSection, Change};
use super::error::{SpecProblem, StudyError};
use crate::sweep::SweepSpec;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Most variants of a study (a typo in an axis should not start 10⁶ sweeps).
pub const MAX_VARIANTS: usize = 1000;

/// The `[study]` section as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StudySection {
    name: Option<String>,
    #[serde(default)]
    axis: Vec<AxisSection>,
}

/// One setting of a variant: an axis and its value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Setting {
    /// The axis.
    pub axis: String,
    /// The value as written in the label (e.g. `55`, `×0.8`, `1–3 N`).
    pub value: String,
}

/// One variant: its settings and its complete sweep spec.
#[derive(Debug, Clone)]
pub struct Variant {
    /// Variant number (first axis slowest).
    pub index: usize,
    /// Its axis values.
    pub settings: Vec<Setting>,
    /// The sweep spec of the variant.
    pub spec: SweepSpec,
}

/// `axis=value, …` of `settings`.
fn label(settings: &[Setting]) -> String {
    settings.iter().map(|s| format!("{}={}", s.axis, s.value)).collect::<Vec<_>>().join(", ")
}

impl Variant {
    /// `axis=value, …`.
    pub fn label(&self) -> String {
        label(&self.settings)
    }

    /// The variant's directory in the study directory `dir`.
    pub fn dir(&self, dir: &Path) -> PathBuf {
        dir.join(format!("v{}", self.index))
    }

    /// Its sweep run directory.
    pub fn run_dir(&self, dir: &Path) -> PathBuf {
        self.dir(dir).join("run")
    }

    /// Its map directory.
    pub fn map_dir(&self, dir: &Path) -> PathBuf {
        self.dir(dir).join("map")
    }
}

/// A study: a name and its variants.
#[derive(Debug, Clone)]
pub struct StudySpec {
    /// The study's name.
    pub name: String,
    /// The axes, in order, with their number of values.
    pub axes: Vec<(String, usize)>,
    /// Every variant.
    pub variants: Vec<Variant>,
}

impl StudySpec {
    /// Reads a study spec file.
    pub fn load(path: &Path) -> Result<Self, StudyError> {
        let text = crate::io::read_text(path, "reading")?;
        Self::from_toml(&text, &path.display().to_string())
    }

    /// Parses a study spec; `origin` names it in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, StudyError> {
        let table: toml::Table =
            text.parse().map_err(|e| StudyError::Spec { origin: origin.to_string(), problem: SpecProblem::Toml(e) })?;
        Self::from_table(table, origin)
    }

    /// A study spec from its parsed TOML (see [`crate::job::Job::load`],
    /// which parses a spec once to tell its kind); `origin` names it in errors.
    pub fn from_table(mut table: toml::Table, origin: &str) -> Result<Self, StudyError> {
        let bad = |problem| StudyError::Spec { origin: origin.to_string(), problem };
        let section = table.remove("study").ok_or_else(|| bad(SpecProblem::NoStudySection))?;
        let section: StudySection = section.try_into().map_err(|e| bad(SpecProblem::StudySection(e)))?;
        let base_text = toml::to_string(&table).map_err(|e| bad(SpecProblem::BaseText(e)))?;
        let base = SweepSpec::from_toml(&base_text, origin).map_err(|e| bad(SpecProblem::Base(Box::new(e))))?;
        if base.planar().is_none() {
            return Err(bad(SpecProblem::CableBase));
        }
        if section.axis.is_empty() {
            return Err(bad(SpecProblem::NoAxes));
        }
        let mut axes: Vec<(String, Vec<(String, Change)>)> = Vec::new();
        for a in &section.axis {
            let changes =
                a.changes().map_err(|source| StudyError::Axis { origin: origin.to_string(), axis: a.name.clone(), source })?;
            if axes.iter().any(|(n, _)| *n == a.name) {
                return Err(bad(SpecProblem::AxisTwice { axis: a.name.clone() }));
            }
            // The tension ladder of a cable driven by its displacement is unused.
            if base.planar().is_some_and(|p| p.displacement.is_some()) && changes.iter().any(|(_, c)| matches!(c, Change::Tension { .. })) {
                return Err(bad(SpecProblem::TensionOfDisplacement { axis: a.name.clone() }));
            }
            axes.push((a.name.clone(), changes));
        }
        let count = axes.iter().try_fold(1usize, |n, (_, v)| n.checked_mul(v.len())).filter(|&n| n <= MAX_VARIANTS);
        let Some(count) = count else {
            return Err(bad(SpecProblem::TooManyVariants { most: MAX_VARIANTS }));
        };
        let base_json: serde_json::Value = serde_json::from_str(&base.canonical_json()).expect("the spec's canonical JSON parses");
        let mut variants = Vec::with_capacity(count);
        for index in 0..count {
            // Mixed radix, first axis slowest.
            let mut rest = index;
            let mut picks = vec![0; axes.len()];
            for (slot, (_, values)) in picks.iter_mut().zip(&axes).rev() {
                *slot = rest % values.len();
                rest /= values.len();
            }
            let mut json = base_json.clone();
            let mut settings = Vec::new();
            for ((name, values), &pick) in axes.iter().zip(&picks) {
                let (value, change) = &values[pick];
                change.apply(&mut json);
                settings.push(Setting { axis: name.clone(), value: value.clone() });
            }
            let label = label(&settings);
            let spec: SweepSpec =
                serde_json::from_value(json).map_err(|source| bad(SpecProblem::VariantSettings { index, label: label.clone(), source }))?;
            spec.validate().map_err(|source| StudyError::Variant {
                origin: origin.to_string(),
                index,
                label,
                source: crate::sweep::SweepError::BadSpec { origin: format!("variant {index}"), source },
            })?;
            variants.push(Variant { index, settings, spec });
        }
        let name = section.name.unwrap_or_else(|| axes.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>().join(" × "));
        Ok(Self { name, axes: axes.iter().map(|(n, v)| (n.clone(), v.len())).collect(), variants })
    }

    /// The variants that task `shard` of `shards` runs (every `shards`-th).
    pub fn variants_of_shard(&self, shard: u64, shards: u64) -> impl Iterator<Item = &Variant> {
        self.variants.iter().filter(move |v| v.index as u64 % shards.max(1) == shard)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const STUDY: &str = "[grid]\nlevels = 3\n[tension]\ncount = 5\n[study]\nname = \"t\"\n\
        [[study.axis]]\nname = \"length_mm\"\nvalues = [55, 65.0]\n\
        [[study.axis]]\nname = \"ei_n_mm2\"\nscale = [0.8, 1.25]\n";

    #[test]
    fn variants_are_every_combination_first_axis_slowest() {
        let s = StudySpec::from_toml(STUDY, "t").unwrap();
        assert_eq!(s.variants.len(), 4);
        let v = &s.variants[1];
        assert_eq!(v.label(), "length_mm=55, ei_n_mm2=×1.25");
        assert_eq!(v.spec.planar().unwrap().actuator.length_mm, 55.0);
        assert_eq!(v.spec.planar().unwrap().actuator.ei_n_mm2, 115.117 * 1.25);
        assert_eq!(v.spec.planar().unwrap().grid.levels, 3);
        assert_eq!(s.variants[2].spec.planar().unwrap().actuator.length_mm, 65.0);
        // The variant's spec.toml reads back as the same spec (same hash: same run).
        let text = toml::to_string(&v.spec).unwrap();
        assert_eq!(SweepSpec::from_toml(&text, "v").unwrap().hash_hex(), v.spec.hash_hex());
    }

    #[test]
    fn tension_and_effects_axes() {
        let friction = crate::model::effects::FRICTION.key;
        let s = StudySpec::from_toml(
            &format!(
                "[study]\n[[study.axis]]\nname = \"tension_n\"\nvalues = [[1.0, 2.0], [1, 3]]\n\
                 [[study.axis]]\nname = \"effects\"\nvalues = [{{}}, {{ {friction} = 0.1 }}]\n"
            ),
            "t",
        )
        .unwrap();
        assert_eq!(s.variants.len(), 4);
        assert_eq!(s.variants[3].spec.planar().unwrap().tension.max_n, 3.0);
        assert_eq!(s.variants[3].spec.planar().unwrap().actuator.effects.friction_mu, 0.1);
        assert_eq!(s.variants[2].spec.planar().unwrap().actuator.effects.friction_mu, 0.0);
        assert_eq!(s.variants[3].label(), format!("tension_n=1–3 N, effects={{{friction}:0.1}}"));
    }

    #[test]
    fn every_registry_effect_parameter_is_an_axis() {
        for info in crate::model::REGISTRY.iter() {
            let v = if info.default == 0.0 { 0.25 } else if info.default.is_finite() { info.default * 0.5 } else { 40.0 };
            // Without mirror_dedup: a tilt or an offset breaks the mirror symmetry.
            let text = format!("[grid]\nmirror_dedup = false\n[study]\n[[study.axis]]\nname = \"{}\"\nvalues = [{v}]\n", info.path);
            let s = StudySpec::from_toml(&text, "t").unwrap_or_else(|e| panic!("{}: {e}", info.path));
            assert_eq!((info.get)(&s.variants[0].spec.planar().unwrap().actuator), v, "{}", info.path);
        }
    }

    #[test]
    fn bad_studies_name_the_problem() {
        let err = |t: &str| StudySpec::from_toml(t, "s.toml").unwrap_err().to_string();
        assert!(err("[grid]\nlevels = 3\n").contains("no [study] section"));
        assert!(err("[study]\n").contains("no [[study.axis]]"));
        assert!(err("[study]\n[[study.axis]]\nname = \"colour\"\nvalues = [1]\n").contains("unknown axis 'colour'"));
        assert!(err("[study]\n[[study.axis]]\nname = \"length_mm\"\nvalues = [1]\nscale = [2.0]\n").contains("not both"));
        assert!(err("[study]\n[[study.axis]]\nname = \"length_mm\"\nvalues = [\"a\"]\n").contains("not a number"));
        assert!(err("[study]\n[[study.axis]]\nname = \"ei_n_mm2\"\nscale = [-1.0]\n").contains("positive"));
        assert!(err("[study]\n[[study.axis]]\nname = \"tension_n\"\nvalues = [[1.0]]\n").contains("pair"));
        let displaced = "[displacement]\nmin_mm = 0.5\nmax_mm = 2.0\ncount = 3\n";
        assert!(err(&format!("{displaced}[study]\n[[study.axis]]\nname = \"tension_n\"\nvalues = [[1.0, 2.0]]\n")).contains("[displacement]"));
        // Other axes over a displacement-driven base keep its ladder.
        let s = StudySpec::from_toml(&format!("{displaced}[study]\n[[study.axis]]\nname = \"ei_n_mm2\"\nvalues = [100.0, 120.0]\n"), "t").unwrap();
        assert!(s.variants.iter().all(|v| v.spec.planar().unwrap().displacement.as_ref().is_some_and(|d| d.count == 3)));
        let e = err("[study]\n[[study.axis]]\nname = \"length_mm\"\nvalues = [65, -5]\n");
        assert!(e.contains("variant 1 (length_mm=-5)") && e.contains("length_mm"), "{e}");
        assert!(err("[grid]\nlevles = 3\n[study]\n[[study.axis]]\nname = \"length_mm\"\nvalues = [65]\n").contains("levles"));
    }
}
