//! Pictures: every PNG cablemap draws of actuators, maps and moulds,
//! shared by `simulate`, reduce, study, mould and design. One file per
//! kind of picture; the surface (font, backend, error), the series of a
//! hanging-rod picture and the frame of a map picture are shared.

mod body;
mod canvas;
mod design_shape;
mod diagnosis_loops;
mod diagnosis_residuals;
mod diagnosis_shapes;
pub mod heatmap;
pub mod map_frame;
pub mod modes;
pub mod mould;
mod reach;
mod series;
mod simulation;
pub mod spatial;

pub use body::{body_series, draw_bodies, BodyDrawing};
pub use design_shape::draw_design_shape;
pub use diagnosis_loops::draw_diagnosis_loops;
pub use diagnosis_residuals::draw_diagnosis_residuals;
pub use diagnosis_shapes::draw_diagnosis_shapes;
pub use canvas::{png_backend, register_fonts, PlotError, FONT};
pub use series::{
    clamp_half_width_mm, clamp_series, draw_legend, draw_series_labels, draw_series_on, hanging_chart, legend_size, series_points, Mark, PageChart, PictureSeries,
    CLAMP_HALF_WIDTH_PER_RADIUS,
};

pub use heatmap::{draw_heatmap, draw_heatmap_laid_out, HeatmapLayout};
pub use map_frame::{MapFrame, Scale};
pub use modes::{draw_modes, ModesLayout};
pub use mould::draw_mould;

/// Reach maps, as the cable map draws them.
pub use reach::{draw_reach_maps, ReachPlane};
pub use simulation::draw_simulation;

/// One picture with the explanation the index page shows.
#[derive(Debug, Clone)]
pub struct Picture {
    /// File name in the map directory.
    pub file: String,
    /// Title.
    pub title: String,
    /// One line of explanation.
    pub explanation: String,
}

#[cfg(test)]
pub(crate) use body::tests;
