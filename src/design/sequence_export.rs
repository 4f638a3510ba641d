//! The files of a several-cable design (`design --targets … --out DIR`):
//! design.json, one channel CSV per cable, and per target the actuator
//! file that reproduces it (`target_N.toml`, for `simulate --actuator`) and
//! its picture (`target_N.png`); for a trajectory, the sampled path
//! (`trajectory.csv`) and its picture (`trajectory.png`).

use super::sequence::Setup;
use super::sequence_report::SequenceRun;
use super::export::Export;
use super::DesignError;
use crate::model::cable;
use std::fmt::Write as _;
use std::path::Path;

/// The actuator file of target `index` (from 0).
pub fn actuator_file_name(index: usize) -> String {
    format!("target_{}.toml", index + 1)
}

/// Writes the design's files into `dir` and returns their names, in order.
pub fn write_all(dir: &Path, run: &SequenceRun, setup: &Setup) -> Result<Vec<String>, DesignError> {
    let mut export = Export::create(dir)?;
    let mut text = serde_json::to_string_pretty(&run.to_json()).expect("JSON values serialise");
    text.push('\n');
    export.write("design.json", text.as_bytes())?;
    let first = &run.targets[0].actuator;
    let channels = first.channels().map_err(|source| DesignError::Channels { source })?;
    for (i, ch) in channels.iter().enumerate() {
        let end = first.cables[i].anchor_or_tip_mm(first.rod.length_mm);
        export.write(&cable::channel_file_name(i), ch.csv(end).as_bytes())?;
    }
    for (i, t) in run.targets.iter().enumerate() {
        let toml = toml::to_string(&t.actuator).map_err(|source| DesignError::ActuatorToml { target: t.target.name.clone(), source })?;
        let head = format!("# {}: the actuator of this design at this target; cablemap simulate --actuator FILE solves it again\n", t.target.name);
        export.write(&actuator_file_name(i), format!("{head}{toml}").as_bytes())?;
    }
    if let Some(tr) = &run.trajectory {
        let mut csv = String::from("leg,step,cable,actuation,tension_n,tip_x_mm,tip_y_mm,tip_z_mm,deviation_mm\n");
        for l in &tr.legs {
            for s in &l.samples {
                for (c, a) in s.actuation.iter().enumerate() {
                    let num = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v}"));
                    let tip = s.tip_mm.map_or([None; 3], |t| t.map(Some));
                    let _ = writeln!(csv, "{},{},{},{a},{},{},{},{},{}", l.from, s.step, c + 1, num(s.tensions_n.as_ref().map(|t| t[c])), num(tip[0]), num(tip[1]), num(tip[2]), num(s.deviation_mm));
                }
            }
        }
        export.write("trajectory.csv", csv.as_bytes())?;
        let waypoint = |t: &super::sequence_report::TargetOutcome| t.target.tip_mm().map(|v| v.unwrap_or(f64::NAN));
        let drawing = crate::plot::spatial::TrajectoryDrawing {
            waypoints: run.targets.iter().map(waypoint).collect(),
            legs: tr.legs.iter().map(|l| l.samples.iter().map(|s| s.tip_mm).collect()).collect(),
            base_radius_mm: run.design.actuator.rod.radius_at(0.0),
        };
        let title = format!("trajectory: {} waypoints, actuation linear in each leg, {} steps per leg; largest distance from the straight legs {:.3} mm", run.targets.len(), tr.steps_per_leg, tr.max_deviation_mm);
        export.draw("trajectory.png", |path| Ok(drawing.draw(path, &title)?))?;
    }
    for (i, t) in run.targets.iter().enumerate() {
        let sim = setup.simulate(&t.actuator).map_err(|source| DesignError::ResimulateTarget { target: t.target.name.clone(), source })?;
        let name = format!("target_{}.png", i + 1);
        let tensions: Vec<String> = sim.pose.tensions_n.iter().map(|v| format!("{v:.3}")).collect();
        export.draw(&name, |path| Ok(crate::plot::spatial::draw_spatial(path, &format!("{}: tensions [{}] N", t.target.name, tensions.join(", ")), &sim)?))?;
    }
    Ok(export.written())
}
