//! The drawings of the modes' representative bodies: the map stores only a
//! representative's routing and tension, so its body is simulated again
//! (with the run's actuator and solver) for modes.png and index.html.

use super::{Design, MapData};
use crate::model::{Rod, SolverOptions};
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
    pub fn of_map(map: &MapData, actuator: &Rod, solver: &SolverOptions) -> Self {
        let mut drawings = Self::default();
        for m in &map.modes {
            let shape = m.representative.as_ref().map(|d| draw(m.mode, d, actuator, solver)).transpose();
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

fn draw(mode: usize, d: &Design, actuator: &Rod, solver: &SolverOptions) -> Result<BodyDrawing, DrawingError> {
    let routing = crate::model::Routing::for_actuator(d.routing_mm, actuator)
        .map_err(|source| DrawingError::Routing { mode, source })?;
    let sim = crate::model::simulate(actuator, solver, &routing, d.tension_n, 1, crate::shape::LengthBasis::default())
        .map_err(|e| DrawingError::Simulation { mode, source: Box::new(e) })?;
    Ok(BodyDrawing::of_body(&sim, actuator, format!("mode {mode}"), plotters::style::full_palette::BLUE_800))
}
