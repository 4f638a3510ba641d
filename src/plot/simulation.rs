//! The picture of one simulate request ([`SimulateReport`]): a routing's
//! deformed body, channel and tip in the plane, or an actuator's body and
//! cables in two views.

use super::{draw_bodies, spatial::draw_spatial, BodyDrawing, PlotError};
use crate::solver::request::{RecordKind, SimulateReport};
use plotters::style::full_palette::BLUE_800;
use std::path::Path;

/// Draws `report`'s simulation to `path` (PNG), titled by what was asked:
/// the routing and its tension, or the cables' tensions.
pub fn draw_simulation(path: &Path, report: &SimulateReport) -> Result<(), PlotError> {
    let sim = &report.simulation;
    match report.record {
        RecordKind::Routing => {
            let y: Vec<String> = report.actuator.cables[0].y_mm.iter().map(|y| format!("{y}")).collect();
            let title = format!("routing [{}] mm, tension {:.3} N", y.join(", "), sim.pose.tension_n());
            let drawing = BodyDrawing::of_body(sim, &report.actuator.rod, "body (outline at ±r)".into(), BLUE_800);
            draw_bodies(path, &title, &[drawing], &[])
        }
        RecordKind::Actuator => {
            let tensions: Vec<String> = report.actuator.cables.iter().map(|c| format!("{:.3}", c.tension_n)).collect();
            let title = format!("{} cable(s), tensions [{}] N", report.actuator.cables.len(), tensions.join(", "));
            draw_spatial(path, &title, sim)
        }
    }
}
