//! The design workflow behind `cablemap design`: the request's check, then
//! the thesis's one-target design (the objective with a feasibility map's
//! tension range and verdict when one is given, the search, the comparison
//! with the target, the design's files and moulds) or a sequence's
//! ([`sequence_run`]).

use super::feasible;
use super::map::MapDir;
use super::objective::compare;
use super::record::DesignRecord;
use super::report::DesignRun;
use super::request::DesignRequest;
use super::search::routing::{Design, RoutingProblem};
use super::search::{self, ROUTING_STARTS};
use super::sequence_report::SequenceRun;
use super::sequence_run::{self, Sequence};
use super::target::Target;
use super::targets::DEFAULT_TOLERANCE_PCT;
use super::DesignError;
use crate::model::Routing;
use crate::mould::{MouldParams, MouldSet};
use std::path::Path;

/// What a design returns: the thesis's one-target design, or a sequence's.
#[derive(Debug, Clone)]
pub enum DesignReport {
    /// `target`: design.json's record of one planar cable.
    Target(Box<DesignRun>),
    /// `targets`: every cable's channel and each target's actuation.
    Sequence(Box<SequenceRun>),
}

impl DesignReport {
    /// The JSON `--json` prints (design.json's object).
    pub fn to_json(&self) -> serde_json::Value {
        match self {
            DesignReport::Target(run) => run.record.to_json_value(),
            DesignReport::Sequence(run) => run.to_json(),
        }
    }

    /// The export directory and the files written into it.
    pub fn exported(&self) -> (Option<&std::path::Path>, &[String]) {
        match self {
            DesignReport::Target(run) => (run.out.as_deref(), &run.exported),
            DesignReport::Sequence(run) => (run.out.as_deref(), &run.exported),
        }
    }
}

impl std::fmt::Display for DesignReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DesignReport::Target(run) => run.fmt(f),
            DesignReport::Sequence(run) => run.fmt(f),
        }
    }
}

/// Runs a design: the request's check, then the thesis's one-target design
/// or a sequence's ([`sequence_run::run`]).
pub fn run(request: &DesignRequest) -> Result<DesignReport, DesignError> {
    request.check()?;
    match (&request.target, &request.targets) {
        (Some(target), _) => design_target(request, target).map(|r| DesignReport::Target(Box::new(r))),
        (None, Some(targets)) => sequence_run::run(request, &sequence(request, targets)?).map(|r| DesignReport::Sequence(Box::new(r))),
        (None, None) => Err(DesignError::TargetOrTargets),
    }
}

/// The one-target design: with a map, its verdict first (reported, not
/// enforced: the optimiser still returns the closest design) and its
/// nearest designs as seeds; then the search, the comparison and the exports.
fn design_target(request: &DesignRequest, target: &Target) -> Result<DesignRun, DesignError> {
    if let Some(dir) = &request.out {
        // Before the search, not after it.
        super::export::check_export_dir(dir)?;
    }
    request.check_moulds()?;
    let map = request.map.as_deref().map(MapDir::open).transpose()?;
    let objective = request.objective(target, map.as_ref())?;
    let search = request.search_options(ROUTING_STARTS);
    let tolerance_pct = request.tolerance_pct.unwrap_or(DEFAULT_TOLERANCE_PCT);
    let feasibility = match &map {
        Some(m) => Some(feasible::check(m, &objective.target, objective.length_basis, &objective.weights, 2 * search.starts)?),
        None => None,
    };
    let map_designs: Vec<Design> = feasibility.iter().flat_map(|f| f.nearest.iter().map(|d| d.seed())).collect();
    let outcome = search::search(&RoutingProblem { objective: &objective, grid: &search, map_designs }, &search)?;
    let results = compare(&objective, &outcome.solution, tolerance_pct);
    let mut record = DesignRecord::new(&objective, &outcome, &results);
    if let Some(f) = &feasibility {
        record = record.with_feasibility(f, request.map.as_deref());
    }
    let (mut exported, mut moulds) = (Vec::new(), None);
    if let Some(dir) = &request.out {
        let tube_mm = request.moulds().map_or(MouldParams::default().tube_diameter_mm, |p| p.tube_diameter_mm);
        exported = super::export::write_all(dir, &objective, &outcome.solution, &record, tube_mm)?;
        if let Some(params) = request.moulds() {
            let act = &objective.rod;
            let routing = Routing::for_actuator(&outcome.solution.routing_mm, act)?;
            moulds = Some(MouldSet::new(&routing, act.radius_mm, params)?.write_all(dir)?);
        }
    }
    Ok(DesignRun { objective, outcome, results, tolerance_pct, feasibility, record, out: request.out.clone(), exported, moulds })
}

/// A targets request's actuator ([`DesignRequest::design_actuator`]) and
/// its targets, each within the request's tolerance when it gives one.
fn sequence(request: &DesignRequest, targets: &Path) -> Result<Sequence, DesignError> {
    let design = request.design_actuator()?;
    let mut targets = request.target_set(targets, &design)?;
    if let Some(tol) = request.tolerance_pct {
        targets.targets.iter_mut().for_each(|t| t.tolerance_pct = tol);
    }
    Ok(Sequence { design, targets })
}
