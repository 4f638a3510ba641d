//! The design problem of 1–N cables for a sequence of targets: every free
//! channel coordinate (shared by the targets) and each cable's actuation per
//! target, eq. 3.17 summed over the targets (and, for a smooth trajectory,
//! a penalty on each leg's tension reversals). The unknowns and their unit
//! box are [`Setup`]'s ([`crate::design::sequence`]).
//!
//! Seeds: every combination of the cables' candidate channels at a few
//! actuation levels ([`grid_seeds`]), a map's designs' channels first (up to
//! half of the starts); seeds of equal cost (two interchangeable cables
//! swapped) are refined once. A start also stops when it stalls.

use super::{Problem, Seed, SeedSource, Seeds, Stall, Start, FD_STEP};
use crate::design::sequence::{grid_seeds, point_of, Achieved, Channel, Point, Setup};
use crate::design::DesignError;
use crate::numerics::lm;
use nalgebra::DMatrix;

/// The problem: its setup and a map's designs' channels.
#[derive(Debug, Clone)]
pub struct ChannelsProblem<'a> {
    /// The actuator, its freedoms, the targets and the solver settings.
    pub setup: &'a Setup,
    /// A map's nearest designs, every cable's channel.
    pub map_channels: Vec<Vec<Channel>>,
}

/// A start stops when its best cost fell by less than 1 % over 10
/// iterations: a flat valley, where the remaining gain is below what any
/// target's tolerance resolves.
pub const STALL: Stall = Stall { iterations: 10, fraction: 0.01 };

/// The last point solved and every target's solve there (a smooth
/// trajectory's Jacobian needs the neighbours of a moved target).
pub type LastSolve = Option<(Point, Vec<Achieved>)>;

impl ChannelsProblem<'_> {
    /// Rows of target `t` in the residual vector.
    fn rows(&self, t: usize) -> std::ops::Range<usize> {
        let targets = &self.setup.targets;
        let start: usize = targets[..t].iter().map(|g| g.components.len()).sum();
        start..start + targets[t].components.len()
    }

    /// Rows of leg `k`'s reversal residuals (after every target's rows).
    fn leg_rows(&self, k: usize) -> std::ops::Range<usize> {
        let n = self.setup.reversal_cables().len();
        let start = self.rows(self.setup.targets.len() - 1).end + k * n;
        start..start + n
    }
}

/// Every target's solve at `x` (the last solve's, when it was at `x`).
fn solved_at(start: &mut Start<'_, ChannelsProblem<'_>>, x: &[f64]) -> Option<Vec<Achieved>> {
    match &start.worker {
        Some((at, all)) if at.as_slice() == x => Some(all.clone()),
        _ => start.evaluate(x).map(|r| r.1),
    }
}

impl Problem for ChannelsProblem<'_> {
    type Solution = Vec<Achieved>;
    type Worker = LastSolve;

    fn worker(&self) -> LastSolve {
        None
    }

    fn settings(&self) -> lm::Settings {
        self.setup.settings()
    }

    fn solve(&self, last: &mut LastSolve, x: &[f64], evaluations: &mut usize) -> Option<(Vec<f64>, Vec<Achieved>)> {
        let setup = self.setup;
        let channels = setup.channels(x);
        let mut r = Vec::new();
        let mut all = Vec::with_capacity(setup.targets.len());
        for t in 0..setup.targets.len() {
            *evaluations += 1;
            let a = setup.solve(&channels, x, t).ok()?;
            r.extend(setup.residuals_of(t, &a));
            all.push(a);
        }
        if setup.enforces_smooth() {
            for k in 0..all.len() - 1 {
                *evaluations += setup.smooth_samples();
                let leg = setup.leg_residuals(&channels, (&setup.actuation(x, k), &setup.actuation(x, k + 1)), (&all[k], &all[k + 1]))?;
                r.extend(leg);
            }
        }
        *last = Some((x.to_vec(), all.clone()));
        Some((r, all))
    }

    /// Forward differences, inward at an upper bound; a channel variable
    /// moves every target, an actuation variable only its own target.
    fn jacobian(start: &mut Start<'_, Self>, x: &[f64], r: &[f64], free: &[usize]) -> Option<DMatrix<f64>> {
        let problem = start.problem;
        let setup = problem.setup;
        let mut jac = DMatrix::zeros(r.len(), free.len());
        let nc = setup.channel_var_count();
        let channels = setup.channels(x);
        for (k, &j) in free.iter().enumerate() {
            let (lo, hi) = if j < nc { (-1.0, 1.0) } else { (0.0, 1.0) };
            let mut h = if x[j] + FD_STEP > hi { -FD_STEP } else { FD_STEP };
            let mut at = x.to_vec();
            at[j] += h;
            if at[j] < lo {
                h = -h;
                at[j] = x[j] + h;
            }
            if j < nc {
                let (rh, _) = start.evaluate(&at)?;
                for i in 0..r.len() {
                    jac[(i, k)] = (rh[i] - r[i]) / h;
                }
            } else {
                let t = (j - nc) / setup.cables();
                start.evaluations += 1;
                let a = setup.solve(&channels, &at, t).ok()?;
                let rh = setup.residuals_of(t, &a);
                for (i, row) in problem.rows(t).enumerate() {
                    jac[(row, k)] = (rh[i] - r[row]) / h;
                }
                if setup.enforces_smooth() {
                    // The legs into and out of target t move with it.
                    let base = solved_at(start, x)?;
                    for leg in t.saturating_sub(1)..(t + 1).min(setup.targets.len() - 1) {
                        let ends = if leg == t { (&a, &base[t + 1]) } else { (&base[leg], &a) };
                        start.evaluations += setup.smooth_samples();
                        let lh = setup.leg_residuals(&channels, (&setup.actuation(&at, leg), &setup.actuation(&at, leg + 1)), ends)?;
                        for (i, row) in problem.leg_rows(leg).enumerate() {
                            jac[(row, k)] = (lh[i] - r[row]) / h;
                        }
                    }
                }
            }
        }
        Some(jac)
    }

    /// A map's designs (up to half of `count`, with the best grid seed's
    /// actuation levels), then the grid's seeds, best first, one of each cost.
    fn seeds(&self, count: usize) -> Result<Seeds, DesignError> {
        let setup = self.setup;
        let (grid, mut simulated) = grid_seeds(setup);
        let mut seeds: Vec<Seed> = Vec::new();
        for channels in self.map_channels.iter().take(count.div_ceil(2)) {
            simulated += 1;
            let mut x = point_of(setup, channels);
            // Their actuation: the best grid combination's levels, per target.
            if let Some((_, g)) = grid.first() {
                let s = setup.channel_var_count();
                x[s..].copy_from_slice(&g[s..]);
            }
            seeds.push(Seed { point: x, source: SeedSource::Map });
        }
        // Seeds of equal cost are one design twice (two interchangeable cables
        // swapped): one of them is refined.
        let mut last_cost = f64::NAN;
        for (cost, x) in &grid {
            if seeds.len() >= count {
                break;
            }
            if (cost - last_cost).abs() <= 1e-9 * cost.abs() {
                continue;
            }
            last_cost = *cost;
            seeds.push(Seed { point: x.clone(), source: SeedSource::Grid });
        }
        Ok(Seeds { seeds, simulated })
    }

    /// Per target, and per leg its samples when the trajectory is smooth.
    fn budget(&self, max_evaluations: usize) -> usize {
        let setup = self.setup;
        let legs = if setup.enforces_smooth() { setup.targets.len() - 1 } else { 0 };
        max_evaluations * (setup.targets.len() + legs * setup.smooth_samples())
    }

    fn same_channels(&self, a: &[f64], b: &[f64]) -> bool {
        let n = self.setup.channel_var_count();
        a[..n] == b[..n]
    }

    fn stall(&self) -> Option<Stall> {
        Some(STALL)
    }
}
