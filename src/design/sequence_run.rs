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
use super::search::{self, SearchOptions, ROUTING_STARTS, SEQUENCE_STARTS};
use super::sequence::{Achieved, Channel, Setup};
use super::target::{Target, Weights};
use super::targets::{ComponentOutcome, Quantity, ShapeTarget, TargetSet};
use super::sequence_report::{SequenceRun, TargetOutcome};
use super::TipBeyondReach;
use super::{map_channels as map, sequence_export as export, trajectory, DesignError};
use crate::model::Actuator;

/// What a sequence design designs: the actuator with what each cable may
/// change, and the targets (a sequence, or a trajectory's waypoints).
#[derive(Debug, Clone)]
pub struct Sequence {
    /// The actuator and what may change of each cable.
    pub design: DesignActuator,
    /// The targets.
    pub targets: TargetSet,
}

/// Refuses targets no design can reach, before any search: a tip farther
/// from the clamp than the rod is long (its asked components alone).
pub fn check_reachable(design: &DesignActuator, targets: &TargetSet) -> Result<(), DesignError> {
    let length = design.actuator.rod.length_mm;
    // The rod stretches under its weight by far less than this.
    let reach = length * (1.0 + 1e-3);
    let tips: Vec<TipBeyondReach> = targets
        .targets
        .iter()
        .filter_map(|t| {
            let tip_mm = t.tip_mm();
            let distance_mm = tip_mm.iter().flatten().map(|v| v * v).sum::<f64>().sqrt();
            (distance_mm > reach).then(|| TipBeyondReach { target: t.name.clone(), tip_mm, distance_mm, length_mm: length })
        })
        .collect();
    if tips.is_empty() {
        Ok(())
    } else {
        Err(DesignError::Unreachable { tips })
    }
}

/// Compares what was achieved with target `t`.
fn compare(t: &ShapeTarget, a: &Achieved, length_mm: f64) -> Vec<ComponentOutcome> {
    t.components
        .iter()
        .map(|&(quantity, target, _)| ComponentOutcome::judge(quantity, target, a.value(quantity), t.tolerance_pct, length_mm))
        .collect()
}

/// The `cablemap simulate` command of an actuator (`--actuator FILE` when
/// it was written to `file`, else rod flags and `--cable`s).
fn command_of(actuator: &Actuator, file: Option<&std::path::Path>) -> String {
    match file {
        Some(p) => format!("cablemap simulate --actuator {} --json", super::feasible::shell_word(&p.display().to_string())),
        None => {
            let c = crate::solver::record::simulate_command(actuator, &crate::solver::SolverOptions::default());
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
    let key = Quantity::planar_key;
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
        Some(tr) => Some(trajectory::path(&setup, &channels, &targets.iter().map(|t| (&t.target, t.actuation.as_slice())).collect::<Vec<_>>(), tr)?),
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
