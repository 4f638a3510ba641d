//! The design workflow behind `cablemap design`: build the objective (with a
//! feasibility map's tension range and verdict when one is given), search,
//! compare with the target, and export the design (and its moulds).

use super::feasible;
use super::map::MapDir;
use super::objective::{Bounds, Objective};
use super::optimise::{self, compare, SearchOptions, Seed};
use super::record::DesignRecord;
use super::report::DesignRun;
use super::target::{Target, Weights};
use super::DesignError;
use crate::model::{Rod, Routing};
use crate::solver::SolverOptions;
use crate::mould::{MouldParams, MouldSet};
use crate::shape::LengthBasis;
use std::path::PathBuf;

/// Tension bounds without a map, N (the thesis's design range, §5).
pub const DEFAULT_TENSION_RANGE_N: [f64; 2] = [1.0, 2.0];

/// Everything a design needs.
#[derive(Debug, Clone)]
pub struct DesignRequest {
    /// The actuator to design for (validated here).
    pub actuator: Rod,
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
    /// Largest |y_i|, mm; the thesis's 0.999 r when none. With `moulds`, no
    /// more than the moulds can cast ([`MouldParams::max_channel_offset_mm`]).
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
    /// The moulds' parameters: with `write_moulds` the moulds written;
    /// without, the bound `cablemap mould` will need is named when this
    /// search allows more ([`DesignRequest::mould_bound_exceeded`]).
    pub mould: MouldParams,
    /// With `out`: also write the printable moulds; the search then keeps
    /// the channel where they can cast it.
    pub write_moulds: bool,
}

/// The channel offset `cablemap mould` will need, when a design's search
/// allows more ([`DesignRequest::mould_bound_exceeded`]).
#[derive(Debug, Clone, PartialEq)]
pub struct MouldBound {
    /// The search's largest |y_i|, mm.
    pub search_max_offset_mm: f64,
    /// The largest |y_c| the moulds can cast, mm ([`MouldParams::max_channel_offset_mm`]).
    pub mould_max_offset_mm: f64,
    /// The moulds' parameters that bound it.
    pub mould: MouldParams,
}

impl std::fmt::Display for MouldBound {
    /// The note `design` prints before its search.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "`cablemap mould` (tube Ø {} mm, skin {} mm) needs |y_i| ≤ {:.3} mm, this search allows {:.3} mm: add --moulds to design within it",
            self.mould.tube_diameter_mm, self.mould.min_skin_mm, self.mould_max_offset_mm, self.search_max_offset_mm
        )
    }
}

/// How far inside the moulds' limit `design --moulds` keeps the control
/// points, mm: the spline's sum of control points may round a hair past
/// them, and a channel exactly at the limit must still be accepted.
const MOULD_ROUNDING_MM: f64 = 1e-9;

impl DesignRequest {
    /// The objective, with bounds from the request, else the map's tension
    /// range, else the defaults; a map made for another actuator is refused
    /// ([`MapDir::check_actuator`]).
    pub fn objective(&self, map: Option<&MapDir>) -> Result<Objective, DesignError> {
        self.actuator.validate()?;
        if let Some(m) = map {
            m.check_actuator(&self.actuator)?;
        }
        if !(self.tolerance_pct.is_finite() && self.tolerance_pct >= 0.0) {
            return Err(DesignError::BadSearch(format!("the tolerance must be a finite number ≥ 0 %, got {}", self.tolerance_pct)));
        }
        if self.search.starts == 0 {
            return Err(DesignError::BadSearch("the number of starts must be at least 1".into()));
        }
        let [lo, hi] = map.map_or(DEFAULT_TENSION_RANGE_N, |m| m.summary.tension_range_n);
        let mut bounds = Bounds::thesis(self.actuator.channel_radius_mm(), self.tension_min_n.unwrap_or(lo), self.tension_max_n.unwrap_or(hi));
        bounds.max_offset_mm = self.requested_max_offset_mm();
        if let Some(params) = self.moulds() {
            bounds.max_offset_mm = bounds.max_offset_mm.min(params.max_channel_offset_mm(self.actuator.radius_mm) - MOULD_ROUNDING_MM);
        }
        Ok(Objective::new(self.actuator.clone(), self.options.clone(), self.target.clone(), self.weights.clone(), bounds)?
            .with_length_basis(self.length_basis))
    }

    /// The largest |y_i| asked for, mm: the request's, else the thesis's.
    fn requested_max_offset_mm(&self) -> f64 {
        self.max_offset_mm.unwrap_or_else(|| Bounds::thesis_max_offset_mm(self.actuator.channel_radius_mm()))
    }

    /// The moulds' parameters when the moulds are to be written.
    fn moulds(&self) -> Option<&MouldParams> {
        self.write_moulds.then_some(&self.mould)
    }

    /// Without moulds asked for: the bound `cablemap mould` (with `mould`)
    /// will need, when this search's is wider and the body is one mould
    /// makes (uniform); `None` otherwise.
    pub fn mould_bound_exceeded(&self) -> Option<MouldBound> {
        if self.write_moulds || crate::mould::check_uniform_body(&self.actuator).is_err() {
            return None;
        }
        let bound = MouldBound {
            search_max_offset_mm: self.requested_max_offset_mm(),
            mould_max_offset_mm: self.mould.max_channel_offset_mm(self.actuator.radius_mm),
            mould: self.mould.clone(),
        };
        (bound.search_max_offset_mm > bound.mould_max_offset_mm).then_some(bound)
    }

    /// With moulds asked for: refuses, before any search, a body the moulds
    /// cannot cast and mould parameters they refuse (checked on a straight
    /// channel, which every usable parameter set casts).
    fn check_moulds(&self) -> Result<(), DesignError> {
        let Some(params) = self.moulds() else { return Ok(()) };
        let act = &self.actuator;
        crate::mould::check_uniform_body(act)?;
        act.validate()?;
        let straight = Routing::for_actuator([0.0; 5], act)?;
        crate::mould::Moulds::new(&straight, act.radius_mm, params)?;
        Ok(())
    }
}

/// Runs a design: with a map, its verdict first (reported, not enforced: the
/// optimiser still returns the closest design) and its nearest designs as
/// seeds; then the search, the comparison and the exports.
pub fn run(request: &DesignRequest) -> Result<DesignRun, DesignError> {
    if let Some(dir) = &request.out {
        // Before the search, not after it.
        super::export::check_export_dir(dir)?;
    }
    request.check_moulds()?;
    let map = request.map.as_deref().map(MapDir::open).transpose()?;
    let objective = request.objective(map.as_ref())?;
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
    let (mut exported, mut moulds) = (Vec::new(), None);
    if let Some(dir) = &request.out {
        let tube_mm = request.moulds().map_or(MouldParams::default().tube_diameter_mm, |p| p.tube_diameter_mm);
        exported = super::export::write_all(dir, &objective, &outcome.best, &record, tube_mm)?;
        if let Some(params) = request.moulds() {
            let act = &objective.actuator;
            let routing = Routing::for_actuator(&outcome.best.routing_mm, act)?;
            moulds = Some(MouldSet::new(&routing, act.radius_mm, params)?.write_all(dir)?);
        }
    }
    Ok(DesignRun { objective, outcome, results, tolerance_pct: request.tolerance_pct, feasibility, record, out: request.out.clone(), exported, moulds })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(moulds: Option<MouldParams>, max_offset_mm: Option<f64>) -> DesignRequest {
        DesignRequest {
            write_moulds: moulds.is_some(),
            mould: moulds.unwrap_or_default(),
            actuator: Rod::default(),
            options: SolverOptions::default(),
            target: Target::parse("x=50,y=5").unwrap(),
            weights: Weights::default(),
            tension_min_n: None,
            tension_max_n: None,
            max_offset_mm,
            length_basis: LengthBasis::Rest,
            map: None,
            search: SearchOptions::default(),
            tolerance_pct: 5.0,
            out: None,
        }
    }

    /// With moulds, the search keeps the control points (so, by the spline's
    /// convex hull, the channel) within what `mould` casts: its own rule.
    #[test]
    fn moulds_bound_the_search_by_the_moulds_own_rule() {
        let params = MouldParams::default();
        let limit_mm = params.max_channel_offset_mm(5.0);
        assert!(limit_mm < Bounds::thesis_max_offset_mm(5.0), "the thesis's bound exceeds the moulds': the case this guards");
        let bound = |r: &DesignRequest| r.objective(None).unwrap().bounds.max_offset_mm;
        let with = request(Some(params.clone()), None);
        assert!(bound(&with) <= limit_mm && bound(&with) > limit_mm - 1e-6, "{}", bound(&with));
        // A tighter bound of the user's stays; a wider one gives way to the moulds'.
        assert_eq!(bound(&request(Some(params.clone()), Some(3.0))), 3.0);
        assert!(bound(&request(Some(params.clone()), Some(4.9))) <= limit_mm);
        // Another tube moves the bound with it.
        let thin = MouldParams { tube_diameter_mm: 0.6, ..params.clone() };
        assert!(bound(&request(Some(thin.clone()), None)) > limit_mm + 0.19);
        // The design the search may return is one the moulds accept.
        let act = Rod::default();
        let y = bound(&with);
        let edge = Routing::for_actuator([y, y, -y, y, y], &act).unwrap();
        assert!(crate::mould::Moulds::new(&edge, act.radius_mm, &params).is_ok());
        // Without moulds: the thesis's bound, and the moulds' named.
        assert_eq!(bound(&request(None, None)), Bounds::thesis_max_offset_mm(5.0));
        let note = request(None, None).mould_bound_exceeded().expect("the default bound exceeds the moulds'");
        assert_eq!(
            note,
            MouldBound { search_max_offset_mm: Bounds::thesis_max_offset_mm(5.0), mould_max_offset_mm: limit_mm, mould: params.clone() }
        );
        assert_eq!(request(None, Some(4.0)).mould_bound_exceeded(), None);
        assert_eq!(request(Some(params.clone()), None).mould_bound_exceeded(), None);
        let mut tapered = request(None, None);
        tapered.actuator.radius_profile_mm = vec![(0.0, 5.0), (65.0, 4.0)];
        assert_eq!(tapered.mould_bound_exceeded(), None, "mould makes no tapered body: nothing to say");
    }
}
