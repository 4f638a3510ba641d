//! Single solves of an actuator, whichever backend serves it
//! ([`simulate_actuator`]): a ladder of tensions from zero (continuation, so
//! that large deformations start from a nearby solution), then the
//! coefficients, repeated at a finer discretisation until it resolves the
//! result. [`simulate`] is the planar backends' ladder, [`simulate_spatial`]
//! the spatial one's; both return the one [`Simulation`].

use super::error::SimulateError;
use super::result::Simulation;
use super::{tip_tolerance_mm, until_resolved, planar_problem, Backend, Given, Hold, SolveFailure, Solver, SolverMethod, SolverOptions, Simulator, Unresolved, MAX_NODES_PER_SPAN};
use crate::model::parameter::ParameterError;
use crate::solver::spatial::collocation::check_dwell;
use crate::solver::spatial::{check_order, SpatialError, SpatialRk4, SpatialCollocation};
use crate::model::{Actuator, Cable, Rod, Routing};
use crate::shape::LengthBasis;

/// Solves one actuator at `tension_n`, stepping up from a low tension by
/// continuation so that large deformations start from a nearby solution.
pub fn simulate(
    rod: &Rod,
    options: &SolverOptions,
    routing: &Routing,
    tension_n: f64,
    order: usize,
    basis: LengthBasis,
) -> Result<Simulation, SimulateError> {
    let hold = Hold { direction: rod.effects.load_direction, dwell_s: rod.effects.creep_hold_s };
    simulate_held(rod, options, routing, tension_n, order, basis, hold)
}

/// Like [`simulate`], with the final tension reached in direction
/// `hold.direction` (friction) and held for `hold.dwell_s` from a virgin
/// rod (creep); the ladder below it is loaded without dwell.
pub fn simulate_held(
    rod: &Rod,
    options: &SolverOptions,
    routing: &Routing,
    tension_n: f64,
    order: usize,
    basis: LengthBasis,
    hold: Hold,
) -> Result<Simulation, SimulateError> {
    check_ladder_tension("tension_n", tension_n)?;
    simulate_planar_cable(rod, options, &Cable::planar(routing.control_points_mm().0, tension_n), routing, order, basis, hold)
}

/// The planar ladder of one `cable` (its routing `routing`, built for the
/// rod): up its tension, or its displacement; then the coefficients.
fn simulate_planar_cable(
    rod: &Rod,
    options: &SolverOptions,
    cable: &Cable,
    routing: &Routing,
    order: usize,
    basis: LengthBasis,
    hold: Hold,
) -> Result<Simulation, SimulateError> {
    crate::solver::resolution::check_order(order, options)?;
    hold.check()?;
    let actuator = Actuator::with_cables(rod.clone(), vec![cable.clone()]);
    // A solve the discretisation does not resolve is repeated, from the
    // bottom of the ladder, at a finer one, up to the most there is.
    until_resolved(
        options,
        |options| {
            let mut sim = Simulator::for_rod(rod, options)?;
            sim.set_routing(routing);
            sim.set_cable_stiffness(cable.cable_ea_n);
            Ok(sim.simulate_in_plane(&actuator, hold, order, basis)?)
        },
        |e| matches!(e, SimulateError::Solve(SolveFailure::Unresolved(_))),
        refined,
    )
}

/// Highest tension the continuation ladders of [`simulate`] and
/// [`simulate_spatial`] climb to, N: 10⁵ rungs of [`ladder::TENSION_RUNG_N`]
/// (a few seconds); an absurd tension is refused rather than climbed for hours.
pub const MAX_LADDER_TENSION_N: f64 = 25_000.0;

/// Refuses a tension above [`MAX_LADDER_TENSION_N`] (parameter `name`).
pub fn check_ladder_tension(name: &'static str, tension_n: f64) -> Result<(), ParameterError> {
    if tension_n > MAX_LADDER_TENSION_N {
        return Err(ParameterError::OutOfRange {
            name,
            value: tension_n,
            expected: "a tension of at most 25000 N (solves climb to it in steps of 0.25 N; the thesis's cable pulls up to 2 N)",
        });
    }
    Ok(())
}

/// Raises `options`' resolution one step for an unresolved solve (1.5×
/// the collocation intervals, up to [`MAX_NODES_PER_SPAN`]; 2× the RK4
/// steps, up to [`MAX_AUTO_STEPS_PER_SPAN`]); false at the most.
fn refined(options: &mut SolverOptions) -> bool {
    match options.method {
        SolverMethod::Collocation if options.nodes_per_span < MAX_NODES_PER_SPAN => {
            options.nodes_per_span = (options.nodes_per_span * 3 / 2).clamp(options.nodes_per_span + 2, MAX_NODES_PER_SPAN);
            true
        }
        SolverMethod::Rk4 if options.planar_steps_per_span < MAX_AUTO_STEPS_PER_SPAN => {
            options.planar_steps_per_span = (2 * options.planar_steps_per_span).min(MAX_AUTO_STEPS_PER_SPAN);
            true
        }
        _ => false,
    }
}

/// Most RK4 steps per span [`simulate`] refines to by itself (a solve
/// there takes tens of milliseconds; more must be asked for).
pub const MAX_AUTO_STEPS_PER_SPAN: usize = 6144;

/// Solves `actuator` at its cables' tensions, stepping all tensions up
/// together from zero (rungs of at most 0.25 N on the largest) so that large
/// deformations start from a nearby solution, and computes the coefficients
/// a_0 … a_order in `basis`, by `options.method`:
///
/// - collocation (the default, [`SpatialCollocation`]): every solve estimates its
///   own error (the tip within [`tip_tolerance_mm`], every coefficient within
///   [`crate::solver::resolution::ORDER_TOLERANCE_PER_MM`]); where it is above,
///   the ladder is solved again at twice the intervals, up to
///   [`MAX_NODES_PER_SPAN`], beyond which the solve is refused as unresolved;
/// - RK4 (the reference, [`SpatialRk4`]): the result is checked against
///   the same solve at half the steps (RK4's error falls as h⁴, so their
///   difference is well above the finer one's error), doubling the steps up
///   to [`MAX_AUTO_SPATIAL_STEPS_PER_SPAN`].
///
/// A tip farther from the clamp than the stretched rod is long is refused too.
pub fn simulate_spatial(
    actuator: &Actuator,
    options: &SolverOptions,
    order: usize,
    basis: LengthBasis,
) -> Result<Simulation, SpatialError> {
    simulate_spatial_held(actuator, options, order, basis, None)
}

/// [`simulate_spatial`] with the final tensions reached in direction
/// `hold.direction` (friction) and held for `hold.dwell_s` from a virgin rod
/// (creep); `None` holds every rung as the actuator's effects say. (The RK4
/// reference models no effect a hold acts on.)
pub fn simulate_spatial_held(
    actuator: &Actuator,
    options: &SolverOptions,
    order: usize,
    basis: LengthBasis,
    hold: Option<Hold>,
) -> Result<Simulation, SpatialError> {
    check_order(order, options)?;
    let top = actuator.cables.iter().map(|c| c.tension_n).fold(0.0, f64::max);
    check_ladder_tension("cable tension_n", top)?;
    if options.method == SolverMethod::Rk4 {
        return simulate_spatial_rk4(actuator, options, order, basis);
    }
    if let Some(h) = hold {
        check_dwell(h)?;
    }
    until_resolved(
        options,
        |options| SpatialCollocation::new(actuator, options)?.simulate(actuator, hold, order, basis),
        |e| matches!(e, SpatialError::Solve(SolveFailure::Unresolved(_))),
        |options| {
            let finer = options.nodes_per_span < MAX_NODES_PER_SPAN;
            options.nodes_per_span = (2 * options.nodes_per_span).min(MAX_NODES_PER_SPAN);
            finer
        },
    )
}

/// [`simulate_spatial`] by the RK4 reference, refining by comparison with half the steps.
fn simulate_spatial_rk4(actuator: &Actuator, options: &SolverOptions, order: usize, basis: LengthBasis) -> Result<Simulation, SpatialError> {
    let ladder = |options: &SolverOptions| SpatialRk4::new(actuator, options)?.simulate(actuator, None, order, basis);
    let half = SolverOptions { spatial_steps_per_span: (options.spatial_steps_per_span / 2).max(2), ..options.clone() };
    // A coarse solve that fails says nothing about the fine one: the
    // comparison then moves one level up.
    let mut coarse = ladder(&half).ok();
    until_resolved(
        options,
        |options| {
            let fine = ladder(options)?;
            let steps = options.spatial_steps_per_span;
            let failure = match &coarse {
                Some(c) => unresolved_part(&fine, c, steps),
                None => Some(unresolved("the tip position".into(), f64::INFINITY, 0.0, "mm", steps)),
            };
            match failure {
                None => Ok(fine),
                Some(failure) => {
                    coarse = Some(fine);
                    Err(failure.into())
                }
            }
        },
        |e| matches!(e, SpatialError::Solve(SolveFailure::Unresolved(_))),
        |options| {
            let finer = options.spatial_steps_per_span < MAX_AUTO_SPATIAL_STEPS_PER_SPAN;
            options.spatial_steps_per_span = (2 * options.spatial_steps_per_span).min(MAX_AUTO_SPATIAL_STEPS_PER_SPAN);
            finer
        },
    )
}

/// Most RK4 steps per span [`simulate_spatial`] refines to by itself.
pub const MAX_AUTO_SPATIAL_STEPS_PER_SPAN: usize = 2560;

/// [`SolveFailure::Unresolved`] for `what` at `steps` per span.
fn unresolved(what: String, estimate: f64, tolerance: f64, unit: &'static str, steps: usize) -> SolveFailure {
    let advice = format!("raise --steps-per-span above {steps} (sweep spec: [solver] steps_per_span), or lower the tensions");
    SolveFailure::Unresolved(Unresolved { what, estimate, tolerance, unit, advice })
}

/// What of `fine` (at `steps` per span) is not resolved, judged against
/// `coarse` (at fewer steps): the tip or a coefficient further off than
/// its tolerance, or a tip beyond the stretched length. `None` if all is.
fn unresolved_part(fine: &Simulation, coarse: &Simulation, steps: usize) -> Option<SolveFailure> {
    let unresolved = |what: String, estimate: f64, tolerance: f64, unit| Some(unresolved(what, estimate, tolerance, unit, steps));
    let tolerance = tip_tolerance_mm(fine.actuator.rod.length_mm);
    let [x, y, z] = fine.pose.tip_mm();
    let reach = (x * x + y * y + z * z).sqrt();
    if reach > fine.pose.length_mm + tolerance {
        let what = format!(
            "the tip (|tip| = {} mm is more than the stretched length ℓ = {} mm)",
            crate::io::fmt_num(reach),
            crate::io::fmt_num(fine.pose.length_mm)
        );
        return unresolved(what, reach - fine.pose.length_mm, tolerance, "mm");
    }
    let (f, c) = (fine.pose.tip_mm(), coarse.pose.tip_mm());
    let tip_difference = (0..3).map(|i| (f[i] - c[i]).powi(2)).sum::<f64>().sqrt();
    if !(tip_difference <= tolerance) {
        return unresolved("the tip position".into(), tip_difference, tolerance, "mm");
    }
    let series = [("a_twist", &fine.a_twist, &coarse.a_twist), ("a_bend_y", &fine.a_bend_y, &coarse.a_bend_y), ("a_bend_z", &fine.a_bend_z, &coarse.a_bend_z)];
    let a_tolerance = crate::solver::resolution::ORDER_TOLERANCE_PER_MM;
    for (name, f, c) in series {
        for (k, (p, q)) in f.iter().zip(c.iter()).enumerate() {
            if !((p - q).abs() <= a_tolerance) {
                return unresolved(format!("{name}[{k}]"), (p - q).abs(), a_tolerance, "mm⁻¹");
            }
        }
    }
    None
}

/// Solves `actuator` with the backend that serves it ([`Backend::serving`]):
/// one in-plane cable with gravity in the plane takes the planar fast path
/// (and `hold` for the final tension), anything else a 3-D backend, each
/// reading its settings of `options`. `given` names the settings asked for
/// explicitly; one a backend does not read is refused, not ignored. The
/// result holds `actuator` as given.
pub fn simulate_actuator(
    actuator: &Actuator,
    options: &SolverOptions,
    given: Given,
    hold: Option<Hold>,
    order: usize,
    basis: LengthBasis,
) -> Result<Simulation, SpatialError> {
    actuator.channels()?;
    let backend = Backend::serving(actuator, options, given)?;
    if matches!(backend, Backend::SpatialCollocation | Backend::SpatialRk4) {
        // The backend picked is the method's.
        let method = if backend == Backend::SpatialCollocation { SolverMethod::Collocation } else { SolverMethod::Rk4 };
        return simulate_spatial_held(actuator, &SolverOptions { method, ..options.clone() }, order, basis, hold);
    }
    let (rod, routing) = planar_problem(actuator)?;
    let cable = &actuator.cables[0];
    let hold = hold.unwrap_or(Hold { direction: rod.effects.load_direction, dwell_s: rod.effects.creep_hold_s });
    if cable.displacement_mm.is_none() {
        check_ladder_tension("tension_n", cable.tension_n)?;
    }
    let mut sim = simulate_planar_cable(&rod, options, cable, &routing, order, basis, hold)?;
    let tension = sim.pose.tension_n();
    sim.actuator = actuator.clone();
    sim.actuator.cables[0].tension_n = tension;
    Ok(sim)
}
