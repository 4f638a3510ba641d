//! Several cables with spatial routings (issue 16, the thesis's future work).
//!
//! An actuator here is the thesis's rod ([`Rod`]) with 1–8 cables, each
//! routed along r_c,i(s) = (0, y_i(s), z_i(s)) in the body frame, y and z
//! each the thesis's five-point parametric B-spline ([`cable`]); torsion
//! enters with GJ (default EI/1.5: ν = 0.5, incompressible silicone) and
//! gravity acts along any global direction. The 3-D solver ([`solver`]) is
//! the equilibrium-at-a-cut form generalised to three dimensions; the planar
//! single-cable solver ([`crate::model::simulate`]) stays the fast path for
//! planar single-cable work, and the two agree on planar cases.

pub mod collocation;
pub mod record;
pub mod solver;

pub use crate::model::cable::{self, Cable, MAX_CABLES};
pub use crate::model::actuator::{Actuator, EI_OVER_GJ};
pub use collocation::SpatialSolver;
pub use solver::{check_order, SpatialFailure, SpatialNode, SpatialOptions, SpatialPose, SpatialRk4Solver, MAX_SPATIAL_ORDER};

use crate::model::routing::RoutingError;
use crate::model::ParameterError;
use crate::shape::LengthBasis;
use serde::Serialize;

/// Why a spatial actuator or solve was rejected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpatialError {
    /// Too few or too many cables.
    #[error("an actuator needs 1 to {MAX_CABLES} cables, got {0}")]
    CableCount(usize),
    /// A tension is negative or not finite.
    #[error("cable {cable}: tension {} N is invalid: a cable pulls with a finite tension ≥ 0 N", crate::io::fmt_num(*tension_n))]
    Tension { cable: usize, tension_n: f64 },
    /// A control point is bad.
    #[error("cable {cable}, {axis} control points: {source}")]
    Routing { cable: usize, axis: char, source: RoutingError },
    /// The channel leaves the body between control points.
    #[error("cable {cable}: the channel reaches {distance_mm:.3} mm from the axis at s = {s_mm:.2} mm, on or outside the radius r = {radius_mm} mm; move its control points toward the axis (|r_c(s)| = √(y² + z²) must stay below r everywhere)")]
    OutsideBody { cable: usize, s_mm: f64, distance_mm: f64, radius_mm: f64 },
    /// Two cables share one channel.
    #[error("cables {first} and {second} have the same path (identical y and z control points); two cables cannot share a channel: merge them into one cable with the summed tension, or move one")]
    SamePath { first: usize, second: usize },
    /// An anchor lies outside the rod.
    #[error("cable {cable}: anchor s_k = {} mm must lie in (0, L = {} mm]", crate::io::fmt_num(*anchor_mm), crate::io::fmt_num(*length_mm))]
    Anchor { cable: usize, anchor_mm: f64, length_mm: f64 },
    /// Gravity direction is zero or not finite.
    #[error("gravity direction {0:?} must be a finite, non-zero 3-vector (it is normalised; the weight per length comes from the density)")]
    GravityDirection([f64; 3]),
    /// A rod parameter is bad.
    #[error(transparent)]
    Parameter(#[from] ParameterError),
    /// The solver serving the request does not model part of it
    /// ([`crate::model::Backend::check`]).
    #[error(transparent)]
    Unsupported(#[from] crate::model::Unsupported),
    /// A planar solve (the fast path of a one-cable in-plane actuator) failed.
    #[error(transparent)]
    Planar(#[from] crate::model::SimulateError),
    /// The `--cable` text could not be read.
    #[error("cable \"{text}\": {why} (expected \"y=Y0,Y1,Y2,Y3,Y4 z=Z0,Z1,Z2,Z3,Z4 tension=T\", z= optional, anchor=S optional)")]
    CableSpec { text: String, why: String },
    /// An actuator file is not valid TOML or has unknown fields.
    #[error("actuator file {source_name}: {message}(see docs/schema.md, \"Spatial actuator file\")")]
    Toml { source_name: String, message: String },
    /// A numerical setting is bad.
    #[error("spatial solver: {0}")]
    Option(String),
    /// The solve failed.
    #[error(transparent)]
    Solve(#[from] SpatialFailure),
    /// An actuator file cannot be read.
    #[error("reading actuator file {path}: {message}")]
    Read {
        /// The file.
        path: String,
        /// The cause (as text: this error is cloned and compared).
        message: String,
    },
}

/// Everything about one spatial solve (allocates; for single solves).
#[derive(Debug, Clone, Serialize)]
pub struct SpatialSimulation {
    /// The actuator solved (its tensions are the final ones).
    pub actuator: Actuator,
    /// Tip pose and length.
    pub pose: SpatialPose,
    /// Legendre coefficients of the twist u_1, a_0 … a_order, 1/mm.
    pub a_twist: Vec<f64>,
    /// Of the bending curvature about the body y-axis (out of the x–y plane).
    pub a_bend_y: Vec<f64>,
    /// Of the bending curvature about the body z-axis (in the x–y plane;
    /// the planar solver's a_i for a planar rod).
    pub a_bend_z: Vec<f64>,
    /// The coefficients' length basis.
    pub length_basis: LengthBasis,
    /// Centreline nodes, clamp to tip.
    pub nodes: Vec<SpatialNode>,
}

impl SpatialSimulation {
    /// Each cable's path in the global frame at the nodes, mm.
    pub fn cable_paths_mm(&self) -> Vec<Vec<[f64; 3]>> {
        let channels = self.actuator.channels().expect("validated when solved");
        channels
            .iter()
            .map(|c| {
                self.nodes
                    .iter()
                    .map(|n| {
                        let p = c.at(n.s_mm);
                        n.body_point_mm(p.r_mm[0], p.r_mm[1])
                    })
                    .collect()
            })
            .collect()
    }
}

/// Solves `actuator` at its cables' tensions, stepping all tensions up
/// together from zero (rungs of at most 0.25 N on the largest) so that large
/// deformations start from a nearby solution, and computes the coefficients
/// a_0 … a_order in `basis`, by `options.method`:
///
/// - collocation (the default, [`SpatialSolver`]): every solve estimates its
///   own error (the tip within [`crate::model::solver::tip_tolerance_mm`],
///   every coefficient within [`crate::model::resolution::ORDER_TOLERANCE_PER_MM`]);
///   where it is above, the ladder is solved again at twice the intervals,
///   up to [`crate::model::solver::MAX_NODES_PER_SPAN`], beyond which the
///   solve is refused as unresolved;
/// - RK4 (the reference, [`SpatialRk4Solver`]): the result is checked against
///   the same solve at half the steps (RK4's error falls as h⁴, so their
///   difference is well above the finer one's error), doubling the steps
///   up to [`MAX_AUTO_SPATIAL_STEPS_PER_SPAN`].
///
/// A tip farther from the clamp than the stretched rod is long is refused too.
pub fn simulate_spatial(
    actuator: &Actuator,
    options: &SpatialOptions,
    order: usize,
    basis: LengthBasis,
) -> Result<SpatialSimulation, SpatialError> {
    simulate_spatial_held(actuator, options, order, basis, None)
}

/// [`simulate_spatial`] with the final tensions reached in direction
/// `hold.direction` (friction) and held for `hold.dwell_s` from a virgin rod
/// (creep); the ladder below is loaded as the effects say. `None` holds
/// every rung as the actuator's effects say (collocation only: the RK4
/// reference models no effect with a hold).
pub fn simulate_spatial_held(
    actuator: &Actuator,
    options: &SpatialOptions,
    order: usize,
    basis: LengthBasis,
    hold: Option<crate::model::Hold>,
) -> Result<SpatialSimulation, SpatialError> {
    let top = actuator.cables.iter().map(|c| c.tension_n).fold(0.0, f64::max);
    crate::model::solver::check_ladder_tension("cable tension_n", top)?;
    if options.method == crate::model::SolverMethod::Rk4 {
        return simulate_spatial_rk4(actuator, options, order, basis);
    }
    if order > MAX_SPATIAL_ORDER {
        return Err(SpatialError::Option(format!("order {order} is above the spatial solver's highest order {MAX_SPATIAL_ORDER}")));
    }
    let mut options = options.clone();
    loop {
        match solve_collocation_ladder(actuator, &options, order, basis, hold) {
            Err(SpatialError::Solve(SpatialFailure::Unresolved(_))) if options.nodes_per_span < crate::model::solver::MAX_NODES_PER_SPAN => {
                options.nodes_per_span = (2 * options.nodes_per_span).min(crate::model::solver::MAX_NODES_PER_SPAN);
            }
            result => return result,
        }
    }
}

/// One ladder of the collocation solver at `options`, with its checks.
fn solve_collocation_ladder(
    actuator: &Actuator,
    options: &SpatialOptions,
    order: usize,
    basis: LengthBasis,
    hold: Option<crate::model::Hold>,
) -> Result<SpatialSimulation, SpatialError> {
    let mut solver = SpatialSolver::new(actuator, options)?;
    let top = actuator.cables.iter().map(|c| c.tension_n).fold(0.0, f64::max);
    let rungs = ((top / 0.25).ceil() as usize).max(1);
    let mut pose = None;
    for k in 1..=rungs {
        if let (true, Some(h)) = (k == rungs, hold) {
            solver.set_hold(h)?;
        }
        pose = Some(solver.solve_scaled(k as f64 / rungs as f64)?);
    }
    let pose = pose.expect("at least one rung");
    let [a_twist, a_bend_y, a_bend_z] = solver.coefficients(order, basis)?;
    if !a_twist.iter().chain(&a_bend_y).chain(&a_bend_z).all(|v| v.is_finite()) {
        return Err(SpatialFailure::NonFinite.into());
    }
    Ok(SpatialSimulation { actuator: actuator.clone(), pose, a_twist, a_bend_y, a_bend_z, length_basis: basis, nodes: solver.centreline() })
}

/// [`simulate_spatial`] by the RK4 reference, refining by comparison with half the steps.
fn simulate_spatial_rk4(actuator: &Actuator, options: &SpatialOptions, order: usize, basis: LengthBasis) -> Result<SpatialSimulation, SpatialError> {
    solver::check_order(order, options)?;
    let half = SpatialOptions { steps_per_span: (options.steps_per_span / 2).max(2), ..options.clone() };
    // A coarse solve that fails says nothing about the fine one: the
    // comparison then moves one level up.
    let mut coarse = solve_ladder(actuator, &half, order, basis).ok();
    let mut options = options.clone();
    loop {
        let fine = solve_ladder(actuator, &options, order, basis)?;
        let steps = options.steps_per_span;
        let failure = match &coarse {
            Some(c) => unresolved_part(&fine, c, steps),
            None => Some(unresolved("the tip position".into(), f64::INFINITY, 0.0, "mm", steps)),
        };
        let Some(failure) = failure else {
            return Ok(fine);
        };
        if steps >= MAX_AUTO_SPATIAL_STEPS_PER_SPAN {
            return Err(failure.into());
        }
        options.steps_per_span = (2 * steps).min(MAX_AUTO_SPATIAL_STEPS_PER_SPAN);
        coarse = Some(fine);
    }
}

/// Most RK4 steps per span [`simulate_spatial`] refines to by itself.
pub const MAX_AUTO_SPATIAL_STEPS_PER_SPAN: usize = 2560;

/// [`SpatialFailure::Unresolved`] for `what` at `steps` per span.
fn unresolved(what: String, estimate: f64, tolerance: f64, unit: &'static str, steps: usize) -> SpatialFailure {
    let advice = format!("raise --steps-per-span above {steps} (sweep spec: [solver] steps_per_span), or lower the tensions");
    SpatialFailure::Unresolved(crate::model::solver::Unresolved { what, estimate, tolerance, unit, advice })
}

/// What of `fine` (at `steps` per span) is not resolved, judged against
/// `coarse` (at fewer steps): the tip or a coefficient further off than
/// its tolerance, or a tip beyond the stretched length. `None` if all is.
fn unresolved_part(fine: &SpatialSimulation, coarse: &SpatialSimulation, steps: usize) -> Option<SpatialFailure> {
    let unresolved = |what: String, estimate: f64, tolerance: f64, unit| Some(unresolved(what, estimate, tolerance, unit, steps));
    let tolerance = crate::model::solver::tip_tolerance_mm(fine.actuator.rod.length_mm);
    let [x, y, z] = fine.pose.tip_mm;
    let reach = (x * x + y * y + z * z).sqrt();
    if reach > fine.pose.length_mm + tolerance {
        let what = format!(
            "the tip (|tip| = {} mm is more than the stretched length ℓ = {} mm)",
            crate::io::fmt_num(reach),
            crate::io::fmt_num(fine.pose.length_mm)
        );
        return unresolved(what, reach - fine.pose.length_mm, tolerance, "mm");
    }
    let tip_difference = (0..3).map(|i| (fine.pose.tip_mm[i] - coarse.pose.tip_mm[i]).powi(2)).sum::<f64>().sqrt();
    if !(tip_difference <= tolerance) {
        return unresolved("the tip position".into(), tip_difference, tolerance, "mm");
    }
    let series = [("a_twist", &fine.a_twist, &coarse.a_twist), ("a_bend_y", &fine.a_bend_y, &coarse.a_bend_y), ("a_bend_z", &fine.a_bend_z, &coarse.a_bend_z)];
    let a_tolerance = crate::model::resolution::ORDER_TOLERANCE_PER_MM;
    for (name, f, c) in series {
        for (k, (p, q)) in f.iter().zip(c.iter()).enumerate() {
            if !((p - q).abs() <= a_tolerance) {
                return unresolved(format!("{name}[{k}]"), (p - q).abs(), a_tolerance, "mm⁻¹");
            }
        }
    }
    None
}

/// One ladder of [`simulate_spatial_rk4`] at `options`' steps, without the
/// resolution check (but refusing non-finite results).
fn solve_ladder(actuator: &Actuator, options: &SpatialOptions, order: usize, basis: LengthBasis) -> Result<SpatialSimulation, SpatialError> {
    let mut solver = SpatialRk4Solver::new(actuator, options)?;
    let top = actuator.cables.iter().map(|c| c.tension_n).fold(0.0, f64::max);
    let rungs = ((top / 0.25).ceil() as usize).max(1);
    let mut pose = None;
    for k in 1..=rungs {
        pose = Some(solver.solve_scaled(k as f64 / rungs as f64)?);
    }
    let pose = pose.expect("at least one rung");
    solver.settle_moments()?;
    let [a_twist, a_bend_y, a_bend_z] = solver.coefficients_unchecked(order, basis);
    let finite = pose.tip_mm.iter().chain(&[pose.length_mm, pose.tip_angle_rad]).chain(&a_twist).chain(&a_bend_y).chain(&a_bend_z).all(|v| v.is_finite());
    if !finite {
        return Err(SpatialFailure::NonFinite.into());
    }
    Ok(SpatialSimulation {
        actuator: actuator.clone(),
        pose,
        a_twist,
        a_bend_y,
        a_bend_z,
        length_basis: basis,
        nodes: solver.nodes().to_vec(),
    })
}

/// What [`simulate_actuator`] solved: the planar result of the fast path
/// (kept for what only it has, the planar centreline), and the one result
/// type of an actuator, [`SpatialSimulation`] (the planar values as its
/// in-plane special case).
#[derive(Debug, Clone)]
pub struct ActuatorSimulation {
    /// The backend that solved it.
    pub backend: crate::model::Backend,
    /// The planar solve, when a planar backend served the request.
    pub planar: Option<crate::model::Simulation>,
    /// The result in the actuator's terms.
    pub spatial: SpatialSimulation,
}

/// Solves `actuator` with the backend that serves it ([`crate::model::Backend::serving`]):
/// one in-plane cable with gravity in the plane takes the planar fast path
/// (`options`, and `hold` for the final tension), anything else the 3-D
/// solver (`spatial_options`). `given` names the settings asked for
/// explicitly; one a backend does not read is refused, not ignored.
#[allow(clippy::too_many_arguments)]
pub fn simulate_actuator(
    actuator: &Actuator,
    options: &crate::model::SolverOptions,
    spatial_options: &SpatialOptions,
    given: crate::model::Given,
    hold: Option<crate::model::Hold>,
    order: usize,
    basis: LengthBasis,
) -> Result<ActuatorSimulation, SpatialError> {
    use crate::model::Backend;
    actuator.channels()?;
    let backend = Backend::serving(actuator, options, given)?;
    if matches!(backend, Backend::Spatial | Backend::SpatialRk4) {
        // One set of settings: the method picked the backend, and the
        // collocation's intervals are the planar solver's option.
        let method = if backend == Backend::Spatial { crate::model::SolverMethod::Collocation } else { crate::model::SolverMethod::Rk4 };
        let spatial_options = SpatialOptions { method, nodes_per_span: options.nodes_per_span, ..spatial_options.clone() };
        let spatial = simulate_spatial_held(actuator, &spatial_options, order, basis, hold)?;
        return Ok(ActuatorSimulation { backend, planar: None, spatial });
    }
    let (rod, routing) = planar_problem(actuator)?;
    let cable = &actuator.cables[0];
    let hold = hold.unwrap_or(crate::model::Hold { direction: rod.effects.load_direction, dwell_s: rod.effects.creep_hold_s });
    let planar = crate::model::simulate_held(&rod, options, &routing, cable.tension_n, order, basis, hold)?;
    let spatial = planar_as_spatial(actuator, &planar);
    Ok(ActuatorSimulation { backend, planar: Some(planar), spatial })
}

/// The planar solver's input for a planar `actuator` (one cable, z ≡ 0,
/// gravity in the x–y plane): the rod with the cable's anchor and gravity's
/// in-plane direction, and the cable's routing over [0, anchor].
pub fn planar_problem(actuator: &Actuator) -> Result<(crate::model::Rod, crate::model::Routing), SpatialError> {
    let cable = &actuator.cables[0];
    let mut rod = actuator.rod.clone();
    if let Some(anchor) = cable.anchor_mm {
        if rod.cable_anchor_mm.is_some_and(|k| k != anchor) {
            return Err(SpatialError::Option(format!(
                "cable 1 has anchor={} mm and the rod cable_anchor_mm = {} mm: give the anchor once",
                crate::io::fmt_num(anchor),
                crate::io::fmt_num(rod.cable_anchor_mm.unwrap_or(anchor))
            )));
        }
        rod.cable_anchor_mm = Some(anchor);
    }
    if let (Some(g), true) = (actuator.gravity_direction, rod.gravity.enabled) {
        rod.gravity.direction_rad = g[1].atan2(g[0]);
    }
    let routing = crate::model::Routing::for_actuator(cable.y_mm, &rod)
        .map_err(|source| SpatialError::Routing { cable: 1, axis: 'y', source })?;
    Ok((rod, routing))
}

/// A planar solve of `actuator` as its [`SpatialSimulation`]: the frame
/// turns about z by φ, v = (v1, v2, 0), u = (0, 0, u), the in-plane series
/// is the planar a_i and the out-of-plane and twist series are zero.
pub fn planar_as_spatial(actuator: &Actuator, planar: &crate::model::Simulation) -> SpatialSimulation {
    let p = &planar.pose;
    let (st, ct) = p.tip_angle_rad.sin_cos();
    let (sf, cf) = p.tip_frame_angle_rad.sin_cos();
    let pose = SpatialPose {
        tip_mm: [p.tip_x_mm, p.tip_y_mm, 0.0],
        tip_tangent: [ct, st, 0.0],
        tip_body_y_axis: [-sf, cf, 0.0],
        // As the spatial solver measures it: the unsigned angle to +x.
        tip_angle_rad: ct.clamp(-1.0, 1.0).acos(),
        length_mm: p.length_mm,
        passes: p.iterations,
    };
    let nodes = planar
        .centreline
        .iter()
        .map(|c| {
            let (s, co) = c.frame_angle_rad.sin_cos();
            SpatialNode {
                s_mm: c.s_mm,
                p_mm: [c.x_mm, c.y_mm, 0.0],
                rotation: [[co, -s, 0.0], [s, co, 0.0], [0.0, 0.0, 1.0]],
                v: [c.v1, c.v2, 0.0],
                u_per_mm: [0.0, 0.0, c.u_per_mm],
                arc_length_mm: c.arc_length_mm,
            }
        })
        .collect();
    let zeros = vec![0.0; planar.a.len()];
    SpatialSimulation {
        actuator: actuator.clone(),
        pose,
        a_twist: zeros.clone(),
        a_bend_y: zeros,
        a_bend_z: planar.a.clone(),
        length_basis: planar.length_basis,
        nodes,
    }
}

impl SpatialError {
    /// The status a sweep stores for a failed solve (`unresolved`,
    /// `non_finite`, …), whichever backend failed; `None` for bad input.
    pub fn failure_status(&self) -> Option<&'static str> {
        match self {
            SpatialError::Solve(f) => Some(f.status()),
            SpatialError::Planar(crate::model::SimulateError::Solve(f)) => Some(f.status()),
            _ => None,
        }
    }
}
