//! The 3-D solver by spectral collocation per knot span: the planar
//! collocation ([`crate::solver`]) generalised to several cables,
//! spatial channels, torsion and gravity in any direction.
//!
//! Cutting the rod at s and taking the distal part, rod and cables together,
//! as a free body gives, in the body frame (model-notes §3b),
//!
//! ```text
//! v = v* + K_se⁻¹ n,   n = Rᵀ W(s) − Σ τ_i(s) t_i            K_se = diag(EA, GA, GA)
//! u = c(m),            m = Rᵀ M_W(s) − Σ τ_i(s) r_i × t_i     c: the bending and torsion law
//! t_i = q_i / |q_i|,   q_i = v + u × r_i + r_i'
//! ```
//!
//! with W(s) the distal weight (closed form for every body) and M_W(s) its
//! moment about p(s), M_W' = −p' × W, M_W(L) = 0. Cable i pulls only where
//! s < s_k,i (its anchor). At each node this is a local 6×6 system in
//! x = (v, u), solved by Newton with the exact Jacobian.
//!
//! **Collocation.** The channels are cubic in their parameter on each knot
//! span, so every integrand is analytic on the spans between the
//! breakpoints (the channels' knots, anchors, the body's breakpoints). On
//! each span the local equations are solved at m + 1 Chebyshev–Lobatto
//! nodes and every integral along the span is the exact integral of the
//! degree-m interpolant ([`crate::numerics::chebyshev`]): the error falls
//! geometrically with m.
//!
//! - The frames follow from u by a sixth-order Magnus step between
//!   consecutive nodes whose first term is the exact integral of u's
//!   interpolant: R_j = R_{j−1} exp(∫u + commutators of u at the interval's
//!   Gauss points). For a planar rod the commutators vanish and the frame
//!   angle is exactly the planar solver's φ = ∫ u.
//! - The positions, deformed arc length and gravity's moment are spectral
//!   quadratures of R v, |v| and p' × W.
//!
//! The unknowns are the distal weight's force and moment in the body frame
//! at the nodes, N_b = Rᵀ W and M_b = Rᵀ M_W (what the local solves read;
//! θ₀ of clamp compliance follows from the clamp's moment within a sweep).
//! Without distributed loads and friction the strains do not depend on
//! them: one sweep (local solves → frames → positions) is the solution, no
//! shooting. With gravity or friction the sweep is a fixed-point
//! map, accelerated by Anderson's method ([`crate::numerics::anderson`]);
//! where it does not contract (heavy rods), Newton's method on the whole
//! collocation system takes over (Newton–Krylov: GMRES,
//! [`crate::numerics::gmres`], on directional derivatives by one sweep
//! each), continued in the weight from a weightless rod if it fails from
//! the warm start.
//!
//! **Coefficients.** The bending curvature of the centreline is the rotation
//! rate of its unit tangent, κ = u − (u·v̂) v̂ + v̂ × v̂' in the body frame
//! (v̂' by spectral differentiation on each span), plus the tangent's jump
//! where v jumps (an anchor, a change of material). Each series is
//! a_i = (2i + 1)/L ∫ P_i(2σ/ℓ − 1) κ_k ds (the thesis's basis) with κ_k
//! the component about body z (in the x–y plane: the planar a_i), about
//! body y, and the torsion u_1 (twist).

use super::cable::Channel;
use super::solver::MAX_SPATIAL_ORDER;
use crate::solver::{SolveFailure, SolverOptions};
use super::{Actuator, SpatialError};
use crate::solver::result::{CableAtNode, CentrelinePoint, PerCable, TipFrame, TipPose};
use crate::solver::collocation::FRICTION_SUBSTEPS;
use crate::solver::creep::Creep;
use crate::solver::friction::{MAX_PASSES as FRICTION_MAX_PASSES, TOLERANCE as FRICTION_TOLERANCE};
use crate::model::{Body, Rod};
use crate::solver::Hold;
use crate::numerics::anderson::Anderson;
use crate::numerics::chebyshev::{self, next_coefficient, ESTIMATE_SAFETY};
use crate::shape::{LegendreSeries, LengthBasis};
use std::sync::Arc;
use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, Quaternion, Rotation3, UnitQuaternion, Vector3};

type V3 = Vector3<f64>;
type M3 = Matrix3<f64>;

// One job per file: the outer Newton–Krylov solve, one pass along the rod,
// the local 6×6 solve, the constitutive law, the outputs with their error
// estimates, and sampling.
mod constitutive;
mod estimate;
mod local;
mod newton;
mod sampling;
mod sweep;


/// Most fixed-point sweeps before Newton takes over.
const MAX_SWEEPS: u32 = 40;
/// Change of the frames between sweeps accepted as settled, rad.
const SWEEP_ANGLE_TOLERANCE_RAD: f64 = 3e-10;
/// Newton on the whole system: scaled residual (rad) accepted as converged.
const NEWTON_TOLERANCE: f64 = 1e-11;
/// Newton iterations per solve before giving up.
const NEWTON_MAX_ITERATIONS: u32 = 40;
/// Newton: the backtracking's sufficient decrease (Armijo) factor.
const NEWTON_SUFFICIENT_DECREASE: f64 = 1e-4;
/// Newton–Krylov: GMRES's relative tolerance on J δ = −F, and its most
/// iterations (sweeps) before a fresh Jacobian is made instead.
const KRYLOV_TOLERANCE: f64 = 1e-2;
const KRYLOV_MAX_ITERATIONS: usize = 40;
/// The kinds of Newton step.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Step {
    /// With the kept factors of an earlier Jacobian.
    Chord,
    /// Newton–Krylov: GMRES, preconditioned by the kept factors if any.
    Krylov,
    /// With a fresh Jacobian.
    Fresh,
}
/// Newton: smallest damping factor tried before giving up.
const NEWTON_MIN_DAMPING: f64 = 1.0 / 1024.0;
/// Weight continuation: first and largest steps, smallest step (fractions of the weight).
const FIRST_WEIGHT_STEP: f64 = 0.25;
const MAX_WEIGHT_STEP: f64 = 0.5;
const MIN_WEIGHT_STEP: f64 = 1.0 / 1024.0;
/// The local Newton's step (in v and u) below which it has converged: the
/// Broyden-updated chord steps contract by about 0.03 there, so what is
/// left is about 1e-10. (Measured: 3e-9 instead of 1e-9 changes neither
/// the reference cases, the in-plane agreement nor the displacement round
/// trip, 2.6–4.8e-10 mm either way, and saves a residual at a third of the
/// nodes: the quintic prediction's first steps are 1–3e-9.)
const LOCAL_STEP_TOLERANCE: f64 = 3e-9;
/// Local Newton: a chord step whose size is not below this fraction of the
/// previous step's takes a fresh Jacobian next.
const CHORD_CONTRACTION: f64 = 0.25;
/// The tolerances' factor when a cable is driven by displacement: its
/// tension comes from differences of displacements, so each solve is
/// converged past the discretisation's noise (≈ 1e-13 mm in a path length).
const PRECISE_TOLERANCE_SCALE: f64 = 1e-3;
/// Converged solves kept for the prediction of the next (Lagrange
/// extrapolation along a tension ladder: quintic with six; measured on
/// `cablemap bench`'s ladders, cubic left 3.9 sweeps per solve with gravity,
/// quintic 3.1, and eight points 3.3).
const HISTORY: usize = 6;
/// Local Newton: most steps.
const LOCAL_MAX_ITERATIONS: usize = 100;
/// Material stiffening's law: Newton's tolerance and iteration cap.
const STIFFENING_TOLERANCE: f64 = 1e-15;
const STIFFENING_MAX_ITERATIONS: usize = 50;
/// Nodes at least with material stiffening (its law has complex branch
/// points near the real axis, which slows the spectral convergence).
const MIN_NODES_WITH_STIFFENING: usize = 16;
/// Most collocation intervals per span (the buffers of a span are this + 1 long).
const MAX_NODES: usize = crate::solver::MAX_NODES_PER_SPAN;

/// The Chebyshev–Lobatto matrices of one span at m intervals, with the
/// rows this solver's Magnus steps and friction grid read: built once per m
/// and shared ([`Grid::of`]), since a sweep builds a solver per routing.
#[derive(Debug)]
struct Grid {
    /// Nodes on [−1, 1].
    xn: Vec<f64>,
    /// Integration matrix (row m: the Clenshaw–Curtis weights).
    q: Vec<f64>,
    /// Differentiation matrix.
    diff: Vec<f64>,
    /// The discrete Chebyshev transform's highest rows (error estimates).
    tail: Vec<f64>,
    /// Per interval [x_{j−1}, x_j], the rows its Magnus step reads: the exact
    /// integral of the interpolant over the interval, and at its Gauss points
    /// c = ½ − √15/10, ½, ½ + √15/10 the combinations u(c₂), u(c₃) − u(c₁),
    /// u(c₃) − 2u(c₂) + u(c₁): m (m + 1) entries, node by node, each the
    /// four rows' weights of that node.
    magnus: Vec<[f64; 4]>,
    /// Interpolation rows onto the friction grid of each interval
    /// (m (FRICTION_SUBSTEPS − 1) rows of m + 1).
    fine: Vec<f64>,
}

impl Grid {
    /// The grid of `m` intervals, built on first use.
    fn of(m: usize) -> Arc<Grid> {
        static GRIDS: std::sync::OnceLock<std::sync::Mutex<Vec<Option<Arc<Grid>>>>> = std::sync::OnceLock::new();
        let grids = GRIDS.get_or_init(|| std::sync::Mutex::new(vec![None; MAX_NODES + 1]));
        let mut grids = grids.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        grids[m].get_or_insert_with(|| Arc::new(Grid::build(m))).clone()
    }

    fn build(m: usize) -> Grid {
        let np = m + 1;
        let xn = chebyshev::lobatto_nodes(m);
        let q = chebyshev::integration_matrix(m);
        let mut magnus = Vec::with_capacity(m * np);
        let mut g = [vec![0.0; np], vec![0.0; np], vec![0.0; np]];
        for j in 1..np {
            for (row, c) in g.iter_mut().zip([0.5 - 15f64.sqrt() / 10.0, 0.5, 0.5 + 15f64.sqrt() / 10.0]) {
                chebyshev::interpolation_weights(&xn, xn[j - 1] + c * (xn[j] - xn[j - 1]), row);
            }
            magnus.extend((0..np).map(|k| [q[j * np + k] - q[(j - 1) * np + k], g[1][k], g[2][k] - g[0][k], g[2][k] - 2.0 * g[1][k] + g[0][k]]));
        }
        let mut fine = Vec::with_capacity(m * (FRICTION_SUBSTEPS - 1) * np);
        let mut row = vec![0.0; np];
        for j in 1..np {
            for k in 1..FRICTION_SUBSTEPS {
                chebyshev::interpolation_weights(&xn, xn[j - 1] + (xn[j] - xn[j - 1]) * k as f64 / FRICTION_SUBSTEPS as f64, &mut row);
                fine.extend_from_slice(&row);
            }
        }
        Grid { diff: chebyshev::differentiation_matrix(m), tail: chebyshev::tail_rows(m), xn, q, magnus, fine }
    }
}

/// The cross-section at a node as the residual uses it: GJ, EI, r and the four compliances.
#[derive(Debug, Clone, Copy)]
struct NodeCompliance {
    gj: f64,
    ei: f64,
    radius: f64,
    /// 1/EA, 1/GA, 1/GJ, 1/EI (the residual multiplies: no divisions in the hot loop).
    inv_ea: f64,
    inv_ga: f64,
    inv_gj: f64,
    inv_ei: f64,
}

/// A cable's channel at a node, body frame.
#[derive(Debug, Clone, Copy, Default)]
struct Chan {
    r: V3,
    dr: V3,
}

/// What the solver keeps of a converged solve, to extrapolate the next.
#[derive(Debug, Clone)]
struct Solved {
    tensions: Vec<f64>,
    state: Vec<f64>,
    local: Vec<[f64; 6]>,
}

/// LU factors of Newton's Jacobian on the whole collocation system.
type Factors = nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>;

/// The 3-D collocation solver for one actuator: set tensions, then solve
/// (in a ladder, for the best warm starts).
#[derive(Debug, Clone)]
pub struct SpatialCollocation {
    rod: Rod,
    options: SolverOptions,
    cables: usize,
    /// Each cable's tension in the last solve, N.
    tensions_n: Vec<f64>,
    /// Unit gravity direction (global) and the fraction of the weight on
    /// (1, or less during the weight continuation).
    gravity_unit: V3,
    weight_fraction: f64,
    has_weight: bool,
    clamp_stiffness: Option<f64>,
    /// Material stiffening's α.
    stiffening: f64,
    /// Cable–channel friction: on, and μ η (η the slip sign: +1 loading).
    friction: bool,
    signed_mu: f64,
    /// Where the friction profiles τ_c(s)/τ_c(0) start in the state (nn × cables, node-major).
    ratio_at: usize,
    /// The cables' global directions at the nodes (node-major), scratch.
    global_dir: Vec<V3>,
    /// Viscoelastic creep in bending: two components (about body y and z) per node.
    creep: Creep,
    hold: Hold,
    // The collocation grid: intervals per span, nodes per span, the span
    // matrices (shared by every solver of the same m).
    m: usize,
    np: usize,
    grid: Arc<Grid>,
    start: Vec<f64>,
    half: Vec<f64>,
    // Per node.
    s: Vec<f64>,
    section: Vec<NodeCompliance>,
    /// The weight beyond the cut (all of it), N.
    distal_weight: Vec<f64>,
    /// Channels, node-major (nn × cables).
    chan: Vec<Chan>,
    /// Whether each cable pulls at each node (node-major).
    active: Vec<bool>,
    /// The cables' channels (for the centreline's cable paths).
    channels: Vec<Channel>,
    /// Each cable's path length in the straight, unloaded rod, mm (the
    /// span quadrature of |e₁ + r'|), and its axial stiffness EA, N.
    rest_length_mm: Vec<f64>,
    cable_ea_n: Vec<Option<f64>>,
    // The state: per node the distal weight's force and moment in the body
    // frame (N_b = Rᵀ W, M_b = Rᵀ M_W, of the full weight), scaled by
    // L²/EI and L/EI (angle units), then the friction profiles.
    state: Vec<f64>,
    next: Vec<f64>,
    /// Local solutions (warm starts) and their factors.
    local: Vec<[f64; 6]>,
    /// The inverse local Jacobian of the last fresh Newton step per node (chord steps).
    inverse: Vec<Option<Matrix6<f64>>>,
    /// Frames of the solution, and scratch frames of a finite-difference sweep.
    rot: Vec<M3>,
    rot_alt: Vec<M3>,
    /// A sweep's u, v and M_W at the nodes.
    ubuf: Vec<V3>,
    vbuf: Vec<V3>,
    mbuf: Vec<V3>,
    pos: Vec<V3>,
    sigma: Vec<f64>,
    dp: Vec<V3>,
    /// |v| at the nodes (σ' of the solution).
    speed: Vec<f64>,
    dmom: Vec<V3>,
    anderson: Anderson,
    /// Newton's Jacobian factors on the whole system, kept for chord steps
    /// and as the Krylov steps' preconditioner.
    newton_factors: Option<Factors>,
    /// A factor on the sweeps' and the local Newton's tolerances (1; below
    /// for displacement-driven cables, whose tensions are found by
    /// differences of solves).
    tolerance_scale: f64,
    /// The last [`HISTORY`] converged solves, newest first (`solved` of them valid).
    history: Vec<Solved>,
    solved: usize,
    passes: u32,
    last: Option<TipPose>,
    /// The last solve's estimated errors ([`SpatialCollocation::error_estimate`]).
    estimate: (f64, f64),
    n_scale: f64,
    m_scale: f64,
}

impl SpatialCollocation {
    /// A solver for `actuator` (its cables, rod, body, torsion and gravity).
    pub fn new(actuator: &Actuator, options: &SolverOptions) -> Result<Self, SpatialError> {
        let channels = super::solver::validated_channels(actuator, crate::solver::Backend::SpatialCollocation)?;
        super::solver::check_options(options)?;
        let rod = actuator.rod.clone();
        let body = rod.body().map_err(SpatialError::Body)?;
        let length = rod.length_mm;
        let m = if rod.effects.stiffening_alpha > 0.0 { options.nodes_per_span.max(MIN_NODES_WITH_STIFFENING) } else { options.nodes_per_span };
        let np = m + 1;
        // Breakpoints: clamp, tip, every channel's knot, anchors, the body's breakpoints.
        let mut cuts = vec![0.0, length];
        cuts.extend(channels.iter().map(Channel::knot_mm));
        cuts.extend(actuator.cables.iter().filter_map(|c| c.anchor_mm).filter(|&a| a < length));
        if let Some(b) = &body {
            cuts.extend(b.breakpoints_mm());
        }
        let cuts = crate::model::body::merge_sorted(cuts, length);
        let spans = cuts.len() - 1;
        let nn = spans * np;
        let nc = channels.len();
        let gj_uniform = actuator.torsional_rigidity_n_mm2();
        let gj_over_ei = gj_uniform / rod.ei_n_mm2;
        let beta = rod.effects.stiffness_gradient_beta;
        let delta = rod.effects.channel_offset_mm;
        let weight_factor = match &body {
            None => rod.weight_n_per_mm(),
            Some(_) if !rod.gravity.enabled => 0.0,
            Some(_) => rod.gravity.scale * 1e-6 * std::f64::consts::PI * rod.gravity.g_m_s2,
        };
        let grid = Grid::of(m);
        let xn = &grid.xn;
        let mut s = Vec::with_capacity(nn);
        let mut section = Vec::with_capacity(nn);
        let mut distal_weight = Vec::with_capacity(nn);
        let mut chan = Vec::with_capacity(nn * nc);
        let mut active = Vec::with_capacity(nn * nc);
        let (mut start, mut half) = (Vec::with_capacity(spans), Vec::with_capacity(spans));
        for w in cuts.windows(2) {
            let (a, b) = (w[0], w[1]);
            start.push(a);
            half.push(0.5 * (b - a));
            let mid = 0.5 * (a + b);
            for j in 0..np {
                // Exact end points, so breakpoints are hit exactly.
                let sj = match j {
                    0 => a,
                    _ if j == m => b,
                    _ => a + 0.5 * (b - a) * (1.0 + xn[j]),
                };
                let left = j == m;
                s.push(sj);
                let (ea, ga, ei, radius) = match &body {
                    None => (rod.ea_n, rod.ga_n, rod.ei_n_mm2, rod.radius_mm),
                    Some(b) => {
                        let x = b.section_at_side(sj, left);
                        (x.ea_n, x.ga_n, x.ei_n_mm2, x.radius_mm)
                    }
                };
                let mut ei = ei;
                // GJ scales with the section as EI does; the stiffness
                // gradient (a material gradient) scales both.
                let mut gj = gj_over_ei * ei;
                if beta != 0.0 {
                    let f = (beta * (sj / length - 0.5)).exp();
                    ei *= f;
                    gj *= f;
                }
                section.push(NodeCompliance { gj, ei, radius, inv_ea: 1.0 / ea, inv_ga: 1.0 / ga, inv_gj: 1.0 / gj, inv_ei: 1.0 / ei });
                distal_weight.push(match &body {
                    None => weight_factor * (length - sj),
                    Some(b) => weight_factor * b.distal_density_area(sj),
                });
                for (c, cable) in channels.iter().zip(&actuator.cables) {
                    let anchor = cable.anchor_or_tip_mm(length);
                    let on = mid < anchor;
                    active.push(on);
                    chan.push(if on {
                        let p = c.at(sj.min(anchor));
                        Chan {
                            r: V3::new(0.0, p.r_mm[0] + delta, p.r_mm[1]),
                            dr: V3::new(0.0, p.dr_ds[0], p.dr_ds[1]),
                        }
                    } else {
                        Chan::default()
                    });
                }
            }
        }
        if let Some(b) = &body {
            check_channels_inside(actuator, &channels, b, delta)?;
        }
        let q = &grid.q;
        // Each cable's rest path, by the span quadrature the deformed one takes.
        let mut rest_length_mm = vec![0.0; nc];
        for (span, &h) in half.iter().enumerate() {
            for j in 0..np {
                let i = span * np + j;
                for (c, r) in rest_length_mm.iter_mut().enumerate() {
                    if active[i * nc + c] {
                        *r += h * q[(np - 1) * np + j] * (V3::x() + chan[i * nc + c].dr).norm();
                    }
                }
            }
        }
        let gravity_unit = V3::from(actuator.gravity_unit()?);
        let has_weight = weight_factor != 0.0;
        let ei0 = section[0].ei;
        let friction = rod.effects.friction_mu > 0.0;
        let n_state = 6 * nn + if friction { nn * nc } else { 0 };
        let hold = Hold { direction: rod.effects.load_direction, dwell_s: rod.effects.creep_hold_s };
        let mut creep = Creep::new(&rod.effects, rod.ei_n_mm2, 2 * nn);
        creep.set_dwell(hold.dwell_s);
        let straight = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let tolerance_scale = if actuator.cables.iter().any(|c| c.is_displacement_driven()) { PRECISE_TOLERANCE_SCALE } else { 1.0 };
        let mut solver = Self {
            options: options.clone(),
            cables: nc,
            tensions_n: actuator.cables.iter().map(|c| c.tension_n).collect(),
            gravity_unit,
            weight_fraction: 1.0,
            has_weight,
            clamp_stiffness: rod.effects.clamp_stiffness_n_mm_per_rad,
            stiffening: rod.effects.stiffening_alpha,
            friction,
            signed_mu: rod.effects.friction_mu * rod.effects.load_direction.slip_sign(),
            ratio_at: 6 * nn,
            global_dir: vec![V3::x(); nn * nc],
            creep,
            hold,
            m,
            np,
            grid: grid.clone(),
            start,
            half,
            s,
            section,
            distal_weight,
            rest_length_mm,
            cable_ea_n: actuator.cables.iter().map(|c| c.cable_ea_n).collect(),
            chan,
            active,
            channels,
            state: vec![0.0; n_state],
            next: vec![0.0; n_state],
            local: vec![straight; nn],
            inverse: vec![None; nn],
            rot: vec![M3::identity(); nn],
            rot_alt: vec![M3::identity(); nn],
            ubuf: vec![V3::zeros(); nn],
            vbuf: vec![V3::zeros(); nn],
            mbuf: vec![V3::zeros(); nn],
            pos: vec![V3::zeros(); nn],
            sigma: vec![0.0; nn],
            dp: vec![V3::zeros(); nn],
            speed: vec![1.0; nn],
            dmom: vec![V3::zeros(); nn],
            anderson: Anderson::new(n_state),
            newton_factors: None,
            tolerance_scale,
            history: Vec::with_capacity(HISTORY),
            solved: 0,
            passes: 0,
            last: None,
            estimate: (0.0, 0.0),
            n_scale: length * length / ei0,
            m_scale: length / ei0,
            rod,
        };
        solver.straight_state();
        Ok(solver)
    }

    /// The state of the straight, unloaded rod: the full weight W(s) in the
    /// identity frames, no moment M_W, friction profiles 1.
    fn straight_state(&mut self) {
        let nn = self.nodes_count();
        for i in 0..nn {
            let n = self.gravity_unit * (self.distal_weight[i] * self.n_scale);
            self.state[6 * i..6 * i + 6].copy_from_slice(&[n[0], n[1], n[2], 0.0, 0.0, 0.0]);
        }
        self.state[self.ratio_at..].iter_mut().for_each(|r| *r = 1.0);
    }

    fn nodes_count(&self) -> usize {
        self.s.len()
    }

    fn spans(&self) -> usize {
        self.half.len()
    }

    /// The rod parameters.
    pub fn rod(&self) -> &Rod {
        &self.rod
    }

    /// Tension of every cable in the last solve, N.
    pub fn tensions_n(&self) -> Vec<f64> {
        self.tensions_n.clone()
    }

    /// Sets every cable's tension (N, one per cable, each ≥ 0) and solves,
    /// warm-started from the previous solves.
    pub fn solve(&mut self, tensions_n: &[f64]) -> Result<TipPose, SpatialError> {
        SpatialError::check_tensions(tensions_n, self.cables)?;
        self.tensions_n.copy_from_slice(tensions_n);
        self.last = None;
        let tensions = self.tensions_n();
        self.predict(&tensions);
        self.creep.begin_solve();
        match self.solve_inner(&tensions) {
            Ok(passes) => {
                self.settle_outputs();
                self.creep.end_solve();
                self.passes = passes;
                self.estimate = self.estimate_errors();
                let pose = self.pose_of_state(passes, &tensions);
                if !pose.tip_mm().iter().chain(&[pose.length_mm, pose.tip_angle_rad]).all(|v| v.is_finite()) {
                    self.forget();
                    return Err(SolveFailure::NonFinite { s_mm: None }.into());
                }
                if let Err(e) = self.check_resolved(&pose) {
                    self.forget();
                    return Err(SolveFailure::Unresolved(e).into());
                }
                self.remember(&tensions);
                self.last = Some(pose);
                Ok(pose)
            }
            Err(e) => {
                self.forget();
                Err(e.into())
            }
        }
    }

    /// Sets how the next solves are held: the load direction (friction's
    /// slip sign) and the dwell before the reading (creep). From then on the
    /// solves follow a protocol: creep's history carries over from solve to
    /// solve. Without this call every solve is held `effects.creep_hold_s`
    /// on a rod with no load history, in `effects.load_direction`.
    pub fn set_hold(&mut self, hold: Hold) -> Result<(), SpatialError> {
        check_dwell(hold)?;
        self.follow_hold(hold);
        Ok(())
    }

    /// [`SpatialCollocation::set_hold`] of a checked `hold`.
    fn follow_hold(&mut self, hold: Hold) {
        self.creep.follow_protocol();
        self.creep.set_dwell(hold.dwell_s);
        self.signed_mu = self.rod.effects.friction_mu * hold.direction.slip_sign();
        self.hold = hold;
    }

    /// Like [`SpatialCollocation::set_hold`] for independent captures: each of
    /// the next solves is reached in `hold.direction` and held `hold.dwell_s`
    /// from a rod with no load history (creep's history does not carry
    /// over from solve to solve; the warm start does).
    pub fn set_independent_hold(&mut self, hold: Hold) -> Result<(), SpatialError> {
        check_dwell(hold)?;
        self.creep.start_each_solve_virgin();
        self.creep.set_dwell(hold.dwell_s);
        self.signed_mu = self.rod.effects.friction_mu * hold.direction.slip_sign();
        self.hold = hold;
        Ok(())
    }

    /// The hold of the next solves.
    pub fn hold(&self) -> Hold {
        self.hold
    }

    /// Keeps the converged state of `tensions` as the newest of the last
    /// [`HISTORY`] solves (ring buffers: no allocation once full).
    fn remember(&mut self, tensions: &[f64]) {
        if self.history.len() < HISTORY {
            self.history.push(Solved { tensions: tensions.to_vec(), state: self.state.clone(), local: self.local.clone() });
            self.history.rotate_right(1);
        } else {
            self.history.rotate_right(1);
            let h = &mut self.history[0];
            h.tensions.copy_from_slice(tensions);
            h.state.copy_from_slice(&self.state);
            h.local.copy_from_slice(&self.local);
        }
        self.solved = (self.solved + 1).min(HISTORY);
    }

    /// Forgets the warm start (after a failed solve).
    fn forget(&mut self) {
        self.solved = 0;
        self.newton_factors = None;
        self.anderson.clear();
        self.straight_state();
        self.local.iter_mut().for_each(|l| *l = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        self.inverse.iter_mut().for_each(|f| *f = None);
    }

    /// Predicts the state for `tensions` from the previous solves: Lagrange
    /// extrapolation along the line of the last tension steps when they are
    /// collinear (a ladder), the newest solve otherwise.
    fn predict(&mut self, tensions: &[f64]) {
        if self.solved == 0 {
            return;
        }
        let newest = &self.history[0];
        let origin = &newest.tensions;
        // Differences of tension vectors, on the stack (at most MAX_CABLES).
        let difference = |a: &[f64]| -> [f64; super::cable::MAX_CABLES] {
            let mut d = [0.0; super::cable::MAX_CABLES];
            for ((d, x), o) in d.iter_mut().zip(a).zip(origin) {
                *d = x - o;
            }
            d
        };
        let step = difference(tensions);
        let norm = step.iter().map(|d| d * d).sum::<f64>().sqrt();
        // Parameter λ along `step` of each earlier solve, if it lies on the line.
        let mut params = [0.0; HISTORY];
        let mut k = 1;
        if norm > 0.0 {
            for h in &self.history[1..self.solved] {
                let d = difference(&h.tensions);
                let lambda = d.iter().zip(&step).map(|(a, b)| a * b).sum::<f64>() / (norm * norm);
                let off = d.iter().zip(&step).map(|(a, b)| (a - lambda * b).powi(2)).sum::<f64>().sqrt();
                if off > 1e-9 * (1.0 + norm) || params[..k].iter().any(|p: &f64| (p - lambda).abs() < 1e-12) {
                    break;
                }
                params[k] = lambda;
                k += 1;
            }
        }
        let mut w = [0.0; HISTORY];
        for i in 0..k {
            let mut weight = 1.0;
            for j in 0..k {
                if i != j {
                    weight *= (1.0 - params[j]) / (params[i] - params[j]);
                }
            }
            w[i] = weight;
        }
        if !w.iter().all(|v| v.is_finite()) {
            w = [0.0; HISTORY];
            w[0] = 1.0;
        }
        // Without weight or friction no sweep reads the state: its
        // prediction is skipped.
        let state_read = self.has_weight || self.friction;
        if state_read {
            self.state.iter_mut().for_each(|v| *v = 0.0);
        }
        self.local.iter_mut().for_each(|l| *l = [0.0; 6]);
        for (h, &wh) in self.history[..k].iter().zip(&w) {
            if state_read {
                for (v, z) in self.state.iter_mut().zip(&h.state) {
                    *v += wh * z;
                }
            }
            for (l, x) in self.local.iter_mut().zip(&h.local) {
                for c in 0..6 {
                    l[c] += wh * x[c];
                }
            }
        }
    }

}

/// The spatial backend: several and out-of-plane cables by collocation.
impl crate::solver::Solver for SpatialCollocation {
    type Error = SpatialError;
    fn backend(&self) -> crate::solver::Backend {
        crate::solver::Backend::SpatialCollocation
    }
    fn solve_tensions(&mut self, tensions_n: &[f64]) -> Result<TipPose, SpatialError> {
        self.solve(tensions_n)
    }
    fn hold_next(&mut self, hold: Hold) {
        self.follow_hold(hold);
    }
    fn centreline(&self) -> Vec<CentrelinePoint> {
        SpatialCollocation::centreline(self)
    }
    /// Refuses coefficients that are not finite.
    fn coefficients(&mut self, order: usize, basis: LengthBasis) -> Result<[Vec<f64>; 3], SpatialError> {
        let a = SpatialCollocation::coefficients(self, order, basis)?;
        if !a.iter().flatten().all(|v| v.is_finite()) {
            return Err(SolveFailure::NonFinite { s_mm: None }.into());
        }
        Ok(a)
    }
}

impl From<crate::solver::actuation::DisplacementNotMet> for SpatialError {
    fn from(e: crate::solver::actuation::DisplacementNotMet) -> Self {
        SolveFailure::DisplacementNotMet(e).into()
    }
}

/// Refuses a hold whose dwell is not a finite time ≥ 0 s.
pub(crate) fn check_dwell(hold: Hold) -> Result<(), SpatialError> {
    if !(hold.dwell_s.is_finite() && hold.dwell_s >= 0.0) {
        return Err(SpatialError::Dwell(hold.dwell_s));
    }
    Ok(())
}

/// exp of the skew matrix of `w` (Rodrigues). Below 0.5 rad, as a Magnus
/// step between collocation nodes is, sin θ/θ and (1 − cos θ)/θ² by their
/// Taylor series to θ¹⁴ (error below 1e-17): no sin or cos.
#[inline]
fn exp_so3(w: &V3) -> M3 {
    let t2 = w.norm_squared();
    let (a, b) = if t2 < 0.25 {
        // sin θ/θ = Σ (−θ²)^n/(2n+1)!, (1 − cos θ)/θ² = Σ (−θ²)^n/(2n+2)!,
        // by Horner with the coefficients' ratios as products (a division
        // costs several multiplications).
        const A: [f64; 7] = [1.0 / 6.0, 1.0 / 20.0, 1.0 / 42.0, 1.0 / 72.0, 1.0 / 110.0, 1.0 / 156.0, 1.0 / 210.0];
        const B: [f64; 7] = [1.0 / 12.0, 1.0 / 30.0, 1.0 / 56.0, 1.0 / 90.0, 1.0 / 132.0, 1.0 / 182.0, 1.0 / 240.0];
        let (mut a, mut b) = (1.0, 1.0);
        for k in (0..7).rev() {
            a = 1.0 - t2 * A[k] * a;
            b = 1.0 - t2 * B[k] * b;
        }
        (a, 0.5 * b)
    } else {
        let theta = t2.sqrt();
        (theta.sin() / theta, (1.0 - theta.cos()) / t2)
    };
    // I + a K + b K² with K² = w wᵀ − θ² I (no matrix product).
    let c = 1.0 - b * t2;
    let (x, y, z) = (w[0], w[1], w[2]);
    let (bx, by, bz) = (b * x, b * y, b * z);
    let (ax, ay, az) = (a * x, a * y, a * z);
    M3::new(c + bx * x, bx * y - az, bx * z + ay, bx * y + az, c + by * y, by * z - ax, bx * z - ay, by * z + ax, c + bz * z)
}

/// H f for a 6×6 matrix (column-major, as nalgebra stores it), written
/// out: nalgebra's generic product builds temporaries in this hot loop.
#[inline(always)]
fn mul6(h: &Matrix6<f64>, f: &[f64; 6]) -> [f64; 6] {
    let a = h.as_slice();
    let mut y = [0.0; 6];
    for (k, fk) in f.iter().enumerate() {
        for (r, yr) in y.iter_mut().enumerate() {
            *yr += a[6 * k + r] * fk;
        }
    }
    y
}

/// |f|² of a 6-vector.
#[inline(always)]
fn norm_squared6(f: &[f64; 6]) -> f64 {
    f.iter().map(|v| v * v).sum()
}

/// Broyden's ("good") update of an inverse Jacobian `h` with the step just
/// taken and the residuals after and before it: h += (s − h δf)(sᵀ h)/(sᵀ h δf).
/// Chord steps then converge superlinearly, and the kept inverse follows
/// the Jacobian from solve to solve. Written out (one pass per column, no
/// 6×6 temporaries).
#[inline(always)]
fn broyden_update(h: &mut Matrix6<f64>, step: &[f64; 6], f: &[f64; 6], f_old: &[f64; 6]) {
    let df: [f64; 6] = std::array::from_fn(|k| f[k] - f_old[k]);
    let h_df = mul6(h, &df);
    let denominator: f64 = step.iter().zip(&h_df).map(|(a, b)| a * b).sum();
    if denominator.abs() > 1e-300 {
        let inv = 1.0 / denominator;
        let w: [f64; 6] = std::array::from_fn(|r| (step[r] - h_df[r]) * inv);
        for column in h.as_mut_slice().chunks_exact_mut(6) {
            let z: f64 = step.iter().zip(column.iter()).map(|(a, b)| a * b).sum();
            for (a, wr) in column.iter_mut().zip(&w) {
                *a += wr * z;
            }
        }
    }
}

/// Checks every cable's channel against the body's radius r(s) along s:
/// |r_c(s)| < r(s) (the uniform rod's check is in [`super::cable::validate`]).
fn check_channels_inside(actuator: &Actuator, channels: &[Channel], body: &Body, offset_y_mm: f64) -> Result<(), SpatialError> {
    let length = actuator.rod.length_mm;
    for (index, (channel, cable)) in channels.iter().zip(&actuator.cables).enumerate() {
        let anchor = cable.anchor_or_tip_mm(length);
        let n = 2048;
        for k in 0..=n {
            let s = anchor * k as f64 / n as f64;
            let p = channel.at(s);
            let distance = (p.r_mm[0] + offset_y_mm).hypot(p.r_mm[1]);
            let radius = body.radius_at(s);
            if distance >= radius {
                return Err(crate::model::ActuatorError::OutsideBody { cable: index + 1, s_mm: s, distance_mm: distance, radius_mm: radius }.into());
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
