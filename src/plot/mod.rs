//! Pictures: every PNG cablemap draws of actuators and maps, shared by
//! `simulate`, reduce and design. One file per kind of picture; the
//! surface (font, backend, error) and the series of a hanging-rod picture
//! are shared.

mod body;
mod canvas;
mod design_shape;
mod reach;
mod series;
pub mod spatial;

pub use body::{body_series, draw_bodies, BodyDrawing};
pub use design_shape::draw_design_shape;
pub use canvas::{png_backend, register_fonts, PlotError, FONT};
pub use series::{
    clamp_half_width_mm, clamp_series, draw_legend, draw_series_on, hanging_chart, legend_size, series_points, Mark, PageChart, PictureSeries,
    CLAMP_HALF_WIDTH_PER_RADIUS,
};

/// Reach maps, as the cable map draws them.
pub use reach::{draw_reach_maps, ReachPlane};

#[cfg(test)]
pub(crate) use body::tests;
