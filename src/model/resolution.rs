//! How many shape coefficients the discretisation resolves.
//!
//! The curvature coefficients a_k come from the solver's nodes (2 spans of
//! `steps_per_span` RK4 steps). High-order Legendre polynomials oscillate
//! faster than the nodes sample them, so a_k's error grows quickly with k:
//! at the default 24 steps, a_5 is within 1e-5 mm⁻¹ of the converged value
//! but a_9 is off by ~3e-3 and a_12 by ~5e-2 (issue 10). cablemap does not
//! refine silently; it refuses an order the chosen steps do not resolve and
//! names the steps that would.
//!
//! [`REQUIRED_STEPS_PER_SPAN`] was measured with `cablemap simulate --json`:
//! seven routings (straight to fully alternating, ±4 mm) at 0.5–2 N, each
//! a_k compared with a 2048-step solve; an entry is the fewest steps (on a
//! grid of 4, then 16) at which a_0 … a_k all lie within
//! [`ORDER_TOLERANCE_PER_MM`] of it. Orders above the table are refused.

/// Accuracy the order check guarantees for every a_k, mm⁻¹.
pub const ORDER_TOLERANCE_PER_MM: f64 = 5e-5;

/// Fewest steps per span resolving a_0 … a_k, indexed by k.
pub const REQUIRED_STEPS_PER_SPAN: [usize; 17] = [4, 4, 8, 8, 16, 20, 32, 40, 60, 80, 96, 112, 144, 160, 192, 224, 256];

/// Highest order supported at all (with enough steps).
pub const MAX_RESOLVED_ORDER: usize = REQUIRED_STEPS_PER_SPAN.len() - 1;

/// Highest order resolved at `steps_per_span`.
pub fn max_order(steps_per_span: usize) -> usize {
    REQUIRED_STEPS_PER_SPAN.iter().rposition(|&s| s <= steps_per_span).unwrap_or(0)
}

/// Checks that `order` is resolved at `steps_per_span`; the message names
/// the fix.
pub fn check_order(order: usize, steps_per_span: usize) -> Result<(), String> {
    if order > MAX_RESOLVED_ORDER {
        return Err(format!(
            "order {order} is above the highest supported order {MAX_RESOLVED_ORDER} (higher coefficients are not resolved \
             by the solver's discretisation; see docs/reliability.md)"
        ));
    }
    let needed = REQUIRED_STEPS_PER_SPAN[order];
    if steps_per_span < needed {
        return Err(format!(
            "order {order} is not resolved at {steps_per_span} steps per span (a_k would be off by more than \
             {ORDER_TOLERANCE_PER_MM:e} mm⁻¹; at most order {} here): use steps_per_span ≥ {needed} \
             (--steps-per-span {needed}), or a lower order",
            max_order(steps_per_span)
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_monotone_and_the_defaults_resolve_order_3() {
        assert!(REQUIRED_STEPS_PER_SPAN.windows(2).all(|w| w[0] <= w[1]));
        assert!(REQUIRED_STEPS_PER_SPAN.iter().all(|s| s % 2 == 0));
        assert_eq!(max_order(24), 5);
        assert!(check_order(3, 24).is_ok());
        let e = check_order(12, 24).unwrap_err();
        assert!(e.contains("--steps-per-span 144"), "{e}");
        assert!(check_order(12, 144).is_ok());
        assert!(check_order(100, 100_000).unwrap_err().contains("highest supported order 16"));
    }

    /// The claim behind the table, re-measured at two entries: a_k at the
    /// tabulated steps is within the tolerance of a much finer solve.
    #[test]
    fn tabulated_steps_meet_the_tolerance() {
        use crate::model::{Actuator, Routing, Simulator, SolverOptions};
        let actuator = Actuator::default();
        let routing = Routing::new(&[-4.0, 4.0, -4.0, 4.0, -4.0], actuator.length_mm, actuator.radius_mm).unwrap();
        // The solver itself (not `simulate`, which would refuse the coarse case).
        let at = |steps: usize, order: usize| {
            let options = SolverOptions { steps_per_span: steps, ..SolverOptions::default() };
            let mut sim = Simulator::new(&actuator, &options).unwrap();
            sim.set_routing(&routing);
            for t in [0.5, 1.0, 1.5, 2.0] {
                sim.solve(t).unwrap();
            }
            let mut a = vec![0.0; order + 1];
            sim.coefficients_into(crate::shape::LengthBasis::Rest, &mut a);
            a
        };
        for order in [5, 9] {
            let coarse = at(REQUIRED_STEPS_PER_SPAN[order], order);
            let fine = at(1024, order);
            for k in 0..=order {
                assert!((coarse[k] - fine[k]).abs() <= ORDER_TOLERANCE_PER_MM, "a_{k} at order {order}: {} vs {}", coarse[k], fine[k]);
            }
            // And one step below the table is not (the table is not slack).
            let below = at(REQUIRED_STEPS_PER_SPAN[order] / 2, order);
            assert!((below[order] - fine[order]).abs() > ORDER_TOLERANCE_PER_MM / 10.0);
        }
    }
}
