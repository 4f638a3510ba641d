//! The drawings of the modes' representative bodies: the map stores only a
//! representative's routing and tension, so its body is simulated again
//! (with the run's actuator and solver) for modes.png and index.html; a
//! several-cable map's representative with all its cables
//! ([`ModeDrawings::of_cables`]).

use super::{Design, MapCables, MapData};
use crate::solver::spatial::simulate_spatial;
use crate::model::Rod;
use crate::solver::SolverOptions;
use crate::plot::BodyDrawing;

/// Why a representative could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum DrawingError {
    /// Its routing is not a valid routing of the actuator.
    #[error("mode {mode}: its representative's routing is invalid: {source}")]
    Routing {
        /// The mode.
        mode: usize,
        /// The routing's error.
        source: crate::model::RoutingError,
    },
    /// Simulating it again failed.
    #[error("mode {mode}: simulating its representative again failed: {source}")]
    Simulation {
        /// The mode.
        mode: usize,
        /// The simulation's error.
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}

/// The representatives' bodies, one entry per mode (index = mode).
#[derive(Debug, Default)]
pub struct ModeDrawings {
    /// The body of each mode's representative (None for a mode without
    /// simulations, or whose representative could not be drawn).
    pub shapes: Vec<Option<BodyDrawing>>,
    /// The representatives that could not be drawn.
    pub failures: Vec<DrawingError>,
}

impl ModeDrawings {
    /// Simulates every mode's representative of `map` again and draws it.
    pub fn of_map(map: &MapData, rod: &Rod, solver: &SolverOptions) -> Self {
        let mut drawings = Self::default();
        for m in &map.modes {
            let shape = m.representative.as_ref().map(|d| draw(m.mode, d, rod, solver)).transpose();
            match shape {
                Ok(shape) => drawings.shapes.push(shape),
                Err(e) => {
                    drawings.shapes.push(None);
                    drawings.failures.push(e);
                }
            }
        }
        drawings
    }

    /// Solves every mode's representative of the map of a cable sweep
    /// again with all the cables of its row (its `routing_id` is the row
    /// key, [`MapCables::actuator`]) and draws it in the x–y plane with
    /// every cable's path.
    pub fn of_cables(map: &MapData, cables: &MapCables) -> Self {
        let spec = cables.spec();
        let rod = &spec.actuator.rod;
        let mut drawings = Self::default();
        for m in &map.modes {
            let Some(d) = &m.representative else {
                drawings.shapes.push(None);
                continue;
            };
            match simulate_spatial(&cables.actuator(d.routing_id), cables.solver(), 1, cables.output().length_basis) {
                // The sweep reached the row along its tension path; a solve from
                // zero could in principle land on another equilibrium: then the
                // drawing would not be the row's, and is not made.
                Ok(sim) if tip_gap_mm(&sim.pose.tip_mm(), d) > REDRAW_TOLERANCE_MM => {
                    drawings.shapes.push(None);
                    let message = format!(
                        "the solve from zero ends at ({:.3}, {:.3}) mm, not at the row's tip ({:.3}, {:.3}) mm",
                        sim.pose.tip_x_mm, sim.pose.tip_y_mm, d.tip_x_mm, d.tip_y_mm
                    );
                    drawings.failures.push(DrawingError::Simulation { mode: m.mode, source: message.into() });
                }
                Ok(sim) => {
                    let label = format!("mode {}", m.mode);
                    drawings.shapes.push(Some(BodyDrawing::of_body(&sim, rod, label, plotters::style::full_palette::BLUE_800)));
                }
                Err(e) => {
                    drawings.shapes.push(None);
                    drawings.failures.push(DrawingError::Simulation { mode: m.mode, source: Box::new(e) });
                }
            }
        }
        drawings
    }

    /// A sentence naming the representatives that could not be drawn (empty
    /// when all were).
    pub fn failure_note(&self) -> String {
        if self.failures.is_empty() {
            return String::new();
        }
        let list: Vec<String> = self.failures.iter().map(ToString::to_string).collect();
        format!(" Not drawn: {}.", list.join("; "))
    }
}

fn draw(mode: usize, d: &Design, rod: &Rod, solver: &SolverOptions) -> Result<BodyDrawing, DrawingError> {
    let routing = crate::model::Routing::for_actuator(d.routing_mm, rod)
        .map_err(|source| DrawingError::Routing { mode, source })?;
    let sim = crate::solver::simulate(rod, solver, &routing, d.tension_n, 1, crate::shape::LengthBasis::default())
        .map_err(|e| DrawingError::Simulation { mode, source: Box::new(e) })?;
    Ok(BodyDrawing::of_body(&sim, rod, format!("mode {mode}"), plotters::style::full_palette::BLUE_800))
}

/// Largest distance, mm, between a representative's stored tip and the tip
/// of its solve again for drawing.
const REDRAW_TOLERANCE_MM: f64 = 1e-3;

/// In-plane distance between a solved tip and a design's, mm.
fn tip_gap_mm(tip: &[f64; 3], d: &Design) -> f64 {
    (tip[0] - d.tip_x_mm).hypot(tip[1] - d.tip_y_mm)
}
