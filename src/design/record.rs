//! design.json: the record of a design that `cablemap design --json` prints,
//! `design --out` writes and `cablemap mould --design` reads. This module owns
//! the format: its fields (the struct below), writer and reader.

use super::feasible::{FeasibilityReport, Verdict};
use super::objective::{Bounds, Objective};
use super::objective::Evaluation;
use super::target::target_key;
use super::targets::ComponentOutcome;
use super::search::{routing, Found};
use super::DesignError;
use crate::model::routing::ControlPoints;
use crate::model::Rod;
use crate::shape::LengthBasis;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One design, as design.json holds it. Keys print in alphabetical order.
#[derive(Debug, Clone, Serialize)]
pub struct DesignRecord {
    /// Curvature coefficients a_0..a_n achieved, mm⁻¹, in `length_basis`.
    pub a: Vec<f64>,
    /// Achieved value of each target component (x, y in mm; a_i in mm⁻¹).
    pub achieved: BTreeMap<String, f64>,
    /// The actuator designed for.
    pub actuator: Rod,
    /// Tangent angle at the clamp, rad.
    pub base_angle_rad: f64,
    /// Search bounds (tension range, largest control-point offset).
    pub bounds: Bounds,
    /// Objective value (eq. 3.17) of the design.
    pub cost: f64,
    /// Relative error of each component, % (none where the target is 0).
    pub error_pct: BTreeMap<String, Option<f64>>,
    /// The map's verdict on the target, when a map was given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub feasibility: Option<FeasibilityRecord>,
    /// The length the coefficients are per unit of.
    pub length_basis: LengthBasis,
    /// Deformed length ℓ, mm.
    pub length_mm: f64,
    /// Every component met within the tolerance.
    pub met: bool,
    /// Routing control points y_0..y_4, mm.
    pub routing_mm: ControlPoints,
    /// Wall time of the search, s.
    pub seconds: f64,
    /// Seed designs simulated before refining.
    pub seeds_simulated: usize,
    /// Each refined start.
    pub starts: Vec<serde_json::Value>,
    /// The target as given.
    pub target: serde_json::Value,
    /// Cable tension, N.
    pub tension_n: f64,
    /// Tangent angle at the tip, rad.
    pub tip_angle_rad: f64,
    /// Tip position, mm.
    pub tip_x_mm: f64,
    /// Tip position, mm.
    pub tip_y_mm: f64,
    /// Components not met.
    pub unmet: Vec<String>,
    /// Weight λ of each target component.
    pub weights: BTreeMap<String, f64>,
}

/// A feasibility map's verdict on the target, inside a [`DesignRecord`].
#[derive(Debug, Clone, Serialize)]
pub struct FeasibilityRecord {
    /// The map directory.
    pub map: Option<PathBuf>,
    /// Why, one sentence per finding.
    pub reasons: Vec<String>,
    /// The verdict.
    pub verdict: Verdict,
}

impl DesignRecord {
    /// The record of `outcome` for `objective`, with each component's result.
    pub fn new(objective: &Objective, outcome: &Found<Evaluation>, results: &[ComponentOutcome]) -> Self {
        let e = &outcome.solution;
        let key_values = |f: &dyn Fn(&ComponentOutcome) -> f64| results.iter().map(|r| (target_key(r.quantity), f(r))).collect();
        DesignRecord {
            a: e.a.clone(),
            achieved: key_values(&|r| r.achieved),
            actuator: objective.rod.clone(),
            base_angle_rad: e.pose.base_angle_rad,
            bounds: objective.bounds.clone(),
            cost: outcome.cost,
            error_pct: results.iter().map(|r| (target_key(r.quantity), r.error_pct)).collect(),
            feasibility: None,
            length_basis: objective.length_basis,
            length_mm: e.pose.length_mm,
            met: results.iter().all(|r| r.met),
            routing_mm: e.routing_mm,
            seconds: outcome.seconds,
            seeds_simulated: outcome.seeds_simulated,
            starts: outcome
                .starts
                .iter()
                .map(|s| {
                    let (routing_mm, tension_n) = routing::design_at(&objective.bounds, &s.seed);
                    serde_json::json!({
                        "cost": s.cost,
                        "evaluations": s.evaluations,
                        "seed": { "routing_mm": routing_mm, "source": s.source, "tension_n": tension_n },
                        "seed_cost": s.seed_cost,
                        "termination": s.termination,
                    })
                })
                .collect(),
            target: objective.target.to_json(),
            tension_n: e.tension_n,
            tip_angle_rad: e.pose.tip_angle_rad,
            tip_x_mm: e.pose.tip_x_mm,
            tip_y_mm: e.pose.tip_y_mm,
            unmet: results.iter().filter(|r| !r.met).map(|r| target_key(r.quantity)).collect(),
            weights: objective.target.components.iter().map(|(c, _)| (target_key(*c), objective.weights.get(*c))).collect(),
        }
    }

    /// Adds a map's verdict.
    pub fn with_feasibility(mut self, report: &FeasibilityReport, map: Option<&Path>) -> Self {
        self.feasibility =
            Some(FeasibilityRecord { map: map.map(Path::to_path_buf), reasons: report.reasons.clone(), verdict: report.verdict });
        self
    }

    /// The record as a JSON value; every object's keys sorted (nested
    /// records included), the order design.json has always had.
    pub fn to_json_value(&self) -> serde_json::Value {
        serde_json::to_value(self).expect("design records serialise")
    }

    /// The record as one line of JSON.
    pub fn to_json_line(&self) -> String {
        self.to_json_value().to_string()
    }

    /// The record as design.json's text: indented, ending in a newline.
    pub fn to_file_text(&self) -> String {
        serde_json::to_string_pretty(&self.to_json_value()).expect("JSON values serialise") + "\n"
    }
}

/// What a reader of design.json needs to rebuild the actuator: the routing
/// and the actuator it was designed for.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct DesignFile {
    /// Routing control points y_0..y_4, mm.
    pub routing_mm: Vec<f64>,
    /// The actuator (the thesis's when the file has none).
    #[serde(default)]
    pub actuator: Rod,
}

/// What is wrong with a design.json read back ([`read_design_file`]).
#[derive(Debug, thiserror::Error)]
pub enum DesignFileProblem {
    /// Not JSON.
    #[error("is not JSON ({0})")]
    NotJson(#[source] serde_json::Error),
    /// No routing.
    #[error("has no numeric routing_mm list")]
    NoRouting,
    /// An actuator that is no rod.
    #[error("bad actuator object: {0}")]
    Actuator(#[source] serde_json::Error),
}

/// Reads the routing and actuator of a design.json written by `design --out`.
pub fn read_design_file(path: &Path) -> Result<DesignFile, DesignError> {
    let bad = |problem| DesignError::DesignFile { path: path.to_path_buf(), problem };
    let text = std::fs::read_to_string(path)
        .map_err(crate::io::FileError::on("reading", path))?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| bad(DesignFileProblem::NotJson(e)))?;
    let routing_mm: Vec<f64> = v
        .get("routing_mm")
        .and_then(|r| serde_json::from_value(r.clone()).ok())
        .ok_or_else(|| bad(DesignFileProblem::NoRouting))?;
    let actuator = match v.get("actuator") {
        Some(a) => serde_json::from_value(a.clone()).map_err(|e| bad(DesignFileProblem::Actuator(e)))?,
        None => Rod::default(),
    };
    Ok(DesignFile { routing_mm, actuator })
}
