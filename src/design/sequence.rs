//! The unknowns and objective of a design for a sequence of targets
//! ([`Setup`]): one set of channels and one actuation vector per target,
//! the weighted squared errors of every target together (eq. 3.17 summed
//! over the targets), searched by [`super::search::channels`].
//!
//! Variables live in a unit box for the library's one bounded
//! Levenberg–Marquardt ([`crate::numerics::lm`]): a control point free in
//! y and z is a point (u, v) of the square [−1, 1]², carried onto the disc
//! of radius `max_offset_mm` by the elliptical grid map
//! y = R u √(1 − v²/2), z = R v √(1 − u²/2) (smooth, one to one); a B-spline
//! lies in the convex hull of its control points, so the whole channel
//! stays within the disc. A point free in y alone moves within
//! √(R² − z_i²). Each actuation is its range scaled to [0, 1].
//!
//! Every evaluation solves each target's actuator with
//! [`crate::solver::simulate_actuator`], the path `cablemap simulate` takes,
//! so a design's reported values are what its `simulate` command prints.
//! The seed grid ([`grid_seeds`]): straight channels in 8 directions, or
//! 5 levels and ramps for one free coordinate, × 3 actuation levels per
//! cable.

use super::actuator::{ActuationBounds, CableFreedom, DesignActuator};
use super::targets::{Quantity, ShapeTarget};
use crate::solver::spatial::SpatialError;
use crate::model::Actuator;
use crate::solver::{simulate_actuator, Backend, Given, Simulation, Simulator, Solver, SolverOptions, TipPose};
use crate::numerics::lm;
use crate::shape::LengthBasis;
use rayon::prelude::*;

/// What one solve of one target's actuator achieved.
#[derive(Debug, Clone, PartialEq)]
pub struct Achieved {
    /// The pose (tip, tangent, tensions, displacements).
    pub pose: TipPose,
    /// In-plane bending series, 1/mm.
    pub a_bend_z: Vec<f64>,
    /// Out-of-plane bending series, 1/mm.
    pub a_bend_y: Vec<f64>,
    /// Twist series, 1/mm.
    pub a_twist: Vec<f64>,
}

impl Achieved {
    /// From a simulation.
    pub fn of(sim: &Simulation) -> Self {
        Self { pose: sim.pose, a_bend_z: sim.a_bend_z.clone(), a_bend_y: sim.a_bend_y.clone(), a_twist: sim.a_twist.clone() }
    }

    /// The achieved value of `q` (NaN for an order not computed).
    pub fn value(&self, q: Quantity) -> f64 {
        let at = |s: &[f64], k: usize| s.get(k).copied().unwrap_or(f64::NAN);
        match q {
            Quantity::TipX => self.pose.tip_x_mm,
            Quantity::TipY => self.pose.tip_y_mm,
            Quantity::TipZ => self.pose.tip_z_mm,
            Quantity::Tangent(i) => self.pose.tip_tangent()[i],
            Quantity::BendZ(k) => at(&self.a_bend_z, k),
            Quantity::BendY(k) => at(&self.a_bend_y, k),
            Quantity::Twist(k) => at(&self.a_twist, k),
        }
    }
}

/// The problem: actuator, freedoms, targets and solver settings.
#[derive(Debug, Clone)]
pub struct Setup {
    /// The actuator and what may change.
    pub design: DesignActuator,
    /// The targets, in order.
    pub targets: Vec<ShapeTarget>,
    /// Planar solver settings (the planar fast path, and the collocation's intervals).
    pub options: SolverOptions,
    /// The coefficients' length basis.
    pub basis: LengthBasis,
    /// A trajectory with `smooth = true`: its steps per leg. No cable's
    /// tension may reverse at the leg's samples ([`Setup::enforces_smooth`]).
    pub smooth_steps: Option<usize>,
}

/// Weight of a leg's tension reversal ([`reversal_n`]) in
/// the objective, per (N per leg)²: a reversal of 0.1 mN per leg costs as
/// much as a tip 1 mm off its target. Large, because a least-squares
/// penalty only shrinks a violation by 1/(1 + w k²) (k its sensitivity to
/// the design), never to zero.
pub const REVERSAL_WEIGHT: f64 = 1e8;

/// A point of the search: the unit-box coordinates.
pub type Point = Vec<f64>;

/// Control points (y, z) of one cable.
pub type Channel = ([f64; 5], [f64; 5]);

/// Square → disc, both normalised (the elliptical grid map).
fn disc_of(u: f64, v: f64) -> (f64, f64) {
    (u * (1.0 - 0.5 * v * v).max(0.0).sqrt(), v * (1.0 - 0.5 * u * u).max(0.0).sqrt())
}

/// Disc → square (the inverse of [`disc_of`]), clamped into the square.
fn square_of(x: f64, y: f64) -> (f64, f64) {
    let s2 = 2.0 * std::f64::consts::SQRT_2;
    let half = |a: f64, b: f64| {
        let p = (2.0 + a * a - b * b + s2 * a).max(0.0).sqrt();
        let m = (2.0 + a * a - b * b - s2 * a).max(0.0).sqrt();
        (0.5 * (p - m)).clamp(-1.0, 1.0)
    };
    (half(x, y), half(y, x))
}

impl Setup {
    /// Number of cables.
    pub fn cables(&self) -> usize {
        self.design.cables()
    }

    /// Channel variables of cable `c`.
    fn channel_vars(&self, c: usize) -> usize {
        let f = &self.design.freedom[c];
        5 * (f.free_y as usize + f.free_z as usize)
    }

    /// Index of cable `c`'s first channel variable.
    fn channel_start(&self, c: usize) -> usize {
        (0..c).map(|k| self.channel_vars(k)).sum()
    }

    /// Number of channel variables (shared by every target).
    pub fn channel_var_count(&self) -> usize {
        self.channel_start(self.cables())
    }

    /// Index of target `t`'s first actuation variable.
    pub fn actuation_start(&self, t: usize) -> usize {
        self.channel_var_count() + t * self.cables()
    }

    /// Whether the search penalises tension reversals: a trajectory with
    /// `smooth = true` and a displacement-driven cable (a tension-driven
    /// cable's tension is linear in a leg and never reverses).
    pub fn enforces_smooth(&self) -> bool {
        self.smooth_steps.is_some() && self.targets.len() > 1 && !self.reversal_cables().is_empty()
    }

    /// Interior samples per leg the search solves for a smooth trajectory
    /// (those of the report: `steps_per_leg` − 1), 0 when not enforced.
    pub fn smooth_samples(&self) -> usize {
        match self.smooth_steps {
            Some(n) if self.enforces_smooth() => n.saturating_sub(1),
            _ => 0,
        }
    }

    /// The cables whose tension may reverse inside a leg: the displacement-driven ones.
    pub fn reversal_cables(&self) -> Vec<usize> {
        self.design.freedom.iter().enumerate().filter(|(_, f)| matches!(f.actuation, ActuationBounds::Displacement { .. })).map(|(c, _)| c).collect()
    }

    /// A leg's reversal residuals, one per displacement-driven cable:
    /// √w · [`reversal_n`] of its tension at the leg's
    /// ends (`ends`, as solved) and at the report's interior samples
    /// ([`Setup::smooth_samples`]), the actuation moving linearly from
    /// `from` to `to`. None when a sample's solve fails.
    pub fn leg_residuals(&self, channels: &[Channel], (from, to): (&[f64], &[f64]), ends: (&Achieved, &Achieved)) -> Option<Vec<f64>> {
        let cables = self.reversal_cables();
        let mut series: Vec<Vec<f64>> = cables.iter().map(|&c| vec![ends.0.pose.tensions_n[c]]).collect();
        let n = self.smooth_samples();
        for j in 1..=n {
            let f = j as f64 / (n + 1) as f64;
            let act: Vec<f64> = from.iter().zip(to).map(|(p, q)| p + f * (q - p)).collect();
            let a = self.quick(&self.actuator(channels, &act)).ok()?;
            for (s, &c) in series.iter_mut().zip(&cables) {
                s.push(a.pose.tensions_n[c]);
            }
        }
        for (s, &c) in series.iter_mut().zip(&cables) {
            s.push(ends.1.pose.tensions_n[c]);
        }
        Some(series.iter().map(|s| REVERSAL_WEIGHT.sqrt() * reversal_n(s)).collect())
    }

    /// Number of variables.
    pub fn var_count(&self) -> usize {
        self.actuation_start(self.targets.len())
    }

    /// The coefficient order every solve computes.
    pub fn order(&self) -> usize {
        self.targets.iter().map(ShapeTarget::order).max().unwrap_or(2)
    }

    /// The channels at `x`.
    pub fn channels(&self, x: &[f64]) -> Vec<Channel> {
        (0..self.cables())
            .map(|c| {
                let f = &self.design.freedom[c];
                let cable = &self.design.actuator.cables[c];
                let (mut y, mut z) = (cable.y_mm, cable.z_mm);
                let s = self.channel_start(c);
                let r = f.max_offset_mm;
                match (f.free_y, f.free_z) {
                    (true, true) => {
                        for i in 0..5 {
                            let (a, b) = disc_of(x[s + i], x[s + 5 + i]);
                            y[i] = r * a;
                            z[i] = r * b;
                        }
                    }
                    (true, false) => (0..5).for_each(|i| y[i] = x[s + i] * (r * r - z[i] * z[i]).sqrt()),
                    (false, true) => (0..5).for_each(|i| z[i] = x[s + i] * (r * r - y[i] * y[i]).sqrt()),
                    (false, false) => {}
                }
                (y, z)
            })
            .collect()
    }

    /// The unit coordinates of cable `c`'s channel (inside its bounds).
    fn unit_channel(&self, c: usize, ch: &Channel) -> Vec<f64> {
        let f = &self.design.freedom[c];
        let r = f.max_offset_mm;
        let (y, z) = ch;
        match (f.free_y, f.free_z) {
            (true, true) => {
                let pairs: Vec<(f64, f64)> = (0..5)
                    .map(|i| {
                        let (a, b) = (y[i] / r, z[i] / r);
                        let n = a.hypot(b);
                        let (a, b) = if n > 1.0 { (a / n, b / n) } else { (a, b) };
                        square_of(a, b)
                    })
                    .collect();
                pairs.iter().map(|p| p.0).chain(pairs.iter().map(|p| p.1)).collect()
            }
            (true, false) => (0..5).map(|i| (y[i] / (r * r - z[i] * z[i]).sqrt()).clamp(-1.0, 1.0)).collect(),
            (false, true) => (0..5).map(|i| (z[i] / (r * r - y[i] * y[i]).sqrt()).clamp(-1.0, 1.0)).collect(),
            (false, false) => Vec::new(),
        }
    }

    /// The actuation of target `t` at `x` (tension in N or displacement in mm, per cable).
    pub fn actuation(&self, x: &[f64], t: usize) -> Vec<f64> {
        let s = self.actuation_start(t);
        self.design.freedom.iter().enumerate().map(|(c, f)| {
            let (lo, hi) = f.actuation.range();
            lo + (hi - lo) * x[s + c]
        }).collect()
    }

    /// The actuator with `channels` and `actuation`.
    pub fn actuator(&self, channels: &[Channel], actuation: &[f64]) -> Actuator {
        let mut a = self.design.actuator.clone();
        for ((cable, (y, z)), (f, &v)) in a.cables.iter_mut().zip(channels).zip(self.design.freedom.iter().zip(actuation)) {
            cable.y_mm = *y;
            cable.z_mm = *z;
            match f.actuation {
                ActuationBounds::Tension { .. } => {
                    cable.tension_n = v;
                    cable.displacement_mm = None;
                }
                ActuationBounds::Displacement { .. } => {
                    cable.tension_n = 0.0;
                    cable.displacement_mm = Some(v);
                }
            }
        }
        a
    }

    /// Solves one actuator by the backend `simulate` would use.
    pub fn simulate(&self, actuator: &Actuator) -> Result<Simulation, SpatialError> {
        simulate_actuator(actuator, &self.options, Given::default(), None, self.order(), self.basis)
    }

    /// Solves target `t` at `x` ([`Setup::quick`]).
    pub fn solve(&self, channels: &[Channel], x: &[f64], t: usize) -> Result<Achieved, SpatialError> {
        self.quick(&self.actuator(channels, &self.actuation(x, t)))
    }

    /// What the search solves: for a tension-driven actuator the 3-D
    /// collocation serves, one cold solve at the full tensions (about 4×
    /// cheaper than the ladder, the same pose to the solver's tolerance; the
    /// planar backends' ladders are cheap already); where that fails, and
    /// for every other actuator, [`Setup::simulate`]. The design's reported
    /// values are [`Setup::simulate`]'s.
    pub fn quick(&self, actuator: &Actuator) -> Result<Achieved, SpatialError> {
        let tension_driven = !actuator.cables.iter().any(|c| c.is_displacement_driven());
        let cold = tension_driven.then(|| Backend::serving(actuator, &self.options, Given::default()));
        if let Some(Ok(backend @ Backend::SpatialCollocation)) = cold {
            let options = SolverOptions { nodes_per_span: self.options.nodes_per_span, ..SolverOptions::default() };
            if let Ok(mut solver) = Simulator::build(backend, actuator, &options) {
                let tensions: Vec<f64> = actuator.cables.iter().map(|c| c.tension_n).collect();
                if let Ok(pose) = solver.solve_tensions(&tensions) {
                    if let Ok([a_twist, a_bend_y, a_bend_z]) = solver.coefficients(self.order(), self.basis) {
                        if a_twist.iter().chain(&a_bend_y).chain(&a_bend_z).all(|v| v.is_finite()) {
                            return Ok(Achieved { pose, a_bend_z, a_bend_y, a_twist });
                        }
                    }
                }
            }
        }
        self.simulate(actuator).map(|s| Achieved::of(&s))
    }

    /// Target `t`'s weighted residuals √λ (achieved − asked).
    pub fn residuals_of(&self, t: usize, a: &Achieved) -> Vec<f64> {
        self.targets[t].components.iter().map(|(q, v, w)| w.sqrt() * (a.value(*q) - v)).collect()
    }

    /// Target `t`'s cost.
    pub fn cost_of(&self, t: usize, a: &Achieved) -> f64 {
        self.residuals_of(t, a).iter().map(|r| r * r).sum()
    }

    /// The unit box and the free variables (an actuation whose bounds coincide is held).
    pub fn settings(&self) -> lm::Settings {
        let nc = self.channel_var_count();
        let bounds: Vec<(f64, f64)> = (0..self.var_count()).map(|i| if i < nc { (-1.0, 1.0) } else { (0.0, 1.0) }).collect();
        let free = (0..self.var_count())
            .filter(|&i| {
                i < nc || {
                    let c = (i - nc) % self.cables();
                    let (lo, hi) = self.design.freedom[c].actuation.range();
                    hi > lo
                }
            })
            .collect();
        lm::Settings { bounds, free, max_iterations: usize::MAX }
    }
}

/// Candidate channels of one cable for the seed grid, as unit coordinates:
/// straight channels in 8 directions at 0.6 of the bound (y and z free);
/// the axis, ±0.6 and ramps 0 → ±0.8 of the bound (one coordinate free);
/// the channel as given (fixed).
fn candidates(f: &CableFreedom) -> Vec<Vec<f64>> {
    match (f.free_y, f.free_z) {
        (true, true) => (0..8)
            .map(|k| {
                let th = k as f64 * std::f64::consts::FRAC_PI_4;
                let (u, v) = square_of(0.6 * th.cos(), 0.6 * th.sin());
                [u; 5].into_iter().chain([v; 5]).collect()
            })
            .collect(),
        (false, false) => vec![Vec::new()],
        _ => {
            let ramp = [0.0, 0.2, 0.4, 0.6, 0.8];
            vec![vec![0.6; 5], vec![-0.6; 5], ramp.to_vec(), ramp.iter().map(|v| -v).collect(), vec![0.0; 5]]
        }
    }
}

/// Most seed solves (channel combinations × actuation levels) of the grid.
const MAX_SEED_SOLVES: usize = 1500;

/// The seed grid: every combination of the cables' candidate channels (an
/// evenly spaced subset when there are too many), each solved at every
/// actuation level vector; a combination's cost is the sum over targets
/// of the least cost over its levels. Returns (cost, start point), best
/// first (ties in combination order), and the number of solves.
pub fn grid_seeds(setup: &Setup) -> (Vec<(f64, Point)>, usize) {
    let n = setup.cables();
    let per_cable: Vec<Vec<Vec<f64>>> = setup.design.freedom.iter().map(candidates).collect();
    let levels: Vec<f64> = if n <= 3 { vec![0.0, 0.5, 1.0] } else { vec![0.0, 1.0] };
    let level_vectors: Vec<Vec<f64>> = (0..levels.len().pow(n as u32))
        .map(|mut k| {
            (0..n)
                .map(|_| {
                    let l = levels[k % levels.len()];
                    k /= levels.len();
                    l
                })
                .collect()
        })
        .collect();
    let total: usize = per_cable.iter().map(Vec::len).product();
    let cap = (MAX_SEED_SOLVES / level_vectors.len()).max(4);
    let picks: Vec<usize> = if total <= cap { (0..total).collect() } else { (0..cap).map(|i| i * total / cap).collect() };
    let combos: Vec<Vec<f64>> = picks
        .into_iter()
        .filter_map(|mut k| {
            let mut x = Vec::new();
            for c in &per_cable {
                x.extend(&c[k % c.len()]);
                k /= c.len();
            }
            x.resize(setup.var_count(), 0.0);
            // Two cables cannot share one path.
            let ch = setup.channels(&x);
            let distinct = (0..n).all(|a| (a + 1..n).all(|b| ch[a] != ch[b]));
            distinct.then_some(x)
        })
        .collect();
    let solves = combos.len() * level_vectors.len();
    let nt = setup.targets.len();
    let mut seeds: Vec<(usize, f64, Point)> = combos
        .par_iter()
        .enumerate()
        .filter_map(|(i, x)| {
            let channels = setup.channels(x);
            let mut best: Vec<(f64, usize)> = vec![(f64::INFINITY, 0); nt];
            for (li, lv) in level_vectors.iter().enumerate() {
                let act: Vec<f64> = setup.design.freedom.iter().zip(lv).map(|(f, l)| {
                    let (lo, hi) = f.actuation.range();
                    lo + (hi - lo) * l
                }).collect();
                let Ok(a) = setup.quick(&setup.actuator(&channels, &act)) else { continue };
                for (t, b) in best.iter_mut().enumerate() {
                    let c = setup.cost_of(t, &a);
                    if c < b.0 {
                        *b = (c, li);
                    }
                }
            }
            let cost: f64 = best.iter().map(|b| b.0).sum();
            if !cost.is_finite() {
                return None;
            }
            let mut x = x.clone();
            for (t, b) in best.iter().enumerate() {
                let s = setup.actuation_start(t);
                x[s..s + n].copy_from_slice(&level_vectors[b.1]);
            }
            Some((i, cost, x))
        })
        .collect();
    seeds.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    (seeds.into_iter().map(|s| (s.1, s.2)).collect(), solves)
}

/// A start from given channels (a map's design): each target's actuation
/// from the grid's levels, as [`grid_seeds`] does for its combinations.
pub fn point_of(setup: &Setup, channels: &[Channel]) -> Point {
    let mut x: Point = (0..setup.cables()).flat_map(|c| setup.unit_channel(c, &channels[c])).collect();
    x.resize(setup.var_count(), 0.5);
    x
}

/// How steeply `values` (a cable's tension at evenly spaced samples of a
/// leg, N) move against their direction: over the two directions, the
/// lesser of the largest step against it, times the number of steps (N per
/// leg). Zero exactly when the values never both rise and fall, and, unlike
/// the depth of a dip, linear in how far a design is from not reversing,
/// so a least-squares penalty drives it to zero
/// ([`Setup::leg_residuals`]).
pub fn reversal_n(values: &[f64]) -> f64 {
    let steps: Vec<f64> = values.windows(2).map(|w| w[1] - w[0]).collect();
    let against = |sign: f64| steps.iter().map(|d| (-sign * d).max(0.0)).fold(0.0, f64::max);
    steps.len() as f64 * against(1.0).min(against(-1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_disc_map_round_trips_and_stays_inside() {
        for &(u, v) in &[(0.3, -0.7), (1.0, 1.0), (-1.0, 0.2), (0.0, 0.0), (0.99, -0.5)] {
            let (x, y) = disc_of(u, v);
            assert!(x.hypot(y) <= 1.0 + 1e-12);
            let (a, b) = square_of(x, y);
            assert!((a - u).abs() < 1e-9 && (b - v).abs() < 1e-9, "{u},{v} → {a},{b}");
        }
    }

    /// The search's penalty: zero exactly for a series that never moves
    /// against its overall direction, else how far it does.
    #[test]
    fn the_reversal_penalty_is_zero_only_without_a_reversal() {
        assert_eq!(reversal_n(&[0.0, 0.5, 1.0, 1.0]), 0.0);
        assert_eq!(reversal_n(&[2.0, 1.5, 1.5, 0.2]), 0.0);
        assert_eq!(reversal_n(&[]), 0.0);
        // Up 1.0 then down 0.4 (2 steps): the lesser steepest step against a direction, 0.4, × 2.
        assert!((reversal_n(&[0.0, 1.0, 0.6]) - 0.8).abs() < 1e-15);
        // A hump: against rising, its steepest fall 0.3; against falling, its steepest rise 0.3; × 4 steps.
        assert!((reversal_n(&[1.0, 1.3, 1.5, 1.2, 1.0]) - 1.2).abs() < 1e-15);
        // Linear in the dip as a trend removes it: a dip c f (f − 1) plus a trend D f.
        let dip = |d: f64| reversal_n(&(0..=20).map(|j| { let f = j as f64 / 20.0; d * f + f * (f - 1.0) }).collect::<Vec<_>>());
        assert!((dip(0.5) - 0.45).abs() < 1e-12 && (dip(0.75) - 0.2).abs() < 1e-12, "{} {}", dip(0.5), dip(0.75));
        assert_eq!(dip(1.0), 0.0);
        for v in [[0.0, 0.5, 0.4], [1.0, 0.2, 0.3]] {
            assert!(reversal_n(&v) > 0.0);
        }
    }
}
