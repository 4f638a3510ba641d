//! Static solver for the coupled Cosserat rod–cable model (Rucker & Webster
//! 2011) in the equilibrium-at-a-cut form of model-notes §3b.
//!
//! Cutting the rod at s and taking the distal part as a free body gives the
//! strains at s from the cable tension τ(s), the cable direction in the body
//! frame, and the loads of distributed external forces beyond the cut. Writing
//! the cable direction as t_c = (cos α, sin α) leaves one scalar equation per
//! point (t_c ∥ v + u × r_c + r_c'), solved by Newton. The centreline then
//! follows by integrating from the clamp on each knot span of the routing,
//! where the routing is a polynomial: by default with spectral collocation
//! on Chebyshev–Lobatto nodes ([`SolverMethod::Collocation`], in the
//! `collocation` submodule, which also replaces the shooting below by
//! fixed-point sweeps and Newton's method), or with classical RK4
//! ([`SolverMethod::Rk4`], the reference the collocation is checked against, in `rk4`).
//!
//! One file per piece: this file holds the state both planar backends
//! share and the cut equations ([`PlanarState::strains_at`]); `planar` the
//! planar backends ([`PlanarSolver`] over one [`Integrator`], written once
//! around the integration); `collocation` and `rk4` are the two
//! integrators; `continuation` is RK4's warm-start predictor; `friction` and
//! `creep` are the two effects with state.
//!
//! Gravity's moment beyond the cut, M_W(s), depends on the distal shape; it
//! obeys M_W' = w (L − s)(y' cos β − x' sin β) with M_W(L) = 0, so its value at
//! the clamp is the one unknown of a scalar shooting (secant, warm-started
//! across a continuation in tension). Without distributed loads there is no
//! shooting at all.
//!
//! Effects (model-notes §6) enter as local terms: the bending law
//! ([`PlanarState::bending_curvature`]), the clamp boundary (`clamp_angle` in
//! each integrator), the routing (channel offset) and the weight.
//! The section's rigidities and the weight beyond a cut are looked up in one
//! place each ([`PlanarState::section_at`], [`PlanarState::distal_weight_n`]),
//! and the bending moment at a cut is one function ([`bending_moment`]).
//!
//! Two effects carry state beyond one point, each a small state type with
//! the few hooks the integrators call:
//! - **Cable–channel friction** (`friction`: capstan law
//!   dτ/ds = −η μ τ |ψ'| with the slip sign η): a tension profile τ(s)/τ(0)
//!   updated from the cable angles of the last pass until it settles.
//! - **Viscoelastic creep in bending** (`creep`: standard linear solid): a
//!   local, linear law at the end of each held step, and the internal
//!   curvature q(s) advanced after the solve. `set_routing` and
//!   `reset_history` clear that history.
//!
//! (σ is the deformed arc length throughout.)
//!
//! The hot paths (RK4's `integrate`, collocation's sweeps) work in buffers
//! allocated once per [`PlanarSolver`]; solving allocates nothing, except in
//! collocation's Newton fallback for heavy rods (a dense Jacobian).

use crate::model::parameter::ParameterError;
use crate::model::rod::{LoadDirection, Rod};
use crate::model::body::{merge_sorted, Body, BodySection};
use crate::model::routing::Routing;
use crate::shape::LengthBasis;
use serde::{Deserialize, Serialize};

pub mod actuation;
pub mod backend;
mod error;
pub mod interface;
pub mod ladder;
pub mod record;
pub mod request;
pub mod resolution;
pub mod spatial;
pub(crate) mod collocation;
mod continuation;
pub(crate) mod creep;
pub(crate) mod friction;
mod probe;
pub mod result;
mod rk4;
pub mod simulate;
pub mod options;
pub mod planar;
mod simulator;

pub use backend::{Backend, Support, Unsupported};
pub use error::SimulateError;
pub use interface::{until_resolved, Solver};
pub use result::{CableAtNode, CentrelinePoint, PerCable, Simulation, TipFrame, TipPose};
pub use simulate::{
    check_ladder_tension, simulate, simulate_actuator, simulate_held, simulate_spatial, MAX_AUTO_SPATIAL_STEPS_PER_SPAN,
    MAX_AUTO_STEPS_PER_SPAN, MAX_LADDER_TENSION_N,
};
pub use options::{Given, SolverMethod, SolverOptions, SolverSettings};
pub use planar::{Integrator, PlanarSolver};
pub use simulator::{planar_problem, PlanarCollocation, PlanarRk4, Simulator};
use creep::Creep;
use friction::Friction;

/// Why a solve produced no result. The sweep stores [`SolveFailure::status`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveFailure {
    /// The tension is negative or not finite.
    #[error("tension {} N is invalid: a cable pulls with a finite tension ≥ 0 N", crate::io::fmt_num(*.0))]
    InvalidTension(f64),
    /// The per-point cable-direction equation did not converge.
    #[error("the cable-direction equation did not converge at s = {s_mm:.3} mm; try smaller tension steps from a lower tension")]
    CableDirectionNotConverged { s_mm: f64 },
    /// The cable tangent vanished (v + u × r_c + r_c' = 0 or points backwards).
    #[error("the cable tangent is degenerate at s = {s_mm:.3} mm (the cable would leave the channel backwards); try smaller tension steps from a lower tension, or a lower tension")]
    CableTangentDegenerate { s_mm: f64 },
    /// Axial stretch fell to zero or below: the rod would collapse.
    #[error("the rod collapses axially (v1 ≤ 0) at s = {s_mm:.3} mm: the load exceeds the axial rigidity EA; lower the tension")]
    RodCollapsed { s_mm: f64 },
    /// The shooting on gravity's base moment did not converge.
    #[error("the shooting on the base moment did not converge after {iterations} passes (residual {residual_n_mm:.3e} N·mm); try smaller tension steps, or the default collocation method")]
    ShootingNotConverged { iterations: u32, residual_n_mm: f64 },
    /// The clamp-compliance fixed point did not converge.
    #[error("the clamp rotation did not converge; try a stiffer clamp (clamp stiffness) or smaller tension steps")]
    ClampNotConverged,
    /// A non-finite number appeared in the state at `s_mm` (planar), or in
    /// the tip or a coefficient (spatial: `None`).
    #[error("{}", non_finite_sentence(*s_mm))]
    NonFinite { s_mm: Option<f64> },
    /// The cables' tension profiles with friction did not settle.
    #[error("the cable tension profile with friction did not converge; try smaller tension steps or a smaller friction coefficient")]
    FrictionNotConverged,
    /// The spatial cut equations at a point did not converge.
    #[error("the cut equations did not converge at s = {s_mm:.3} mm (tension too high for this routing, or a cable pulls straight through the axis); lower the tension or raise --steps-per-span")]
    CutEquationsNotConverged { s_mm: f64 },
    /// The spatial backends' iteration on gravity's moment did not converge.
    #[error("gravity's moment did not converge in {passes} passes (residual {residual_n_mm:.3e} N·mm); the rod may be too heavy for its stiffness")]
    GravityNotConverged { passes: u32, residual_n_mm: f64 },
    /// The equilibrium under the rod's own weight was not found, even by
    /// Newton's method with continuation in the weight.
    #[error("the equilibrium under the rod's weight did not converge (reached {reached_percent:.0} % of the weight); try smaller tension steps from a lower tension, more nodes per span, or a smaller gravity scale")]
    WeightNotConverged { reached_percent: f64 },
    /// The discretisation does not resolve the solution: the a posteriori
    /// error estimate of something reported is above its tolerance (or
    /// the tip lies farther from the clamp than the stretched rod is long).
    #[error(transparent)]
    Unresolved(Unresolved),
    /// A displacement-driven cable's displacement was not met.
    #[error(transparent)]
    DisplacementNotMet(actuation::DisplacementNotMet),
}

/// What a solve does not resolve, by how much, and what to raise
/// ([`SolveFailure::Unresolved`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the solver's discretisation does not resolve this shape: {what} is off by about {} {unit} (tolerance {} {unit}); {advice}",
    crate::io::fmt_sig(*estimate, 3),
    crate::io::fmt_sig(*tolerance, 3)
)]
pub struct Unresolved {
    /// What is off: "the tip position", "a_11", "a_bend_z[3]", ….
    pub what: String,
    /// Its estimated error.
    pub estimate: f64,
    /// The error accepted.
    pub tolerance: f64,
    /// The unit of both.
    pub unit: &'static str,
    /// Which setting to raise, and how.
    pub advice: String,
}

impl SolveFailure {
    /// Short machine-readable status, as stored in sweep rows.
    pub fn status(&self) -> &'static str {
        match self {
            SolveFailure::InvalidTension(_) => "invalid_tension",
            SolveFailure::CableDirectionNotConverged { .. } => "cable_direction_not_converged",
            SolveFailure::CableTangentDegenerate { .. } => "cable_tangent_degenerate",
            SolveFailure::RodCollapsed { .. } => "rod_collapsed",
            SolveFailure::ShootingNotConverged { .. } => "shooting_not_converged",
            SolveFailure::ClampNotConverged => "clamp_not_converged",
            SolveFailure::NonFinite { .. } => "non_finite",
            SolveFailure::FrictionNotConverged => "friction_not_converged",
            SolveFailure::WeightNotConverged { .. } => "weight_not_converged",
            SolveFailure::Unresolved(_) => "unresolved",
            SolveFailure::DisplacementNotMet(_) => "displacement_not_met",
            SolveFailure::CutEquationsNotConverged { .. } => "cut_equations_not_converged",
            SolveFailure::GravityNotConverged { .. } => "gravity_not_converged",
        }
    }
}

/// [`SolveFailure::NonFinite`]'s sentence: where the value appeared, if known.
fn non_finite_sentence(s_mm: Option<f64>) -> String {
    match s_mm {
        Some(s) => format!("a non-finite value appeared at s = {s:.3} mm; check the actuator parameters, or try smaller tension steps"),
        None => "the solve gave a non-finite tip or coefficient; check the rod's parameters (rigidities, length, density) for absurd values".into(),
    }
}

/// Most Newton iterations of material stiffening's cubic curvature law.
const STIFFENING_MAX_ITERATIONS: usize = 60;
/// Relative Newton step accepted as converged in the stiffening law.
const STIFFENING_TOLERANCE: f64 = 1e-15;
/// Most Newton iterations of the cable-direction equation at one point.
const CABLE_ANGLE_MAX_ITERATIONS: usize = 50;
/// Most fixed-point iterations of the compliant clamp's rotation (RK4).
const CLAMP_MAX_ITERATIONS: usize = 100;
/// Change of the clamp rotation accepted as converged, rad.
const CLAMP_TOLERANCE_RAD: f64 = 1e-14;

/// Collocation intervals per span used at least when material stiffening is on.
pub const MIN_NODES_WITH_STIFFENING: usize = 16;

/// Tip position error a solve may have, mm: its a posteriori estimate must
/// stay below this plus [`TIP_TOLERANCE_PER_LENGTH`] times the rod's length
/// ([`tip_tolerance_mm`]), or the solve is refused as unresolved.
pub const TIP_TOLERANCE_MM: f64 = 5e-4;
/// The part of the tip tolerance proportional to the rod's length.
pub const TIP_TOLERANCE_PER_LENGTH: f64 = 1e-5;

/// The tip position error accepted on a rod of `length_mm`, mm.
pub fn tip_tolerance_mm(length_mm: f64) -> f64 {
    TIP_TOLERANCE_MM + TIP_TOLERANCE_PER_LENGTH * length_mm
}

/// Most collocation intervals per span.
pub const MAX_NODES_PER_SPAN: usize = 64;
/// Most RK4 steps per span.
pub const MAX_STEPS_PER_SPAN: usize = 100_000;

/// Orders a_0 … a_{ESTIMATED_ORDERS−1} get an error estimate (above the
/// highest order any check allows).
const ESTIMATED_ORDERS: usize = 24;

/// Status string of a successful solve.
pub const STATUS_OK: &str = "ok";

/// Strains at one point.
#[derive(Debug, Clone, Copy, Default)]
struct Strains {
    v1: f64,
    v2: f64,
    u: f64,
}

/// Channel sample (y_c, dy_c/ds) at one stage point.
#[derive(Debug, Clone, Copy, Default)]
struct ChannelSample {
    y: f64,
    dy: f64,
}


/// Bending moment at a cut, N·mm: the cable's moment τ y_c cos α about the
/// centreline (`tension` at the cut, channel offset `channel_y_mm`, cable
/// direction cos α) plus gravity's distal moment M.
#[inline]
fn bending_moment(tension: f64, channel_y_mm: f64, cos_alpha: f64, distal_moment: f64) -> f64 {
    tension * channel_y_mm * cos_alpha + distal_moment
}

/// The state both planar backends share ([`PlanarSolver`]): the rod, the
/// routing's channel at the integrator's points, the hold, the effects
/// with state (friction, creep's load history) and the warm starts of the
/// cut equations; the cut equations themselves ([`PlanarState::strains_at`]).
#[derive(Debug, Clone)]
pub struct PlanarState {
    rod: Rod,
    options: SolverOptions,
    weight_n_per_mm: f64,
    gravity_cos: f64,
    gravity_sin: f64,
    routing: Option<Routing>,
    /// Channel at the 2N+1 stage points of each span, span 0 then span 1.
    channel: Vec<ChannelSample>,
    /// Cable direction (cos α, sin α) at each stage point, kept as the Newton start.
    cable_dir: Vec<(f64, f64)>,
    /// The tension of the last successful solve, N (`None` after a failure).
    last_tension_n: Option<f64>,
    /// Cable–channel friction: slip sign and tension profile per point.
    friction: Friction,
    /// Creep: the hold and the load history per point.
    creep: Creep,
    /// The non-uniform body (radius profile, segments); `None` for the
    /// uniform cylinder, solved on the fast path.
    body: Option<Body>,
    /// Index of the first point beyond the cable's anchor (the number of
    /// points when the cable is knotted at the tip): from there on the cut
    /// carries no cable load.
    cable_end: usize,
    /// The cable's path length in the straight, unloaded rod, mm (collocation).
    cable_rest_length_mm: f64,
    /// The cable's axial stiffness EA, N (`None`: inextensible), for its
    /// displacement's stretch.
    cable_ea_n: Option<f64>,
    /// The estimated error of the tangent angle along the last solve, rad
    /// (the coefficients' error estimate starts from it).
    theta_error_rad: f64,
    /// The estimated error of the largest coefficient asked for in the
    /// last [`PlanarSolver::coefficients_into`], mm⁻¹, and its index.
    coefficient_error: (f64, usize),
    /// The routing as given (before the channel offset), for the probe.
    given_routing: Option<Routing>,
    /// The hold of the solves (the probe's are held alike).
    hold: Hold,
    /// A finer solver that settles an error estimate above the tolerance
    /// by a solve at twice the intervals ([`probe`]); made when first needed.
    probe: Option<Box<probe::Probe>>,
    /// Whether this solver is itself a probe (its solves are the
    /// reference: they are not estimated).
    is_probe: bool,
}

/// How a solve is held: the direction of the last tension change (friction)
/// and the dwell before the reading (creep).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Hold {
    /// Tension rising (load) or falling (unload).
    pub direction: LoadDirection,
    /// Seconds held at the tension before the reading.
    pub dwell_s: f64,
}

impl Hold {
    /// Refuses a dwell that is not a finite time ≥ 0 s.
    pub fn check(&self) -> Result<(), ParameterError> {
        if !(self.dwell_s.is_finite() && self.dwell_s >= 0.0) {
            return Err(ParameterError::OutOfRange { name: "dwell_s", value: self.dwell_s, expected: "a finite time ≥ 0 s" });
        }
        Ok(())
    }
}

impl PlanarState {
    /// The section's rigidities at reference arc length `s` (mm): the
    /// actuator's, or the non-uniform body's ([`Body::section_at`]), with
    /// the stiffness gradient.
    #[inline]
    fn section_at(&self, s: f64) -> BodySection {
        self.section_at_side(s, false)
    }

    /// [`PlanarState::section_at`], where a section that jumps at `s` (a
    /// segment's end) is taken from the left with `left` (the last node of
    /// a span), from the right otherwise.
    #[inline]
    fn section_at_side(&self, s: f64, left: bool) -> BodySection {
        let a = &self.rod;
        let mut section = match &self.body {
            None => BodySection { ea_n: a.ea_n, ga_n: a.ga_n, ei_n_mm2: a.ei_n_mm2, radius_mm: a.radius_mm },
            Some(b) => b.section_at_side(s, left),
        };
        let beta = a.effects.stiffness_gradient_beta;
        if beta != 0.0 {
            section.ei_n_mm2 *= (beta * (s / a.length_mm - 0.5)).exp();
        }
        section
    }

    /// The rod's weight beyond the cut at `s` (mm), N: w·(L − s) for the
    /// uniform rod, the closed-form ∫_s^L w dσ for a non-uniform body.
    #[inline]
    fn distal_weight_n(&self, s: f64) -> f64 {
        match &self.body {
            None => self.weight_n_per_mm * (self.rod.length_mm - s),
            Some(b) => self.weight_n_per_mm * b.distal_density_area(s),
        }
    }

    /// The cable tension at point `i` for base tension `tension`: friction's
    /// profile, and none beyond the cable's anchor.
    #[inline]
    fn tension_at(&self, i: usize, tension: f64) -> f64 {
        if i >= self.cable_end {
            return 0.0;
        }
        tension * self.friction.ratio(i)
    }

    /// Curvature u from the bending moment `m` (N·mm) on `section` and du/dm.
    /// Linear (m = EI u) unless material stiffening makes it
    /// m = EI u (1 + α (r u)²); a rod cured bent adds its rest curvature u*
    /// (m = EI (u − u*), [`Rod::rest_curvature_per_mm`]).
    #[inline]
    fn bending_curvature(&self, m: f64, section: &BodySection) -> (f64, f64) {
        let (u, du_dm) = self.elastic_curvature(m, section.ei_n_mm2, section.radius_mm);
        (u + self.rod.rest_curvature_per_mm, du_dm)
    }

    /// The elastic part of [`PlanarState::bending_curvature`] with rigidity
    /// `ei` and radius `radius_mm`.
    #[inline]
    fn elastic_curvature(&self, m: f64, ei: f64, radius_mm: f64) -> (f64, f64) {
        let alpha = self.rod.effects.stiffening_alpha;
        if alpha == 0.0 {
            return (m / ei, 1.0 / ei);
        }
        // Monotone cubic EI (u + c u³) = m, c = α r²: Newton from the linear guess.
        let c = alpha * radius_mm.powi(2);
        let mut u = m / ei;
        for _ in 0..STIFFENING_MAX_ITERATIONS {
            let f = ei * (u + c * u * u * u) - m;
            let df = ei * (1.0 + 3.0 * c * u * u);
            let du = f / df;
            u -= du;
            if du.abs() <= STIFFENING_TOLERANCE * (1.0 + u.abs()) {
                break;
            }
        }
        (u, 1.0 / (ei * (1.0 + 3.0 * c * u * u)))
    }

    /// Solves the cut equations at one point (arc length `s`, cross-section
    /// `section`) for the cable angle α and the
    /// strains, starting Newton from the direction `dir0` = (cos α, sin α);
    /// `(sp, cp)` = sin, cos of φ; `tension` is the cable tension at the cut
    /// and `creep_offset` the creep's held curvature f E q₀ (1/mm). Returns
    /// the strains and (cos α, sin α).
    ///
    /// Newton converges quadratically, so once a step is below
    /// `angle_tolerance_rad` the remaining error is of the order of its
    /// square: the strains are then corrected to first order in that step
    /// instead of being re-evaluated (one sin/cos per iteration).
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn strains_at(
        &self,
        s: f64,
        section: &BodySection,
        ch: ChannelSample,
        (sp, cp): (f64, f64),
        moment: f64,
        tension: f64,
        dir0: (f64, f64),
        creep_offset: f64,
    ) -> Result<(Strains, (f64, f64)), SolveFailure> {
        let (ea, ga) = (section.ea_n, section.ga_n);
        let creep_gain = self.creep.gain(section.ei_n_mm2);
        // Weight beyond the cut, in the body frame: Rᵀ W.
        let wl = self.distal_weight_n(s);
        let w1 = wl * (cp * self.gravity_cos + sp * self.gravity_sin);
        let w2 = wl * (cp * self.gravity_sin - sp * self.gravity_cos);
        let (mut ca, mut sa) = dir0;
        for _ in 0..CABLE_ANGLE_MAX_ITERATIONS {
            let v1 = 1.0 + (w1 - tension * ca) / ea;
            let v2 = (w2 - tension * sa) / ga;
            let m = bending_moment(tension, ch.y, ca, moment);
            let (u_el, du_dm_el) = self.bending_curvature(m, section);
            let u = u_el + creep_gain * m + creep_offset;
            let du_dm = du_dm_el + creep_gain;
            let p = v1 - u * ch.y;
            let q = v2 + ch.dy;
            let g = p * sa - q * ca;
            // Derivatives of v1, v2, u with respect to α.
            let dv1 = tension * sa / ea;
            let dv2 = -tension * ca / ga;
            let du = -tension * ch.y * sa * du_dm;
            let dg = (dv1 - du * ch.y) * sa + p * ca - dv2 * ca + q * sa;
            let step = g / dg;
            if !step.is_finite() {
                return Err(SolveFailure::CableTangentDegenerate { s_mm: s });
            }
            let (ca_next, sa_next) = rotate((ca, sa), -step);
            if step.abs() <= self.options.angle_tolerance_rad {
                let e = Strains { v1: v1 - dv1 * step, v2: v2 - dv2 * step, u: u - du * step };
                // α and α + π both solve g = 0; the cable runs along +t_c.
                let along = p * ca + q * sa;
                if along <= 1e-12 {
                    return Err(SolveFailure::CableTangentDegenerate { s_mm: s });
                }
                if e.v1 <= 0.0 {
                    return Err(SolveFailure::RodCollapsed { s_mm: s });
                }
                return Ok((e, (ca_next, sa_next)));
            }
            (ca, sa) = (ca_next, sa_next);
        }
        Err(SolveFailure::CableDirectionNotConverged { s_mm: s })
    }
}

/// The largest of the per-order coefficient `errors` (one that is not a
/// number counts as largest) and its order, converted like the
/// coefficients from the deformed basis into `basis`.
fn largest_error(errors: impl Iterator<Item = f64>, basis: LengthBasis, deformed_length_mm: f64, rest_length_mm: f64) -> (f64, usize) {
    let mut worst = (0.0f64, 0usize);
    for (n, error) in errors.enumerate() {
        if !(error <= worst.0) {
            worst = (error, n);
        }
    }
    let mut error = [worst.0];
    basis.convert_from_deformed(&mut error, deformed_length_mm, rest_length_mm);
    (error[0], worst.1)
}

/// What to raise when a solve at `resolution` (intervals or steps per
/// span) with `options` is not resolved.
fn resolution_advice(options: &SolverOptions, resolution: usize) -> String {
    match options.method {
        SolverMethod::Collocation if resolution < MAX_NODES_PER_SPAN => format!(
            "raise --nodes-per-span (now {resolution}, at most {MAX_NODES_PER_SPAN}; sweep spec: [solver] nodes_per_span), e.g. --nodes-per-span {}",
            (2 * resolution).min(MAX_NODES_PER_SPAN)
        ),
        SolverMethod::Collocation => format!(
            "{MAX_NODES_PER_SPAN} intervals per span, the most, do not resolve it: use --method rk4 with more --steps-per-span \
             (sweep spec: [solver] method = \"rk4\", steps_per_span), or a lower tension"
        ),
        SolverMethod::Rk4 => format!(
            "raise --steps-per-span (now {resolution}, at most {MAX_STEPS_PER_SPAN}; sweep spec: [solver] steps_per_span), e.g. --steps-per-span {}",
            (4 * resolution).min(MAX_STEPS_PER_SPAN)
        ),
    }
}

/// The collocation's span boundaries from the clamp to the tip: the
/// routing's knot `knot_mm`, the cable's anchor and the body's breakpoints
/// (so that every span's integrands are smooth); [0, knot, L] for the
/// uniform rod.
fn span_boundaries(a: &Rod, body: Option<&Body>, knot_mm: f64) -> Vec<f64> {
    let length = a.length_mm;
    let mut cuts = vec![0.0, knot_mm, a.cable_length_mm(), length];
    if let Some(b) = body {
        cuts.extend(b.breakpoints_mm());
    }
    merge_sorted(cuts, length)
}

/// Rotates the unit vector (cos a, sin a) by `delta` rad. Small angles (the
/// usual case: Newton corrections, RK4 stage offsets) use a Taylor series
/// accurate to rounding, which is several times cheaper than sin/cos.
#[inline]
fn rotate((c, s): (f64, f64), delta: f64) -> (f64, f64) {
    let (sd, cd) = if delta.abs() < 0.125 {
        let d2 = delta * delta;
        // Errors below δ¹⁰/10! and δ¹¹/11!: < 1e-16 for |δ| < 1/8.
        let cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0 * (1.0 - d2 / 56.0 * (1.0 - d2 / 90.0))));
        let sd = delta * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0 * (1.0 - d2 / 72.0 * (1.0 - d2 / 110.0)))));
        (sd, cd)
    } else {
        delta.sin_cos()
    };
    (c * cd - s * sd, s * cd + c * sd)
}


impl From<actuation::DisplacementNotMet> for SolveFailure {
    fn from(e: actuation::DisplacementNotMet) -> Self {
        SolveFailure::DisplacementNotMet(e)
    }
}

#[cfg(test)]
mod tests;
