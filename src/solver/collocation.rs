//! Spectral collocation per knot span: the default [`super::SolverMethod`].
//!
//! The routing is a cubic polynomial in its parameter on each knot span, so
//! every integrand of the cut equations (strains, tangent, gravity's moment
//! rate) is analytic on a span. On each span the strains are taken at the
//! m + 1 Chebyshev–Lobatto nodes and every integral along the span is the
//! exact integral of the degree-m interpolant (a fixed (m+1)×(m+1) matrix):
//! the error falls geometrically with m, so about a dozen nodes per span
//! reach the accuracy that RK4 needed 24 steps × 4 stages for.
//!
//! Unknowns are the frame angle φ and gravity's distal moment M at the nodes.
//! Without distributed loads the strains do not depend on them and one sweep
//! (strains → φ → x, y) is the solution. With gravity a sweep also integrates
//! M backward from M(L) = 0, so there is no shooting: sweeps are repeated to
//! a fixed point, which contracts fast for the thesis's light rod (the
//! weight's moment hardly changes the curvature). Warm starts extrapolate φ
//! and M over the previous tensions. For heavy rods, where the fixed point
//! does not contract, Newton's method on the full collocation system (φ and M
//! at every node, with the exact Jacobian from the local cut equations) takes
//! over, damped by backtracking, and if it fails from the warm start it is
//! continued in the weight from a weightless rod.

use super::friction::{MAX_PASSES as FRICTION_MAX_PASSES, TOLERANCE as FRICTION_TOLERANCE};
use super::result::{PerCable, PlanarPoint};
use super::{bending_moment, CentrelinePoint, ChannelSample, PlanarState, SolveFailure, Strains, TipPose};
use crate::model::body::BodySection;
use crate::model::Routing;
use crate::shape::LengthBasis;
use crate::numerics::anderson::Anderson;
use crate::numerics::chebyshev::{self, next_coefficient, ESTIMATE_SAFETY, TAIL_COEFFICIENTS};
use nalgebra::{DMatrix, DVector};

/// Most fixed-point sweeps before Newton takes over.
const MAX_SWEEPS: u32 = 30;
/// Change of the frame angle between sweeps accepted as settled, rad. The
/// accelerated sweeps converge faster than linearly, so the state accepted
/// is much closer than this (reference cases unchanged to 1e-9 mm vs 1e-10).
const SWEEP_ANGLE_TOLERANCE_RAD: f64 = 1e-9;
/// Newton: scaled residual (rad) accepted as converged.
const NEWTON_TOLERANCE: f64 = 1e-12;
/// Newton iterations per solve before giving up.
const NEWTON_MAX_ITERATIONS: u32 = 40;
/// Newton: residual accepted after the last iteration (stalled at rounding).
const NEWTON_STALL_TOLERANCE: f64 = 1e3 * NEWTON_TOLERANCE;
/// Newton: the backtracking's sufficient decrease (Armijo) factor.
const NEWTON_SUFFICIENT_DECREASE: f64 = 1e-4;
/// Newton: smallest damping factor λ tried before giving up.
const NEWTON_MIN_DAMPING: f64 = 1e-4;
/// First and largest weight steps of the continuation, as fractions of the weight.
const FIRST_WEIGHT_STEP: f64 = 0.25;
const MAX_WEIGHT_STEP: f64 = 0.5;
/// Smallest weight step of the continuation, as a fraction of the weight.
const MIN_WEIGHT_STEP: f64 = 1.0 / 1024.0;

/// Nodes, integration matrix and state of the collocation.
#[derive(Debug, Clone)]
pub struct Colloc {
    /// Intervals per span (m); m + 1 nodes per span.
    m: usize,
    /// Integration matrix on [−1, 1], row-major: q[j][k] = ∫_{−1}^{x_j} ℓ_k(x) dx.
    q: Vec<f64>,
    /// Nodes on [−1, 1], x_j = −cos(π j / m).
    x: Vec<f64>,
    /// Node arc lengths s, mm: span 0, span 1, … (a boundary appears in
    /// both spans it joins).
    s: Vec<f64>,
    /// Half length and start of each span, mm: two spans (the routing's
    /// knot) for the uniform rod, more at a non-uniform body's breakpoints
    /// and the cable's anchor.
    half: Vec<f64>,
    start: Vec<f64>,
    /// The cross-section at each node (a span's last node takes a jump
    /// at its end from the left).
    section: Vec<BodySection>,
    /// Frame angle φ and gravity's distal moment M at the nodes.
    phi: Vec<f64>,
    mom: Vec<f64>,
    /// Position and deformed arc length at the nodes.
    px: Vec<f64>,
    py: Vec<f64>,
    sigma: Vec<f64>,
    /// (sin φ, cos φ) at the nodes.
    trig: Vec<(f64, f64)>,
    strain: Vec<Strains>,
    /// Integrands at the nodes: u, x', y', σ', M'.
    du: Vec<f64>,
    dx: Vec<f64>,
    dy: Vec<f64>,
    dsig: Vec<f64>,
    dmom: Vec<f64>,
    /// Buffer for the next φ.
    scratch: Vec<f64>,
    /// qb[j][k] = q[m][k] − q[j][k]: integrals from node j to the span end.
    qb: Vec<f64>,
    /// Interpolation weights onto the friction grid, row-major: row
    /// (j − 1)·(FRICTION_SUBSTEPS − 1) + (k − 1) gives the value at
    /// x_{j−1} + k/FRICTION_SUBSTEPS·(x_j − x_{j−1}) from the np node values
    /// (fixed nodes: computed once instead of a barycentric sum per point).
    fine: Vec<f64>,
    /// Rows of the discrete Chebyshev transform of a span's node values
    /// for its [`TAIL_COEFFICIENTS`] highest coefficients c_{m−2}, c_{m−1},
    /// c_m, row-major: their size is about the interpolant's error, the
    /// a posteriori estimate of [`PlanarState::colloc_error_estimate`].
    tail: Vec<f64>,
    /// Anderson acceleration memory.
    anderson: Anderson,
    /// Converged solves of this routing, newest first: tension, φ, M.
    hist_t: [f64; 3],
    hist_phi: [Vec<f64>; 3],
    hist_mom: [Vec<f64>; 3],
    solved: usize,
}

/// Derivatives of the local strains with respect to φ and M at one node.
#[derive(Debug, Clone, Copy, Default)]
struct Partials {
    du_dphi: f64,
    du_dm: f64,
    dmom_dphi: f64,
    dmom_dm: f64,
    /// Bending moment at the node and its derivatives (clamp compliance).
    bend: f64,
    dbend_dphi: f64,
    dbend_dm: f64,
}

impl Colloc {
    pub(super) fn new(m: usize, spans: usize) -> Self {
        let np = m + 1;
        let nn = spans * np;
        let x = chebyshev::lobatto_nodes(m);
        let mut c = Self {
            m,
            q: chebyshev::integration_matrix(m),
            x,
            s: vec![0.0; nn],
            half: vec![0.0; spans],
            start: vec![0.0; spans],
            section: Vec::with_capacity(nn),
            phi: vec![0.0; nn],
            mom: vec![0.0; nn],
            px: vec![0.0; nn],
            py: vec![0.0; nn],
            sigma: vec![0.0; nn],
            trig: vec![(0.0, 1.0); nn],
            strain: vec![Strains::default(); nn],
            du: vec![0.0; nn],
            dx: vec![0.0; nn],
            dy: vec![0.0; nn],
            dsig: vec![0.0; nn],
            dmom: vec![0.0; nn],
            scratch: vec![0.0; nn],
            qb: {
                let q = chebyshev::integration_matrix(m);
                let mut qb = vec![0.0; np * np];
                for j in 0..np {
                    for k in 0..np {
                        qb[j * np + k] = q[m * np + k] - q[j * np + k];
                    }
                }
                qb
            },
            fine: Vec::new(),
            tail: chebyshev::tail_rows(m),
            anderson: Anderson::new(3 * nn),
            hist_t: [0.0; 3],
            hist_phi: std::array::from_fn(|_| vec![0.0; nn]),
            hist_mom: std::array::from_fn(|_| vec![0.0; nn]),
            solved: 0,
        };
        c.fine = c.friction_grid_weights();
        c
    }

    /// The rows of [`Colloc::fine`]: the interpolant's weights at each
    /// friction grid point (the interpolation of each unit vector there).
    fn friction_grid_weights(&self) -> Vec<f64> {
        let np = self.np();
        let mut unit = vec![0.0; np];
        let mut out = Vec::with_capacity((np - 1) * (FRICTION_SUBSTEPS - 1) * np);
        for j in 1..np {
            for k in 1..FRICTION_SUBSTEPS {
                let at = self.x[j - 1] + (self.x[j] - self.x[j - 1]) * k as f64 / FRICTION_SUBSTEPS as f64;
                for i in 0..np {
                    unit[i] = 1.0;
                    out.push(self.interpolate(&unit, at));
                    unit[i] = 0.0;
                }
            }
        }
        out
    }

    /// Forgets the warm start: the next solve starts from the straight rod.
    pub(super) fn forget(&mut self) {
        self.solved = 0;
        self.anderson.clear();
        self.set_straight();
    }

    fn set_straight(&mut self) {
        self.phi.iter_mut().for_each(|v| *v = 0.0);
        self.mom.iter_mut().for_each(|v| *v = 0.0);
        self.trig.iter_mut().for_each(|v| *v = (0.0, 1.0));
    }

    fn np(&self) -> usize {
        self.m + 1
    }

    /// Chebyshev–Lobatto intervals per span, m.
    pub(super) fn intervals(&self) -> usize {
        self.m
    }

    /// The number of spans.
    fn spans(&self) -> usize {
        self.half.len()
    }

    /// The highest [`TAIL_COEFFICIENTS`] Chebyshev coefficients,
    /// c_{m−3} … c_m, of each of `K` functions' node values on one span
    /// (`fs`, the span's slices), in one pass over the transform's rows.
    #[inline]
    fn tails_of<const K: usize>(&self, fs: [&[f64]; K]) -> [[f64; TAIL_COEFFICIENTS]; K] {
        chebyshev::tails_of(&self.tail, self.np(), fs)
    }

    /// Σ_k q[j][k] f[k] over one span's values `f`.
    #[inline]
    fn row_dot(&self, j: usize, f: &[f64]) -> f64 {
        let np = self.np();
        self.q[j * np..(j + 1) * np].iter().zip(f).map(|(a, b)| a * b).sum()
    }

    /// Integrates `f` forward over each span from `start` (span 0) and
    /// continuously across the knot: out = start + ∫_0^s f.
    fn integrate_forward(&self, f: &[f64], start: f64, out: &mut [f64]) {
        let np = self.np();
        let mut begin = start;
        for span in 0..self.spans() {
            let base = span * np;
            let fs = &f[base..base + np];
            let h = self.half[span];
            for (j, o) in out[base..base + np].iter_mut().enumerate() {
                let row = &self.q[j * np..(j + 1) * np];
                let mut acc = 0.0;
                for k in 0..np {
                    acc += row[k] * fs[k];
                }
                *o = begin + h * acc;
            }
            begin = out[base + np - 1];
        }
    }

    /// Predicts φ and M for `tension` from the previous solves (Lagrange
    /// extrapolation over up to three tensions).
    fn predict(&mut self, tension: f64) {
        let k = self.solved.min(3);
        if k == 0 {
            self.set_straight();
            return;
        }
        let mut w = [0.0; 3];
        for i in 0..k {
            let mut weight = 1.0;
            for j in 0..k {
                if i != j {
                    weight *= (tension - self.hist_t[j]) / (self.hist_t[i] - self.hist_t[j]);
                }
            }
            w[i] = weight;
        }
        if !w.iter().all(|v| v.is_finite()) {
            // Repeated tensions: start from the newest solution.
            w = [1.0, 0.0, 0.0];
        }
        for i in 0..self.phi.len() {
            let (mut p, mut m) = (0.0, 0.0);
            for h in 0..k {
                p += w[h] * self.hist_phi[h][i];
                m += w[h] * self.hist_mom[h][i];
            }
            let delta = p - self.phi[i];
            self.phi[i] = p;
            self.mom[i] = m;
            // sin/cos φ of the last solve, turned by the (small) prediction.
            self.trig[i] = turn(self.trig[i], delta, p);
        }
    }

    /// Takes the solution of `other` (the same spans, other nodes),
    /// interpolated onto these nodes, as the only solve of `tension` in the
    /// history: the next solve starts from it.
    pub(super) fn seed_from(&mut self, other: &Colloc, tension: f64) {
        let (np, other_np) = (self.np(), other.np());
        for span in 0..self.spans().min(other.spans()) {
            let from = span * other_np..(span + 1) * other_np;
            for j in 0..np {
                let i = span * np + j;
                self.hist_phi[0][i] = other.interpolate(&other.phi[from.clone()], self.x[j]);
                self.hist_mom[0][i] = other.interpolate(&other.mom[from.clone()], self.x[j]);
            }
        }
        self.hist_t[0] = tension;
        self.solved = 1;
    }

    /// Stores the converged φ, M of `tension` as the newest history entry.
    fn record(&mut self, tension: f64) {
        self.hist_t.rotate_right(1);
        self.hist_phi.rotate_right(1);
        self.hist_mom.rotate_right(1);
        self.hist_t[0] = tension;
        self.hist_phi[0].copy_from_slice(&self.phi);
        self.hist_mom[0].copy_from_slice(&self.mom);
        self.solved += 1;
    }

    /// Replaces the state G(z) left by the last sweep with the Anderson
    /// (depth 2) combination of the last sweeps, and keeps sin/cos φ in step.
    fn accelerate(&mut self, scale: f64, ratio: &mut [f64]) {
        let nn = self.phi.len();
        let a = &mut self.anderson;
        let g = a.output_mut();
        for i in 0..nn {
            g[i] = self.phi[i];
            g[nn + i] = self.mom[i] * scale;
            g[2 * nn + i] = ratio[i];
        }
        let Some(next) = a.step() else { return };
        for i in 0..nn {
            ratio[i] = next[2 * nn + i];
            let delta = next[i] - self.phi[i];
            self.phi[i] = next[i];
            self.mom[i] = next[nn + i] / scale;
            self.trig[i] = turn(self.trig[i], delta, next[i]);
        }
    }

    /// Records the input z = (φ, M·scale, τ(s)/τ(0)) of the next sweep for Anderson.
    fn begin_sweep(&mut self, ratio: &[f64], scale: f64) {
        let nn = self.phi.len();
        let z = self.anderson.input_mut();
        for i in 0..nn {
            z[i] = self.phi[i];
            z[nn + i] = self.mom[i] * scale;
            z[2 * nn + i] = ratio[i];
        }
    }

    /// Barycentric interpolation of node values `f` (one span) at unit
    /// coordinate `x` ∈ [−1, 1].
    fn interpolate(&self, f: &[f64], x: f64) -> f64 {
        chebyshev::interpolate(&self.x, f, x)
    }
}

/// (sin φ, cos φ) after φ changed by `delta` to `phi`: small changes rotate
/// the stored pair (cheaper than sin/cos), large ones recompute it.
#[inline]
fn turn((sn, cs): (f64, f64), delta: f64, phi: f64) -> (f64, f64) {
    if delta.abs() < 0.125 {
        let (c, s) = super::rotate((cs, sn), delta);
        (s, c)
    } else {
        phi.sin_cos()
    }
}

impl PlanarState {
    /// Places the nodes on the knot spans of `built` and samples the channel there.
    pub(super) fn colloc_set_routing(&mut self, c: &mut Colloc, built: &Routing) {
        let knot = built.knot_mm();
        let bounds = super::span_boundaries(&self.rod, self.body.as_ref(), knot);
        assert_eq!(bounds.len() - 1, c.spans(), "span count fixed by the actuator");
        for span in 0..c.spans() {
            c.start[span] = bounds[span];
            c.half[span] = (bounds[span + 1] - bounds[span]) / 2.0;
        }
        let np = c.np();
        let anchor = self.rod.cable_length_mm();
        // Boundaries closer than this were merged (the anchor may have been
        // merged into a breakpoint just below it).
        let merged = crate::model::body::MERGE_TOLERANCE * self.rod.length_mm;
        self.cable_end = c.s.len();
        c.section.clear();
        for span in 0..c.spans() {
            // Spans from the anchor on carry no cable (and have no channel).
            let cable = c.start[span] + merged < anchor;
            if !cable && self.cable_end == c.s.len() {
                self.cable_end = span * np;
            }
            for j in 0..np {
                let i = span * np + j;
                // Exact end points, so the knot and the tip are hit exactly.
                let s = match j {
                    0 => c.start[span],
                    _ if j == np - 1 => c.start[span] + 2.0 * c.half[span],
                    _ => c.start[span] + c.half[span] * (1.0 + c.x[j]),
                };
                c.s[i] = s;
                c.section.push(self.section_at_side(s, j == np - 1));
                self.channel[i] = if cable {
                    let ch = built.channel_at(s.min(built.length_mm()));
                    ChannelSample { y: ch.y_mm, dy: ch.dy_ds }
                } else {
                    ChannelSample::default()
                };
            }
        }
        // The cable's path in the straight, unloaded rod, by the same quadrature.
        let mut rest = 0.0;
        for span in 0..c.spans() {
            if span * np >= self.cable_end {
                break;
            }
            for j in 0..np {
                rest += c.half[span] * c.q[(np - 1) * np + j] * self.channel[span * np + j].dy.hypot(1.0);
            }
        }
        self.cable_rest_length_mm = rest;
    }

    /// Solves for `tension` from the warm start; returns the passes used
    /// (sweeps, plus Newton iterations if the fallback ran).
    pub(super) fn colloc_solve(&mut self, c: &mut Colloc, tension: f64) -> Result<u32, SolveFailure> {
        c.predict(tension);
        let has_weight = self.weight_n_per_mm != 0.0;
        let has_friction = self.friction.acts_at(tension);
        if !has_weight && !has_friction {
            // The strains do not depend on φ or M: one sweep is the solution.
            self.colloc_sweep(c, tension)?;
            self.colloc_positions(c);
            c.record(tension);
            return Ok(1);
        }
        let max_sweeps = if has_weight { MAX_SWEEPS } else { FRICTION_MAX_PASSES as u32 };
        let mut passes = 0u32;
        let mut previous = f64::INFINITY;
        // Anderson acceleration of the sweeps, a fixed map of (φ, M, τ(s)/τ(0)).
        let scale = self.rod.length_mm / self.rod.ei_n_mm2;
        c.anderson.restart();
        let outcome = loop {
            c.begin_sweep(self.friction.ratios(), scale);
            let (dphi, dmom) = match self.colloc_sweep(c, tension) {
                Ok(change) => change,
                Err(e) => break Err(e),
            };
            passes += 1;
            let dratio = if has_friction { self.colloc_update_tension_ratio(c) } else { 0.0 };
            // The moment's change in angle units: δM·L/EI turns the tip by about that.
            let change = dphi.max(dmom * self.rod.length_mm / self.rod.ei_n_mm2);
            // Settled, and still contracting (a stalled iteration goes to Newton).
            let settled = dphi <= SWEEP_ANGLE_TOLERANCE_RAD && dmom <= self.options.planar_moment_tolerance_n_mm && dratio < FRICTION_TOLERANCE;
            if settled && (passes == 1 || change <= 0.5 * previous || !has_weight) {
                break Ok(());
            }
            if passes >= max_sweeps {
                break Err(if has_weight {
                    SolveFailure::WeightNotConverged { reached_percent: 100.0 }
                } else {
                    SolveFailure::FrictionNotConverged
                });
            }
            // A fixed point that does not contract (heavy rods): hand over to Newton.
            if has_weight && passes >= 3 && change > 0.5 * previous {
                break Err(SolveFailure::WeightNotConverged { reached_percent: 100.0 });
            }
            previous = change;
            c.accelerate(scale, self.friction.ratios_mut());
        };
        match outcome {
            Ok(()) => {
                self.colloc_positions(c);
                c.record(tension);
                Ok(passes)
            }
            Err(_) if has_weight => {
                let newton = self.colloc_newton_continued(c, tension)?;
                c.record(tension);
                Ok(passes + newton)
            }
            Err(e) => Err(e),
        }
    }

    /// Strains at every node from the current φ, M; records the cable
    /// direction (friction reads it with φ) and the bending moment (creep).
    fn colloc_strains(&mut self, c: &mut Colloc, tension: f64) -> Result<(), SolveFailure> {
        for i in 0..c.s.len() {
            let ch = self.channel[i];
            let t = self.tension_at(i, tension);
            let (e, dir) = self.strains_at(c.s[i], &c.section[i], ch, c.trig[i], c.mom[i], t, self.cable_dir[i], self.creep.offset(i))?;
            self.cable_dir[i] = dir;
            if self.creep.is_on() {
                let ei = c.section[i].ei_n_mm2;
                self.creep.record_moment(i, bending_moment(t, ch.y, dir.0, c.mom[i]), ei);
            }
            c.strain[i] = e;
            c.du[i] = e.u;
        }
        Ok(())
    }

    /// Frame angle at the clamp from node 0's bending moment.
    fn colloc_clamp_angle(&self, c: &Colloc, tension: f64) -> f64 {
        match self.rod.effects.clamp_stiffness_n_mm_per_rad {
            Some(k) => bending_moment(self.tension_at(0, tension), self.channel[0].y, self.cable_dir[0].0, c.mom[0]) / k,
            None => 0.0,
        }
    }

    /// Gravity's distal moment from the strains and φ at the nodes,
    /// integrated backward from M(L) = 0. Returns its largest change.
    fn colloc_moment(&mut self, c: &mut Colloc) -> f64 {
        if self.weight_n_per_mm == 0.0 {
            return 0.0;
        }
        let (gc, gs) = (self.gravity_cos, self.gravity_sin);
        for i in 0..c.s.len() {
            let (sp, cp) = c.trig[i];
            let e = c.strain[i];
            // M' = w (L − s)(y' cos β − x' sin β).
            let dx = e.v1 * cp - e.v2 * sp;
            let dy = e.v1 * sp + e.v2 * cp;
            c.dmom[i] = self.distal_weight_n(c.s[i]) * (dy * gc - dx * gs);
        }
        let np = c.np();
        let mut change: f64 = 0.0;
        let mut end = 0.0;
        for span in (0..c.spans()).rev() {
            let base = span * np;
            let h = c.half[span];
            let fm = &c.dmom[base..base + np];
            for j in 0..np {
                let back = &c.qb[j * np..(j + 1) * np];
                let mut acc = 0.0;
                for k in 0..np {
                    acc += back[k] * fm[k];
                }
                let v = end - h * acc;
                change = change.max((v - c.mom[base + j]).abs());
                c.mom[base + j] = v;
            }
            end = c.mom[base];
        }
        change
    }

    /// Positions and deformed arc length at the nodes from the strains and φ.
    fn colloc_positions(&mut self, c: &mut Colloc) {
        for i in 0..c.s.len() {
            let (sp, cp) = c.trig[i];
            let e = c.strain[i];
            c.dx[i] = e.v1 * cp - e.v2 * sp;
            c.dy[i] = e.v1 * sp + e.v2 * cp;
            c.dsig[i] = (e.v1 * e.v1 + e.v2 * e.v2).sqrt();
        }
        let np = c.np();
        let (mut x0, mut y0, mut s0) = (0.0, 0.0, 0.0);
        for span in 0..c.spans() {
            let base = span * np;
            let h = c.half[span];
            let (fx, fy, fs) = (&c.dx[base..base + np], &c.dy[base..base + np], &c.dsig[base..base + np]);
            for j in 0..np {
                let row = &c.q[j * np..(j + 1) * np];
                let (mut ax, mut ay, mut asg) = (0.0, 0.0, 0.0);
                for k in 0..np {
                    ax += row[k] * fx[k];
                    ay += row[k] * fy[k];
                    asg += row[k] * fs[k];
                }
                c.px[base + j] = x0 + h * ax;
                c.py[base + j] = y0 + h * ay;
                c.sigma[base + j] = s0 + h * asg;
            }
            (x0, y0, s0) = (c.px[base + np - 1], c.py[base + np - 1], c.sigma[base + np - 1]);
        }
    }

    /// One fixed-point sweep: strains from the current φ, M; then φ, the
    /// positions and M. Returns the largest changes of φ and M.
    fn colloc_sweep(&mut self, c: &mut Colloc, tension: f64) -> Result<(f64, f64), SolveFailure> {
        self.colloc_strains(c, tension)?;
        let phi0 = self.colloc_clamp_angle(c, tension);
        let old = std::mem::take(&mut c.phi);
        let mut phi = std::mem::take(&mut c.scratch);
        c.integrate_forward(&c.du, phi0, &mut phi);
        let mut dphi: f64 = 0.0;
        for i in 0..phi.len() {
            let delta = phi[i] - old[i];
            dphi = dphi.max(delta.abs());
            c.trig[i] = turn(c.trig[i], delta, phi[i]);
        }
        c.phi = phi;
        c.scratch = old;
        let dmom = self.colloc_moment(c);
        // A non-finite strain reaches every later φ and every earlier M.
        if !(c.phi[c.phi.len() - 1] + c.phi[c.np() - 1] + c.mom[0] + dphi + dmom).is_finite() {
            return Err(SolveFailure::NonFinite { s_mm: Some(self.rod.length_mm) });
        }
        Ok((dphi, dmom))
    }

    /// Friction: the tension profile τ(s)/τ(0) at the nodes from the cable
    /// angles of the last sweep, by the capstan law ln τ(s)/τ(0) =
    /// −η μ ∫_0^s |ψ'| ds (slip sign η). The cable's global angle ψ = φ + α is smooth on a
    /// span, but |ψ'| has kinks where the cable turns back, so the turning
    /// is summed over a fine grid of the interpolated ψ (exact wherever ψ is
    /// monotone between grid points). Returns the largest change.
    fn colloc_update_tension_ratio(&mut self, c: &mut Colloc) -> f64 {
        const SUBSTEPS: usize = FRICTION_SUBSTEPS;
        let np = c.np();
        let mut psi = std::mem::take(&mut c.scratch);
        for (i, p) in psi.iter_mut().enumerate() {
            let (ca, sa) = self.cable_dir[i];
            *p = c.phi[i] + sa.atan2(ca);
        }
        let mut change: f64 = 0.0;
        let mut turning = 0.0;
        for span in 0..c.spans() {
            let base = span * np;
            let values = &psi[base..base + np];
            for j in 0..np {
                if j > 0 {
                    let mut prev = values[j - 1];
                    for k in 1..=SUBSTEPS {
                        let v = if k == SUBSTEPS {
                            values[j]
                        } else {
                            let row = &c.fine[((j - 1) * (SUBSTEPS - 1) + (k - 1)) * np..][..np];
                            row.iter().zip(values).map(|(w, v)| w * v).sum()
                        };
                        turning += (v - prev).abs();
                        prev = v;
                    }
                }
                change = change.max(self.friction.set_from_turning(base + j, turning));
            }
        }
        c.scratch = psi;
        change
    }

    /// Newton's method from the current state; if it fails, continuation in
    /// the weight from a weightless rod. Returns the Newton iterations.
    fn colloc_newton_continued(&mut self, c: &mut Colloc, tension: f64) -> Result<u32, SolveFailure> {
        c.predict(tension);
        let (saved_phi, saved_mom) = (c.phi.clone(), c.mom.clone());
        for (t, p) in c.trig.iter_mut().zip(&c.phi) {
            *t = p.sin_cos();
        }
        let saved_dir = self.cable_dir.clone();
        if let Ok(n) = self.colloc_newton(c, tension) {
            return Ok(n);
        }
        let full = self.weight_n_per_mm;
        // Weightless rod: one sweep from any start (friction settles in Newton below).
        c.set_straight();
        self.cable_dir.iter_mut().for_each(|d| *d = (1.0, 0.0));
        self.weight_n_per_mm = 0.0;
        let mut iterations = 0;
        let result = (|| -> Result<(), SolveFailure> {
            self.colloc_sweep(c, tension)?;
            iterations += self.colloc_newton(c, tension)?;
            let (mut reached, mut step) = (0.0f64, FIRST_WEIGHT_STEP);
            while reached < 1.0 {
                let next = (reached + step).min(1.0);
                let (phi, mom, dir) = (c.phi.clone(), c.mom.clone(), self.cable_dir.clone());
                self.weight_n_per_mm = full * next;
                match self.colloc_newton(c, tension) {
                    Ok(n) => {
                        iterations += n;
                        reached = next;
                        step = (step * 2.0).min(MAX_WEIGHT_STEP);
                    }
                    Err(_) => {
                        (c.phi, c.mom) = (phi, mom);
                        self.cable_dir.copy_from_slice(&dir);
                        for (t, p) in c.trig.iter_mut().zip(&c.phi) {
                            *t = p.sin_cos();
                        }
                        step /= 2.0;
                        if step < MIN_WEIGHT_STEP {
                            return Err(SolveFailure::WeightNotConverged { reached_percent: 100.0 * reached });
                        }
                    }
                }
            }
            Ok(())
        })();
        self.weight_n_per_mm = full;
        if let Err(e) = result {
            // Leave the warm start as it was.
            c.phi.copy_from_slice(&saved_phi);
            c.mom.copy_from_slice(&saved_mom);
            self.cable_dir.copy_from_slice(&saved_dir);
            return Err(e);
        }
        Ok(iterations)
    }

    /// Newton's method on the collocation equations in (φ, M) at the nodes,
    /// damped by backtracking; the friction profile is settled around it.
    fn colloc_newton(&mut self, c: &mut Colloc, tension: f64) -> Result<u32, SolveFailure> {
        let has_friction = self.friction.acts_at(tension);
        let mut iterations = 0;
        for _ in 0..FRICTION_MAX_PASSES {
            iterations += self.colloc_newton_inner(c, tension)?;
            if !has_friction || self.colloc_update_tension_ratio(c) < FRICTION_TOLERANCE {
                self.colloc_strains(c, tension)?;
                self.colloc_positions(c);
                return Ok(iterations);
            }
        }
        Err(SolveFailure::FrictionNotConverged)
    }

    fn colloc_newton_inner(&mut self, c: &mut Colloc, tension: f64) -> Result<u32, SolveFailure> {
        let nn = c.s.len();
        let mut jac = DMatrix::<f64>::zeros(2 * nn, 2 * nn);
        let mut res = DVector::<f64>::zeros(2 * nn);
        let mut norm = self.colloc_residual(c, tension, &mut res, Some(&mut jac))?;
        for it in 0..NEWTON_MAX_ITERATIONS {
            if norm <= NEWTON_TOLERANCE {
                return Ok(it);
            }
            let delta = jac.clone().lu().solve(&(-&res)).ok_or(SolveFailure::WeightNotConverged { reached_percent: 0.0 })?;
            let (phi0, mom0, dir0) = (c.phi.clone(), c.mom.clone(), self.cable_dir.clone());
            let mut lambda = 1.0;
            loop {
                for i in 0..nn {
                    c.phi[i] = phi0[i] + lambda * delta[i];
                    c.mom[i] = mom0[i] + lambda * delta[nn + i];
                    c.trig[i] = c.phi[i].sin_cos();
                }
                match self.colloc_residual(c, tension, &mut res, Some(&mut jac)) {
                    Ok(n) if n.is_finite() && n < (1.0 - NEWTON_SUFFICIENT_DECREASE * lambda) * norm => {
                        norm = n;
                        break;
                    }
                    _ => {
                        self.cable_dir.copy_from_slice(&dir0);
                        lambda /= 2.0;
                        if lambda < NEWTON_MIN_DAMPING {
                            return Err(SolveFailure::WeightNotConverged { reached_percent: 0.0 });
                        }
                    }
                }
            }
        }
        if norm <= NEWTON_STALL_TOLERANCE {
            return Ok(NEWTON_MAX_ITERATIONS);
        }
        Err(SolveFailure::WeightNotConverged { reached_percent: 0.0 })
    }

    /// Strains at a node with their derivatives with respect to φ and M
    /// (implicit function theorem on the cable-direction equation).
    #[allow(clippy::too_many_arguments)]
    fn colloc_node_partials(&self, s: f64, section: &BodySection, ch: ChannelSample, (sp, cp): (f64, f64), moment: f64, t: f64, dir: (f64, f64), e: Strains) -> Partials {
        let (ea, ga) = (section.ea_n, section.ga_n);
        let wl = self.distal_weight_n(s);
        let (gc, gs) = (self.gravity_cos, self.gravity_sin);
        let w1 = wl * (cp * gc + sp * gs);
        let w2 = wl * (cp * gs - sp * gc);
        let (ca, sa) = dir;
        let bend = bending_moment(t, ch.y, ca, moment);
        let (_, du_dm_el) = self.bending_curvature(bend, section);
        let dudm = du_dm_el + self.creep.gain(section.ei_n_mm2);
        let p = e.v1 - e.u * ch.y;
        let q = e.v2 + ch.dy;
        let (dv1a, dv2a, dua) = (t * sa / ea, -t * ca / ga, -t * ch.y * sa * dudm);
        let dg = (dv1a - dua * ch.y) * sa + p * ca - dv2a * ca + q * sa;
        let a_phi = -(w2 * sa / ea + w1 * ca / ga) / dg;
        let a_m = -(-dudm * ch.y * sa) / dg;
        let (dv1p, dv2p, dup) = (w2 / ea + dv1a * a_phi, -w1 / ga + dv2a * a_phi, dua * a_phi);
        let (dv1m, dv2m, dum) = (dv1a * a_m, dv2a * a_m, dudm + dua * a_m);
        // M' = wl (y' cos β − x' sin β), x' = v1 cos φ − v2 sin φ, y' = v1 sin φ + v2 cos φ.
        let (v1, v2) = (e.v1, e.v2);
        let dxp = dv1p * cp - v1 * sp - dv2p * sp - v2 * cp;
        let dyp = dv1p * sp + v1 * cp + dv2p * cp - v2 * sp;
        let dxm = dv1m * cp - dv2m * sp;
        let dym = dv1m * sp + dv2m * cp;
        Partials {
            du_dphi: dup,
            du_dm: dum,
            dmom_dphi: wl * (dyp * gc - dxp * gs),
            dmom_dm: wl * (dym * gc - dxm * gs),
            bend,
            dbend_dphi: -t * ch.y * sa * a_phi,
            dbend_dm: 1.0 - t * ch.y * sa * a_m,
        }
    }

    /// Residual of the collocation equations at the current (φ, M), scaled to
    /// angle units (M by L/EI), and optionally its Jacobian. Returns the
    /// residual's largest entry.
    fn colloc_residual(&mut self, c: &mut Colloc, tension: f64, res: &mut DVector<f64>, jac: Option<&mut DMatrix<f64>>) -> Result<f64, SolveFailure> {
        self.colloc_strains(c, tension)?;
        let nn = c.s.len();
        let np = c.np();
        let scale = self.rod.length_mm / self.rod.ei_n_mm2;
        let (gc, gs) = (self.gravity_cos, self.gravity_sin);
        let mut parts = vec![Partials::default(); nn];
        for i in 0..nn {
            let t = self.tension_at(i, tension);
            let e = c.strain[i];
            parts[i] = self.colloc_node_partials(c.s[i], &c.section[i], self.channel[i], c.trig[i], c.mom[i], t, self.cable_dir[i], e);
            let (sp, cp) = c.trig[i];
            let dx = e.v1 * cp - e.v2 * sp;
            let dy = e.v1 * sp + e.v2 * cp;
            c.dmom[i] = self.distal_weight_n(c.s[i]) * (dy * gc - dx * gs);
        }
        let k_theta = self.rod.effects.clamp_stiffness_n_mm_per_rad;
        let mut jac = jac;
        if let Some(j) = jac.as_deref_mut() {
            j.fill(0.0);
        }
        let last = c.spans() - 1;
        for span in 0..c.spans() {
            let base = span * np;
            let phi_anchor = if span == 0 { 0 } else { base - 1 };
            let mom_anchor = if span < last { base + np } else { nn - 1 };
            let h = c.half[span];
            let us = &c.du[base..base + np];
            let ms = &c.dmom[base..base + np];
            let total = c.row_dot(np - 1, ms);
            for j in 0..np {
                let i = base + j;
                // φ equations: φ_i = φ_anchor + ∫ u (span 0, j = 0: the clamp).
                if span == 0 && j == 0 {
                    let (target, dtp, dtm) = match k_theta {
                        Some(k) => (parts[0].bend / k, parts[0].dbend_dphi / k, parts[0].dbend_dm / k),
                        None => (0.0, 0.0, 0.0),
                    };
                    res[i] = c.phi[0] - target;
                    if let Some(jm) = jac.as_deref_mut() {
                        jm[(i, 0)] += 1.0 - dtp;
                        jm[(i, nn)] -= dtm;
                    }
                } else {
                    res[i] = c.phi[i] - c.phi[phi_anchor] - h * c.row_dot(j, us);
                    if let Some(jm) = jac.as_deref_mut() {
                        jm[(i, i)] += 1.0;
                        jm[(i, phi_anchor)] -= 1.0;
                        for k in 0..np {
                            let qk = h * c.q[j * np + k];
                            jm[(i, base + k)] -= qk * parts[base + k].du_dphi;
                            jm[(i, nn + base + k)] -= qk * parts[base + k].du_dm;
                        }
                    }
                }
                // M equations: M_i = M_anchor − ∫_{s_i}^{end} M' (tip: M = 0).
                let r = nn + i;
                if span == last && j == np - 1 {
                    res[r] = c.mom[i] * scale;
                    if let Some(jm) = jac.as_deref_mut() {
                        jm[(r, nn + i)] += scale;
                    }
                } else {
                    res[r] = (c.mom[i] - c.mom[mom_anchor] + h * (total - c.row_dot(j, ms))) * scale;
                    if let Some(jm) = jac.as_deref_mut() {
                        jm[(r, nn + i)] += scale;
                        jm[(r, nn + mom_anchor)] -= scale;
                        for k in 0..np {
                            let qk = h * (c.q[(np - 1) * np + k] - c.q[j * np + k]) * scale;
                            jm[(r, base + k)] += qk * parts[base + k].dmom_dphi;
                            jm[(r, nn + base + k)] += qk * parts[base + k].dmom_dm;
                        }
                    }
                }
            }
        }
        Ok(res.amax())
    }

    /// A posteriori error estimate of the converged state: the errors of
    /// the tangent angle (rad) and of the tip position (mm). Each span's
    /// integrals are those of the interpolants of its node values (the
    /// curvature u for φ, gravity's moment rate M′ for M, the tangent x′, y′
    /// for the position), so what an interpolant misses, about the size of
    /// its highest Chebyshev coefficients, is what the integral misses. An
    /// error of M turns the rod by about δM·L/EI, and an error of the angle
    /// moves the tip by up to ℓ times it.
    pub(super) fn colloc_error_estimate(&self, c: &Colloc) -> (f64, f64) {
        let np = c.np();
        let gravity = self.weight_n_per_mm != 0.0;
        let (mut phi_error, mut moment_error, mut position_error) = (0.0, 0.0, 0.0);
        let mut aliased = false;
        for span in 0..c.spans() {
            let nodes = span * np..(span + 1) * np;
            let length = 2.0 * c.half[span];
            let (du, dx, dy) = (&c.du[nodes.clone()], &c.dx[nodes.clone()], &c.dy[nodes.clone()]);
            let [u, x, y] = if gravity {
                let [u, x, y, m] = c.tails_of([du, dx, dy, &c.dmom[nodes.clone()]]);
                moment_error += length * next_coefficient(m);
                [u, x, y]
            } else {
                c.tails_of([du, dx, dy])
            };
            phi_error += length * next_coefficient(u);
            position_error += length * next_coefficient(x).max(next_coefficient(y));
            // cos φ over a span turning by Δφ is cos(Δφ/2 · x) on [−1, 1],
            // which m + 1 Chebyshev nodes cannot follow for Δφ/2 > m (its
            // samples may even alias onto a smooth low mode).
            aliased |= (c.phi[nodes.end - 1] - c.phi[nodes.start]).abs() > 2.0 * c.m as f64;
        }
        let ei_min = c.section.iter().map(|s| s.ei_n_mm2).fold(f64::INFINITY, f64::min);
        let scale = ESTIMATE_SAFETY / (c.m * c.m) as f64;
        let theta_error = scale * (phi_error + moment_error * self.rod.length_mm / ei_min);
        let ell = c.sigma[c.s.len() - 1];
        let mut tip_error = scale * position_error + ell * theta_error;
        if aliased {
            tip_error = tip_error.max(ell);
        }
        (theta_error, tip_error)
    }

    /// The cable's displacement at the base, mm: the rest path length
    /// (kept at [`PlanarState::colloc_set_routing`]) less the deformed one,
    /// ∫ |(v1 − u y_c, v2 + y_c')| ds over the spans the cable runs in (the
    /// same span quadrature), plus its stretch ∫ τ(s)/EA dℓ.
    fn colloc_displacement_mm(&self, c: &Colloc, tension: f64) -> f64 {
        let np = c.np();
        let (mut path, mut pulled) = (0.0, 0.0);
        for span in 0..c.spans() {
            if span * np >= self.cable_end {
                break;
            }
            let h = c.half[span];
            for j in 0..np {
                let i = span * np + j;
                let (e, ch) = (c.strain[i], self.channel[i]);
                let dl = (e.v1 - e.u * ch.y).hypot(e.v2 + ch.dy);
                let w = h * c.q[(np - 1) * np + j];
                path += w * dl;
                pulled += w * dl * self.tension_at(i, tension);
            }
        }
        let stretch = self.cable_ea_n.map_or(0.0, |ea| pulled / ea);
        self.cable_rest_length_mm - path + stretch
    }

    /// The pose of the converged state.
    pub(super) fn colloc_pose(&self, c: &Colloc, tension: f64, passes: u32) -> TipPose {
        let tip = c.s.len() - 1;
        let (et, e0) = (c.strain[tip], c.strain[0]);
        TipPose {
            tensions_n: PerCable::one(tension),
            displacements_mm: PerCable::one(self.colloc_displacement_mm(c, tension)),
            tip_x_mm: c.px[tip],
            tip_y_mm: c.py[tip],
            tip_angle_rad: c.phi[tip] + et.v2.atan2(et.v1),
            tip_frame_angle_rad: c.phi[tip],
            base_angle_rad: c.phi[0] + e0.v2.atan2(e0.v1),
            length_mm: c.sigma[tip],
            iterations: passes,
            tip_z_mm: 0.0,
            frame_3d: None,
        }
    }

    /// Legendre coefficients of the last solve (model-notes §4):
    /// a_i = (2i+1)/ℓ [θ(L) P_i(1) − θ(0) P_i(−1) − ∫ θ P_i'(t) dt], the
    /// integral by the span quadrature (exact for the interpolant).
    ///
    /// Returns the estimated error of the largest a_n, mm⁻¹, and n. The
    /// quadrature of ∫ θ P_n′ dt on a span is exact for the interpolant of
    /// its node values, so it misses about the size of their highest
    /// Chebyshev coefficients times the span's length; an error δθ of the
    /// angles adds (2n+1)/ℓ·δθ·(2 + ∫|P_n′| dt), with ∫|P_n′| dt ≤ √(2n(n+1)).
    pub(super) fn colloc_coefficients(&self, c: &Colloc, basis: LengthBasis, out: &mut [f64]) -> (f64, usize) {
        out.iter_mut().for_each(|a| *a = 0.0);
        if out.is_empty() {
            return (0.0, 0);
        }
        let np = c.np();
        let tip = c.s.len() - 1;
        let ell = c.sigma[tip];
        let theta = |i: usize| c.phi[i] + c.strain[i].v2.atan2(c.strain[i].v1);
        // Per order, the quadrature's error so far; per order and span, the
        // quadrature's sum and the highest Chebyshev coefficients of
        // θ P_n′ dσ/ds, accumulated together (allocation-free: orders past
        // the buffer, which no check allows, get no estimate).
        let estimated = out.len().min(super::ESTIMATED_ORDERS);
        let mut quadrature_error = [0.0f64; super::ESTIMATED_ORDERS];
        let mut sums = [[0.0f64; 1 + TAIL_COEFFICIENTS]; super::ESTIMATED_ORDERS];
        for span in 0..c.spans() {
            sums[..estimated].iter_mut().for_each(|t| *t = [0.0; 1 + TAIL_COEFFICIENTS]);
            for j in 0..np {
                let i = span * np + j;
                let value = theta(i) * 2.0 * c.dsig[i] / ell;
                let mut weights = [c.half[span] * c.q[(np - 1) * np + j] * value; 1 + TAIL_COEFFICIENTS];
                for (r, w) in weights[1..].iter_mut().enumerate() {
                    *w = c.tail[r * np + j] * value;
                }
                let t = 2.0 * c.sigma[i] / ell - 1.0;
                let mut legendre = crate::shape::LegendreSeries::new(t);
                for (n, a) in out.iter_mut().enumerate() {
                    if n > 0 {
                        legendre.advance();
                    }
                    let dp = legendre.derivative();
                    match sums.get_mut(n) {
                        Some(sum) => sum.iter_mut().zip(&weights).for_each(|(acc, w)| *acc += w * dp),
                        None => *a += weights[0] * dp,
                    }
                }
            }
            for ((a, e), sum) in out.iter_mut().zip(&mut quadrature_error).zip(&sums) {
                *a += sum[0];
                *e += 2.0 * c.half[span] * next_coefficient([sum[1], sum[2], sum[3], sum[4]]);
            }
        }
        let (theta0, theta_e) = (theta(0), theta(tip));
        for (n, a) in out.iter_mut().enumerate() {
            let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
            *a = (2 * n + 1) as f64 / ell * (theta_e - sign * theta0 - *a);
        }
        let errors = (0..out.len()).map(|n| {
            let nf = n as f64;
            let angles = self.theta_error_rad * (2.0 + (2.0 * nf * (nf + 1.0)).sqrt());
            quadrature_error.get(n).map_or(f64::INFINITY, |q| (2.0 * nf + 1.0) / ell * (ESTIMATE_SAFETY * q / (c.m * c.m) as f64 + angles))
        });
        let worst = super::largest_error(errors, basis, ell, self.rod.length_mm);
        basis.convert_from_deformed(out, ell, self.rod.length_mm);
        worst
    }

    /// The centreline of the last solve at 2·steps_per_span + 1 evenly spaced
    /// points, interpolated from the nodes (spectrally accurate on each span),
    /// plus one exactly at the anchor of a cable knotted before the tip, where
    /// its path ends: beyond it the channel and cable fields are NaN.
    pub(super) fn colloc_centreline(&self, c: &Colloc) -> Vec<CentrelinePoint> {
        let routing = self.routing.as_ref().expect("routing");
        let np = c.np();
        let count = 2 * self.options.planar_steps_per_span + 1;
        let tension = self.last_tension_n.unwrap_or(0.0);
        let length = self.rod.length_mm;
        let v1: Vec<f64> = c.strain.iter().map(|e| e.v1).collect();
        let v2: Vec<f64> = c.strain.iter().map(|e| e.v2).collect();
        let u: Vec<f64> = c.strain.iter().map(|e| e.u).collect();
        let anchor = self.rod.cable_length_mm();
        let mut samples: Vec<f64> = (0..count).map(|k| length * k as f64 / (count - 1) as f64).collect();
        if anchor < length && !samples.contains(&anchor) {
            samples.insert(samples.partition_point(|&s| s < anchor), anchor);
        }
        samples
            .into_iter()
            .map(|s| {
                // The anchor's sample on the cable's side of its span boundary (the strains jump there).
                let span = c.start[1..].iter().take_while(|&&b| if s == anchor { s > b } else { s >= b }).count();
                let x = ((s - c.start[span]) / c.half[span] - 1.0).clamp(-1.0, 1.0);
                let base = span * np;
                let at = |f: &[f64]| c.interpolate(&f[base..base + np], x);
                let (px, py, phi) = (at(&c.px), at(&c.py), at(&c.phi));
                let (v1, v2, u) = (at(&v1), at(&v2), at(&u));
                let cable = anchor >= length || s <= anchor;
                // No channel and no cable beyond the anchor.
                let yc = if cable { routing.channel_at(s).y_mm } else { f64::NAN };
                CentrelinePoint::from(PlanarPoint {
                    s_mm: s,
                    x_mm: px,
                    y_mm: py,
                    frame_angle_rad: phi,
                    frame_sin_cos: phi.sin_cos(),
                    tangent_angle_rad: phi + v2.atan2(v1),
                    arc_length_mm: at(&c.sigma),
                    v1,
                    v2,
                    u_per_mm: u,
                    channel_y_mm: yc,
                    cable_tension_n: if cable { tension * at(self.friction.ratios()) } else { 0.0 },
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Rod;
    use crate::solver::{PlanarSolver, SolverOptions};

    /// The tip, tip angle and a_0 … a_order of a ladder up to `tension` at
    /// `m` intervals, with the tip's and the coefficients' error estimates.
    fn estimated(a: &Rod, m: usize, y: &[f64], tension: f64, order: usize) -> Option<([f64; 3], Vec<f64>, f64, f64)> {
        let mut sim = PlanarSolver::<Colloc>::new(a, &SolverOptions { nodes_per_span: m, ..SolverOptions::default() }).ok()?;
        sim.set_routing_mm(y).ok()?;
        let rungs = crate::solver::ladder::tension_rungs(tension);
        let mut pose = None;
        for k in 1..=rungs {
            let t = tension * k as f64 / rungs as f64;
            let passes = sim.state.colloc_solve(&mut sim.integrator, t).ok()?;
            pose = Some(sim.state.colloc_pose(&sim.integrator, t, passes));
        }
        let pose = pose?;
        let (theta_error, tip_error) = sim.state.colloc_error_estimate(&sim.integrator);
        sim.state.theta_error_rad = theta_error;
        let mut c = vec![0.0; order + 1];
        let (a_error, _) = sim.state.colloc_coefficients(&sim.integrator, crate::shape::LengthBasis::Rest, &mut c);
        Some(([pose.tip_x_mm, pose.tip_y_mm, pose.tip_angle_rad], c, tip_error, a_error))
    }

    /// The a posteriori estimates bound the errors (against 64 intervals)
    /// on random bodies, routings and tensions, at the orders the table
    /// allows at each resolution, and at the default the thesis grid's
    /// estimates stay well below the tolerances (so sweeps need no probe).
    #[test]
    fn the_error_estimates_bound_the_errors() {
        let mut rng = crate::calibrate::rng::Rng::new(7);
        let mut checked = 0;
        for _ in 0..12 {
            let (a, y, tension) = super::super::tests::random_case(&mut rng);
            let Some((fine, fine_a, _, _)) = estimated(&a, 64, &y, tension, 12) else { continue };
            for m in [6, 8, 10, 12, 16] {
                let order = crate::solver::resolution::REQUIRED_NODES_PER_SPAN.iter().rposition(|&n| n <= m).unwrap().min(12);
                let Some((tip, c, tip_error, a_error)) = estimated(&a, m, &y, tension, order) else { continue };
                let off = (tip[0] - fine[0]).hypot(tip[1] - fine[1]);
                assert!(off <= tip_error + 1e-7, "m {m}: tip off by {off:e} mm, estimated {tip_error:e}");
                for k in 0..=order {
                    assert!((c[k] - fine_a[k]).abs() <= a_error + 1e-9, "m {m}: a_{k} off by {:e}, estimated {a_error:e}", (c[k] - fine_a[k]).abs());
                }
                checked += 1;
            }
        }
        assert!(checked >= 30, "only {checked} cases solved");
        for gravity in [true, false] {
            let mut a = Rod::default();
            a.gravity.enabled = gravity;
            for y in crate::bench::sample_thesis_routings(40, 5.0) {
                let (_, _, tip_error, a_error) = estimated(&a, 10, &y.0, 2.0, 3).unwrap();
                assert!(tip_error < 0.25 * crate::solver::tip_tolerance_mm(a.length_mm), "{y:?}: {tip_error:e} mm");
                assert!(a_error < 0.1 * crate::solver::resolution::ORDER_TOLERANCE_PER_MM, "{y:?}: {a_error:e} mm⁻¹");
            }
        }
    }

    #[test]
    fn friction_grid_weights_interpolate_polynomials_exactly() {
        // The interpolant through m + 1 nodes reproduces any polynomial of
        // degree ≤ m: the weights must give its exact values between nodes.
        let poly = |x: f64| x * x * x - 0.5 * x + 0.2;
        for m in [4, 10, 16] {
            let c = Colloc::new(m, 2);
            let np = m + 1;
            let f: Vec<f64> = c.x.iter().map(|&x| poly(x)).collect();
            for j in 1..np {
                for k in 1..FRICTION_SUBSTEPS {
                    let at = c.x[j - 1] + (c.x[j] - c.x[j - 1]) * k as f64 / FRICTION_SUBSTEPS as f64;
                    let row = &c.fine[((j - 1) * (FRICTION_SUBSTEPS - 1) + (k - 1)) * np..][..np];
                    let via_weights: f64 = row.iter().zip(&f).map(|(w, v)| w * v).sum();
                    assert!((via_weights - poly(at)).abs() < 1e-12, "m {m}, j {j}, k {k}");
                }
            }
        }
    }

    #[test]
    fn integration_matrix_is_exact_for_polynomials() {
        for m in [4, 7, 12, 20] {
            let c = Colloc::new(m, 2);
            let np = m + 1;
            for degree in 0..=m {
                let f: Vec<f64> = c.x.iter().map(|x| x.powi(degree as i32)).collect();
                for j in 0..np {
                    let exact = (c.x[j].powi(degree as i32 + 1) - (-1.0f64).powi(degree as i32 + 1)) / (degree + 1) as f64;
                    let got = c.row_dot(j, &f);
                    assert!((got - exact).abs() < 1e-13, "m={m} degree={degree} j={j}: {got} vs {exact}");
                }
            }
            // Interpolation reproduces polynomials too.
            let f: Vec<f64> = c.x.iter().map(|x| 1.0 + x - 2.0 * x * x).collect();
            assert!((c.interpolate(&f, 0.3) - (1.0 + 0.3 - 0.18)).abs() < 1e-13);
        }
    }
}

/// Points between consecutive nodes at which friction's turning angle is
/// summed (the cable angle is interpolated there).
pub(crate) const FRICTION_SUBSTEPS: usize = 8;
