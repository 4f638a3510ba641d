//! The objective of eq. 3.17 as weighted residuals, and the bounds on the
//! design variables (control points y_0…y_4 and tension τ).

use super::target::{Target, Weights};
use super::targets::{ComponentOutcome, Quantity};
use super::DesignError;
use crate::model::{ControlPoints, Rod, Routing};
use crate::solver::{Simulator, SolveFailure, SolverOptions, TipPose};
use crate::shape::LengthBasis;
use serde::Serialize;

/// Box bounds of the design variables: |y_i| ≤ `max_offset_mm`,
/// `tension_min_n` ≤ τ ≤ `tension_max_n`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Bounds {
    /// Largest |y_i|, mm. The thesis's bound is the open −r < y_i < r; the
    /// closed stand-in is just inside r (see [`Bounds::thesis`]).
    pub max_offset_mm: f64,
    /// Lower tension bound τ_l, N.
    pub tension_min_n: f64,
    /// Upper tension bound τ_u, N.
    pub tension_max_n: f64,
}

impl Bounds {
    /// The thesis's bounds for radius `radius_mm`: |y_i| < r (closed at
    /// 0.999 r, since the routing must stay strictly inside the body) and
    /// τ_l ≤ τ ≤ τ_u.
    pub fn thesis(radius_mm: f64, tension_min_n: f64, tension_max_n: f64) -> Self {
        Self { max_offset_mm: Self::thesis_max_offset_mm(radius_mm), tension_min_n, tension_max_n }
    }

    /// The thesis's largest |y_i| for radius `radius_mm`: 0.999 r, mm.
    pub fn thesis_max_offset_mm(radius_mm: f64) -> f64 {
        0.999 * radius_mm
    }

    /// Checks the bounds against the body radius.
    pub fn validate(&self, radius_mm: f64) -> Result<(), DesignError> {
        let Bounds { max_offset_mm: y, tension_min_n: lo, tension_max_n: hi } = *self;
        if !(y.is_finite() && y > 0.0 && y < radius_mm) {
            return Err(DesignError::MaxOffset { max_offset_mm: y, radius_mm });
        }
        if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo <= hi) {
            return Err(DesignError::TensionBounds { tension_min_n: lo, tension_max_n: hi });
        }
        Ok(())
    }

    /// Clamps a design into the bounds.
    pub fn clamp(&self, y_mm: &mut ControlPoints, tension_n: &mut f64) {
        for y in y_mm.iter_mut() {
            *y = y.clamp(-self.max_offset_mm, self.max_offset_mm);
        }
        *tension_n = tension_n.clamp(self.tension_min_n, self.tension_max_n);
    }
}

/// What one simulated design achieved.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Evaluation {
    /// Control points y_0…y_4, mm.
    pub routing_mm: ControlPoints,
    /// Cable tension, N.
    pub tension_n: f64,
    /// Tip pose and deformed length.
    pub pose: TipPose,
    /// Achieved a_0 … a_n, 1/mm.
    pub a: Vec<f64>,
}

impl Evaluation {
    /// The achieved value of `component` (None for an order not computed).
    pub fn value(&self, component: Quantity) -> Option<f64> {
        match component {
            Quantity::TipX => Some(self.pose.tip_x_mm),
            Quantity::TipY => Some(self.pose.tip_y_mm),
            Quantity::BendZ(k) => self.a.get(k).copied(),
            _ => None,
        }
    }
}

/// Eq. 3.17 for one target: the actuator model, the target, its weights and
/// the bounds.
#[derive(Debug, Clone)]
pub struct Objective {
    /// The rod being designed (its one cable is the design).
    pub rod: Rod,
    /// Solver settings.
    pub options: SolverOptions,
    /// What to achieve.
    pub target: Target,
    /// λ per component.
    pub weights: Weights,
    /// Box bounds on y_i and τ.
    pub bounds: Bounds,
    /// Which length normalises the curvature coefficients (default: the
    /// thesis's rest length).
    pub length_basis: LengthBasis,
}

impl Objective {
    /// Builds and checks an objective.
    pub fn new(rod: Rod, options: SolverOptions, target: Target, weights: Weights, bounds: Bounds) -> Result<Self, DesignError> {
        rod.validate()?;
        // The solver settings and the target's coefficient order, before any
        // search: every a_k compared must be resolved by the steps.
        Simulator::for_rod(&rod, &options)?;
        crate::solver::resolution::check_order(target.order(), &options).map_err(|source| DesignError::Resolution { source })?;
        weights.check_against(&target)?;
        bounds.validate(rod.channel_radius_mm())?;
        Ok(Self { rod, options, target, weights, bounds, length_basis: LengthBasis::default() })
    }

    /// The same objective with coefficients in `basis`.
    pub fn with_length_basis(mut self, basis: LengthBasis) -> Self {
        self.length_basis = basis;
        self
    }

    /// A fresh simulator for this objective's actuator (one per thread).
    pub fn simulator(&self) -> Simulator {
        Simulator::for_rod(&self.rod, &self.options).expect("actuator validated in Objective::new")
    }

    /// Number of residuals (one per target component).
    pub fn residual_count(&self) -> usize {
        self.target.components.len()
    }

    /// Simulates a design: sets the routing and solves at `tension_n`, then
    /// reads the pose and a_0 … a_n (in the objective's [`LengthBasis`]).
    ///
    /// A routing change loses the warm start. A cold solve at the full
    /// tension converges for routings inside the body at the design
    /// tensions (checked on thousands of random routings, agreeing with the
    /// ladder to 3e-7 mm) and is 4× cheaper, so it is tried first; if it
    /// fails, a continuation ladder from low tension (as `model::simulate`)
    /// takes over.
    pub fn evaluate(&self, sim: &mut Simulator, routing_mm: &ControlPoints, tension_n: f64) -> Result<Evaluation, SolveFailure> {
        let routing = Routing::for_actuator(routing_mm, &self.rod)
            .expect("design variables are kept inside the body by the bounds");
        sim.set_routing(&routing);
        let pose = match sim.solve(tension_n) {
            Ok(pose) => pose,
            Err(_) => {
                sim.set_routing(&routing);
                let rungs = crate::solver::ladder::tension_rungs(tension_n);
                let mut pose = None;
                for k in 1..=rungs {
                    pose = Some(sim.solve(tension_n * k as f64 / rungs as f64)?);
                }
                pose.expect("≥ 1 rung")
            }
        };
        let mut a = vec![0.0; self.target.order() + 1];
        sim.coefficients_into(self.length_basis, &mut a);
        Ok(Evaluation { routing_mm: *routing_mm, tension_n, pose, a })
    }

    /// Weighted residuals √λ_j (c_j − t_j), so that their sum of squares is
    /// the objective of eq. 3.17.
    pub fn residuals_into(&self, eval: &Evaluation, out: &mut [f64]) {
        for ((component, target), r) in self.target.components.iter().zip(out.iter_mut()) {
            let achieved = eval.value(*component).expect("order covers every target component");
            *r = self.weights.get(*component).sqrt() * (achieved - target);
        }
    }

    /// The objective of eq. 3.17 (sum of weighted squared errors).
    pub fn cost(&self, eval: &Evaluation) -> f64 {
        let mut r = vec![0.0; self.residual_count()];
        self.residuals_into(eval, &mut r);
        r.iter().map(|v| v * v).sum()
    }
}

/// Compares `eval` with the objective's target. A component is met when its
/// relative error is within `tolerance_pct`; a zero target is judged against
/// a natural scale instead (the rod length L for positions, 1/L for
/// curvature coefficients: one radian of bending over the rod).
pub fn compare(objective: &Objective, eval: &Evaluation, tolerance_pct: f64) -> Vec<ComponentOutcome> {
    let length = objective.rod.length_mm;
    objective
        .target
        .components
        .iter()
        .map(|&(quantity, target)| {
            let achieved = eval.value(quantity).expect("order covers the target");
            ComponentOutcome::judge(quantity, target, achieved, tolerance_pct, length)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cost_is_zero_at_a_simulated_target_and_weighted_elsewhere() {
        let actuator = Rod::default();
        let bounds = Bounds::thesis(actuator.radius_mm, 1.0, 2.0);
        let probe = Objective::new(actuator.clone(), SolverOptions::default(), Target::parse("x=1").unwrap(), Weights::default(), bounds).unwrap();
        let mut sim = probe.simulator();
        let y = [1.0, -2.0, 3.0, 2.5, -1.0];
        let e = probe.evaluate(&mut sim, &y.into(), 1.5).unwrap();
        let text = format!("x={},y={},a0={},a1={},a2={}", e.pose.tip_x_mm, e.pose.tip_y_mm, e.a[0], e.a[1], e.a[2]);
        let exact = Objective::new(actuator.clone(), SolverOptions::default(), Target::parse(&text).unwrap(), Weights::default(), bounds).unwrap();
        let e2 = exact.evaluate(&mut sim, &y.into(), 1.5).unwrap();
        assert!(exact.cost(&e2) < 1e-20, "{}", exact.cost(&e2));
        // Off by 0.01 in a0 costs λ_0 · 1e-4 = 0.01.
        let text = format!("x={},a0={}", e.pose.tip_x_mm, e.a[0] + 0.01);
        let off = Objective::new(actuator, SolverOptions::default(), Target::parse(&text).unwrap(), Weights::default(), bounds).unwrap();
        assert!((off.cost(&e2) - 0.01).abs() < 1e-9);
    }

    #[test]
    fn bounds_are_checked() {
        assert!(Bounds::thesis(5.0, 1.0, 2.0).validate(5.0).is_ok());
        assert!(Bounds { max_offset_mm: 5.0, tension_min_n: 1.0, tension_max_n: 2.0 }.validate(5.0).is_err());
        assert!(Bounds::thesis(5.0, 2.0, 1.0).validate(5.0).is_err());
        assert!(Bounds::thesis(5.0, 0.0, 1.0).validate(5.0).is_err());
    }
}
