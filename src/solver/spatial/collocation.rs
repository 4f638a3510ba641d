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
use super::solver::{SpatialOptions, MAX_SPATIAL_ORDER};
use super::{Actuator, SpatialError, SpatialFailure};
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

/// The cross-section at a node.
#[derive(Debug, Clone, Copy)]
struct Section {
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
pub struct SpatialSolver {
    rod: Rod,
    options: SpatialOptions,
    cables: usize,
    /// Tensions of the actuator's cables (scaled by `scale` in a solve), N.
    base_tension_n: Vec<f64>,
    scale: f64,
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
    section: Vec<Section>,
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
    /// The last solve's estimated errors ([`SpatialSolver::error_estimate`]).
    estimate: (f64, f64),
    n_scale: f64,
    m_scale: f64,
}

impl SpatialSolver {
    /// A solver for `actuator` (its cables, rod, body, torsion and gravity).
    pub fn new(actuator: &Actuator, options: &SpatialOptions) -> Result<Self, SpatialError> {
        let channels = super::solver::validated_channels(actuator, crate::solver::Backend::Spatial)?;
        options.check()?;
        let rod = actuator.rod.clone();
        let body = rod.body().map_err(|e| SpatialError::Option(e.to_string()))?;
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
                section.push(Section { gj, ei, radius, inv_ea: 1.0 / ea, inv_ga: 1.0 / ga, inv_gj: 1.0 / gj, inv_ei: 1.0 / ei });
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
            base_tension_n: actuator.cables.iter().map(|c| c.tension_n).collect(),
            scale: 1.0,
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

    /// Number of cables.
    pub fn cable_count(&self) -> usize {
        self.cables
    }

    /// Collocation intervals per span in use.
    pub fn intervals(&self) -> usize {
        self.m
    }

    /// Tension of every cable in the last solve, N.
    pub fn tensions_n(&self) -> Vec<f64> {
        self.base_tension_n.iter().map(|t| t * self.scale).collect()
    }

    /// Sets every cable's tension (N, one per cable, each ≥ 0) and solves.
    pub fn solve(&mut self, tensions_n: &[f64]) -> Result<TipPose, SpatialError> {
        SpatialError::check_tensions(tensions_n, self.cables)?;
        self.base_tension_n.copy_from_slice(tensions_n);
        self.solve_scaled(1.0)
    }

    /// Solves with every cable's tension scaled by `scale` (1 = the
    /// actuator's tensions; continuation ladders step it from 0 to 1),
    /// warm-started from the previous solves.
    pub fn solve_scaled(&mut self, scale: f64) -> Result<TipPose, SpatialError> {
        if !(scale.is_finite() && scale >= 0.0) {
            return Err(SpatialError::Option(format!("tension scale {scale} must be finite and ≥ 0")));
        }
        self.scale = scale;
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
                    return Err(SpatialFailure::NonFinite.into());
                }
                if let Err(e) = self.check_resolved(&pose) {
                    self.forget();
                    return Err(SpatialFailure::Unresolved(e).into());
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

    /// [`SpatialSolver::set_hold`] of a checked `hold`.
    fn follow_hold(&mut self, hold: Hold) {
        self.creep.follow_protocol();
        self.creep.set_dwell(hold.dwell_s);
        self.signed_mu = self.rod.effects.friction_mu * hold.direction.slip_sign();
        self.hold = hold;
    }

    /// Like [`SpatialSolver::set_hold`] for independent captures: each of
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

    fn solve_inner(&mut self, tensions: &[f64]) -> Result<u32, SpatialFailure> {
        let has_weight = self.has_weight && self.weight_fraction > 0.0;
        let has_friction = self.friction && tensions.iter().any(|&t| t > 0.0);
        if !has_weight && !has_friction {
            self.sweep(tensions, true)?;
            std::mem::swap(&mut self.state, &mut self.next);
            return Ok(1);
        }
        let mut passes = 0u32;
        // The changes of the last two sweeps (newest first).
        let mut previous = [f64::INFINITY; 2];
        self.anderson.restart();
        // The prediction, for Newton to start from if the sweeps stall.
        let predicted = (self.state.clone(), self.local.clone());
        let outcome = {
            loop {
            self.anderson.input_mut().copy_from_slice(&self.state);
            let change = match self.sweep(tensions, true) {
                Ok(c) => c,
                Err(e) => break Err(e),
            };
            passes += 1;
            let k = self.tolerance_scale;
            let settled = change.0 <= k * SWEEP_ANGLE_TOLERANCE_RAD && change.1 <= k * self.options.moment_tolerance_n_mm * self.m_scale && change.2 < k * FRICTION_TOLERANCE;
            let change = change.0.max(change.1).max(change.2);
            if settled && (passes == 1 || change <= 0.5 * previous[0] || !has_weight) {
                std::mem::swap(&mut self.state, &mut self.next);
                break Ok(());
            }
            let most = if has_weight { MAX_SWEEPS } else { FRICTION_MAX_PASSES as u32 };
            if !has_weight && passes >= most {
                break Err(SpatialFailure::Friction);
            }
            // Stalled (a heavy rod, where the sweeps do not contract): less
            // than a third off over two sweeps (Anderson's changes are not
            // monotone from one sweep to the next).
            if passes >= most || (has_weight && passes >= 3 && change > 0.67 * previous[1]) {
                break Err(SpatialFailure::Gravity { passes, residual_n_mm: change / self.m_scale });
            }
            previous = [change, previous[0]];
            self.anderson.output_mut().copy_from_slice(&self.next);
            match self.anderson.step() {
                Some(z) => self.state.copy_from_slice(z),
                None => std::mem::swap(&mut self.state, &mut self.next),
            }
            }
        };
        match outcome {
            Ok(()) => Ok(passes),
            Err(SpatialFailure::Friction) => Err(SpatialFailure::Friction),
            Err(_) => {
                self.anderson.clear();
                self.state.copy_from_slice(&predicted.0);
                self.local.copy_from_slice(&predicted.1);
                Ok(passes + self.newton_continued(tensions)?)
            }
        }
    }

    /// Newton from the current state; if it fails, continuation in the
    /// weight from a weightless rod. Returns the Newton iterations.
    fn newton_continued(&mut self, tensions: &[f64]) -> Result<u32, SpatialFailure> {
        let saved = self.state.clone();
        let saved_local = self.local.clone();
        if let Ok(n) = self.newton(tensions) {
            return Ok(n);
        }
        self.state.copy_from_slice(&saved);
        self.local.copy_from_slice(&saved_local);
        let full = self.weight_fraction;
        self.weight_fraction = 0.0;
        let mut iterations = 0;
        let result = (|| -> Result<(), SpatialFailure> {
            // Weightless: one sweep from any start.
            self.sweep(tensions, true)?;
            std::mem::swap(&mut self.state, &mut self.next);
            let (mut reached, mut step) = (0.0f64, FIRST_WEIGHT_STEP);
            while reached < 1.0 {
                let next = (reached + step).min(1.0);
                let (state, local) = (self.state.clone(), self.local.clone());
                self.weight_fraction = full * next;
                match self.newton(tensions) {
                    Ok(n) => {
                        iterations += n;
                        reached = next;
                        step = (step * 2.0).min(MAX_WEIGHT_STEP);
                    }
                    Err(_) => {
                        self.state.copy_from_slice(&state);
                        self.local.copy_from_slice(&local);
                        step /= 2.0;
                        if step < MIN_WEIGHT_STEP {
                            return Err(SpatialFailure::Gravity { passes: iterations, residual_n_mm: f64::NAN });
                        }
                    }
                }
            }
            Ok(())
        })();
        self.weight_fraction = full;
        if let Err(e) = result {
            self.state.copy_from_slice(&saved);
            self.local.copy_from_slice(&saved_local);
            return Err(e);
        }
        Ok(iterations)
    }

    /// Newton's method on F(z) = z − G(z) (G: one sweep), with backtracking
    /// on |F|. The steps are Newton–Krylov: GMRES on J δ = −F to
    /// [`KRYLOV_TOLERANCE`], J v by one finite-difference sweep (the
    /// fixed-point map's non-contracting modes, the heavy rod's low bending
    /// modes, are few: about four sweeps a step instead of a Jacobian's one
    /// per unknown and its LU). Only when GMRES does not reach its
    /// tolerance in [`KRYLOV_MAX_ITERATIONS`] or a Krylov step fails its
    /// line search is the Jacobian made by finite differences and
    /// factored; its factors are kept across iterations and solves for
    /// chord steps while those contract by half or better, and then serve
    /// as GMRES's right preconditioner.
    fn newton(&mut self, tensions: &[f64]) -> Result<u32, SpatialFailure> {
        let n = self.state.len();
        let residual = |this: &mut Self| -> Result<DVector<f64>, SpatialFailure> {
            this.sweep(tensions, true)?;
            Ok(DVector::from_iterator(n, this.state.iter().zip(&this.next).map(|(z, g)| z - g)))
        };
        let mut f = residual(self)?;
        let mut norm = f.amax();
        let mut factors = self.newton_factors.take();
        let mut krylov = factors.is_none();
        for it in 0..NEWTON_MAX_ITERATIONS {
            if norm <= NEWTON_TOLERANCE {
                self.newton_factors = factors;
                return Ok(it);
            }
            let failed = SpatialFailure::Gravity { passes: it, residual_n_mm: norm / self.m_scale };
            let mut delta = None;
            let mut step = Step::Chord;
            if krylov {
                step = Step::Krylov;
                delta = self.krylov_step(tensions, &f, factors.as_ref())?;
                if delta.is_none() {
                    factors = None;
                }
            } else if let Some(lu) = factors.as_ref() {
                delta = lu.solve(&(-&f));
                if delta.is_none() {
                    factors = None;
                }
            }
            if delta.is_none() {
                step = Step::Fresh;
                let lu = self.jacobian(tensions)?.lu();
                delta = lu.solve(&(-&f));
                factors = Some(lu);
                krylov = false;
                if delta.is_none() {
                    return Err(failed);
                }
            }
            let delta = delta.expect("set above");
            let base = self.state.clone();
            let mut lambda = 1.0;
            let accepted = loop {
                for i in 0..n {
                    self.state[i] = base[i] + lambda * delta[i];
                }
                match residual(self) {
                    Ok(trial) if trial.amax().is_finite() && trial.amax() < (1.0 - NEWTON_SUFFICIENT_DECREASE * lambda) * norm => break Some(trial),
                    _ => {
                        lambda /= 2.0;
                        if lambda < NEWTON_MIN_DAMPING || (step == Step::Chord && lambda < 0.25) {
                            break None;
                        }
                    }
                }
            };
            match accepted {
                Some(trial) => {
                    let contraction = trial.amax() / norm;
                    norm = trial.amax();
                    f = trial;
                    if step == Step::Chord && contraction > 0.5 {
                        krylov = true;
                    }
                }
                None => {
                    self.state.copy_from_slice(&base);
                    match step {
                        Step::Fresh => return Err(failed),
                        Step::Chord => krylov = true,
                        _ => {
                            factors = None;
                            krylov = false;
                        }
                    }
                    f = residual(self)?;
                    norm = f.amax();
                }
            }
        }
        if norm <= 1e3 * NEWTON_TOLERANCE {
            self.newton_factors = factors;
            return Ok(NEWTON_MAX_ITERATIONS);
        }
        Err(SpatialFailure::Gravity { passes: NEWTON_MAX_ITERATIONS, residual_n_mm: norm / self.m_scale })
    }

    /// A Newton–Krylov step at the current state (F(z) = `f`, G(z) in
    /// `next`, the local solutions committed): GMRES on J δ = −F to
    /// [`KRYLOV_TOLERANCE`], J v = (F(z + εv) − F(z))/ε by one sweep,
    /// right-preconditioned by `factors` when given. `None` when GMRES
    /// does not reach its tolerance.
    fn krylov_step(&mut self, tensions: &[f64], f: &DVector<f64>, factors: Option<&Factors>) -> Result<Option<DVector<f64>>, SpatialFailure> {
        let n = self.state.len();
        let base = self.state.clone();
        let g0 = self.next.clone();
        let scale = 1e-7 * (1.0 + base.iter().fold(0.0f64, |a, v| a.max(v.abs())));
        let b: Vec<f64> = f.iter().map(|v| -v).collect();
        let mut x = vec![0.0; n];
        let outcome = crate::numerics::gmres::gmres(
            &b,
            KRYLOV_MAX_ITERATIONS,
            KRYLOV_TOLERANCE,
            |v: &[f64], out: &mut [f64]| {
                let eps = scale / v.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
                for i in 0..n {
                    self.state[i] = base[i] + eps * v[i];
                }
                let result = self.sweep(tensions, false);
                if result.is_ok() {
                    for i in 0..n {
                        out[i] = ((self.state[i] - self.next[i]) - f[i]) / eps;
                    }
                }
                self.state.copy_from_slice(&base);
                result.map(|_| ())
            },
            |v: &mut [f64]| {
                if let Some(lu) = factors {
                    let mut w = DVector::from_column_slice(v);
                    if lu.solve_mut(&mut w) {
                        v.copy_from_slice(w.as_slice());
                    }
                }
            },
            &mut x,
        );
        self.next.copy_from_slice(&g0);
        let outcome = outcome?;
        if outcome.relative_residual > KRYLOV_TOLERANCE {
            return Ok(None);
        }
        Ok(Some(DVector::from_vec(x)))
    }

    /// The Jacobian of F(z) = z − G(z) at the current state by forward
    /// differences of sweeps (each from the committed local solutions).
    fn jacobian(&mut self, tensions: &[f64]) -> Result<DMatrix<f64>, SpatialFailure> {
        let n = self.state.len();
        let base = self.state.clone();
        let g0 = self.next.clone();
        let mut jac = DMatrix::<f64>::zeros(n, n);
        for k in 0..n {
            let eps = 1e-7 * (1.0 + base[k].abs());
            self.state[k] = base[k] + eps;
            let result = self.sweep(tensions, false);
            if result.is_ok() {
                for i in 0..n {
                    jac[(i, k)] = ((self.state[i] - self.next[i]) - (base[i] - g0[i])) / eps;
                }
            }
            self.state[k] = base[k];
            result?;
        }
        self.next.copy_from_slice(&g0);
        Ok(jac)
    }

    /// The tension of cable `c` at node `i`, N.
    #[inline]
    fn tension_at(&self, tensions: &[f64], i: usize, c: usize) -> f64 {
        let k = i * self.cables + c;
        if !self.active[k] {
            0.0
        } else if self.friction {
            tensions[c] * self.state[self.ratio_at + k]
        } else {
            tensions[c]
        }
    }

    /// One sweep G(z) of the state in `self.state` into `self.next`: local
    /// solves with the state's distal loads (body frame), then θ₀, the
    /// frames, positions and M_W from the new strains, and the distal loads
    /// in the new frames. With `commit` the local solutions, frames and
    /// positions become the solver's (a finite-difference sweep of Newton's
    /// Jacobian leaves them). Returns the largest changes of the distal
    /// force and moment (in angle units: N_b·L²/EI, M_b·L/EI, at the weight
    /// on) and of the friction profiles.
    fn sweep(&mut self, tensions: &[f64], commit: bool) -> Result<(f64, f64, f64), SpatialFailure> {
        let nn = self.nodes_count();
        let mut ubuf = std::mem::take(&mut self.ubuf);
        let w_scale = if self.has_weight { self.weight_fraction } else { 0.0 };
        let mut clamp_moment = V3::zeros();
        let mut failed = None;
        let mut inverse = std::mem::take(&mut self.inverse);
        for i in 0..nn {
            let (nw, mw) = if w_scale > 0.0 { (self.state_n(i) * w_scale, self.state_m(i) * w_scale) } else { (V3::zeros(), V3::zeros()) };
            match self.local_solve(i, tensions, nw, mw, &mut inverse[i], commit) {
                Ok(x) => {
                    ubuf[i] = V3::new(x[3], x[4], x[5]);
                    self.vbuf[i] = V3::new(x[0], x[1], x[2]);
                    if i == 0 {
                        clamp_moment = self.moment_of_curvature(&ubuf[0], 0);
                    }
                    if commit {
                        self.local[i] = x;
                    }
                }
                Err(e) => {
                    failed = Some(e);
                    break;
                }
            }
        }
        self.inverse = inverse;
        if let Some(e) = failed {
            self.ubuf = ubuf;
            return Err(e);
        }
        // θ₀ from the clamp's moment (a rotational spring about both bending axes).
        let theta0 = match self.clamp_stiffness {
            Some(k) => V3::new(0.0, clamp_moment[1] / k, clamp_moment[2] / k),
            None => V3::zeros(),
        };
        let mut rot = if commit { std::mem::take(&mut self.rot) } else { std::mem::take(&mut self.rot_alt) };
        self.frames(&ubuf, exp_so3(&theta0), &mut rot);
        for i in 0..nn {
            self.dp[i] = rot[i] * self.vbuf[i];
        }
        // The distal loads of the full weight in the new frames: W and
        // M_W (from its rate −p' × W, backward from M_W(L) = 0). A weightless
        // sweep of a heavy rod (the weight continuation's start) leaves them too.
        let (mut change_n, mut change_m) = (0.0f64, 0.0f64);
        if self.has_weight {
            let mut mom = std::mem::take(&mut self.mbuf);
            for i in 0..nn {
                self.dmom[i] = -self.dp[i].cross(&(self.gravity_unit * self.distal_weight[i]));
            }
            self.integrate_backward(&mut mom);
            for i in 0..nn {
                let rt = rot[i].transpose();
                let n = rt * (self.gravity_unit * (self.distal_weight[i] * self.n_scale));
                let m = rt * (mom[i] * self.m_scale);
                let at = 6 * i;
                change_n = change_n.max((n - V3::new(self.state[at], self.state[at + 1], self.state[at + 2])).amax());
                change_m = change_m.max((m - V3::new(self.state[at + 3], self.state[at + 4], self.state[at + 5])).amax());
                self.next[at..at + 3].copy_from_slice(n.as_slice());
                self.next[at + 3..at + 6].copy_from_slice(m.as_slice());
            }
            self.mbuf = mom;
        } else {
            self.next[..6 * nn].iter_mut().for_each(|z| *z = 0.0);
        }
        if commit {
            self.rot = rot;
        } else {
            self.rot_alt = rot;
        }
        self.ubuf = ubuf;
        let change_ratio = if self.friction { self.friction_profiles(commit) } else { 0.0 };
        let (change_n, change_m) = (change_n * w_scale, change_m * w_scale);
        if !(change_n + change_m + change_ratio).is_finite() {
            return Err(SpatialFailure::NonFinite);
        }
        Ok((change_n, change_m, change_ratio))
    }

    /// The distal weight's force at node `i` in the state (body frame, full weight), N.
    #[inline]
    fn state_n(&self, i: usize) -> V3 {
        V3::new(self.state[6 * i], self.state[6 * i + 1], self.state[6 * i + 2]) / self.n_scale
    }

    /// The distal weight's moment at node `i` in the state (body frame, full weight), N·mm.
    #[inline]
    fn state_m(&self, i: usize) -> V3 {
        V3::new(self.state[6 * i + 3], self.state[6 * i + 4], self.state[6 * i + 5]) / self.m_scale
    }

    /// Frames at the nodes from the curvatures `u` and the clamp frame `r0`:
    /// sixth-order Magnus steps between nodes (Blanes, Casas & Ros, with
    /// u at the interval's three Gauss points) whose first term, ∫u, is the
    /// exact integral of u's interpolant.
    fn frames(&self, u: &[V3], r0: M3, out: &mut [M3]) {
        let np = self.np;
        let sqrt15 = 15f64.sqrt();
        let mut r = r0;
        for span in 0..self.spans() {
            let base = span * np;
            let h = self.half[span];
            out[base] = r;
            let us = &u[base..base + np];
            for j in 1..np {
                // The four functionals of u, node by node (twelve
                // independent sums).
                let mut acc = [[0.0f64; 3]; 4];
                for (w, uk) in self.grid.magnus[(j - 1) * np..j * np].iter().zip(us) {
                    for (sum, wr) in acc.iter_mut().zip(w) {
                        sum[0] += wr * uk[0];
                        sum[1] += wr * uk[1];
                        sum[2] += wr * uk[2];
                    }
                }
                let g = acc.map(V3::from);
                let step = h * (self.grid.xn[j] - self.grid.xn[j - 1]);
                let integral = g[0] * h;
                let a1 = g[1] * step;
                let a2 = g[2] * (sqrt15 * step / 3.0);
                let a3 = g[3] * (10.0 * step / 3.0);
                let c1 = a1.cross(&a2);
                let c2 = a1.cross(&(c1 - a3 * 2.0)) / 60.0;
                let omega = integral + (a1 * 20.0 + a3 + c1).cross(&(a2 - c2)) / 240.0;
                r *= exp_so3(&omega);
                out[base + j] = r;
            }
        }
    }

    /// What a converged solve leaves besides the state: |v|, the positions
    /// and deformed arc length (from the last committed sweep's `dp`), and
    /// the bending moments creep keeps.
    fn settle_outputs(&mut self) {
        let nn = self.nodes_count();
        for i in 0..nn {
            let x = &self.local[i];
            self.speed[i] = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        }
        self.positions();
        if self.creep.is_on() {
            for i in 0..nn {
                let x = self.local[i];
                let m = self.moment_of_curvature(&V3::new(x[3], x[4], x[5]), i);
                let ei = self.section[i].ei;
                self.creep.record_moment(2 * i, m[1], ei);
                self.creep.record_moment(2 * i + 1, m[2], ei);
            }
        }
    }

    /// Positions and deformed arc length from `self.dp` and the local v.
    fn positions(&mut self) {
        let np = self.np;
        let (mut p0, mut s0) = (V3::zeros(), 0.0);
        for span in 0..self.spans() {
            let base = span * np;
            let h = self.half[span];
            for j in 0..np {
                let row = &self.grid.q[j * np..(j + 1) * np];
                let (mut ap, mut asg) = (V3::zeros(), 0.0);
                for k in 0..np {
                    ap += self.dp[base + k] * row[k];
                    asg += row[k] * self.speed[base + k];
                }
                self.pos[base + j] = p0 + ap * h;
                self.sigma[base + j] = s0 + h * asg;
            }
            p0 = self.pos[base + np - 1];
            s0 = self.sigma[base + np - 1];
        }
    }

    /// M_W at the nodes from its rate in `self.dmom`, backward from M_W(L) = 0.
    fn integrate_backward(&self, out: &mut [V3]) {
        let np = self.np;
        let mut end = V3::zeros();
        for span in (0..self.spans()).rev() {
            let base = span * np;
            let h = self.half[span];
            let last = &self.grid.q[(np - 1) * np..np * np];
            for j in 0..np {
                let row = &self.grid.q[j * np..(j + 1) * np];
                let mut acc = V3::zeros();
                for k in 0..np {
                    acc += self.dmom[base + k] * (last[k] - row[k]);
                }
                out[base + j] = end - acc * h;
            }
            end = out[base];
        }
    }

    /// Newton on the cut equations at node `i` (body-frame distal loads
    /// `nw`, `mw`), warm-started from the last (or predicted) local
    /// solution there. Steps use the inverse Jacobian kept from an earlier
    /// solve (chord steps) while they contract fast, and a fresh one
    /// otherwise; a step below [`LOCAL_STEP_TOLERANCE`] ends it (what is
    /// left is about the contraction factor times that step).
    fn local_solve(&self, i: usize, tensions: &[f64], nw: V3, mw: V3, kept: &mut Option<Matrix6<f64>>, commit: bool) -> Result<[f64; 6], SpatialFailure> {
        let mut x = self.local[i];
        // The kept inverse is updated in place by a committed sweep, on a
        // copy by a finite-difference sweep.
        let mut copy;
        let inverse = if commit {
            kept
        } else {
            copy = *kept;
            &mut copy
        };
        let mut previous = f64::INFINITY;
        // The last step taken and the residual before it (Broyden's update).
        let mut last: Option<([f64; 6], [f64; 6])> = None;
        for _ in 0..LOCAL_MAX_ITERATIONS {
            let fresh = inverse.is_none();
            let f = if fresh {
                let (f, j) = self.residual_and_jacobian(i, tensions, &x, nw, mw);
                *inverse = j.try_inverse();
                f
            } else {
                let f = self.residual(i, tensions, &x, nw, mw);
                if let (Some((step, f_old)), Some(h)) = (&last, inverse.as_mut()) {
                    broyden_update(h, step, &f, f_old);
                }
                f
            };
            let Some(h) = inverse.as_ref() else { break };
            let mut dx = mul6(h, &f);
            dx.iter_mut().for_each(|d| *d = -*d);
            let big = dx.iter().fold(0.0f64, |a, d| a.max(d.abs()));
            if !big.is_finite() {
                if fresh {
                    break;
                }
                *inverse = None;
                last = None;
                continue;
            }
            // Keep the axial stretch positive: a step through v1 = 0 would
            // fold the rod onto itself.
            let mut lambda = 1.0;
            while x[0] + lambda * dx[0] < 0.05 && lambda > 1e-3 {
                lambda *= 0.5;
            }
            // Far from the solution (a cold start, a large tension step),
            // backtrack until the residual falls, so that Newton cannot
            // jump to another branch of t = q/|q|.
            if big > 0.02 {
                let f0 = norm_squared6(&f);
                while lambda > 1e-3 {
                    let trial: [f64; 6] = std::array::from_fn(|k| x[k] + lambda * dx[k]);
                    let ft = norm_squared6(&self.residual(i, tensions, &trial, nw, mw));
                    if ft.is_finite() && ft < f0 {
                        break;
                    }
                    lambda *= 0.5;
                }
            }
            for k in 0..6 {
                dx[k] *= lambda;
                x[k] += dx[k];
            }
            if big < self.tolerance_scale * LOCAL_STEP_TOLERANCE && lambda == 1.0 && x[0] > 0.0 {
                return Ok(x);
            }
            last = Some((dx, f));
            // Steps that contract slowly: take a fresh Jacobian.
            if !fresh && big > CHORD_CONTRACTION * previous {
                *inverse = None;
                last = None;
            }
            previous = big;
        }
        *inverse = None;
        Err(SpatialFailure::Local { s_mm: self.s[i] })
    }

    /// The internal force and moment (body frame) at node `i` for the
    /// strains `x` and the distal loads `nw`, `mw`: n = N_b − Σ τ t,
    /// m = M_b − Σ τ r × t.
    #[inline(always)]
    fn cut_loads(&self, i: usize, tensions: &[f64], x: &[f64; 6], nw: V3, mw: V3) -> (V3, V3) {
        let v = V3::new(x[0], x[1], x[2]);
        let u = V3::new(x[3], x[4], x[5]);
        let (mut n, mut m) = (nw, mw);
        let nc = self.cables;
        for c in 0..nc {
            let tau = self.tension_at(tensions, i, c);
            if tau == 0.0 {
                continue;
            }
            let ch = &self.chan[i * nc + c];
            let q = v + u.cross(&ch.r) + ch.dr;
            let pull = q * (tau / q.norm());
            n -= pull;
            m -= ch.r.cross(&pull);
        }
        (n, m)
    }

    /// The residual F(x) = x − x* − C(f(x)) of the cut equations at node `i`
    /// (compliance form: f the internal force and moment, C the
    /// constitutive law).
    #[inline]
    fn residual(&self, i: usize, tensions: &[f64], x: &[f64; 6], nw: V3, mw: V3) -> [f64; 6] {
        let (n, m) = self.cut_loads(i, tensions, x, nw, mw);
        let u = self.curvature_law(i, &m, &self.section[i], false).0;
        self.residual_of(i, x, &n, &u)
    }

    /// F(x) from the internal force `n` and the law's curvature `u` at node `i`.
    #[inline(always)]
    fn residual_of(&self, i: usize, x: &[f64; 6], n: &V3, u: &V3) -> [f64; 6] {
        let sec = &self.section[i];
        [x[0] - 1.0 - n[0] * sec.inv_ea, x[1] - n[1] * sec.inv_ga, x[2] - n[2] * sec.inv_ga, x[3] - u[0], x[4] - u[1], x[5] - u[2]]
    }

    /// [`SpatialSolver::residual`] and its Jacobian, I + C S with C =
    /// blockdiag(K_se⁻¹, du/dm) and S the cables' stiffness (only a fresh
    /// local step needs it).
    fn residual_and_jacobian(&self, i: usize, tensions: &[f64], x: &[f64; 6], nw: V3, mw: V3) -> ([f64; 6], Matrix6<f64>) {
        let sec = &self.section[i];
        let (n, m) = self.cut_loads(i, tensions, x, nw, mw);
        let (u_law, c_prime) = self.curvature_law(i, &m, sec, true);
        let f = self.residual_of(i, x, &n, &u_law);
        let v = V3::new(x[0], x[1], x[2]);
        let u = V3::new(x[3], x[4], x[5]);
        let (mut svv, mut svu, mut suv, mut suu) = (M3::zeros(), M3::zeros(), M3::zeros(), M3::zeros());
        let nc = self.cables;
        for c in 0..nc {
            let tau = self.tension_at(tensions, i, c);
            if tau == 0.0 {
                continue;
            }
            let ch = self.chan[i * nc + c];
            let q = v + u.cross(&ch.r) + ch.dr;
            let len = q.norm();
            let t = q / len;
            let p = (M3::identity() - t * t.transpose()) * (tau / len);
            let rh = ch.r.cross_matrix();
            let rp = rh * p;
            svv += p;
            svu -= p * rh;
            suv += rp;
            suu -= rp * rh;
        }
        let kv = M3::from_diagonal(&V3::new(sec.inv_ea, sec.inv_ga, sec.inv_ga));
        let mut j = Matrix6::identity();
        let jvv = M3::identity() + kv * svv;
        let jvu = kv * svu;
        let juv = c_prime * suv;
        let juu = M3::identity() + c_prime * suu;
        j.fixed_view_mut::<3, 3>(0, 0).copy_from(&jvv);
        j.fixed_view_mut::<3, 3>(0, 3).copy_from(&jvu);
        j.fixed_view_mut::<3, 3>(3, 0).copy_from(&juv);
        j.fixed_view_mut::<3, 3>(3, 3).copy_from(&juu);
        (f, j)
    }

    /// The curvature u from the internal moment `m` (body frame) and, when
    /// asked, du/dm: torsion u₁ = m₁/GJ; bending linear, m_b = EI u_b, or
    /// with material stiffening m_b = EI u_b (1 + α r² |u_b|²) (isotropic:
    /// u_b along m_b).
    ///
    /// The linear law is inlined into the local residual (its hot loop);
    /// stiffening's Newton is not.
    #[inline(always)]
    fn curvature_law(&self, i: usize, m: &V3, sec: &Section, derivative: bool) -> (V3, M3) {
        let rest = self.rod.rest_curvature_per_mm;
        if self.stiffening == 0.0 && !self.creep.is_on() {
            // The elastic linear law (most solves) without adding creep's
            // zero terms: measured 3–4 % of a 3-D solve without gravity.
            let u = V3::new(m[0] * sec.inv_gj, m[1] * sec.inv_ei, m[2] * sec.inv_ei + rest);
            let d = if derivative { M3::from_diagonal(&V3::new(sec.inv_gj, sec.inv_ei, sec.inv_ei)) } else { M3::zeros() };
            return (u, d);
        }
        let (gain, off) = self.creep_terms(i, sec);
        if self.stiffening == 0.0 {
            let b = sec.inv_ei + gain;
            let u = V3::new(m[0] * sec.inv_gj, m[1] * b + off[1], m[2] * b + rest + off[2]);
            let d = if derivative { M3::from_diagonal(&V3::new(sec.inv_gj, b, b)) } else { M3::zeros() };
            return (u, d);
        }
        self.stiffened_curvature_law(m, sec, (gain, off), derivative)
    }

    /// [`SpatialSolver::curvature_law`] with material stiffening, given
    /// creep's terms at the node.
    #[inline(never)]
    fn stiffened_curvature_law(&self, m: &V3, sec: &Section, (gain, off): (f64, V3), derivative: bool) -> (V3, M3) {
        let alpha = self.stiffening;
        let rest = self.rod.rest_curvature_per_mm;
        let mb = (m[1] * m[1] + m[2] * m[2]).sqrt();
        let c = alpha * sec.radius * sec.radius;
        // Monotone cubic EI (k + c k³) = |m_b| for the bending magnitude k.
        let mut k = mb / sec.ei;
        for _ in 0..STIFFENING_MAX_ITERATIONS {
            let f = sec.ei * (k + c * k * k * k) - mb;
            let step = f / (sec.ei * (1.0 + 3.0 * c * k * k));
            k -= step;
            if step.abs() <= STIFFENING_TOLERANCE * (1.0 + k.abs()) {
                break;
            }
        }
        let ratio = if mb > 0.0 { k / mb } else { 1.0 / sec.ei };
        let u = V3::new(m[0] / sec.gj, m[1] * (ratio + gain) + off[1], m[2] * (ratio + gain) + rest + off[2]);
        let mut d = M3::zeros();
        if derivative {
            d[(0, 0)] = 1.0 / sec.gj;
            let dk = 1.0 / (sec.ei * (1.0 + 3.0 * c * k * k));
            if mb > 0.0 {
                let (e1, e2) = (m[1] / mb, m[2] / mb);
                // d(k m̂) = dk/d|m| m̂ m̂ᵀ + k/|m| (I − m̂ m̂ᵀ).
                d[(1, 1)] = dk * e1 * e1 + ratio * (1.0 - e1 * e1);
                d[(1, 2)] = dk * e1 * e2 - ratio * e1 * e2;
                d[(2, 1)] = d[(1, 2)];
                d[(2, 2)] = dk * e2 * e2 + ratio * (1.0 - e2 * e2);
            } else {
                d[(1, 1)] = dk;
                d[(2, 2)] = dk;
            }
            d[(1, 1)] += gain;
            d[(2, 2)] += gain;
        }
        (u, d)
    }

    /// The internal moment (body frame, N·mm) whose curvature by the law
    /// of [`SpatialSolver::curvature_law`] at node `i` is `u`: the
    /// law's inverse (bending: m_b ∥ u_b − offset, its size from a scalar
    /// cubic with stiffening and creep).
    fn moment_of_curvature(&self, u: &V3, i: usize) -> V3 {
        let sec = &self.section[i];
        let rest = self.rod.rest_curvature_per_mm;
        let (gain, off) = self.creep_terms(i, sec);
        let ub = V3::new(0.0, u[1] - off[1], u[2] - rest - off[2]);
        let size = ub.norm();
        let c = self.stiffening * sec.radius * sec.radius;
        let ge = gain * sec.ei;
        // The elastic law's curvature k, with k + g EI (k + c k³) = |u_b|
        // (explicit without creep); then m_b = EI (k + c k³).
        let mut k = size / (1.0 + ge);
        if c > 0.0 && ge > 0.0 {
            for _ in 0..STIFFENING_MAX_ITERATIONS {
                let f = (1.0 + ge) * k + ge * c * k * k * k - size;
                let step = f / (1.0 + ge + 3.0 * ge * c * k * k);
                k -= step;
                if step.abs() <= STIFFENING_TOLERANCE * (1.0 + k.abs()) {
                    break;
                }
            }
        }
        let mb = sec.ei * (k + c * k * k * k);
        let scale = if size > 0.0 { mb / size } else { 0.0 };
        V3::new(sec.gj * u[0], ub[1] * scale, ub[2] * scale)
    }

    /// Creep's extra compliance over the hold and its held curvature at
    /// node `i` (components about body y and z in 1 and 2).
    #[inline]
    fn creep_terms(&self, i: usize, sec: &Section) -> (f64, V3) {
        if !self.creep.is_on() {
            return (0.0, V3::zeros());
        }
        (self.creep.gain(sec.ei), V3::new(0.0, self.creep.offset(2 * i), self.creep.offset(2 * i + 1)))
    }

    /// Friction: each cable's tension profile τ_c(s)/τ_c(0) = exp(−μ η Θ_c(s))
    /// from the turning Θ_c of its global direction R t_c, summed over a
    /// fine grid of the direction's interpolant (exact where it turns in a
    /// plane between grid points); written into the next state. Returns
    /// the largest change.
    fn friction_profiles(&mut self, commit: bool) -> f64 {
        let np = self.np;
        let nc = self.cables;
        let nn = self.nodes_count();
        let rot = if commit { &self.rot } else { &self.rot_alt };
        for i in 0..nn {
            let v = self.vbuf[i];
            let u = self.ubuf[i];
            for c in 0..nc {
                let ch = &self.chan[i * nc + c];
                let q = v + u.cross(&ch.r) + ch.dr;
                self.global_dir[i * nc + c] = rot[i] * q.normalize();
            }
        }
        let mut change = 0.0f64;
        for c in 0..nc {
            let mut turning = 0.0;
            for span in 0..self.spans() {
                let base = span * np;
                for j in 0..np {
                    let i = base + j;
                    if j > 0 && self.active[i * nc + c] {
                        let mut prev = self.global_dir[(i - 1) * nc + c];
                        for k in 1..=FRICTION_SUBSTEPS {
                            let g = if k == FRICTION_SUBSTEPS {
                                self.global_dir[i * nc + c]
                            } else {
                                let row = &self.grid.fine[((j - 1) * (FRICTION_SUBSTEPS - 1) + (k - 1)) * np..][..np];
                                let mut g = V3::zeros();
                                for (w, jj) in row.iter().zip(0..np) {
                                    g += self.global_dir[(base + jj) * nc + c] * *w;
                                }
                                g
                            };
                            turning += prev.cross(&g).norm().atan2(prev.dot(&g));
                            prev = g;
                        }
                    }
                    let at = self.ratio_at + i * nc + c;
                    let ratio = (-self.signed_mu * turning).exp();
                    change = change.max((ratio - self.state[at]).abs());
                    self.next[at] = ratio;
                }
            }
        }
        change
    }

    /// The pose of the converged state.
    fn pose_of_state(&self, passes: u32, tensions: &[f64]) -> TipPose {
        let tip = self.nodes_count() - 1;
        let r = &self.rot[tip];
        let x = &self.local[tip];
        let t = (r * V3::new(x[0], x[1], x[2])).normalize();
        let base_v = self.rot[0] * V3::new(self.local[0][0], self.local[0][1], self.local[0][2]);
        let mut tensions_n = PerCable::filled(self.cables, 0.0);
        tensions_n.copy_from_slice(tensions);
        let mut displacements_mm = PerCable::filled(self.cables, 0.0);
        self.displacements_into(tensions, &mut displacements_mm);
        TipPose {
            tensions_n,
            displacements_mm,
            tip_x_mm: self.pos[tip][0],
            tip_y_mm: self.pos[tip][1],
            tip_z_mm: self.pos[tip][2],
            // The angles of the projections on the x–y plane.
            tip_angle_rad: t[1].atan2(t[0]),
            tip_frame_angle_rad: r[(1, 0)].atan2(r[(0, 0)]),
            base_angle_rad: base_v[1].atan2(base_v[0]),
            length_mm: self.sigma[tip],
            iterations: passes,
            frame_3d: Some(TipFrame { tangent: [t[0], t[1], t[2]], body_y_axis: [r[(0, 1)], r[(1, 1)], r[(2, 1)]] }),
        }
    }

    /// Refuses a pose whose estimated tip error is above
    /// [`crate::solver::tip_tolerance_mm`], or whose tip lies farther
    /// from the clamp than the stretched rod is long (no curve can).
    fn check_resolved(&self, pose: &TipPose) -> Result<(), crate::solver::Unresolved> {
        let tolerance = crate::solver::tip_tolerance_mm(self.rod.length_mm);
        let [x, y, z] = pose.tip_mm();
        let reach = (x * x + y * y + z * z).sqrt();
        if reach > pose.length_mm + tolerance {
            let what = format!(
                "the tip (|tip| = {} mm is more than the stretched length ℓ = {} mm)",
                crate::io::fmt_num(reach),
                crate::io::fmt_num(pose.length_mm)
            );
            return Err(self.unresolved(what, reach - pose.length_mm, tolerance, "mm"));
        }
        let (_, tip_error) = self.estimate;
        if !(tip_error <= tolerance) {
            return Err(self.unresolved("the tip position".into(), tip_error, tolerance, "mm"));
        }
        Ok(())
    }

    /// The centreline of the last solve at 2·steps_per_span + 1 evenly
    /// spaced points (the option's centreline resolution) and at every
    /// span boundary (each anchor among them, where its cable ends).
    pub fn centreline(&self) -> Vec<CentrelinePoint> {
        self.nodes(2 * self.options.steps_per_span + 1)
    }

    /// The pose of the last successful solve.
    pub fn pose(&self) -> Option<TipPose> {
        self.last
    }

    /// The tangent angle's and the tip's estimated errors of the last
    /// solve (rad, mm): what the interpolants of u, p' and M_W' miss on each
    /// span, about the size of their highest Chebyshev coefficients
    /// (computed once per solve).
    pub fn error_estimate(&self) -> (f64, f64) {
        self.estimate
    }

    /// [`SpatialSolver::error_estimate`] of the state just solved.
    fn estimate_errors(&self) -> (f64, f64) {
        let np = self.np;
        let (mut angle, mut moment, mut position) = (0.0, 0.0, 0.0);
        let mut comps = [0.0; 9 * (MAX_NODES + 1)];
        for span in 0..self.spans() {
            let base = span * np;
            let length = 2.0 * self.half[span];
            for j in 0..np {
                let x = &self.local[base + j];
                let dp = self.dp[base + j];
                let dm = if self.has_weight { -dp.cross(&(self.gravity_unit * self.distal_weight[base + j])) } else { V3::zeros() };
                for c in 0..3 {
                    comps[c * np + j] = x[3 + c];
                    comps[(3 + c) * np + j] = dp[c];
                    comps[(6 + c) * np + j] = dm[c];
                }
            }
            let slice = |k: usize| &comps[k * np..(k + 1) * np];
            let tails = chebyshev::tails_of(&self.grid.tail, np, [slice(0), slice(1), slice(2), slice(3), slice(4), slice(5)]);
            let next = tails.map(next_coefficient);
            angle += length * next[0].max(next[1]).max(next[2]);
            position += length * next[3].max(next[4]).max(next[5]);
            if self.has_weight {
                // M_W' (zero without weight).
                let next = chebyshev::tails_of(&self.grid.tail, np, [slice(6), slice(7), slice(8)]).map(next_coefficient);
                moment += length * next[0].max(next[1]).max(next[2]);
            }
        }
        let ei_min = self.section.iter().map(|s| s.ei.min(s.gj)).fold(f64::INFINITY, f64::min);
        let scale = ESTIMATE_SAFETY / (self.m * self.m) as f64;
        let theta = scale * (angle + moment * self.rod.length_mm / ei_min);
        let ell = self.sigma[self.nodes_count() - 1];
        (theta, scale * position + ell * theta)
    }

    /// Legendre coefficients of the last solve, order `order`, in `basis`:
    /// `[twist, bending about body y, bending about body z]`, each
    /// a_0 … a_order in 1/mm (see the module comment). Refused as unresolved
    /// when their estimated error is above
    /// [`crate::solver::resolution::ORDER_TOLERANCE_PER_MM`] (the message
    /// names the setting to raise).
    pub fn coefficients(&self, order: usize, basis: LengthBasis) -> Result<[Vec<f64>; 3], SpatialError> {
        let (a, error) = self.coefficients_with_error(order, basis)?;
        let tolerance = crate::solver::resolution::ORDER_TOLERANCE_PER_MM;
        if !(error <= tolerance) {
            return Err(SpatialFailure::Unresolved(self.unresolved(format!("a_0 … a_{order}"), error, tolerance, "mm⁻¹")).into());
        }
        Ok(a)
    }

    /// [`SpatialSolver::unresolved`]'s failure at this solver's resolution.
    fn unresolved(&self, what: String, estimate: f64, tolerance: f64, unit: &'static str) -> crate::solver::Unresolved {
        let advice = format!(
            "raise --nodes-per-span above {} (spec: [solver] nodes_per_span; at most {}), or lower the tensions",
            self.m,
            crate::solver::MAX_NODES_PER_SPAN
        );
        crate::solver::Unresolved { what, estimate, tolerance, unit, advice }
    }

    /// [`SpatialSolver::coefficients`] without the check, with the estimated
    /// error of the largest coefficient, 1/mm.
    pub fn coefficients_with_error(&self, order: usize, basis: LengthBasis) -> Result<([Vec<f64>; 3], f64), SpatialError> {
        if order > MAX_SPATIAL_ORDER {
            return Err(SpatialError::Option(format!("order {order} is above the spatial solver's highest order {MAX_SPATIAL_ORDER}")));
        }
        assert!(self.last.is_some(), "coefficients needs a successful solve");
        let np = self.np;
        let nn = self.nodes_count();
        let length = self.rod.length_mm;
        let ell = self.sigma[nn - 1];
        let (theta_error, _) = self.error_estimate();
        let unit_v = |i: usize| {
            let x = &self.local[i];
            V3::new(x[0], x[1], x[2]).normalize()
        };
        let mut out: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; order + 1]);
        let mut quadrature_error = [0.0f64; MAX_SPATIAL_ORDER + 1];
        // Per span (stack buffers: this runs once per solve of a sweep):
        // v̂ at its nodes, and the highest Chebyshev coefficients of each
        // P_n κ_k, accumulated node by node.
        let mut vhat = [V3::zeros(); MAX_NODES + 1];
        let tail_rows = self.grid.tail.len() / np;
        let to_legendre = 2.0 / ell;
        for span in 0..self.spans() {
            let base = span * np;
            let h = self.half[span];
            let inv_h = 1.0 / h;
            for (j, v) in vhat[..np].iter_mut().enumerate() {
                *v = unit_v(base + j);
            }
            let mut tails = [[[0.0f64; chebyshev::TAIL_COEFFICIENTS]; 3]; MAX_SPATIAL_ORDER + 1];
            for j in 0..np {
                // κ at the node (body frame): u − (u·v̂) v̂ + v̂ × v̂'.
                let row = &self.grid.diff[j * np..(j + 1) * np];
                let mut d = V3::zeros();
                for k in 0..np {
                    d += vhat[k] * row[k];
                }
                let dv = d * inv_h;
                let x = &self.local[base + j];
                let u = V3::new(x[3], x[4], x[5]);
                let vh = vhat[j];
                let mut kappa = u - vh * u.dot(&vh) + vh.cross(&dv);
                kappa[0] = u[0];
                let t = to_legendre * self.sigma[base + j] - 1.0;
                let mut legendre = LegendreSeries::new(t);
                let w = h * self.grid.q[(np - 1) * np + j];
                for (n, tail) in tails[..=order].iter_mut().enumerate() {
                    if n > 0 {
                        legendre.advance();
                    }
                    let p = legendre.value();
                    for k in 0..3 {
                        let value = p * kappa[k];
                        out[k][n] += w * value;
                        for r in 0..tail_rows {
                            tail[k][r] += self.grid.tail[r * np + j] * value;
                        }
                    }
                }
            }
            for (n, tail) in tails[..=order].iter().enumerate() {
                let worst = tail.iter().map(|t| next_coefficient(*t)).fold(0.0, f64::max);
                quadrature_error[n] += 2.0 * h * worst;
            }
            // The tangent's jump to the next span (where v jumps).
            if span + 1 < self.spans() {
                let (a, b) = (vhat[np - 1], unit_v(base + np));
                let axis = a.cross(&b);
                let sin = axis.norm();
                if sin > 0.0 {
                    let jump = axis * (sin.atan2(a.dot(&b)) / sin);
                    let t = 2.0 * self.sigma[base + np - 1] / ell - 1.0;
                    let mut legendre = LegendreSeries::new(t);
                    for n in 0..=order {
                        if n > 0 {
                            legendre.advance();
                        }
                        for k in 1..3 {
                            out[k][n] += legendre.value() * jump[k];
                        }
                    }
                }
            }
        }
        let factor = match basis {
            LengthBasis::Rest => 1.0,
            LengthBasis::Deformed => length / ell,
        };
        for series in out.iter_mut() {
            for (n, a) in series.iter_mut().enumerate() {
                *a *= factor * (2 * n + 1) as f64 / length;
            }
        }
        let scale = ESTIMATE_SAFETY / (self.m * self.m) as f64;
        let error = (0..=order)
            .map(|n| {
                let nf = n as f64;
                let angles = theta_error * (2.0 + (2.0 * nf * (nf + 1.0)).sqrt());
                factor * (2.0 * nf + 1.0) / length * (scale * quadrature_error[n] + angles)
            })
            .fold(0.0, f64::max);
        Ok((out, error))
    }

    /// The centreline of the last solve at `count` evenly spaced points
    /// and at each span boundary, interpolated from the nodes (spectrally
    /// accurate on each span); a boundary's point is taken from the span
    /// before it, so that a cable anchored there still runs through it.
    pub fn nodes(&self, count: usize) -> Vec<CentrelinePoint> {
        let length = self.rod.length_mm;
        let count = count.max(2);
        let mut samples: Vec<f64> = (0..count).map(|k| length * k as f64 / (count - 1) as f64).collect();
        for &b in &self.start[1..] {
            if !samples.contains(&b) {
                samples.insert(samples.partition_point(|&s| s < b), b);
            }
        }
        self.points_at(&samples)
    }

    /// The centreline of the last solve at the rest arc lengths `s_mm`
    /// (each clamped into [0, L]), interpolated from the nodes (spectrally
    /// accurate on each span); a span boundary's point is taken from the
    /// span before it. Body-fixed points (markers) are evaluated here.
    ///
    /// # Panics
    /// Before a successful solve.
    pub fn points_at(&self, s_mm: &[f64]) -> Vec<CentrelinePoint> {
        assert!(self.last.is_some(), "points_at needs a successful solve");
        let np = self.np;
        let nc = self.cables;
        let length = self.rod.length_mm;
        let samples = s_mm.iter().map(|s| s.clamp(0.0, length));
        // Quaternions of the node frames, sign-continuous.
        let mut quats: Vec<[f64; 4]> = Vec::with_capacity(self.rot.len());
        let mut prev: Option<UnitQuaternion<f64>> = None;
        for r in &self.rot {
            let mut q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*r));
            if let Some(p) = prev {
                if p.coords.dot(&q.coords) < 0.0 {
                    q = UnitQuaternion::new_unchecked(-q.into_inner());
                }
            }
            prev = Some(q);
            quats.push([q.w, q.i, q.j, q.k]);
        }
        let tensions = self.tensions_n();
        samples
            .into_iter()
            .map(|s| {
                let span = self.start[1..].iter().take_while(|&&b| s > b).count().min(self.spans() - 1);
                let x = ((s - self.start[span]) / self.half[span] - 1.0).clamp(-1.0, 1.0);
                let base = span * np;
                let mut vals = [0.0; MAX_NODES + 1];
                let mut at = |f: &dyn Fn(usize) -> f64| {
                    for (j, v) in vals[..np].iter_mut().enumerate() {
                        *v = f(base + j);
                    }
                    chebyshev::interpolate(&self.grid.xn, &vals[..np], x)
                };
                let p = [at(&|i| self.pos[i][0]), at(&|i| self.pos[i][1]), at(&|i| self.pos[i][2])];
                let qv: [f64; 4] = std::array::from_fn(|c| at(&|i| quats[i][c]));
                let r = UnitQuaternion::from_quaternion(Quaternion::new(qv[0], qv[1], qv[2], qv[3])).to_rotation_matrix().into_inner();
                let v: [f64; 3] = std::array::from_fn(|c| at(&|i| self.local[i][c]));
                let u: [f64; 3] = std::array::from_fn(|c| at(&|i| self.local[i][3 + c]));
                let sigma = at(&|i| self.sigma[i]);
                let ratios: Vec<f64> = (0..nc).map(|c| if self.friction { at(&|i| self.state[self.ratio_at + i * nc + c]) } else { 1.0 }).collect();
                let tangent = r * V3::new(v[0], v[1], v[2]);
                let mut node = CentrelinePoint {
                    s_mm: s,
                    x_mm: p[0],
                    y_mm: p[1],
                    z_mm: p[2],
                    rotation: std::array::from_fn(|a| std::array::from_fn(|b| r[(a, b)])),
                    frame_angle_rad: r[(1, 0)].atan2(r[(0, 0)]),
                    tangent_angle_rad: tangent[1].atan2(tangent[0]),
                    arc_length_mm: sigma,
                    v,
                    u_per_mm: u,
                    cables: PerCable::filled(nc, CableAtNode::NONE),
                };
                for c in 0..nc {
                    // The cable runs through the nodes of the spans it pulls in.
                    if self.active[base * nc + c] {
                        let ch = self.channels[c].at(s);
                        let (y, z) = (ch.r_mm[0] + self.rod.effects.channel_offset_mm, ch.r_mm[1]);
                        node.cables[c] = CableAtNode { channel_mm: [y, z], position_mm: node.body_point_mm(y, z), tension_n: tensions[c] * ratios[c] };
                    }
                }
                node
            })
            .collect()
    }

    /// Each cable's displacement at the base, mm: its rest path length less
    /// the deformed one, ∫ |q| ds by the span quadrature, plus its stretch
    /// ∫ τ(s)/EA |q| ds (`tensions`: at the base; friction's profile from
    /// the state).
    fn displacements_into(&self, tensions: &[f64], out: &mut [f64]) {
        let np = self.np;
        let nc = self.cables;
        for (c, d) in out.iter_mut().enumerate() {
            let (mut path, mut pulled) = (0.0, 0.0);
            for span in 0..self.spans() {
                let base = span * np;
                if !self.active[base * nc + c] {
                    continue;
                }
                for j in 0..np {
                    let i = base + j;
                    let x = &self.local[i];
                    let ch = &self.chan[i * nc + c];
                    let dl = (V3::new(x[0], x[1], x[2]) + V3::new(x[3], x[4], x[5]).cross(&ch.r) + ch.dr).norm();
                    let w = self.half[span] * self.grid.q[(np - 1) * np + j];
                    path += w * dl;
                    pulled += w * dl * self.tension_at(tensions, i, c);
                }
            }
            *d = self.rest_length_mm[c] - path + self.cable_ea_n[c].map_or(0.0, |ea| pulled / ea);
        }
    }
}

/// The spatial backend: several and out-of-plane cables by collocation.
impl crate::solver::Solver for SpatialSolver {
    type Error = SpatialError;
    fn backend(&self) -> crate::solver::Backend {
        crate::solver::Backend::Spatial
    }
    fn solve_tensions(&mut self, tensions_n: &[f64]) -> Result<TipPose, SpatialError> {
        self.solve(tensions_n)
    }
    fn hold_next(&mut self, hold: Hold) {
        self.follow_hold(hold);
    }
    fn centreline(&self) -> Vec<CentrelinePoint> {
        SpatialSolver::centreline(self)
    }
    /// Refuses coefficients that are not finite.
    fn coefficients(&mut self, order: usize, basis: LengthBasis) -> Result<[Vec<f64>; 3], SpatialError> {
        let a = SpatialSolver::coefficients(self, order, basis)?;
        if !a.iter().flatten().all(|v| v.is_finite()) {
            return Err(SpatialFailure::NonFinite.into());
        }
        Ok(a)
    }
}

impl From<crate::solver::actuation::DisplacementNotMet> for SpatialError {
    fn from(e: crate::solver::actuation::DisplacementNotMet) -> Self {
        SpatialFailure::DisplacementNotMet(e).into()
    }
}

/// Refuses a hold whose dwell is not a finite time ≥ 0 s.
pub(crate) fn check_dwell(hold: Hold) -> Result<(), SpatialError> {
    if !(hold.dwell_s.is_finite() && hold.dwell_s >= 0.0) {
        return Err(SpatialError::Option(format!("dwell_s = {} must be a finite time ≥ 0 s", hold.dwell_s)));
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
mod tests {
    use super::*;
    use crate::solver::spatial::Cable;

    fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    }

    /// A one-cable in-plane actuator (`rod`, routing `y`, tension `tau`,
    /// anchor `anchor`) by the planar collocation solver and by this one:
    /// tip distance (mm), tip angle difference (rad) and largest a_k
    /// difference (1/mm).
    fn planar_against_spatial(rod: &Rod, y: [f64; 5], tau: f64, anchor: Option<f64>) -> (f64, f64, f64) {
        let mut planar_rod = rod.clone();
        planar_rod.cable_anchor_mm = anchor;
        let routing = crate::model::Routing::for_actuator(y, &planar_rod).unwrap();
        let options = crate::solver::SolverOptions { nodes_per_span: 24, ..Default::default() };
        let p = crate::solver::simulate(&planar_rod, &options, &routing, tau, 3, LengthBasis::Rest).unwrap();
        let mut cable = Cable::planar(y, tau);
        cable.anchor_mm = anchor;
        let a = Actuator::with_cables(rod.clone(), vec![cable]);
        let options = SpatialOptions { nodes_per_span: 24, ..Default::default() };
        let sp = crate::solver::spatial::simulate_spatial(&a, &options, 3, LengthBasis::Rest).unwrap();
        let tip = dist(sp.pose.tip_mm(), [p.pose.tip_x_mm, p.pose.tip_y_mm, 0.0]);
        let angle = (sp.pose.tip_angle_rad - p.pose.tip_angle_rad).abs();
        let da = sp.a_bend_z.iter().zip(&p.a_bend_z).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        (tip, angle, da)
    }

    #[test]
    fn in_plane_it_agrees_with_the_planar_solver_for_every_body_and_effect() {
        let y = [3.0, -1.0, 2.5, 1.0, -2.0];
        let taper = |r: &mut Rod| r.radius_profile_mm = vec![(0.0, 5.0), (40.0, 4.5), (65.0, 4.0)];
        let segments = |r: &mut Rod| {
            r.segments = vec![
                crate::model::Segment { end_mm: 30.0, ea_n: None, ga_n: None, ei_n_mm2: Some(160.0), density_g_cm3: Some(1.2) },
                crate::model::Segment { end_mm: 65.0, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None },
            ]
        };
        type Case = (&'static str, fn(&mut Rod), Option<f64>);
        let cases: Vec<Case> = vec![
            ("uniform", |_| {}, None),
            ("sideways gravity", |r| r.gravity.direction_rad = 1.2, None),
            ("tapered", |r| r.radius_profile_mm = vec![(0.0, 5.0), (40.0, 4.5), (65.0, 4.0)], None),
            ("segments", |r| {
                r.segments = vec![
                    crate::model::Segment { end_mm: 30.0, ea_n: None, ga_n: None, ei_n_mm2: Some(160.0), density_g_cm3: Some(1.2) },
                    crate::model::Segment { end_mm: 65.0, ea_n: None, ga_n: None, ei_n_mm2: None, density_g_cm3: None },
                ]
            }, None),
            ("anchored", |_| {}, Some(45.0)),
            ("tapered and anchored", |r| r.radius_profile_mm = vec![(0.0, 5.0), (40.0, 4.5), (65.0, 4.0)], Some(50.0)),
            ("friction, loading", |r| r.effects.friction_mu = 0.2, None),
            ("friction, unloading", |r| {
                r.effects.friction_mu = 0.2;
                r.effects.load_direction = crate::model::LoadDirection::Unload;
            }, None),
            ("clamp compliance", |r| r.effects.clamp_stiffness_n_mm_per_rad = Some(300.0), None),
            ("channel offset", |r| r.effects.channel_offset_mm = 0.4, None),
            ("stiffening", |r| r.effects.stiffening_alpha = 2.0, None),
            ("stiffness gradient", |r| r.effects.stiffness_gradient_beta = -0.8, None),
            ("creep", |r| {
                r.effects.creep_fraction = 0.3;
                r.effects.creep_hold_s = 20.0;
            }, None),
        ];
        let _ = (taper, segments);
        let mut worst = (0.0f64, 0.0f64, 0.0f64);
        for (name, set, anchor) in cases {
            let mut rod = Rod::default();
            set(&mut rod);
            let (tip, angle, da) = planar_against_spatial(&rod, y, 1.6, anchor);
            eprintln!("{name}: tip {tip:.1e} mm, angle {angle:.1e} rad, a {da:.1e} /mm");
            assert!(tip < 1e-6 && angle < 1e-7 && da < 1e-7, "{name}: tip {tip:e} mm, angle {angle:e} rad, a_k {da:e} /mm");
            worst = (worst.0.max(tip), worst.1.max(angle), worst.2.max(da));
        }
        eprintln!("worst: {worst:?}");
    }

    fn simulate(a: &Actuator) -> crate::solver::Simulation {
        let options = crate::solver::SolverOptions::default();
        crate::solver::simulate_actuator(a, &options, &SpatialOptions::default(), Default::default(), None, 3, LengthBasis::Rest).unwrap()
    }

    fn same_shape(p: &crate::solver::Simulation, q: &crate::solver::Simulation) -> f64 {
        p.centreline.iter().zip(&q.centreline).map(|(a, b)| dist(a.position_mm(), b.position_mm())).fold(0.0, f64::max)
    }

    #[test]
    fn exp_so3_is_the_rotation_about_its_vector() {
        for w in [V3::new(1e-9, -2e-9, 0.5e-9), V3::new(0.01, -0.02, 0.03), V3::new(0.3, 0.2, -0.1), V3::new(-0.9, 1.2, 0.4)] {
            let r = exp_so3(&w);
            let expected = Rotation3::new(w);
            assert!((r - expected.matrix()).amax() < 1e-15, "{w:?}: {r} against {}", expected.matrix());
            assert!((r.transpose() * r - M3::identity()).amax() < 1e-15);
        }
    }

    #[test]
    fn a_displacement_gives_back_the_shape_of_the_tension_that_produced_it() {
        // Planar fast path, spatial pair, and a pair with one cable of each kind;
        // gravity on, a stretchy cable for the second.
        let mut rod = Rod::default();
        rod.gravity.enabled = true;
        let y = [3.0, -1.0, 2.5, 1.0, -2.0];
        let one = Actuator::with_cables(rod.clone(), vec![Cable::planar(y, 1.6)]);
        let mut second = Cable::spatial([-1.0, 1.0, 2.0, 0.5, -1.0], [1.0, -1.5, 0.5, 2.0, 1.0], 0.9);
        second.cable_ea_n = Some(40.0);
        let pair = Actuator::with_cables(rod.clone(), vec![Cable::spatial(y, [0.5, 1.0, -1.0, 0.0, 0.5], 1.3), second]);
        for (name, a, driven) in [("planar", &one, vec![0]), ("pair", &pair, vec![0, 1]), ("mixed", &pair, vec![1])] {
            let by_tension = simulate(a);
            let mut b = a.clone();
            for &i in &driven {
                b.cables[i].displacement_mm = Some(by_tension.pose.displacements_mm[i]);
                b.cables[i].tension_n = 0.0;
            }
            let by_displacement = simulate(&b);
            let shape = same_shape(&by_tension, &by_displacement);
            let tension = by_tension.pose.tensions_n.iter().zip(by_displacement.pose.tensions_n.iter()).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
            eprintln!("{name}: displacements {:?} mm, shape {shape:.1e} mm, tensions {tension:.1e} N", &by_tension.pose.displacements_mm[..]);
            assert!(shape < 1e-9 && tension < 1e-9, "{name}: shape {shape:e} mm, tension {tension:e} N");
            assert!(by_tension.pose.displacements_mm.iter().all(|d| d.is_finite() && *d > 0.0));
            for &i in &driven {
                assert!((by_displacement.actuator.cables[i].tension_n - by_tension.pose.tensions_n[i]).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn a_cable_pulled_in_less_than_its_path_needs_is_slack() {
        // Gravity across the rod sags it toward +y: a cable at +y is on the
        // inside of the bend and its path shortens, so a cable pulled in by
        // nothing is slack, and the shape is the weight's alone.
        let mut rod = Rod::default();
        rod.gravity.enabled = true;
        rod.gravity.direction_rad = std::f64::consts::FRAC_PI_2;
        let y = [3.0; 5];
        let weight = simulate(&Actuator::with_cables(rod.clone(), vec![Cable::planar(y, 0.0)]));
        assert!(weight.pose.displacements_mm[0] > 0.0, "the sagging rod's inner path shortens: {:?}", weight.pose.displacements_mm);
        let slack = Cable { displacement_mm: Some(0.0), ..Cable::planar(y, 0.0) };
        for cables in [vec![slack.clone()], vec![Cable { z_mm: [0.0, 1.0, 1.0, 1.0, 0.0], ..slack.clone() }, Cable::planar([-3.0; 5], 0.0)]] {
            let sim = simulate(&Actuator::with_cables(rod.clone(), cables.clone()));
            assert_eq!(sim.pose.tensions_n[0], 0.0, "{cables:?}");
            if cables.len() == 1 {
                assert!(same_shape(&sim, &weight) < 1e-12);
            }
        }
        // Pulled in a little more than the sag gives: taut, with a small tension.
        let taut = Cable { displacement_mm: Some(weight.pose.displacements_mm[0] + 0.05), ..Cable::planar(y, 0.0) };
        let sim = simulate(&Actuator::with_cables(rod, vec![taut]));
        assert!(sim.pose.tensions_n[0] > 0.0 && sim.pose.tensions_n[0] < 0.2, "{:?}", &sim.pose.tensions_n[..]);
    }

    #[test]
    fn bad_displacements_and_stiffnesses_are_refused_by_name() {
        let y = [1.0; 5];
        for (d, ea, needle) in [(-1.0, None, "negative"), (f64::NAN, None, "finite"), (80.0, None, "cannot be pulled in"), (1.0, Some(0.0), "cable_ea_n")] {
            let cable = Cable { displacement_mm: Some(d), cable_ea_n: ea, ..Cable::planar(y, 0.0) };
            let a = Actuator::with_cables(Rod::default(), vec![cable]);
            let e = crate::solver::simulate_actuator(&a, &Default::default(), &SpatialOptions::default(), Default::default(), None, 3, LengthBasis::Rest).unwrap_err();
            assert!(e.to_string().contains(needle) && e.to_string().contains("cable 1"), "{e}");
        }
        // The RK4 references do not integrate the cables' paths.
        let cable = Cable { displacement_mm: Some(1.0), ..Cable::planar(y, 0.0) };
        let a = Actuator::with_cables(Rod::default(), vec![cable]);
        let rk4 = crate::solver::SolverOptions { method: crate::solver::SolverMethod::Rk4, ..Default::default() };
        let e = crate::solver::simulate_actuator(&a, &rk4, &SpatialOptions::default(), Default::default(), None, 3, LengthBasis::Rest).unwrap_err();
        assert!(e.to_string().contains("displacement"), "{e}");
        // A file gives one actuation.
        let both = "[[cable]]\ny_mm = [1, 1, 1, 1, 1]\ntension_n = 1\ndisplacement_mm = 1\n";
        assert!(Actuator::from_toml(both, "a.toml").unwrap_err().to_string().contains("not both"));
        let none = "[[cable]]\ny_mm = [1, 1, 1, 1, 1]\n";
        assert!(Actuator::from_toml(none, "a.toml").unwrap_err().to_string().contains("displacement_mm"));
    }

}

