//! The 3-D solver: equilibrium at a cut with several cables (model-notes §3b
//! generalised), RK4 along the rod, Broyden on gravity's distal moment.
//!
//! Cutting the rod at s and taking the distal part, rod and cables together,
//! as a free body gives, in the body frame,
//!
//! ```text
//! K_se (v − v*) = −Σ τ_i t_i + Rᵀ W(s)          K_se = diag(EA, GA, GA)
//! K_bt u        = −Σ τ_i r_i × t_i + Rᵀ M_W(s)   K_bt = diag(GJ, EI, EI)
//! t_i = q_i / |q_i|,  q_i = v + u × r_i + r_i'
//! ```
//!
//! with W(s) = w (L − s) ĝ the distal weight and M_W(s) its moment about
//! p(s). Cable i contributes only where s < s_k,i (its anchor); beyond it is
//! slack. At each point this is a local 6×6 nonlinear system in (v, u),
//! solved by Newton with the exact Jacobian (dt/dq = (I − t tᵀ)/|q|),
//! warm-started from the same RK4 stage of the previous pass or solve.
//!
//! **Why this and not shooting on the Rucker–Webster ODE.** Shooting needs
//! the six unknowns v(0), u(0) and a 6×6 Jacobian of the tip residual by
//! finite differences (seven integrations per Newton step), and it loses its
//! basin at high tension without continuation. Here the cable loads never
//! need shooting: the tip condition holds by construction at every cut.
//! Without gravity one integration gives the solution. With gravity the only
//! unknown is the 3-vector M_W(0); M_W' = −p' × W, and the residual M_W(L)
//! is nearly the identity in M_W(0) because the rod's weight (0.05 N) is
//! small against the cable loads, so Broyden's method started from the
//! identity (a plain fixed-point sweep on its first step) converges in a
//! few passes with one integration each. Measured: see docs/performance.md.
//!
//! The centreline follows from p' = R v and the quaternion q' = ½ q ⊗ (0, u)
//! (renormalised each step), with RK4 on segments split at the routing's knot
//! (where the channel's second derivative jumps) and at every anchor (where a
//! tension stops).
//!
//! **Coefficients.** The bending curvature of the centreline is the rotation
//! rate of its unit tangent, κ = t̂ × dt̂/ds; in the body frame
//! κ_b = u − (u·v̂) v̂ + v̂ × v̂' with v̂ = v/|v|, and v' comes from
//! differentiating the cut equations along s (one more 6×6 solve with the
//! Newton Jacobian). For a planar rod κ_b·e_z = dθ/ds with θ the tangent
//! angle, so the in-plane series is the planar solver's a_i (model-notes §4).
//! Each series is a_i = (2i + 1)/L ∫ P_i(2σ/ℓ − 1) κ ds over the rest length
//! (σ the deformed arc length, ℓ its total), the thesis's basis; the twist
//! series uses u_1, the torsion of the body frame. Where a cable ends
//! before the tip, v jumps (its tension stops) and the tangent turns at a
//! point: κ has a Dirac part there, the rotation vector from v̂ just before
//! the anchor to v̂ just after it, which the bending series add at that σ
//! (the planar a_i count the same jump of θ).

use super::cable::{Channel, ChannelPoint};
use super::error::SpatialError;
use crate::solver::{SolveFailure, SolverOptions};
use super::Actuator;
use crate::solver::Backend;
use crate::solver::result::{CableAtNode, CentrelinePoint, PerCable, TipFrame, TipPose};
use crate::model::Rod;
use crate::numerics::{rk4_step, Rk4Scratch};
use crate::shape::{self, LengthBasis};
use nalgebra::{Matrix3, Matrix6, Quaternion, UnitQuaternion, Vector3, Vector6, LU, U6};

type V3 = Vector3<f64>;
type M3 = Matrix3<f64>;
/// LU factors (partial pivoting) of a cut-equation Jacobian.
type Factors = LU<f64, U6, U6>;

/// A gravity pass started from a moment residual below this (N·mm) is
/// expected to be the last (Broyden cuts the residual by 100× or more per
/// pass), so it also computes the coefficients; if it is not the last,
/// [`SpatialRk4::coefficients`] runs one more pass.
const LAST_PASS_RESIDUAL_N_MM: f64 = 1e-5;

/// Breakpoints closer than this are one (mm): an anchor this close to a
/// knot ends its cable at the knot.
const ANCHOR_TOLERANCE_MM: f64 = 1e-9;

/// Highest coefficient order the spatial solver reports.
pub const MAX_SPATIAL_ORDER: usize = 8;

/// Fewest RK4 steps per span at which a_0 … a_k of every series lie within
/// [`crate::solver::resolution::ORDER_TOLERANCE_PER_MM`] of a 128-step solve,
/// indexed by k. Measured on a two-cable spatial actuator at 2 N and 1 N
/// (±4 mm S-shaped routings) on the grid 4, 6, 8, 10, 12, 16, 24; an entry
/// within a factor 1.5 of the tolerance was moved to the next grid point,
/// and the table made monotone. At the default 10 steps a_5 is resolved.
pub const REQUIRED_SPATIAL_STEPS_PER_SPAN: [usize; MAX_SPATIAL_ORDER + 1] = [4, 4, 4, 4, 6, 6, 12, 12, 24];

/// What a pass records at one step point of the rod (the centreline's
/// nodes are made from these when asked for, [`SpatialRk4::centreline`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct NodeRecord {
    /// Index of the half-step point (its channels in `chan`).
    point: usize,
    /// Rest arc length s, mm.
    s_mm: f64,
    /// Centreline position, mm.
    p_mm: [f64; 3],
    /// Body frame: rows of R.
    rotation: [[f64; 3]; 3],
    /// Strain v (body frame).
    v: [f64; 3],
    /// Curvature u (body frame), 1/mm.
    u_per_mm: [f64; 3],
    /// Deformed arc length σ, mm.
    arc_length_mm: f64,
}

/// Per-point, per-cable channel data in body coordinates.
#[derive(Debug, Clone, Copy)]
struct Chan {
    r: V3,
    dr: V3,
    d2r: V3,
}

impl From<ChannelPoint> for Chan {
    fn from(c: ChannelPoint) -> Self {
        Self {
            r: V3::new(0.0, c.r_mm[0], c.r_mm[1]),
            dr: V3::new(0.0, c.dr_ds[0], c.dr_ds[1]),
            d2r: V3::new(0.0, c.d2r_ds2[0], c.d2r_ds2[1]),
        }
    }
}

impl Chan {
    /// The cable's unit direction t = q/|q| in the body frame and |q|, with
    /// q = v + u × r + r' (the channel's tangent on the deformed rod).
    #[inline]
    fn direction(&self, v: &V3, u: &V3) -> (V3, f64) {
        let q = v + u.cross(&self.r) + self.dr;
        let n = q.norm();
        (q / n, n)
    }
}

/// The cables that pull at a point: (channel, tension > 0).
#[inline]
fn pulling<'a>(chans: &'a [Chan], tensions: &'a [f64]) -> impl Iterator<Item = (&'a Chan, f64)> + 'a {
    chans.iter().zip(tensions.iter().copied()).filter(|&(_, tau)| tau != 0.0)
}

/// (v, u) of a local solution.
#[inline]
fn strains(x: &[f64; 6]) -> (V3, V3) {
    (V3::new(x[0], x[1], x[2]), V3::new(x[3], x[4], x[5]))
}

/// One RK4 segment: [start, start + steps·h].
#[derive(Debug, Clone)]
struct Segment {
    start_mm: f64,
    h_mm: f64,
    steps: usize,
    /// Index of the segment's first half-step point.
    point0: usize,
    /// Index of the segment's first step (warm-start slots).
    step0: usize,
    /// Whether each cable is loaded on this segment (false beyond its anchor).
    active: Vec<bool>,
}

/// State integrated along s: p (0..3), q (3..7: w, i, j, k), M_W (7..10), σ (10).
type State = [f64; 11];

/// The local solution at one point and, when asked, the curvature vector.
struct Local {
    x: [f64; 6],
    kappa: V3,
}

/// Reusable spatial solver for one actuator: set the cables, then solve.
#[derive(Debug, Clone)]
pub struct SpatialRk4 {
    rod: Rod,
    stiff: [f64; 6],
    /// Weight per unit rest length along the gravity direction, N/mm (global vector).
    weight: V3,
    options: SolverOptions,
    cables: usize,
    tensions_n: Vec<f64>,
    segments: Vec<Segment>,
    points_s: Vec<f64>,
    chan: Vec<Chan>,
    /// Warm start per step and RK4 stage (4 per step), plus one per segment end.
    warm: Vec<[f64; 6]>,
    m0: V3,
    /// The solve before the last: its warm starts, gravity moment and
    /// tensions; with the last solve's they extrapolate the next one.
    warm_prev: Vec<[f64; 6]>,
    m0_prev: V3,
    /// Tensions of the last two successful solves (newest first), N.
    history: Vec<Vec<f64>>,
    binv: M3,
    nodes: Vec<NodeRecord>,
    /// Each cable's anchor (or the tip), mm.
    anchors_mm: Vec<f64>,
    /// The rod's rest curvature about body z, 1/mm ([`Rod::rest_curvature_per_mm`]).
    rest_u3_per_mm: f64,
    /// ∫ (σ/L)^j κ_k ds of the last full pass, k = twist, about y, about z.
    moments: [[f64; MAX_SPATIAL_ORDER + 1]; 3],
    /// Whether `moments` belong to the last solve.
    moments_valid: bool,
    /// Newton's last factors per warm-start slot, for chord passes (`None`
    /// until a Newton solve there, and after a failed solve).
    lus: Vec<Option<Factors>>,
    /// This pass reuses `lus` (simplified Newton).
    chord: bool,
    /// This pass computes the curvature vector and the coefficient moments.
    with_kappa: bool,
    last: Option<TipPose>,
}

impl SpatialRk4 {
    /// A solver for `actuator` (its cables, rod, torsion and gravity).
    pub fn new(actuator: &Actuator, options: &SolverOptions) -> Result<Self, SpatialError> {
        let channels = validated_channels(actuator, Backend::SpatialRk4)?;
        if options.spatial_steps_per_span < 2 {
            return Err(SpatialError::StepsPerSpan(options.spatial_steps_per_span));
        }
        if !(options.spatial_moment_tolerance_n_mm.is_finite() && options.spatial_moment_tolerance_n_mm > 0.0) {
            return Err(SpatialError::MomentTolerance);
        }
        let rod = actuator.rod.clone();
        let gj = actuator.torsional_rigidity_n_mm2();
        let stiff = [rod.ea_n, rod.ga_n, rod.ga_n, gj, rod.ei_n_mm2, rod.ei_n_mm2];
        let g = actuator.gravity_unit()?;
        let weight = V3::from(g) * rod.weight_n_per_mm();
        let length = rod.length_mm;
        // Breakpoints: clamp, every cable's knot (each channel spans its
        // cable, [0, anchor]), anchors, tip.
        let mut cuts = vec![0.0, length];
        cuts.extend(channels.iter().map(Channel::knot_mm));
        cuts.extend(actuator.cables.iter().filter_map(|c| c.anchor_mm).filter(|&a| a < length));
        cuts.sort_by(f64::total_cmp);
        cuts.dedup_by(|a, b| (*a - *b).abs() < ANCHOR_TOLERANCE_MM);
        let span = length / 2.0;
        let mut segments = Vec::new();
        let (mut point0, mut step0) = (0, 0);
        let mut points_s = Vec::new();
        for w in cuts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let steps = ((options.spatial_steps_per_span as f64 * (b - a) / span).ceil() as usize).max(2);
            let h = (b - a) / steps as f64;
            let mid = 0.5 * (a + b);
            let active = actuator.cables.iter().map(|c| mid < c.anchor_or_tip_mm(length)).collect();
            for k in 0..=2 * steps {
                points_s.push(if k == 2 * steps { b } else { a + 0.5 * h * k as f64 });
            }
            segments.push(Segment { start_mm: a, h_mm: h, steps, point0, step0, active });
            point0 += 2 * steps + 1;
            step0 += steps;
        }
        let n = channels.len();
        let mut chan = Vec::with_capacity(points_s.len() * n);
        for &s in &points_s {
            chan.extend(channels.iter().map(|c: &Channel| Chan::from(c.at(s))));
        }
        let straight = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        Ok(Self {
            rod,
            stiff,
            weight,
            options: options.clone(),
            cables: n,
            tensions_n: actuator.cables.iter().map(|c| c.tension_n).collect(),
            segments,
            points_s,
            chan,
            warm: vec![straight; 4 * step0 + cuts.len()],
            m0: V3::zeros(),
            warm_prev: vec![straight; 4 * step0 + cuts.len()],
            m0_prev: V3::zeros(),
            history: Vec::new(),
            binv: M3::identity(),
            nodes: Vec::new(),
            anchors_mm: actuator.cables.iter().map(|c| c.anchor_or_tip_mm(length)).collect(),
            rest_u3_per_mm: actuator.rod.rest_curvature_per_mm,
            moments: [[0.0; MAX_SPATIAL_ORDER + 1]; 3],
            moments_valid: false,
            lus: vec![None; 4 * step0 + cuts.len()],
            chord: false,
            with_kappa: false,
            last: None,
        })
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
    /// warm-started from the previous solve.
    pub fn solve(&mut self, tensions_n: &[f64]) -> Result<TipPose, SpatialError> {
        SpatialError::check_tensions(tensions_n, self.cables)?;
        self.tensions_n.copy_from_slice(tensions_n);
        self.last = None;
        let tensions = self.tensions_n();
        self.predict(&tensions);
        let result = self.solve_inner();
        if result.is_ok() {
            self.history.insert(0, tensions);
            self.history.truncate(2);
        } else {
            self.history.clear();
            // A failed solve leaves no sensible warm start.
            self.warm.iter_mut().for_each(|w| *w = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
            self.lus.iter_mut().for_each(|l| *l = None);
            self.chord = false;
            self.moments_valid = false;
            self.m0 = V3::zeros();
            self.binv = M3::identity();
        }
        result.map_err(SpatialError::from)
    }

    /// Warm start for the next solve. When the tension step continues the
    /// last one (the same direction, as in a sweep's ladder), every point's
    /// strains and the gravity moment are extrapolated linearly from the last
    /// two solves: this takes the first residual from ~3e-2 to ~1e-4 N·mm
    /// and saves about one pass and a Newton step per point. Otherwise the
    /// last solve is the warm start.
    fn predict(&mut self, tensions: &[f64]) {
        let lambda = match self.history.as_slice() {
            [t1, t2] => {
                let d1: Vec<f64> = tensions.iter().zip(t1).map(|(a, b)| a - b).collect();
                let d0: Vec<f64> = t1.iter().zip(t2).map(|(a, b)| a - b).collect();
                let dd: f64 = d0.iter().map(|d| d * d).sum();
                let lambda = if dd > 0.0 { d1.iter().zip(&d0).map(|(a, b)| a * b).sum::<f64>() / dd } else { 0.0 };
                let off: f64 = d1.iter().zip(&d0).map(|(a, b)| (a - lambda * b).powi(2)).sum::<f64>().sqrt();
                let n1: f64 = d1.iter().map(|d| d * d).sum::<f64>().sqrt();
                (dd > 0.0 && off <= 1e-9 * (1.0 + n1) && lambda.abs() <= 2.0).then_some(lambda)
            }
            _ => None,
        };
        match lambda {
            Some(l) => {
                for (p, w) in self.warm_prev.iter_mut().zip(&self.warm) {
                    *p = std::array::from_fn(|i| w[i] + l * (w[i] - p[i]));
                }
                std::mem::swap(&mut self.warm, &mut self.warm_prev);
                let m1 = self.m0;
                self.m0 = m1 + l * (m1 - self.m0_prev);
                self.m0_prev = m1;
            }
            None => {
                self.warm_prev.copy_from_slice(&self.warm);
                self.m0_prev = self.m0;
            }
        }
    }

    fn solve_inner(&mut self) -> Result<TipPose, SolveFailure> {
        let gravity = self.weight.norm() > 0.0;
        let mut passes = 1;
        // The first pass of a solve refactors everything (the tensions
        // changed); later gravity passes move the strains by ~|δM_W|/EI and
        // reuse the factors (chord iterations). The curvature vector (for
        // the coefficients) is worked out only in a pass likely to be the
        // last: without gravity the only one, with gravity once the moment
        // residual is small enough for the next pass to meet the tolerance.
        self.chord = false;
        self.with_kappa = !gravity;
        let (mut end, mut tip) = self.pass(if gravity { self.m0 } else { V3::zeros() })?;
        if gravity {
            let mut m = self.m0;
            let mut f = residual(&end);
            let mut b = self.binv;
            while f.norm() > self.options.spatial_moment_tolerance_n_mm {
                if passes >= self.options.spatial_max_passes {
                    return Err(SolveFailure::GravityNotConverged { passes, residual_n_mm: f.norm() });
                }
                let dm = -(b * f);
                let m_new = m + dm;
                self.chord = true;
                self.with_kappa = f.norm() < LAST_PASS_RESIDUAL_N_MM;
                let (e, t) = self.pass(m_new)?;
                passes += 1;
                let f_new = residual(&e);
                let df = f_new - f;
                let bdf = b * df;
                let denom = dm.dot(&bdf);
                if denom.abs() > 1e-300 {
                    b += (dm - bdf) * (dm.transpose() * b) / denom;
                }
                m = m_new;
                f = f_new;
                end = e;
                tip = t;
            }
            self.m0 = m;
            self.binv = b;
        }
        self.moments_valid = self.with_kappa;
        self.chord = false;
        let q = quat(&end);
        let r = q.to_rotation_matrix().into_inner();
        let v = V3::new(tip[0], tip[1], tip[2]);
        let t = (r * v).normalize();
        // At the clamp R = I: the base tangent is v(0)'s direction.
        let base_v = self.nodes.first().map_or([1.0, 0.0, 0.0], |n| n.v);
        let mut tensions_n = PerCable::filled(self.cables, 0.0);
        for (out, t) in tensions_n.iter_mut().zip(&self.tensions_n) {
            *out = *t;
        }
        let pose = TipPose {
            tensions_n,
            displacements_mm: PerCable::filled(self.cables, f64::NAN),
            tip_x_mm: end[0],
            tip_y_mm: end[1],
            tip_z_mm: end[2],
            tip_angle_rad: t[1].atan2(t[0]),
            tip_frame_angle_rad: r[(1, 0)].atan2(r[(0, 0)]),
            base_angle_rad: base_v[1].atan2(base_v[0]),
            length_mm: end[10],
            iterations: passes,
            frame_3d: Some(TipFrame { tangent: [t[0], t[1], t[2]], body_y_axis: [r[(0, 1)], r[(1, 1)], r[(2, 1)]] }),
        };
        self.last = Some(pose);
        Ok(pose)
    }

    /// One integration from the clamp with gravity's moment `m0` at the
    /// clamp. Records the nodes and accumulates the coefficient moments
    /// ∫ (σ/L)^j κ_k ds (RK4 quadrature with the stage values: a few
    /// back-substitutions, much cheaper than another pass). Returns the tip
    /// state and the local solution there.
    fn pass(&mut self, m0: V3) -> Result<(State, [f64; 6]), SolveFailure> {
        let mut y: State = [0.0; 11];
        y[3] = 1.0;
        y[7..10].copy_from_slice(m0.as_slice());
        let mut moments = [[0.0; MAX_SPATIAL_ORDER + 1]; 3];
        let length = self.rod.length_mm;
        self.nodes.clear();
        let mut tip = [0.0; 6];
        let segments = std::mem::take(&mut self.segments);
        let mut scratch = Rk4Scratch::default();
        // Where a cable ends (its anchor) the strains jump, and so does the
        // tangent: the curvature has a Dirac part there, the rotation from
        // the tangent before to the one after. `ending` holds v just before
        // such a point until the next segment's first stage gives v after it.
        let mut ending: Option<V3> = None;
        let result = (|| -> Result<(), SolveFailure> {
            for (si, seg) in segments.iter().enumerate() {
                let h = seg.h_mm;
                for j in 0..seg.steps {
                    let k0 = seg.point0 + 2 * j;
                    let slot = 4 * (seg.step0 + j);
                    let s0 = seg.start_mm + j as f64 * h;
                    rk4_step(&mut y, h, &mut scratch, |stage, dy| {
                        let i = stage.index;
                        let ys = stage.state;
                        let (f, l) = self.deriv(seg, k0 + stage.half_steps, slot + i, ys)?;
                        if i == 0 {
                            self.record(k0, s0, ys, &l.x);
                        }
                        if self.with_kappa {
                            // RK4 quadrature of the moments with the stage values.
                            let x = ys[10] / length;
                            for (series, kappa) in moments.iter_mut().zip([l.x[3], l.kappa[1], l.kappa[2]]) {
                                let mut pw = stage.weight_sixths * h / 6.0 * kappa;
                                for c in series.iter_mut() {
                                    *c += pw;
                                    pw *= x;
                                }
                            }
                            if let Some(before) = ending.take() {
                                let jump = tangent_turn(&before, &V3::new(l.x[0], l.x[1], l.x[2]));
                                for (series, kappa) in moments[1..].iter_mut().zip([jump[1], jump[2]]) {
                                    let mut pw = kappa;
                                    for c in series.iter_mut() {
                                        *c += pw;
                                        pw *= x;
                                    }
                                }
                            }
                        }
                        *dy = f;
                        Ok::<(), SolveFailure>(())
                    })?;
                    let norm = (y[3] * y[3] + y[4] * y[4] + y[5] * y[5] + y[6] * y[6]).sqrt();
                    y[3..7].iter_mut().for_each(|c| *c /= norm);
                }
                let k = seg.point0 + 2 * seg.steps;
                if si + 1 == segments.len() {
                    let slot = self.warm.len() - 1;
                    let (_, l) = self.deriv(seg, k, slot, &y)?;
                    tip = l.x;
                    self.record(k, length, &y, &l.x);
                } else if self.with_kappa && seg.active != segments[si + 1].active {
                    // The local solution just before the segment's end, in a
                    // slot of its own (one per segment end), warm-started
                    // from the last stage's.
                    let slot = self.warm.len() - segments.len() - 1 + si;
                    if self.lus[slot].is_none() {
                        self.warm[slot] = self.warm[4 * (seg.step0 + seg.steps) - 1];
                    }
                    let (_, l) = self.deriv(seg, k, slot, &y)?;
                    ending = Some(V3::new(l.x[0], l.x[1], l.x[2]));
                }
            }
            Ok(())
        })();
        self.segments = segments;
        if self.with_kappa {
            self.moments = moments;
        }
        result.map(|()| (y, tip))
    }

    fn record(&mut self, point: usize, s_mm: f64, y: &State, x: &[f64; 6]) {
        let r = quat(y).to_rotation_matrix().into_inner();
        self.nodes.push(NodeRecord {
            point,
            s_mm,
            p_mm: [y[0], y[1], y[2]],
            rotation: std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)])),
            v: [x[0], x[1], x[2]],
            u_per_mm: [x[3], x[4], x[5]],
            arc_length_mm: y[10],
        });
    }

    /// Derivative of the state at point `k` (half-step index) and the local solution.
    fn deriv(&mut self, seg: &Segment, k: usize, slot: usize, y: &State) -> Result<(State, Local), SolveFailure> {
        let q = quat(y);
        let r = q.to_rotation_matrix().into_inner();
        let s = self.points_s[k];
        let w_dist = self.weight * (self.rod.length_mm - s);
        let nw = r.transpose() * w_dist;
        let mw = r.transpose() * V3::new(y[7], y[8], y[9]);
        let local = self.local_solve(seg, k, slot, nw, mw, r)?;
        let v = V3::new(local.x[0], local.x[1], local.x[2]);
        let u = V3::new(local.x[3], local.x[4], local.x[5]);
        let dp = r * v;
        let qv = V3::new(y[4], y[5], y[6]);
        let dqw = -0.5 * qv.dot(&u);
        let dqv = 0.5 * (y[3] * u + qv.cross(&u));
        let dmw = -dp.cross(&w_dist);
        let d = [dp[0], dp[1], dp[2], dqw, dqv[0], dqv[1], dqv[2], dmw[0], dmw[1], dmw[2], v.norm()];
        Ok((d, local))
    }

    /// Newton on the cut equations at point `k`, warm-started from `slot`,
    /// then the curvature vector κ_b from x' (with the last Newton
    /// Jacobian's factors: it is within one converged step of the solution's).
    fn local_solve(&mut self, seg: &Segment, k: usize, slot: usize, nw: V3, mw: V3, r: M3) -> Result<Local, SolveFailure> {
        let chans = &self.chan[k * self.cables..(k + 1) * self.cables];
        let mut taus = [0.0; super::cable::MAX_CABLES];
        for (i, (&t, &on)) in self.tensions_n.iter().zip(&seg.active).enumerate() {
            taus[i] = if on { t } else { 0.0 };
        }
        let tensions = &taus[..self.cables];
        let mut x = self.warm[slot];
        if let (true, Some(lu)) = (self.chord, &self.lus[slot]) {
            for _ in 0..4 {
                let mut dx = Vector6::from(self.residual_only(&x, chans, tensions, nw, mw).map(|v| -v));
                if !lu.solve_mut(&mut dx) {
                    break;
                }
                let mut big = 0.0f64;
                for i in 0..6 {
                    x[i] += dx[i];
                    big = big.max(dx[i].abs());
                }
                // Contraction ~|ΔJ|/|J| ≈ 1e-4: a step of 1e-8 leaves ~1e-12.
                if big < 1e-8 && x.iter().all(|v| v.is_finite()) {
                    self.warm[slot] = x;
                    let kappa = if self.with_kappa { self.curvature(&x, chans, tensions, nw, mw, r, lu, true) } else { V3::zeros() };
                    return Ok(Local { x, kappa });
                }
            }
            x = self.warm[slot];
        }
        let mut converged = None;
        for _ in 0..100 {
            let (f, j) = self.residual_jacobian(&x, chans, tensions, nw, mw);
            let lu = j.lu();
            let mut dx = Vector6::from(f.map(|v| -v));
            // A singular Jacobian (or a non-finite one: NaN fills the step)
            // ends Newton as not converged.
            if !lu.solve_mut(&mut dx) || !dx.iter().all(|d| d.is_finite()) {
                break;
            }
            // Keep the axial stretch positive: a Newton step through v1 = 0
            // would fold the rod onto itself.
            let mut lambda = 1.0;
            while x[0] + lambda * dx[0] < 0.05 && lambda > 1e-3 {
                lambda *= 0.5;
            }
            // Far from the solution (a large step: a cold start or a big
            // tension step), backtrack until the residual falls, so that
            // Newton cannot jump into another branch of t_i = q_i/|q_i|.
            if dx.iter().fold(0.0f64, |m, d| m.max(d.abs())) > 0.02 {
                let norm = |r: [f64; 6]| r.iter().map(|v| v * v).sum::<f64>();
                let f0 = norm(f);
                while lambda > 1e-3 {
                    let trial: [f64; 6] = std::array::from_fn(|i| x[i] + lambda * dx[i]);
                    let ft = norm(self.residual_only(&trial, chans, tensions, nw, mw));
                    if ft.is_finite() && ft < f0 {
                        break;
                    }
                    lambda *= 0.5;
                }
            }
            let mut big = 0.0f64;
            for i in 0..6 {
                x[i] += lambda * dx[i];
                big = big.max(dx[i].abs());
            }
            if !x.iter().all(|v| v.is_finite()) {
                break;
            }
            // Quadratic convergence: after a step of 1e-8 the error is ~1e-16.
            if big < 1e-8 {
                converged = Some(lu);
                break;
            }
        }
        let Some(lu) = converged else {
            return Err(SolveFailure::CutEquationsNotConverged { s_mm: self.points_s[k] });
        };
        self.warm[slot] = x;
        self.lus[slot] = Some(lu);
        let kappa = if self.with_kappa { self.curvature(&x, chans, tensions, nw, mw, r, &lu, false) } else { V3::zeros() };
        Ok(Local { x, kappa })
    }

    /// The curvature vector κ_b = u − (u·v̂) v̂ + v̂ × v̂' at the solution
    /// `x`, with x' from differentiating the cut equations along s:
    /// J x' = −∂G/∂s. `lu` factors J or, in a chord pass (`refine`), a
    /// Jacobian within ~1e-4 of it; then one step of iterative refinement
    /// with the exact product J·x' brings x' to ~1e-8 relative.
    #[allow(clippy::too_many_arguments)]
    fn curvature(&self, x: &[f64; 6], chans: &[Chan], tensions: &[f64], nw: V3, mw: V3, r: M3, lu: &Factors, refine: bool) -> V3 {
        let (v, u) = strains(x);
        // ∂G/∂s at fixed (v, u): the channel's motion, then the body-frame
        // change of the distal loads.
        let mut gs_f = V3::zeros();
        let mut gs_m = V3::zeros();
        for (c, tau) in pulling(chans, tensions) {
            let (t, n) = c.direction(&v, &u);
            let b = u.cross(&c.dr) + c.d2r;
            let pb = (b - t * t.dot(&b)) / n;
            gs_f += tau * pb;
            gs_m += tau * (c.dr.cross(&t) + c.r.cross(&pb));
        }
        let nw_s = -u.cross(&nw) - r.transpose() * self.weight;
        let mw_s = -u.cross(&mw) - v.cross(&nw);
        gs_f -= nw_s;
        gs_m -= mw_s;
        let rhs = Vector6::new(-gs_f[0], -gs_f[1], -gs_f[2], -gs_m[0], -gs_m[1], -gs_m[2]);
        // The factors were invertible when they were made: a solve cannot fail.
        let mut xs = rhs;
        lu.solve_mut(&mut xs);
        if refine {
            for _ in 0..1 {
                let jx = self.jacobian_times(x, chans, tensions, &xs.into());
                let mut d = rhs - Vector6::from(jx);
                lu.solve_mut(&mut d);
                xs += d;
            }
        }
        let vs = V3::new(xs[0], xs[1], xs[2]);
        let speed = v.norm();
        let vh = v / speed;
        let vh_s = (vs - vh * vh.dot(&vs)) / speed;
        u - vh * u.dot(&vh) + vh.cross(&vh_s)
    }

    /// J(x)·w without forming J: δq_i = w_v + w_u × r_i, δt_i = P_i δq_i.
    fn jacobian_times(&self, x: &[f64; 6], chans: &[Chan], tensions: &[f64], w: &[f64; 6]) -> [f64; 6] {
        let k = &self.stiff;
        let (v, u) = strains(x);
        let (wv, wu) = strains(w);
        let mut jf = V3::new(k[0] * w[0], k[1] * w[1], k[2] * w[2]);
        let mut jm = V3::new(k[3] * w[3], k[4] * w[4], k[5] * w[5]);
        for (c, tau) in pulling(chans, tensions) {
            let (t, n) = c.direction(&v, &u);
            let dq = wv + wu.cross(&c.r);
            let dt = (dq - t * t.dot(&dq)) * (tau / n);
            jf += dt;
            jm += c.r.cross(&dt);
        }
        [jf[0], jf[1], jf[2], jm[0], jm[1], jm[2]]
    }

    /// The rod's part of the residual: K_se (v − v*) − Rᵀ W and
    /// K_bt (u − u*) − Rᵀ M_W (u* = (0, 0, rest curvature)).
    #[inline]
    fn elastic_residual(&self, x: &[f64; 6], nw: V3, mw: V3) -> (V3, V3) {
        let k = &self.stiff;
        (
            V3::new(k[0] * (x[0] - 1.0), k[1] * x[1], k[2] * x[2]) - nw,
            V3::new(k[3] * x[3], k[4] * x[4], k[5] * (x[5] - self.rest_u3_per_mm)) - mw,
        )
    }

    /// Residual G(x) of the cut equations (chord iterations).
    fn residual_only(&self, x: &[f64; 6], chans: &[Chan], tensions: &[f64], nw: V3, mw: V3) -> [f64; 6] {
        let (v, u) = strains(x);
        let (mut ff, mut fm) = self.elastic_residual(x, nw, mw);
        for (c, tau) in pulling(chans, tensions) {
            let (t, _) = c.direction(&v, &u);
            ff += tau * t;
            fm += tau * c.r.cross(&t);
        }
        [ff[0], ff[1], ff[2], fm[0], fm[1], fm[2]]
    }

    /// Residual G(x) of the cut equations and its Jacobian.
    fn residual_jacobian(&self, x: &[f64; 6], chans: &[Chan], tensions: &[f64], nw: V3, mw: V3) -> ([f64; 6], Matrix6<f64>) {
        let k = &self.stiff;
        let (v, u) = strains(x);
        let (mut ff, mut fm) = self.elastic_residual(x, nw, mw);
        let mut jvv = M3::from_diagonal(&V3::new(k[0], k[1], k[2]));
        let mut jvu = M3::zeros();
        let mut juv = M3::zeros();
        let mut juu = M3::from_diagonal(&V3::new(k[3], k[4], k[5]));
        for (c, tau) in pulling(chans, tensions) {
            let (t, n) = c.direction(&v, &u);
            let a = (M3::identity() - t * t.transpose()) * (tau / n);
            let sk = c.r.cross_matrix();
            ff += tau * t;
            fm += tau * c.r.cross(&t);
            let sa = sk * a;
            jvv += a;
            jvu -= a * sk;
            juv += sa;
            juu -= sa * sk;
        }
        let mut j = Matrix6::zeros();
        j.fixed_view_mut::<3, 3>(0, 0).copy_from(&jvv);
        j.fixed_view_mut::<3, 3>(0, 3).copy_from(&jvu);
        j.fixed_view_mut::<3, 3>(3, 0).copy_from(&juv);
        j.fixed_view_mut::<3, 3>(3, 3).copy_from(&juu);
        ([ff[0], ff[1], ff[2], fm[0], fm[1], fm[2]], j)
    }

    /// The pose of the last successful solve.
    pub fn pose(&self) -> Option<TipPose> {
        self.last
    }

    /// The centreline of the last successful solve at the step points,
    /// clamp to tip, with every cable's channel, path and tension (none
    /// beyond a cable's anchor; a node lies exactly at each anchor).
    pub fn centreline(&self) -> Vec<CentrelinePoint> {
        assert!(self.last.is_some(), "centreline needs a successful solve");
        self.nodes
            .iter()
            .map(|n| {
                let mut node = CentrelinePoint {
                    s_mm: n.s_mm,
                    x_mm: n.p_mm[0],
                    y_mm: n.p_mm[1],
                    z_mm: n.p_mm[2],
                    rotation: n.rotation,
                    // The body x axis and the tangent R v, projected on the x–y plane.
                    frame_angle_rad: n.rotation[1][0].atan2(n.rotation[0][0]),
                    tangent_angle_rad: (0..3).map(|j| n.rotation[1][j] * n.v[j]).sum::<f64>().atan2((0..3).map(|j| n.rotation[0][j] * n.v[j]).sum::<f64>()),
                    arc_length_mm: n.arc_length_mm,
                    v: n.v,
                    u_per_mm: n.u_per_mm,
                    cables: PerCable::filled(self.cables, CableAtNode::NONE),
                };
                let chans = &self.chan[n.point * self.cables..(n.point + 1) * self.cables];
                for (i, (c, &anchor)) in chans.iter().zip(&self.anchors_mm).enumerate() {
                    // Up to the node at the anchor, where the cable ends.
                    if n.s_mm <= anchor + ANCHOR_TOLERANCE_MM {
                        node.cables[i] = CableAtNode {
                            channel_mm: [c.r[1], c.r[2]],
                            position_mm: node.body_point_mm(c.r[1], c.r[2]),
                            tension_n: self.tensions_n[i],
                        };
                    }
                }
                node
            })
            .collect()
    }

    /// Legendre coefficients of the last solve, order `order`, in `basis`:
    /// `[twist, bending about body y, bending about body z]`, each
    /// a_0 … a_order in 1/mm (see the module comment), from the moments the
    /// last (converged) pass accumulated.
    pub fn coefficients(&mut self, order: usize, basis: LengthBasis) -> Result<[Vec<f64>; 3], SpatialError> {
        self.settle_moments()?;
        check_order(order, &self.options)?;
        Ok(self.coefficients_unchecked(order, basis))
    }

    /// Makes the coefficient moments those of the last solve.
    pub(crate) fn settle_moments(&mut self) -> Result<(), SpatialError> {
        assert!(self.last.is_some(), "coefficients needs a successful solve");
        if !self.moments_valid {
            // The converged pass was a chord pass: one full pass at the
            // converged moment (warm: one Newton step per point).
            let m0 = if self.weight.norm() > 0.0 { self.m0 } else { V3::zeros() };
            self.with_kappa = true;
            self.pass(m0)?;
            self.moments_valid = true;
        }
        Ok(())
    }

    /// [`SpatialRk4::coefficients`] of the last solve without the
    /// order check (the error estimate's coarse solve computes the same
    /// orders at half the steps); needs valid moments.
    pub(crate) fn coefficients_unchecked(&self, order: usize, basis: LengthBasis) -> [Vec<f64>; 3] {
        let moments = &self.moments;
        let length = self.rod.length_mm;
        let ell = self.last.expect("checked").length_mm;
        let ratio = length / ell;
        let factor = match basis {
            LengthBasis::Rest => 1.0,
            LengthBasis::Deformed => ratio,
        };
        // P_i(2σ/ℓ − 1) in powers of σ/ℓ = (σ/L)·(L/ℓ): the moments are in σ/L.
        let powers = shape::shifted_legendre_powers(order);
        let out = std::array::from_fn(|k| {
            (0..=order)
                .map(|i| {
                    let mut sum = 0.0;
                    let mut pw = 1.0;
                    for (coefficient, c) in powers[i].iter().zip(&moments[k]) {
                        sum += coefficient * pw * c;
                        pw *= ratio;
                    }
                    factor * (2 * i + 1) as f64 / length * sum
                })
                .collect()
        });
        out
    }
}

/// The spatial RK4 reference: the thesis's uniform rod without effects.
impl crate::solver::Solver for SpatialRk4 {
    type Error = SpatialError;
    fn backend(&self) -> Backend {
        Backend::SpatialRk4
    }
    fn solve_tensions(&mut self, tensions_n: &[f64]) -> Result<TipPose, SpatialError> {
        self.solve(tensions_n)
    }
    /// It models no effect a hold acts on (friction, creep).
    fn hold_next(&mut self, _hold: crate::solver::Hold) {}
    fn centreline(&self) -> Vec<CentrelinePoint> {
        SpatialRk4::centreline(self)
    }
    /// Without the order check (a refinement's coarse solve computes the
    /// same orders at half the steps); refuses a pose or coefficients that
    /// are not finite.
    fn coefficients(&mut self, order: usize, basis: LengthBasis) -> Result<[Vec<f64>; 3], SpatialError> {
        let pose = self.last.expect("coefficients needs a successful solve");
        self.settle_moments()?;
        let a = self.coefficients_unchecked(order, basis);
        let finite = pose.tip_mm().iter().chain(&[pose.length_mm, pose.angle_from_clamp_axis_rad()]).chain(a.iter().flatten()).all(|v| v.is_finite());
        if !finite {
            return Err(SolveFailure::NonFinite { s_mm: None }.into());
        }
        Ok(a)
    }
}

/// Checks `actuator` itself ([`Actuator::channels`]) and that `backend`
/// models it with the default settings ([`Backend::check`]); builds the
/// cables' channels.
pub fn validated_channels(actuator: &Actuator, backend: Backend) -> Result<Vec<Channel>, SpatialError> {
    let channels = actuator.channels()?;
    backend.check(actuator, &crate::solver::SolverOptions::default(), crate::solver::Given::default())?;
    Ok(channels)
}

/// Checks the spatial backends' settings of `options` (the message names
/// the setting and its range).
pub(crate) fn check_options(options: &SolverOptions) -> Result<(), SpatialError> {
    if options.spatial_steps_per_span < 2 {
        return Err(SpatialError::StepsPerSpan(options.spatial_steps_per_span));
    }
    if !(4..=crate::solver::MAX_NODES_PER_SPAN).contains(&options.nodes_per_span) {
        return Err(SpatialError::NodesPerSpan { nodes: options.nodes_per_span, max: crate::solver::MAX_NODES_PER_SPAN });
    }
    if !(options.spatial_moment_tolerance_n_mm.is_finite() && options.spatial_moment_tolerance_n_mm > 0.0) {
        return Err(SpatialError::MomentTolerance);
    }
    Ok(())
}

/// Checks that `order` is resolved with `options` (the message names the
/// fix): the collocation estimates its coefficients' error at every solve
/// (up to [`MAX_SPATIAL_ORDER`]); the RK4 reference needs the steps of
/// [`REQUIRED_SPATIAL_STEPS_PER_SPAN`].
pub fn check_order(order: usize, options: &SolverOptions) -> Result<(), SpatialError> {
    if order > MAX_SPATIAL_ORDER {
        return Err(SpatialError::OrderAbove { order, max: MAX_SPATIAL_ORDER });
    }
    if options.method == crate::solver::SolverMethod::Collocation {
        return Ok(());
    }
    let need = REQUIRED_SPATIAL_STEPS_PER_SPAN[order];
    if options.spatial_steps_per_span < need {
        return Err(SpatialError::OrderSteps { order, need, have: options.spatial_steps_per_span });
    }
    Ok(())
}

/// The rotation vector turning the direction of `before` into that of
/// `after` (both in the body frame): its axis times its angle.
fn tangent_turn(before: &V3, after: &V3) -> V3 {
    let (a, b) = (before.normalize(), after.normalize());
    let axis = a.cross(&b);
    let sin = axis.norm();
    if sin == 0.0 {
        return V3::zeros();
    }
    axis * (sin.atan2(a.dot(&b)) / sin)
}

fn residual(end: &State) -> V3 {
    V3::new(end[7], end[8], end[9])
}

fn quat(y: &State) -> UnitQuaternion<f64> {
    UnitQuaternion::new_unchecked(Quaternion::new(y[3], y[4], y[5], y[6]))
}
