//! The design of an actuator with 1–8 cables (planar or spatial) for a
//! sequence of target shapes or a tip trajectory (`design --targets`): one
//! set of channels, one actuation (tension, or displacement) per target
//! (docs/design.md, "Several cables"); its report, [`SequenceRun`].
//!
//! The search is the one multi-start ([`super::search`]) over the channels
//! problem; one tension-driven planar cable free in y with one in-plane
//! target is the thesis's design, and its problem is the thesis's unknowns
//! (the routing problem, the same answers as `design --target`).

use super::actuator::{ActuationBounds, DesignActuator};
use super::objective::{Bounds, Objective};
use super::search::channels::ChannelsProblem;
use super::search::routing::RoutingProblem;
use super::request::DesignRequest;
use super::search::{self, SearchOptions, StartReport, ROUTING_STARTS, SEQUENCE_STARTS};
use super::sequence::{Achieved, Channel, Setup};
use super::target::{error_pct, Target, Weights};
use super::targets::{Quantity, ShapeTarget, TargetSet};
use super::{map_channels as map, sequence_export as export, trajectory, DesignError};
use crate::model::Actuator;
use crate::shape::LengthBasis;
use serde_json::json;
use std::fmt;
use std::path::PathBuf;

/// What a sequence design designs: the actuator with what each cable may
/// change, and the targets (a sequence, or a trajectory's waypoints).
#[derive(Debug, Clone)]
pub struct Sequence {
    /// The actuator and what may change of each cable.
    pub design: DesignActuator,
    /// The targets.
    pub targets: TargetSet,
}

/// One target component, asked vs achieved.
#[derive(Debug, Clone, PartialEq)]
pub struct ComponentOutcome {
    /// Which.
    pub quantity: Quantity,
    /// Asked.
    pub target: f64,
    /// Achieved.
    pub achieved: f64,
    /// 100 (achieved − target)/|target| (None for a zero target).
    pub error_pct: Option<f64>,
    /// Within the target's tolerance.
    pub met: bool,
}

/// One target's design: its actuation and what it achieves.
#[derive(Debug, Clone)]
pub struct TargetOutcome {
    /// The target.
    pub target: ShapeTarget,
    /// Each cable's actuation (tension N, or displacement mm, as the cable is driven).
    pub actuation: Vec<f64>,
    /// What the solve achieved (its pose holds every cable's tension and displacement).
    pub achieved: Achieved,
    /// Each component.
    pub components: Vec<ComponentOutcome>,
    /// The actuator that reproduces it.
    pub actuator: Actuator,
    /// The `cablemap simulate` command that solves it again.
    pub command: String,
}

impl TargetOutcome {
    /// Distance of the achieved tip from the asked one over the asked components, mm.
    pub fn tip_error_mm(&self) -> Option<f64> {
        let d: Vec<f64> = self.components.iter().filter(|c| matches!(c.quantity, Quantity::TipX | Quantity::TipY | Quantity::TipZ)).map(|c| c.achieved - c.target).collect();
        (!d.is_empty()).then(|| d.iter().map(|v| v * v).sum::<f64>().sqrt())
    }

    /// Angle between the achieved and the asked tip tangent, degrees.
    pub fn tangent_error_deg(&self) -> Option<f64> {
        let asked = self.target.tangent()?;
        let got = self.achieved.pose.tip_tangent();
        let dot: f64 = asked.iter().zip(got).map(|(a, b)| a * b).sum();
        let n: f64 = got.iter().map(|v| v * v).sum::<f64>().sqrt();
        Some((dot / n).clamp(-1.0, 1.0).acos().to_degrees())
    }

    /// Whether every component is met.
    pub fn met(&self) -> bool {
        self.components.iter().all(|c| c.met)
    }

    /// One sentence per component not met: which, by how much.
    pub fn misses(&self) -> Vec<String> {
        self.components
            .iter()
            .filter(|c| !c.met)
            .map(|c| {
                let pct = c.error_pct.map_or(String::new(), |e| format!(", {e:+.2} %"));
                format!(
                    "{}: {} misses by {} (achieved {}, asked {}{pct}; tolerance {} %)",
                    self.target.name,
                    c.quantity.key(),
                    fmt6(c.achieved - c.target),
                    fmt6(c.achieved),
                    fmt6(c.target),
                    self.target.tolerance_pct
                )
            })
            .collect()
    }
}

fn fmt6(v: f64) -> String {
    if v != 0.0 && v.abs() < 1e-3 {
        format!("{v:.3e}")
    } else {
        format!("{v:.4}")
    }
}

/// A finished several-cable design.
#[derive(Debug, Clone)]
pub struct SequenceRun {
    /// The actuator designed for.
    pub design: DesignActuator,
    /// Each cable's designed channel (y, z control points, mm).
    pub channels: Vec<Channel>,
    /// One per target, in order.
    pub targets: Vec<TargetOutcome>,
    /// The summed objective.
    pub cost: f64,
    /// Every refined start.
    pub starts: Vec<StartReport>,
    /// Designs simulated to seed the search.
    pub seeds_simulated: usize,
    /// Wall time, s.
    pub seconds: f64,
    /// How the search ran: `planar` (the thesis's one-cable search) or `cables`.
    pub method: &'static str,
    /// The coefficients' basis.
    pub length_basis: LengthBasis,
    /// The tip path between waypoints, for a trajectory.
    pub trajectory: Option<trajectory::PathReport>,
    /// The export directory and the files written into it.
    pub out: Option<PathBuf>,
    /// Files written, in order.
    pub exported: Vec<String>,
    /// The moulds written, when asked for.
    pub moulds: Option<crate::mould::MouldReport>,
}

impl SequenceRun {
    /// Every target met (and, for a trajectory, every intermediate solve and, with `smooth`, no reversal).
    pub fn met(&self) -> bool {
        self.targets.iter().all(TargetOutcome::met) && self.trajectory.as_ref().is_none_or(|t| t.ok())
    }

    /// Why not, one sentence each.
    pub fn unmet(&self) -> Vec<String> {
        let mut v: Vec<String> = self.targets.iter().flat_map(TargetOutcome::misses).collect();
        if let Some(t) = &self.trajectory {
            v.extend(t.problems());
        }
        v
    }

    /// design.json's object (docs/design.md, "Several cables").
    pub fn to_json(&self) -> serde_json::Value {
        let cables: Vec<serde_json::Value> = self
            .channels
            .iter()
            .zip(&self.design.freedom)
            .enumerate()
            .map(|(i, ((y, z), f))| {
                let c = &self.design.actuator.cables[i];
                json!({
                    "y_mm": y,
                    "z_mm": z,
                    "free": f.free(),
                    "max_offset_mm": f.max_offset_mm,
                    "actuation": f.actuation,
                    "anchor_mm": c.anchor_mm,
                    "cable_ea_n": c.cable_ea_n,
                })
            })
            .collect();
        let targets: Vec<serde_json::Value> = self
            .targets
            .iter()
            .map(|t| {
                let p = &t.achieved.pose;
                let mut errors = serde_json::Map::new();
                let mut achieved = serde_json::Map::new();
                for c in &t.components {
                    errors.insert(c.quantity.key(), json!(c.error_pct));
                    achieved.insert(c.quantity.key(), json!(c.achieved));
                }
                json!({
                    "name": t.target.name,
                    "target": t.target.to_json(),
                    "tensions_n": p.tensions_n.to_vec(),
                    "displacements_mm": p.displacements_mm.iter().map(|d| if d.is_finite() { json!(d) } else { serde_json::Value::Null }).collect::<Vec<_>>(),
                    "actuation": t.actuation,
                    "tip_mm": p.tip_mm(),
                    "tip_tangent": p.tip_tangent(),
                    "length_mm": p.length_mm,
                    "a_bend_z": t.achieved.a_bend_z,
                    "a_bend_y": t.achieved.a_bend_y,
                    "a_twist": t.achieved.a_twist,
                    "achieved": achieved,
                    "error_pct": errors,
                    "tip_error_mm": t.tip_error_mm(),
                    "tangent_error_deg": t.tangent_error_deg(),
                    "tolerance_pct": t.target.tolerance_pct,
                    "weights": t.target.components.iter().map(|c| (c.0.key(), json!(c.2))).collect::<serde_json::Map<_, _>>(),
                    "met": t.met(),
                    "unmet": t.misses(),
                    "command": t.command,
                })
            })
            .collect();
        let mut actuator = serde_json::to_value(&self.design.actuator).unwrap_or(serde_json::Value::Null);
        if let Some(obj) = actuator.as_object_mut() {
            // The cables are above; the actuator keeps rod, torsion and gravity.
            obj.remove("cable");
        }
        json!({
            "cables": cables,
            "targets": targets,
            "met": self.met(),
            "unmet": self.unmet(),
            "cost": self.cost,
            "actuator": actuator,
            "length_basis": self.length_basis,
            "method": self.method,
            "starts": self.starts,
            "seeds_simulated": self.seeds_simulated,
            "seconds": self.seconds,
            "trajectory": self.trajectory,
            "moulds": self.moulds,
        })
    }
}

impl fmt::Display for SequenceRun {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, (y, z)) in self.channels.iter().enumerate() {
            let list = |v: &[f64; 5]| v.iter().map(|x| format!("{x:.4}")).collect::<Vec<_>>().join(",");
            writeln!(f, "cable {}      y = {}  z = {} mm   ({})", i + 1, list(y), list(z), match self.design.freedom[i].free().as_slice() {
                [] => "fixed".to_string(),
                free => format!("free: {}", free.join(", ")),
            })?;
        }
        for t in &self.targets {
            writeln!(f)?;
            let act: Vec<String> = self.design.freedom.iter().zip(&t.achieved.pose.tensions_n.to_vec()).zip(&t.actuation).map(|((fr, tn), a)| match fr.actuation {
                ActuationBounds::Tension { .. } => format!("{tn:.4} N"),
                ActuationBounds::Displacement { .. } => format!("{a:.4} mm ({tn:.4} N)"),
            }).collect();
            writeln!(f, "{}   actuation [{}]", t.target.name, act.join(", "))?;
            writeln!(f, "  {:<16}{:>14}{:>14}{:>12}", "component", "target", "achieved", "error")?;
            for c in &t.components {
                let e = c.error_pct.map_or("n/a (t=0)".to_string(), |e| format!("{e:.3}%"));
                writeln!(f, "  {:<16}{:>14.6}{:>14.6}{:>12}{}", c.quantity.key(), c.target, c.achieved, e, if c.met { "" } else { "  unmet" })?;
            }
            if let Some(d) = t.tip_error_mm() {
                write!(f, "  tip off by {d:.4} mm")?;
                if let Some(a) = t.tangent_error_deg() {
                    write!(f, ", tangent by {a:.4}°")?;
                }
                writeln!(f)?;
            }
            writeln!(f, "  {}", t.command)?;
        }
        if let Some(tr) = &self.trajectory {
            writeln!(f)?;
            write!(f, "{tr}")?;
        }
        writeln!(f)?;
        writeln!(f, "objective    {:.3e}   ({} seed designs simulated, {} refined, {:.2} s)", self.cost, self.seeds_simulated, self.starts.len(), self.seconds)?;
        let unmet = self.unmet();
        if unmet.is_empty() {
            writeln!(f, "verdict      every target met within its tolerance")?;
        } else {
            writeln!(f, "verdict      NOT REACHABLE as asked; the design above is the closest found (least summed cost):")?;
            for u in unmet {
                writeln!(f, "  - {u}")?;
            }
        }
        if let Some(dir) = &self.out {
            writeln!(f, "exported {} to {}", self.exported.join(", "), dir.display())?;
            if let Some(m) = &self.moulds {
                write!(f, "{}", m.report(dir))?;
            }
        }
        Ok(())
    }
}

/// Refuses targets no design can reach, before any search: a tip farther
/// from the clamp than the rod is long (its asked components alone).
pub fn check_reachable(design: &DesignActuator, targets: &TargetSet) -> Result<(), DesignError> {
    let length = design.actuator.rod.length_mm;
    // The rod stretches under its weight by far less than this.
    let reach = length * (1.0 + 1e-3);
    let mut reasons = Vec::new();
    for t in &targets.targets {
        let tip = t.tip_mm();
        let d = tip.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
        if d > reach {
            let given: Vec<String> = ["x", "y", "z"].iter().zip(tip).filter_map(|(k, v)| v.map(|v| format!("{k} = {v}"))).collect();
            reasons.push(format!(
                "{}: the tip ({}) is {} mm from the clamp, beyond the rod's length L = {} mm: it misses by at least {} mm",
                t.name,
                given.join(", "),
                fmt6(d),
                length,
                fmt6(d - length)
            ));
        }
    }
    if reasons.is_empty() {
        Ok(())
    } else {
        Err(DesignError::Unreachable(reasons.join("; ")))
    }
}

/// Compares what was achieved with target `t`.
fn compare(t: &ShapeTarget, a: &Achieved, length_mm: f64) -> Vec<ComponentOutcome> {
    t.components
        .iter()
        .map(|&(quantity, target, _)| {
            let achieved = a.value(quantity);
            let error_pct = error_pct(achieved, target);
            let met = match error_pct {
                Some(e) => e.abs() <= t.tolerance_pct,
                None => (achieved - target).abs() <= t.tolerance_pct / 100.0 * quantity.natural_scale(length_mm),
            };
            ComponentOutcome { quantity, target, achieved, error_pct, met }
        })
        .collect()
}

/// The `cablemap simulate` command of an actuator (`--actuator FILE` when
/// it was written to `file`, else rod flags and `--cable`s).
fn command_of(actuator: &Actuator, file: Option<&std::path::Path>) -> String {
    match file {
        Some(p) => format!("cablemap simulate --actuator {} --json", super::feasible::shell_word(&p.display().to_string())),
        None => {
            let c = crate::solver::record::simulate_command(actuator, &crate::solver::spatial::SpatialOptions::default());
            if c.missing.is_empty() {
                c.text
            } else {
                // What no flag gives: the command alone would solve another actuator.
                format!("{}  # with no flag for: {}; --out writes the actuator file that has them", c.text, c.missing.join(", "))
            }
        }
    }
}

/// Whether the request is the thesis's design: one tension-driven planar
/// cable free in y with a positive lower tension bound (the planar search's
/// τ_l > 0; `tension_min_n = 0` goes to the general search), gravity in its
/// plane, one target asking only for the in-plane tip and a_bend_z.
fn planar_case(r: &Sequence, map: Option<&std::path::Path>) -> bool {
    let d = &r.design;
    let [f] = d.freedom.as_slice() else { return false };
    let cable = &d.actuator.cables[0];
    let in_plane = crate::solver::backend::is_planar(&d.actuator);
    let [t] = r.targets.targets.as_slice() else { return false };
    let planar_target = t.components.iter().all(|(q, v, _)| match q {
        Quantity::TipX | Quantity::TipY | Quantity::BendZ(_) => true,
        Quantity::TipZ => *v == 0.0,
        _ => false,
    });
    f.free_y && !f.free_z && cable.is_planar() && matches!(f.actuation, ActuationBounds::Tension { min_n, .. } if min_n > 0.0) && in_plane && planar_target && r.targets.trajectory.is_none() && map.is_none()
}

/// The thesis's objective (eq. 3.17) of the one-cable case ([`planar_case`]):
/// the rod with the cable's anchor and gravity's direction in the plane,
/// the target's in-plane components and weights, the cable's bounds.
fn routing_objective(design: &DesignActuator, r: &DesignRequest, t: &ShapeTarget) -> Result<Objective, DesignError> {
    let f = &design.freedom[0];
    let key = |q: &Quantity| match q {
        Quantity::TipX => Some("x".to_string()),
        Quantity::TipY => Some("y".to_string()),
        Quantity::BendZ(k) => Some(format!("a{k}")),
        _ => None,
    };
    let target = Target::parse(&t.components.iter().filter_map(|(q, v, _)| key(q).map(|k| format!("{k}={v}"))).collect::<Vec<_>>().join(","))?;
    let weights = Weights::parse(&t.components.iter().filter_map(|(q, _, w)| key(q).map(|k| format!("{k}={w}"))).collect::<Vec<_>>().join(","))?;
    let (lo, hi) = f.actuation.range();
    let mut rod = design.actuator.rod.clone();
    if let Some(g) = design.actuator.gravity_direction {
        rod.gravity.direction_rad = g[1].atan2(g[0]);
    }
    if let Some(anchor) = design.actuator.cables[0].anchor_mm {
        rod.cable_anchor_mm = Some(anchor);
    }
    rod.validate()?;
    let mut bounds = Bounds::thesis(rod.channel_radius_mm(), lo, hi);
    bounds.max_offset_mm = f.max_offset_mm;
    Ok(Objective::new(rod, r.options.clone(), target, weights, bounds)?.with_length_basis(r.length_basis))
}

/// Runs a several-cable design: refuses what no design reaches, searches
/// (the planar search for the thesis's case), compares each target,
/// reports a trajectory's path, and exports.
pub fn run(request: &DesignRequest, sequence: &Sequence) -> Result<SequenceRun, DesignError> {
    let moulds = request.write_moulds.then(|| crate::mould::MouldOptions { params: request.mould.clone(), ..Default::default() });
    let search = request.search_options(SEQUENCE_STARTS);
    let started = std::time::Instant::now();
    if let Some(dir) = &request.out {
        super::export::check_export_dir(dir)?;
    }
    check_reachable(&sequence.design, &sequence.targets)?;
    let mut design = sequence.design.clone();
    if let (Some(m), true) = (&moulds, request.out.is_some()) {
        let limit = super::request::mould_offset_limit_mm(&m.params, design.actuator.rod.radius_mm);
        for f in design.freedom.iter_mut().filter(|f| f.free_y || f.free_z) {
            f.max_offset_mm = f.max_offset_mm.min(limit);
        }
    }
    let setup = Setup {
        design: design.clone(),
        targets: sequence.targets.targets.clone(),
        options: request.options.clone(),
        basis: request.length_basis,
        smooth_steps: sequence.targets.trajectory.as_ref().filter(|t| t.smooth).map(|t| t.steps_per_leg),
    };
    let length = sequence.design.actuator.rod.length_mm;
    let (channels, achieved, cost, starts, seeds_simulated, method) = if planar_case(sequence, request.map.as_deref()) {
        let objective = routing_objective(&design, request, &sequence.targets.targets[0])?;
        let options = SearchOptions { starts: ROUTING_STARTS, max_evaluations: search.max_evaluations, ..SearchOptions::default() };
        let found = search::search(&RoutingProblem { objective: &objective, grid: &options, map_designs: Vec::new() }, &options)?;
        let e = found.solution;
        let zeros = vec![0.0; e.a.len()];
        let achieved = Achieved { pose: e.pose, a_bend_z: e.a, a_bend_y: zeros.clone(), a_twist: zeros };
        let channel: Channel = ((*e.routing_mm).try_into().expect("five control points"), [0.0; 5]);
        (vec![channel], vec![(vec![e.tension_n], achieved)], found.cost, found.starts, found.seeds_simulated, "planar")
    } else {
        let map_channels = match &request.map {
            Some(dir) => map::channels(dir, &setup, 2 * search.starts)?,
            None => Vec::new(),
        };
        let found = search::search(&ChannelsProblem { setup: &setup, map_channels }, &search)?;
        // Reported as `simulate` solves the design (the search may have
        // solved it without the ladder).
        let channels = setup.channels(&found.x);
        let achieved = (0..setup.targets.len())
            .map(|t| {
                let actuation = setup.actuation(&found.x, t);
                let sim = setup.simulate(&setup.actuator(&channels, &actuation)).map_err(|source| DesignError::Resimulate { source })?;
                Ok((actuation, Achieved::of(&sim)))
            })
            .collect::<Result<Vec<_>, DesignError>>()?;
        (channels, achieved, found.cost, found.starts, found.seeds_simulated, "cables")
    };
    let mut targets: Vec<TargetOutcome> = sequence
        .targets
        .targets
        .iter()
        .zip(achieved)
        .map(|(t, (actuation, a))| {
            let actuator = setup.actuator(&channels, &actuation);
            TargetOutcome { components: compare(t, &a, length), target: t.clone(), actuation, achieved: a, command: command_of(&actuator, None), actuator }
        })
        .collect();
    let trajectory = match &sequence.targets.trajectory {
        Some(tr) => Some(trajectory::path(&setup, &channels, &targets, tr)?),
        None => None,
    };
    let mut run = SequenceRun {
        design,
        channels,
        targets: Vec::new(),
        cost,
        starts,
        seeds_simulated,
        seconds: 0.0,
        method,
        length_basis: request.length_basis,
        trajectory,
        out: request.out.clone(),
        exported: Vec::new(),
        moulds: None,
    };
    if let Some(dir) = &request.out {
        for (i, t) in targets.iter_mut().enumerate() {
            t.command = command_of(&t.actuator, Some(&dir.join(export::actuator_file_name(i))));
        }
    }
    run.targets = targets;
    run.seconds = started.elapsed().as_secs_f64();
    if let Some(dir) = &request.out {
        if let Some(m) = &moulds {
            run.moulds = Some(crate::mould::for_actuator(&run.targets[0].actuator, m, dir)?);
        }
        run.exported = export::write_all(dir, &run, &setup)?;
    }
    Ok(run)
}
