//! The design workflow behind `cablemap design`: build the objective (with a
//! feasibility map's tension range and verdict when one is given), search,
//! compare with the target, and export the design (and its moulds).

use super::feasible::{self, FeasibilityReport};
use super::map::MapDir;
use super::objective::{Bounds, Objective};
use super::optimise::{self, compare, ComponentResult, DesignOutcome, SearchOptions, Seed};
use super::record::DesignRecord;
use super::target::{Target, Weights};
use super::DesignError;
use crate::model::{Actuator, Routing, SolverOptions};
use crate::mould::{MouldParams, MouldSet, MouldSummary};
use crate::shape::LengthBasis;
use std::path::{Path, PathBuf};

/// Tension bounds without a map, N (the thesis's design range, §5).
pub const DEFAULT_TENSION_RANGE_N: [f64; 2] = [1.0, 2.0];

/// Everything a design needs.
#[derive(Debug, Clone)]
pub struct DesignRequest {
    /// The actuator to design for (validated here).
    pub actuator: Actuator,
    /// Solver settings.
    pub options: SolverOptions,
    /// The target shape.
    pub target: Target,
    /// Weights λ of eq. 3.17.
    pub weights: Weights,
    /// Lower tension bound, N; the map's, else [`DEFAULT_TENSION_RANGE_N`], when none.
    pub tension_min_n: Option<f64>,
    /// Upper tension bound, N; the map's, else [`DEFAULT_TENSION_RANGE_N`], when none.
    pub tension_max_n: Option<f64>,
    /// Largest |y_i|, mm; the thesis's 0.999 r when none.
    pub max_offset_mm: Option<f64>,
    /// The length the target's coefficients are per unit of.
    pub length_basis: LengthBasis,
    /// A feasibility map: its verdict, its nearest designs as seeds and its tension range.
    pub map: Option<PathBuf>,
    /// Search settings.
    pub search: SearchOptions,
    /// A component counts as met within this many percent.
    pub tolerance_pct: f64,
    /// Export directory (design.json, channel.csv, mould.svg, shape.png).
    pub out: Option<PathBuf>,
    /// With `out`: also the printable moulds, with these parameters.
    pub moulds: Option<MouldParams>,
}

/// A finished design.
#[derive(Debug, Clone)]
pub struct DesignRun {
    /// The objective searched.
    pub objective: Objective,
    /// The search's result.
    pub outcome: DesignOutcome,
    /// Each target component, achieved vs asked.
    pub results: Vec<ComponentResult>,
    /// The map's verdict, when a map was given.
    pub feasibility: Option<FeasibilityReport>,
    /// design.json's content.
    pub record: DesignRecord,
    /// The moulds written, when asked for.
    pub moulds: Option<MouldSummary>,
}

impl DesignRequest {
    /// The objective, with bounds from the request, else the map's tension
    /// range, else the defaults.
    pub fn objective(&self, map: Option<&MapDir>) -> Result<Objective, DesignError> {
        self.actuator.validate()?;
        if !(self.tolerance_pct.is_finite() && self.tolerance_pct >= 0.0) {
            return Err(DesignError::BadSearch(format!("the tolerance must be a finite number ≥ 0 %, got {}", self.tolerance_pct)));
        }
        if self.search.starts == 0 {
            return Err(DesignError::BadSearch("the number of starts must be at least 1".into()));
        }
        let [lo, hi] = map.map_or(DEFAULT_TENSION_RANGE_N, |m| m.summary.tension_range_n);
        let mut bounds = Bounds::thesis(self.actuator.channel_radius_mm(), self.tension_min_n.unwrap_or(lo), self.tension_max_n.unwrap_or(hi));
        if let Some(y) = self.max_offset_mm {
            bounds.max_offset_mm = y;
        }
        Ok(Objective::new(self.actuator.clone(), self.options.clone(), self.target.clone(), self.weights.clone(), bounds)?
            .with_length_basis(self.length_basis))
    }
}

/// Runs a design: with a map, its verdict first (reported, not enforced: the
/// optimiser still returns the closest design) and its nearest designs as
/// seeds; then the search, the comparison and the exports.
pub fn run(request: &DesignRequest) -> Result<DesignRun, DesignError> {
    if let Some(dir) = &request.out {
        // Before the search, not after it.
        check_export_dir(dir)?;
    }
    let map = request.map.as_deref().map(MapDir::open).transpose()?;
    let objective = request.objective(map.as_ref())?;
    if let Some(m) = &map {
        m.check_actuator(&objective.actuator)?;
    }
    let feasibility = match &map {
        Some(m) => Some(feasible::check(m, &objective.target, objective.length_basis, &objective.weights, 2 * request.search.starts)?),
        None => None,
    };
    let seeds: Vec<Seed> = feasibility.iter().flat_map(|f| f.nearest.iter().map(|d| d.seed())).collect();
    let outcome = optimise::design(&objective, &request.search, &seeds)?;
    let results = compare(&objective, &outcome.best, request.tolerance_pct);
    let mut record = DesignRecord::new(&objective, &outcome, &results);
    if let Some(f) = &feasibility {
        record = record.with_feasibility(f, request.map.as_deref());
    }
    let mut moulds = None;
    if let Some(dir) = &request.out {
        super::export::write_all(dir, &objective, &outcome.best, &record)?;
        if let Some(params) = &request.moulds {
            let act = &objective.actuator;
            crate::mould::check_uniform_body(act)?;
            let routing = Routing::for_actuator(&outcome.best.routing_mm, act)?;
            moulds = Some(MouldSet::new(&routing, act.radius_mm, params)?.write_all(dir)?);
        }
    }
    Ok(DesignRun { objective, outcome, results, feasibility, record, moulds })
}

/// Refuses an export directory inside a sweep's run directory.
pub fn check_export_dir(dir: &Path) -> Result<(), DesignError> {
    crate::io::check_not_in_run_dir(dir, "the export directory").map_err(|message| DesignError::ExportDir { message })
}
