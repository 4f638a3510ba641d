//! A design's picture (`design --out DIR`: shape.png): the achieved body
//! over the target shape and the target tip.

use super::{draw_bodies, BodyDrawing, PlotError};
use crate::model::Rod;
use crate::solver::Simulation;
use plotters::style::full_palette::{BLUE_800, GREEN_700};
use std::path::Path;

/// Draws the achieved body (`achieved`, of `rod`), the target shape's
/// centreline (`target_centreline`, x–y points from the clamp; none when
/// the target gives no coefficient) and the target tip (a cross) into `path`.
pub fn draw_design_shape(
    path: &Path,
    title: &str,
    achieved: &Simulation,
    rod: &Rod,
    target_centreline: Option<&[[f64; 2]]>,
    target_tip: Option<(f64, f64)>,
) -> Result<(), PlotError> {
    let mut bodies = vec![BodyDrawing::of_body(achieved, rod, "achieved body (outline at ±r), cable in red".into(), BLUE_800)];
    if let Some(pts) = target_centreline {
        let angles: Vec<f64> = pts.windows(2).map(|w| (w[1][1] - w[0][1]).atan2(w[1][0] - w[0][0])).collect();
        let mut frame = angles.clone();
        frame.push(*angles.last().unwrap_or(&0.0));
        bodies.push(BodyDrawing {
            centreline: pts.iter().map(|p| (p[0], p[1])).collect(),
            frame_angle_rad: frame,
            cable: Vec::new(),
            further_cables: Vec::new(),
            radius_mm: 0.0,
            radii_mm: Vec::new(),
            label: "target shape (target a_i; achieved ℓ and base angle)".into(),
            colour: GREEN_700,
        });
    }
    draw_bodies(path, title, &bodies, &target_tip.into_iter().collect::<Vec<_>>())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Routing;
    use crate::solver::simulate;

    /// The pictures (design's shape.png, simulate --png) draw a cable knotted
    /// before the tip from the clamp to its anchor, not on to the tip.
    #[test]
    fn the_drawn_cable_ends_at_its_anchor() {
        let anchor_mm = 41.7;
        let act = crate::model::Rod { cable_anchor_mm: Some(anchor_mm), ..Default::default() };
        let routing = Routing::for_actuator([3.0, 1.0, -2.0, 3.0, 4.0], &act).unwrap();
        let sim = simulate(&act, &Default::default(), &routing, 1.5, 2, crate::shape::LengthBasis::Rest).unwrap();
        let drawing = BodyDrawing::of_body(&sim, &act, "body".into(), BLUE_800);
        let knot = sim.centreline.iter().find(|c| c.s_mm == anchor_mm).expect("a centreline point at the anchor");
        assert_eq!(drawing.cable.last(), Some(&(knot.cables[0].position_mm[0], knot.cables[0].position_mm[1])));
        assert_eq!(drawing.cable.len(), sim.centreline.iter().filter(|c| c.s_mm <= anchor_mm).count());
        // The channel's offset there (y_4 = 4 mm at the anchor): the path does not fall back onto the centreline.
        assert!((knot.cables[0].channel_mm[0] - 4.0).abs() < 1e-9, "{knot:?}");
        assert!(drawing.cable.iter().all(|p| p.0.is_finite() && p.1.is_finite()));
    }
}
