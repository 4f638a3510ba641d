//! The request of `cablemap feasible` and its report: a map's (or a
//! study's maps') verdict on a target ([`super::feasible`]), or a cable
//! sweep's map on every target of a targets file ([`super::reach`]).

use super::feasible::{check, design_command, FeasibilityReport, Verdict};
use super::map::MapDir;
use super::reach::TargetsFeasibility;
use super::request::TargetOnly;
use super::target::{Target, Weights};
use super::targets::TargetSet;
use super::DesignError;
use crate::shape::LengthBasis;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::PathBuf;

/// What `feasible` judges the target against.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MapSource {
    /// One feasibility map directory (`cablemap reduce` output).
    Map(PathBuf),
    /// A study directory (`cablemap study` output): every variant's map.
    Study(PathBuf),
}

/// Everything a feasibility check needs: a target against a map or a
/// study's maps, or a targets file against a cable sweep's map.
/// Deserialises from the Python keywords' names.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FeasibleRequest {
    /// One feasibility map directory (`cablemap reduce` output).
    #[serde(default)]
    pub map: Option<PathBuf>,
    /// A study directory (`cablemap study` output): every variant's map.
    #[serde(default)]
    pub study: Option<PathBuf>,
    /// The thesis's target.
    #[serde(default, deserialize_with = "super::request::target_text")]
    pub target: Option<Target>,
    /// A targets file (with the map of a cable sweep).
    #[serde(default)]
    pub targets: Option<PathBuf>,
    /// Weights of the distance to the nearest designs for `target`
    /// (checked against it here; the thesis's when none).
    #[serde(default, deserialize_with = "super::request::weights_text")]
    pub weights: Option<Weights>,
    /// The length the target's coefficients are per unit of.
    #[serde(default)]
    pub length_basis: LengthBasis,
    /// Nearest simulated designs to list.
    pub nearest: usize,
}

/// One study variant's verdict.
#[derive(Debug, Clone)]
pub struct VariantVerdict {
    /// Variant number.
    pub index: usize,
    /// Its settings, `axis=value, …`.
    pub label: String,
    /// Its map's verdict.
    pub report: FeasibilityReport,
}

/// The answer of `feasible`.
#[derive(Debug, Clone)]
pub enum FeasibleReport {
    /// One map's verdict.
    Map {
        /// The verdict and its evidence.
        report: FeasibilityReport,
        /// The command that designs for the target with the map's designs as seeds.
        next: String,
    },
    /// A cable sweep's map on every target of a targets file.
    Targets(TargetsFeasibility),
    /// Every variant's verdict of a study.
    Study {
        /// The study directory.
        dir: PathBuf,
        /// One verdict per variant.
        variants: Vec<VariantVerdict>,
    },
}

impl FeasibleReport {
    /// The variants of a study whose maps reach the target feasibly (`v0`, …).
    pub fn feasible_variants(&self) -> Vec<String> {
        match self {
            FeasibleReport::Map { .. } | FeasibleReport::Targets(_) => Vec::new(),
            FeasibleReport::Study { variants, .. } => {
                variants.iter().filter(|v| v.report.verdict == Verdict::Feasible).map(|v| format!("v{}", v.index)).collect()
            }
        }
    }
}

impl Serialize for FeasibleReport {
    /// The JSON `feasible --json` prints.
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            FeasibleReport::Map { report, .. } => report.serialize(serializer),
            FeasibleReport::Targets(report) => report.serialize(serializer),
            FeasibleReport::Study { dir, variants } => {
                let rows: Vec<_> = variants
                    .iter()
                    .map(|v| serde_json::json!({ "variant": v.index, "label": v.label, "verdict": v.report.verdict, "report": v.report }))
                    .collect();
                serde_json::json!({ "study": dir, "feasible_variants": self.feasible_variants(), "variants": rows }).serialize(serializer)
            }
        }
    }
}

impl fmt::Display for FeasibleReport {
    /// The text `feasible` prints.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FeasibleReport::Map { report, next } => {
                write!(f, "{report}")?;
                writeln!(f, "next      {next}")
            }
            FeasibleReport::Targets(report) => write!(f, "{report}"),
            FeasibleReport::Study { variants, .. } => {
                for v in variants {
                    let first = v.report.reasons.first().map_or(String::new(), |s| format!(": {s}"));
                    writeln!(f, "v{:<3} {}: {}{first}", v.index, v.label, v.report.verdict.label())?;
                }
                let reach = self.feasible_variants();
                if reach.is_empty() {
                    writeln!(f, "no variant reaches the target feasibly (see the borderline ones, or widen the study)")
                } else {
                    writeln!(f, "reach the target: {} of {} variants ({})", reach.len(), variants.len(), reach.join(", "))
                }
            }
        }
    }
}

impl FeasibleRequest {
    /// What the target is judged against, with what the request cannot
    /// mean refused: both or neither of a map and a study, both or neither
    /// of `target` and `targets`, `targets` without one map, weights with
    /// `targets`.
    pub fn check(&self) -> Result<MapSource, DesignError> {
        let source = match (&self.map, &self.study) {
            (Some(_), Some(_)) => return Err(DesignError::MapAndStudy),
            (Some(map), None) => MapSource::Map(map.clone()),
            (None, Some(study)) => MapSource::Study(study.clone()),
            (None, None) => return Err(DesignError::NoMapOrStudy),
        };
        match (&self.target, &self.targets, &source) {
            (Some(_), Some(_), _) | (None, None, _) => Err(DesignError::TargetOrTargets),
            (None, Some(_), MapSource::Study(_)) => Err(DesignError::TargetsNeedMap),
            (None, Some(_), _) if self.weights.is_some() => Err(DesignError::TargetOnly { setting: TargetOnly::Weights }),
            _ => Ok(source),
        }
    }
}

/// Runs `feasible`: the map's verdict on the target, or every study
/// variant's, or a cable sweep's map on every target of a targets file.
pub fn run(request: &FeasibleRequest) -> Result<FeasibleReport, DesignError> {
    let source = &request.check()?;
    let FeasibleRequest { target, targets, weights, length_basis, nearest, .. } = request;
    if let (Some(targets), MapSource::Map(dir)) = (targets, source) {
        // The rod's length only sets the targets' default weights; the map's own rod is the thesis's unless its spec says otherwise.
        let targets = TargetSet::read(targets, crate::model::Rod::default().length_mm)?;
        return Ok(FeasibleReport::Targets(super::reach::check(dir, &targets, *length_basis, *nearest)?));
    }
    let target = target.as_ref().ok_or(DesignError::TargetOrTargets)?;
    let weights = &weights.clone().unwrap_or_default();
    weights.check_against(target)?;
    match source {
        MapSource::Map(dir) => {
            let map = MapDir::open(dir)?;
            let report = check(&map, target, *length_basis, weights, *nearest)?;
            Ok(FeasibleReport::Map { report, next: design_command(target, dir) })
        }
        MapSource::Study(dir) => {
            let mut variants = Vec::new();
            for (index, label, map_dir) in crate::study::mapped_variants(dir).map_err(Box::new)? {
                let map = MapDir::open(&map_dir).map_err(|e| DesignError::Variant { index, label: label.clone(), source: Box::new(e) })?;
                let report = check(&map, target, *length_basis, weights, *nearest)?;
                variants.push(VariantVerdict { index, label, report });
            }
            Ok(FeasibleReport::Study { dir: dir.clone(), variants })
        }
    }
}
