//! Simulating measurement rows: each routing's rows are solved in protocol
//! order with one [`Simulator`], so tensions reuse warm starts and the load
//! history (friction direction, creep) follows the experiment. And the
//! `predict` workflow: captures simulated with a given actuator, no fitting
//! ([`run`]).

use super::data::{Dataset, Direction, RoutingGroup};
use super::observations::captures::errors::ErrorReport;
use super::observations::captures::files::{read_actuator, read_actuator_set};
use super::observations::captures::simulate::solve_captures;
use super::{CalibrateError, Refused};
use crate::model::RodOverrides;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::PathBuf;
use crate::model::{Rod, LoadDirection, Routing};
use crate::solver::{CentrelinePoint, Hold, Simulator, SolverOptions, SolverSettings, TipPose};
use rayon::prelude::*;

/// The model's answer for one row.
#[derive(Debug, Clone)]
pub struct Prediction {
    /// Tip pose.
    pub pose: TipPose,
    /// Centreline, if asked for.
    pub centreline: Option<Vec<CentrelinePoint>>,
}

/// The actuator of one routing group: the clamp tilt turns gravity the
/// other way in the clamp's frame (gravity direction −tilt from the axis).
pub fn group_actuator(rod: &Rod, group: &RoutingGroup) -> Rod {
    let mut a = rod.clone();
    a.gravity.direction_rad -= group.clamp_tilt_rad;
    a
}

/// Solves the rows of one routing in protocol order, from an unloaded,
/// virgin rod (no creep history) at the first row.
pub fn predict_group(
    rod: &Rod,
    options: &SolverOptions,
    data: &Dataset,
    group: &RoutingGroup,
    keep_centrelines: bool,
) -> Result<Vec<Prediction>, CalibrateError> {
    let a = group_actuator(rod, group);
    let first_row = data.rows[group.rows[0]].row;
    let routing = Routing::for_actuator(group.routing_mm, &a)
        .map_err(|source| CalibrateError::Routing { routing: group.routing.clone(), row: first_row, source })?;
    let mut sim = Simulator::for_rod(&a, options)?;
    sim.set_routing(&routing);
    let mut out = Vec::with_capacity(group.rows.len());
    for &i in &group.rows {
        let m = &data.rows[i];
        if m.direction == Direction::Static {
            // An independent capture: a virgin rod, no history, no warm start.
            sim.reset_history();
            sim.reset_warm_start();
        }
        // At rest the tension is 0 and the friction sign does not matter; a
        // static capture is taken as reached by loading.
        let direction = if matches!(m.direction, Direction::Load | Direction::Static) { LoadDirection::Load } else { LoadDirection::Unload };
        let hold = Hold { direction, dwell_s: m.dwell_s };
        let fail = |failure| CalibrateError::Solve { routing: group.routing.clone(), row: m.row, tension_n: m.tension_n, failure };
        sim.set_hold(hold)?;
        let pose = match sim.solve(m.tension_n) {
            Ok(p) => p,
            Err(_) => {
                // A large jump left Newton's basin: climb from zero in small
                // steps without dwell (which leaves the creep history alone).
                sim.set_hold(Hold { direction: LoadDirection::Load, dwell_s: 0.0 })?;
                let rungs = (m.tension_n / 0.05).ceil().max(1.0) as usize;
                for k in 1..rungs {
                    sim.solve(m.tension_n * k as f64 / rungs as f64).map_err(fail)?;
                }
                sim.set_hold(hold)?;
                sim.solve(m.tension_n).map_err(fail)?
            }
        };
        out.push(Prediction { pose, centreline: keep_centrelines.then(|| sim.centreline()) });
    }
    Ok(out)
}

/// Solves every row of `groups` (in parallel over routings); the result is
/// indexed like `data.rows`, `None` for rows of routings not in `groups`.
pub fn predict(
    rod: &Rod,
    options: &SolverOptions,
    data: &Dataset,
    groups: &[RoutingGroup],
    keep_centrelines: bool,
) -> Result<Vec<Option<Prediction>>, CalibrateError> {
    let per_group: Vec<Vec<Prediction>> = groups
        .par_iter()
        .map(|g| predict_group(rod, options, data, g, keep_centrelines))
        .collect::<Result<_, _>>()?;
    let mut out = vec![None; data.rows.len()];
    for (g, preds) in groups.iter().zip(per_group) {
        for (&i, p) in g.rows.iter().zip(preds) {
            out[i] = Some(p);
        }
    }
    Ok(out)
}

/// What `predict` needs; deserialises from the Python keywords' names.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PredictRequest {
    /// The captures file.
    pub captures: PathBuf,
    /// The markers file (optional when the captures file has tip columns).
    #[serde(default)]
    pub markers: Option<PathBuf>,
    /// The actuator file.
    pub actuator: PathBuf,
    /// Rod settings: refused, the rod is the actuator file's.
    #[serde(rename = "rod_fields", default)]
    pub rod: RodOverrides,
    /// The 3-D solver's settings.
    #[serde(rename = "solver", default, deserialize_with = "SolverSettings::deserialize_options")]
    pub options: SolverOptions,
}

/// The markers' errors of a prediction; serialises to `predict --json`.
#[derive(Debug, Clone, Serialize)]
pub struct PredictReport {
    /// The actuator file used.
    pub actuator: String,
    /// The errors.
    #[serde(flatten)]
    pub errors: ErrorReport,
}

/// Simulates every capture with the request's actuator and reports the errors.
pub fn run(request: &PredictRequest) -> Result<PredictReport, CalibrateError> {
    if !request.rod.is_empty() {
        return Err(Refused::RodOnPredict.into());
    }
    let actuator = read_actuator(&request.actuator)?;
    let set = read_actuator_set(&request.captures, request.markers.as_deref(), &actuator)?;
    let solutions = solve_captures(&actuator, &request.options, &set)?;
    Ok(PredictReport { actuator: request.actuator.display().to_string(), errors: ErrorReport::of(&set, &solutions) })
}

impl PredictReport {
    /// The `--json` object on one line.
    pub fn to_json_line(&self) -> String {
        serde_json::to_value(self).expect("a report serialises").to_string()
    }
}

impl fmt::Display for PredictReport {
    fn fmt(&self, out: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(out, "prediction with {} (no fitting)", self.actuator)?;
        write!(out, "{}", self.errors)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::data::Measurement;

    fn rest_row(routing: &str, tilt: f64) -> Measurement {
        Measurement {
            measurement: 1,
            routing: routing.into(),
            routing_mm: Default::default(),
            tension_n: 0.0,
            direction: Direction::Rest,
            step: 0,
            dwell_s: 0.0,
            tip_x_mm: 0.0,
            tip_y_mm: 0.0,
            tip_angle_rad: 0.0,
            clamp_tilt_rad: tilt,
            noise_mm: None,
            noise_deg: None,
            row: 1,
        }
    }

    #[test]
    fn a_tilted_clamp_lets_the_rod_sag_against_the_tilt() {
        // Clamp axis turned toward +y from the vertical: in the clamp's frame
        // gravity points toward −y, so the unloaded rod sags toward −y.
        let data = Dataset { rows: vec![rest_row("t", 0.3)], actuator: None };
        let groups = data.groups();
        let p = predict(&Rod::default(), &SolverOptions::default(), &data, &groups, false).unwrap();
        let pose = p[0].as_ref().unwrap().pose;
        assert!(pose.tip_y_mm < -0.1 && pose.tip_angle_rad < 0.0, "{pose:?}");
        let level = Dataset { rows: vec![rest_row("t", 0.0)], actuator: None };
        let p0 = predict(&Rod::default(), &SolverOptions::default(), &level, &level.groups(), false).unwrap();
        assert!(p0[0].as_ref().unwrap().pose.tip_y_mm.abs() < 1e-12);
    }

    #[test]
    fn static_captures_are_not_chained_as_one_history() {
        // With creep, a reading after a long hold at a high tension carries
        // that history in a protocol, but not as an independent capture.
        let mut a = Rod::default();
        a.effects.creep_fraction = 0.3;
        let row = |id: i64, step: i64, tension_n: f64, direction: Direction, dwell_s: f64| Measurement {
            measurement: id,
            step,
            tension_n,
            direction,
            dwell_s,
            routing_mm: [2.0; 5].into(),
            ..rest_row("r", 0.0)
        };
        let angle = |rows: Vec<Measurement>| {
            let data = Dataset { rows, actuator: None };
            let p = predict(&a, &SolverOptions::default(), &data, &data.groups(), false).unwrap();
            p.last().unwrap().as_ref().unwrap().pose.tip_angle_rad
        };
        let alone = angle(vec![row(1, 0, 0.5, Direction::Static, 5.0)]);
        let chained = angle(vec![row(1, 0, 2.0, Direction::Load, 60.0), row(2, 1, 0.5, Direction::Unload, 5.0)]);
        let independent = angle(vec![row(1, 0, 2.0, Direction::Static, 60.0), row(2, 1, 0.5, Direction::Static, 5.0)]);
        assert!((independent - alone).abs() < 1e-9, "{independent} vs {alone}");
        assert!((chained - alone).abs() > 1e-3, "the protocol carries creep: {chained} vs {alone}");
    }
}
