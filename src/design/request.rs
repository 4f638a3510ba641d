//! The one request of `cablemap design` and its check: the thesis's design
//! of one planar cable for one target, or an actuator of 1–8 cables for a
//! sequence of targets, decided from its input.

use super::actuator::{default_tension_min_n, DesignActuator, DEFAULT_TENSION_MAX_N, DEFAULT_TENSION_RANGE_N};
use super::map::MapDir;
use super::objective::{Bounds, Objective};
use super::search::SearchOptions;
use super::target::{Target, Weights};
use super::targets::TargetSet;
use super::DesignError;
use crate::model::{Actuator, Rod, RodOverrides, Routing};
use crate::mould::{MouldParams, MouldSettings};
use crate::shape::LengthBasis;
use crate::solver::{SolverOptions, SolverSettings};
use serde::{Deserialize, Deserializer};
use std::path::{Path, PathBuf};

/// Everything a design needs, as given: the thesis's design of one planar
/// cable for one target (`target`), or an actuator of 1–8 cables for a
/// sequence of targets or a trajectory (`targets`). The request decides
/// which from its input, refuses in [`DesignRequest::check`] the settings
/// that do not apply to it, and reads its files
/// ([`DesignRequest::design_actuator`], [`DesignRequest::target_set`]).
/// Deserialises from the Python keywords' names.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DesignRequest {
    /// The rod (validated here); with `targets` and no `actuator_file`, the
    /// rod of the one cable free in y that is designed. Given as an
    /// actuator without cables, torsion or gravity direction.
    #[serde(rename = "actuator", deserialize_with = "rod_alone")]
    pub rod: Rod,
    /// With `targets`: the actuator to design and what each cable may
    /// change (`--actuator FILE.toml`, [`DesignActuator`]).
    #[serde(rename = "design_actuator", default)]
    pub actuator_file: Option<PathBuf>,
    /// Values set on `actuator_file`'s rod (the rod flags; a rod file is
    /// refused: the rod is the file's `[rod]`).
    #[serde(rename = "rod_fields", default)]
    pub actuator_rod: RodOverrides,
    /// Solver settings.
    #[serde(rename = "solver", default, deserialize_with = "SolverSettings::deserialize_options")]
    pub options: SolverOptions,
    /// The thesis's target shape (one planar cable; `x=50,y=5,a0=-0.025`).
    #[serde(default, deserialize_with = "target_text")]
    pub target: Option<Target>,
    /// A targets file: a sequence of targets or a trajectory (1–8 cables).
    #[serde(default)]
    pub targets: Option<PathBuf>,
    /// Weights λ of eq. 3.17 for `target` (the thesis's when none).
    #[serde(default, deserialize_with = "weights_text")]
    pub weights: Option<Weights>,
    /// Lower tension bound, N; the map's, else [`DEFAULT_TENSION_RANGE_N`], when none.
    #[serde(default)]
    pub tension_min_n: Option<f64>,
    /// Upper tension bound, N; the map's, else [`DEFAULT_TENSION_RANGE_N`], when none.
    #[serde(default)]
    pub tension_max_n: Option<f64>,
    /// Largest |y_i|, mm; the thesis's 0.999 r when none. With `moulds`, no
    /// more than the moulds can cast ([`MouldParams::max_castable_offset_mm`]).
    #[serde(default)]
    pub max_offset_mm: Option<f64>,
    /// The length the target's coefficients are per unit of.
    #[serde(default)]
    pub length_basis: LengthBasis,
    /// A feasibility map: with `target` its verdict, its nearest designs as
    /// seeds and its tension range; with `targets` (a cable sweep's map) its
    /// nearest designs' channels as seeds.
    #[serde(default)]
    pub map: Option<PathBuf>,
    /// Starts refined to convergence ([`super::search::ROUTING_STARTS`] or [`super::search::SEQUENCE_STARTS`] when none).
    #[serde(default)]
    pub starts: Option<usize>,
    /// Most solves per converging start (per target with `targets`).
    #[serde(default = "default_max_evaluations", deserialize_with = "max_evaluations")]
    pub max_evaluations: usize,
    /// A component counts as met within this many percent (5, or each
    /// target's own `tolerance_pct`, when none).
    #[serde(default)]
    pub tolerance_pct: Option<f64>,
    /// Export directory (design.json, channel files, pictures).
    #[serde(default)]
    pub out: Option<PathBuf>,
    /// The moulds' parameters: with `write_moulds` the moulds written;
    /// without, the bound `cablemap mould` will need is named when this
    /// search allows more ([`DesignRequest::mould_bound_exceeded`]).
    #[serde(default, deserialize_with = "MouldSettings::deserialize_params")]
    pub mould: MouldParams,
    /// With `out`: also write the printable moulds; the search then keeps
    /// the channels where they can cast them.
    #[serde(rename = "moulds", default)]
    pub write_moulds: bool,
}

/// The rod of an actuator given without cables, torsion or gravity
/// direction (a design's `rod`).
fn rod_alone<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Rod, D::Error> {
    let actuator = Actuator::deserialize(deserializer)?;
    if !actuator.cables.is_empty() || actuator.gj_n_mm2.is_some() || actuator.gravity_direction.is_some() {
        return Err(serde::de::Error::custom(DesignError::ActuatorWithTarget));
    }
    Ok(actuator.rod)
}

/// A target from its text (`x=50,y=5,a0=-0.025`), the error named by its field.
pub(crate) fn target_text<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Option<Target>, D::Error> {
    let text = Option::<String>::deserialize(deserializer)?;
    text.as_deref().map(Target::parse).transpose().map_err(|e| serde::de::Error::custom(format!("target: {e}")))
}

/// Weights from their text (`a0=200`), the error named by its field.
pub(crate) fn weights_text<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Option<Weights>, D::Error> {
    let text = Option::<String>::deserialize(deserializer)?;
    text.as_deref().map(Weights::parse).transpose().map_err(|e| serde::de::Error::custom(format!("weights: {e}")))
}

fn default_max_evaluations() -> usize {
    SearchOptions::default().max_evaluations
}

/// The most solves per start, the search's default when none.
fn max_evaluations<'de, D: Deserializer<'de>>(deserializer: D) -> Result<usize, D::Error> {
    Ok(Option::<usize>::deserialize(deserializer)?.unwrap_or_else(default_max_evaluations))
}

/// A setting that applies to the thesis's one-target design only: with
/// `targets` each is said per target or per cable in the files.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TargetOnly {
    /// `--weights`.
    Weights,
    /// `--tension-min-n`.
    TensionMin,
    /// `--tension-max-n`.
    TensionMax,
    /// `--max-offset-mm`.
    MaxOffset,
}

impl TargetOnly {
    /// The request's field (and the Python keyword).
    pub fn key(self) -> &'static str {
        match self {
            TargetOnly::Weights => "weights",
            TargetOnly::TensionMin => "tension_min_n",
            TargetOnly::TensionMax => "tension_max_n",
            TargetOnly::MaxOffset => "max_offset_mm",
        }
    }

    /// The command-line flag.
    pub fn flag(self) -> &'static str {
        match self {
            TargetOnly::Weights => "--weights",
            TargetOnly::TensionMin => "--tension-min-n",
            TargetOnly::TensionMax => "--tension-max-n",
            TargetOnly::MaxOffset => "--max-offset-mm",
        }
    }

    /// Where the files say it instead.
    pub fn instead(self) -> &'static str {
        match self {
            TargetOnly::Weights => "weights = { … } in each [[target]]",
            TargetOnly::TensionMin => "tension_min_n in each [[cable]] of --actuator",
            TargetOnly::TensionMax => "tension_max_n in each [[cable]] of --actuator",
            TargetOnly::MaxOffset => "max_offset_mm in each [[cable]] of --actuator",
        }
    }
}

/// The channel offset `cablemap mould` will need, when a design's search
/// allows more ([`DesignRequest::mould_bound_exceeded`]).
#[derive(Debug, Clone, PartialEq)]
pub struct MouldBound {
    /// The search's largest |y_i|, mm.
    pub search_max_offset_mm: f64,
    /// The largest |y_c| the moulds can cast, mm ([`MouldParams::max_castable_offset_mm`]).
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

/// The largest control-point offset a design for the moulds allows: what
/// they cast ([`MouldParams::max_castable_offset_mm`]), a hair inside it.
pub fn mould_offset_limit_mm(params: &MouldParams, radius_mm: f64) -> f64 {
    params.max_castable_offset_mm(radius_mm) - MOULD_ROUNDING_MM
}

impl DesignRequest {
    /// The objective, with bounds from the request, else the map's tension
    /// range, else the defaults; a map made for another actuator is refused
    /// ([`MapDir::check_actuator`]).
    pub fn objective(&self, target: &Target, map: Option<&MapDir>) -> Result<Objective, DesignError> {
        self.check()?;
        self.rod.validate()?;
        if let Some(m) = map {
            m.check_actuator(&self.rod)?;
        }
        let [lo, hi] = map.map_or(DEFAULT_TENSION_RANGE_N, |m| m.summary.tension_range_n);
        let mut bounds = Bounds::thesis(self.rod.channel_radius_mm(), self.tension_min_n.unwrap_or(lo), self.tension_max_n.unwrap_or(hi));
        bounds.max_offset_mm = self.requested_max_offset_mm();
        if let Some(params) = self.moulds() {
            bounds.max_offset_mm = bounds.max_offset_mm.min(mould_offset_limit_mm(params, self.rod.radius_mm));
        }
        let weights = self.weights.clone().unwrap_or_default();
        Ok(Objective::new(self.rod.clone(), self.options.clone(), target.clone(), weights, bounds)?.with_length_basis(self.length_basis))
    }

    /// Refuses what the request cannot mean, before anything is read or
    /// solved: both or neither of `target` and `targets`, an actuator file
    /// with `target`, a one-target setting with `targets`, no starts, a
    /// tolerance that is no percentage.
    pub fn check(&self) -> Result<(), DesignError> {
        match (&self.target, &self.targets) {
            (Some(_), Some(_)) | (None, None) => return Err(DesignError::TargetOrTargets),
            (Some(_), None) if self.actuator_file.is_some() => return Err(DesignError::ActuatorWithTarget),
            (None, Some(_)) => {
                for (given, setting) in [
                    (self.weights.is_some(), TargetOnly::Weights),
                    (self.tension_min_n.is_some(), TargetOnly::TensionMin),
                    (self.tension_max_n.is_some(), TargetOnly::TensionMax),
                    (self.max_offset_mm.is_some(), TargetOnly::MaxOffset),
                ] {
                    if given {
                        return Err(DesignError::TargetOnly { setting });
                    }
                }
            }
            _ => {}
        }
        if self.actuator_file.is_some() && self.actuator_rod.file.is_some() {
            return Err(DesignError::RodTwice);
        }
        if self.starts == Some(0) {
            return Err(DesignError::NoStarts);
        }
        if let Some(t) = self.tolerance_pct.filter(|t| !(t.is_finite() && *t >= 0.0)) {
            return Err(DesignError::Tolerance { tolerance_pct: t });
        }
        Ok(())
    }

    /// A targets request's actuator: the file's (its rod with
    /// `actuator_rod` set), else the rod with one cable free in y (1 … 2 N,
    /// the bounds of `target`).
    pub fn design_actuator(&self) -> Result<DesignActuator, DesignError> {
        match &self.actuator_file {
            Some(path) => DesignActuator::read(path, |rod| self.actuator_rod.apply(rod)),
            None => Ok(DesignActuator::planar(self.rod.clone(), default_tension_min_n(1), DEFAULT_TENSION_MAX_N, None)),
        }
    }

    /// The targets file's targets, their default weights set by the rod of `design`.
    pub fn target_set(&self, path: &Path, design: &DesignActuator) -> Result<TargetSet, DesignError> {
        TargetSet::read(path, design.actuator.rod.length_mm)
    }

    /// The search settings, with `default_starts` when the request gives none.
    pub fn search_options(&self, default_starts: usize) -> SearchOptions {
        SearchOptions { starts: self.starts.unwrap_or(default_starts), max_evaluations: self.max_evaluations, ..SearchOptions::default() }
    }

    /// The largest |y_i| asked for, mm: the request's, else the thesis's.
    fn requested_max_offset_mm(&self) -> f64 {
        self.max_offset_mm.unwrap_or_else(|| Bounds::thesis_max_offset_mm(self.rod.channel_radius_mm()))
    }

    /// The moulds' parameters when the moulds are to be written.
    pub fn moulds(&self) -> Option<&MouldParams> {
        self.write_moulds.then_some(&self.mould)
    }

    /// Without moulds asked for: the bound `cablemap mould` (with `mould`)
    /// will need, when this search's is wider and the body is one mould
    /// makes (uniform); `None` otherwise.
    pub fn mould_bound_exceeded(&self) -> Option<MouldBound> {
        if self.target.is_none() || self.write_moulds || crate::mould::check_uniform_body(&self.rod).is_err() {
            return None;
        }
        let bound = MouldBound {
            search_max_offset_mm: self.requested_max_offset_mm(),
            mould_max_offset_mm: self.mould.max_castable_offset_mm(self.rod.radius_mm),
            mould: self.mould.clone(),
        };
        (bound.search_max_offset_mm > bound.mould_max_offset_mm).then_some(bound)
    }

    /// With moulds asked for: refuses, before any search, a body the moulds
    /// cannot cast and mould parameters they refuse (checked on a straight
    /// channel, which every usable parameter set casts).
    pub fn check_moulds(&self) -> Result<(), DesignError> {
        let Some(params) = self.moulds() else { return Ok(()) };
        let act = &self.rod;
        crate::mould::check_uniform_body(act)?;
        act.validate()?;
        let straight = Routing::for_actuator([0.0; 5], act)?;
        crate::mould::Moulds::new(&straight, act.radius_mm, params)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(moulds: Option<MouldParams>, max_offset_mm: Option<f64>) -> DesignRequest {
        DesignRequest {
            write_moulds: moulds.is_some(),
            mould: moulds.unwrap_or_default(),
            rod: Rod::default(),
            actuator_file: None,
            actuator_rod: RodOverrides::default(),
            options: SolverOptions::default(),
            target: Some(Target::parse("x=50,y=5").unwrap()),
            targets: None,
            weights: None,
            tension_min_n: None,
            tension_max_n: None,
            max_offset_mm,
            length_basis: LengthBasis::Rest,
            map: None,
            starts: None,
            max_evaluations: SearchOptions::default().max_evaluations,
            tolerance_pct: None,
            out: None,
        }
    }

    /// With moulds, the search keeps the control points (so, by the spline's
    /// convex hull, the channel) within what `mould` casts: its own rule.
    #[test]
    fn moulds_bound_the_search_by_the_moulds_own_rule() {
        let params = MouldParams::default();
        let limit_mm = params.max_castable_offset_mm(5.0);
        assert!(limit_mm < Bounds::thesis_max_offset_mm(5.0), "the thesis's bound exceeds the moulds': the case this guards");
        let bound = |r: &DesignRequest| r.objective(r.target.as_ref().unwrap(), None).unwrap().bounds.max_offset_mm;
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
        tapered.rod.radius_profile_mm = vec![(0.0, 5.0), (65.0, 4.0)];
        assert_eq!(tapered.mould_bound_exceeded(), None, "mould makes no tapered body: nothing to say");
    }
}
