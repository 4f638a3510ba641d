//! The mirror rule, in one place. A run that dropped mirror images stores
//! one of each pair of routings y and −y; the dropped twin's solve is the
//! stored one reflected in the x axis: every quantity that changes sign
//! under y → −y (control points, tip y, tip angle, every a_i) is negated,
//! the rest (tip x, tension, routing id) is kept.

use super::sample::{RowRef, Sample};
use super::Design;

/// How many simulations a stored row stands for: 2 when the run dropped
/// mirror images and the routing is not its own mirror (all control points
/// 0), else 1.
pub(crate) fn copies(run_mirrored: bool, y_mm: impl IntoIterator<Item = f64>) -> u64 {
    let self_mirror = y_mm.into_iter().all(|y| y == 0.0);
    if run_mirrored && !self_mirror {
        2
    } else {
        1
    }
}

/// A record of a simulation that has a mirror image.
pub(crate) trait Mirror {
    /// The record of the reflected simulation (flagged as mirrored).
    fn mirror(&self) -> Self;
}

impl Mirror for Sample {
    fn mirror(&self) -> Self {
        Sample { y_mm: -self.y_mm, a: self.a.map(|v| -v), at: self.at.mirror(), ..*self }
    }
}

impl Mirror for RowRef {
    fn mirror(&self) -> Self {
        Self { mirrored: true, ..*self }
    }
}

impl Mirror for Design {
    fn mirror(&self) -> Self {
        Design {
            mirrored: true,
            routing_mm: self.routing_mm.mirrored(),
            tip_y_mm: -self.tip_y_mm,
            tip_angle_rad: -self.tip_angle_rad,
            a: self.a.iter().map(|v| -v).collect(),
            ..self.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_mirrored_run_doubles_and_the_straight_routing_is_its_own_mirror() {
        assert_eq!(copies(true, [0.0, 1.0, 0.0, 0.0, 0.0]), 2);
        assert_eq!(copies(true, [0.0; 5]), 1);
        assert_eq!(copies(false, [0.0, 1.0, 0.0, 0.0, 0.0]), 1);
    }

    #[test]
    fn a_design_reflects_in_the_x_axis_and_twice_is_itself() {
        let d = Design {
            ix: 1,
            iy: 2,
            routing_id: 7,
            mirrored: false,
            routing_mm: [0.0, 1.0, -2.0, 3.0, 0.5].into(),
            tension_n: 1.5,
            tip_x_mm: 50.0,
            tip_y_mm: 5.0,
            tip_angle_rad: 0.3,
            a: vec![-0.02, 0.01, 0.003],
        };
        let m = d.mirror();
        assert!(m.mirrored);
        assert_eq!((m.tip_x_mm, m.tip_y_mm, m.tip_angle_rad, m.tension_n), (50.0, -5.0, -0.3, 1.5));
        assert_eq!(m.routing_mm, [0.0, -1.0, 2.0, -3.0, -0.5]);
        assert_eq!(m.a, vec![0.02, -0.01, -0.003]);
        assert_eq!(Design { mirrored: false, ..m.mirror() }, d);
    }
}
