//! The continuation ladder: an actuation is reached from the straight rod
//! in rungs, so that large deformations start from a nearby solution (and
//! Newton's method and the shooting stay in their basin for curled-up
//! shapes). Every ladder — single simulations, sweeps, fits, searches —
//! counts its rungs here.

use crate::model::Actuation;

/// Largest tension step of a rung, N.
pub const TENSION_RUNG_N: f64 = 0.25;

/// Largest displacement step of a rung, mm (at the thesis rod's ≈ 2.5 mm/N
/// about a [`TENSION_RUNG_N`] tension rung).
pub const DISPLACEMENT_RUNG_MM: f64 = 0.5;

/// The rungs of a ladder from the straight rod to `actuation` (one per
/// cable): enough that no cable's tension or displacement changes by more
/// than a rung's; at least one. A value that is not finite counts as one
/// rung (the solve refuses it).
pub fn rungs(actuation: &[Actuation]) -> usize {
    actuation
        .iter()
        .map(|a| match *a {
            Actuation::Tension(t) => (t / TENSION_RUNG_N).ceil(),
            Actuation::Displacement(d) => (d / DISPLACEMENT_RUNG_MM).ceil(),
        })
        .filter(|n| n.is_finite())
        .fold(1.0, f64::max) as usize
}

/// The rungs of a ladder to the single tension `tension_n`.
pub fn tension_rungs(tension_n: f64) -> usize {
    rungs(&[Actuation::Tension(tension_n)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rungs_cover_the_largest_step_and_are_at_least_one() {
        assert_eq!(tension_rungs(0.0), 1);
        assert_eq!(tension_rungs(1.0), 4);
        assert_eq!(tension_rungs(1.01), 5);
        assert_eq!(tension_rungs(f64::INFINITY), 1);
        assert_eq!(rungs(&[Actuation::Tension(0.5), Actuation::Displacement(3.0)]), 6);
        assert_eq!(rungs(&[]), 1);
    }
}
