//! The probe: a finer collocation solver kept beside a [`super::PlanarCollocation`] to
//! settle an a posteriori error estimate that came out above the
//! tolerance. The estimates (`collocation`) are upper bounds, often far
//! above the error; the probe solves the same routing, tension and hold at
//! twice the intervals per span, started from the solution interpolated onto
//! its nodes, and the difference to it decides. It is made when first
//! needed and kept with its buffers, so a sweep pays only for the solves
//! whose estimate is above the tolerance.

use super::collocation::Colloc;
use super::planar::PlanarSolver;
use super::{SolveFailure, SolverOptions, TipPose, ESTIMATED_ORDERS, MAX_NODES_PER_SPAN};
use crate::shape::LengthBasis;

/// The finer solver and what it holds.
#[derive(Debug, Clone)]
pub(super) struct Probe {
    sim: PlanarSolver<Colloc>,
    /// Whether `sim` has the main solver's current routing and hold.
    current: bool,
    /// The tension of `sim`'s last solve, when that solve belongs to the
    /// main solver's last one.
    solved_at: Option<f64>,
}

impl Probe {
    /// The main solver's routing or hold changed.
    pub(super) fn stale(&mut self) {
        self.current = false;
        self.solved_at = None;
    }

    /// The main solver starts a solve: the probe's last one is not its.
    pub(super) fn forget_solve(&mut self) {
        self.solved_at = None;
    }
}

impl PlanarSolver<Colloc> {
    /// Whether a probe can settle this solver's estimates: collocation
    /// below the most intervals, and no creep (the probe has no load history).
    fn can_probe(&self) -> bool {
        !self.state.is_probe && self.resolution() < MAX_NODES_PER_SPAN && !self.state.creep.is_on()
    }

    /// The probe's pose at `tension_n`, solved from this solver's last
    /// state; `None` where no probe can be made.
    pub(super) fn probe_pose(&mut self, tension_n: f64) -> Option<Result<TipPose, SolveFailure>> {
        if !self.can_probe() {
            return None;
        }
        let mut probe = match self.state.probe.take() {
            Some(p) => p,
            None => {
                let options = SolverOptions { nodes_per_span: (2 * self.resolution()).min(MAX_NODES_PER_SPAN), ..self.state.options.clone() };
                let mut sim = PlanarSolver::new(&self.state.rod, &options).ok()?;
                sim.state.is_probe = true;
                Box::new(Probe { sim, current: false, solved_at: None })
            }
        };
        let result = (|| {
            if !probe.current {
                probe.sim.set_routing(self.state.given_routing.as_ref()?);
                probe.sim.apply_hold(self.state.hold);
                probe.current = true;
            }
            probe.sim.integrator.seed_from(&self.integrator, tension_n);
            Some(probe.sim.solve(tension_n))
        })();
        probe.solved_at = matches!(result, Some(Ok(_))).then_some(tension_n);
        self.state.probe = Some(probe);
        result
    }

    /// The largest difference between the coefficients `a` of the last
    /// solve (in `basis`) and the probe's, and its index; `None` where no
    /// probe can be made or its solve failed.
    pub(super) fn probe_coefficient_difference(&mut self, basis: LengthBasis, a: &[f64]) -> Option<(f64, usize)> {
        let tension = self.state.last_tension_n?;
        if a.len() > ESTIMATED_ORDERS {
            return None;
        }
        if self.state.probe.as_ref().is_none_or(|p| p.solved_at != Some(tension)) {
            self.probe_pose(tension)?.ok()?;
        }
        let probe = self.state.probe.as_mut()?;
        let mut fine = [0.0; ESTIMATED_ORDERS];
        probe.sim.coefficients_into(basis, &mut fine[..a.len()]);
        let mut worst = (0.0f64, 0usize);
        for (n, (p, q)) in a.iter().zip(&fine).enumerate() {
            let d = (p - q).abs();
            if !(d <= worst.0) {
                worst = (d, n);
            }
        }
        Some(worst)
    }
}
