//! Why moulds could not be made or written.

use super::{MAX_TRIANGLES, SUMMARY_FILE};

/// Why moulds could not be made or written.
#[derive(Debug, thiserror::Error)]
pub enum MouldError {
    /// The meshes would be too large to build or print.
    #[error(
        "the moulds would have about {} triangles, more than {} (about {} MB of STL): the body ({} mm long, r = {} mm) with wall {} mm and clamp block {} mm is too large to mesh at the station step; give the sizes in mm, and mould a body of printable size",
        crate::io::fmt_sig(*triangles, 3),
        crate::io::fmt_sig(MAX_TRIANGLES, 3),
        crate::io::fmt_sig(*triangles * 50.0 / 1e6, 3),
        crate::io::fmt_num(*length_mm),
        crate::io::fmt_num(*radius_mm),
        crate::io::fmt_num(*wall_mm),
        crate::io::fmt_num(*clamp_mm)
    )]
    TooLarge { triangles: f64, length_mm: f64, radius_mm: f64, wall_mm: f64, clamp_mm: f64 },
    /// The output directory holds other files.
    #[error("{}: the directory exists and is not a mould directory (it has files but no {SUMMARY_FILE}); give a new or empty directory, or one written by cablemap mould", path.display())]
    NotAMouldDir { path: std::path::PathBuf },
    /// The output directory has no name (".", "/").
    #[error("{}: give the moulds a directory of their own by name (e.g. --out moulds)", path.display())]
    OutUnnamed { path: std::path::PathBuf },
    /// A parameter is out of range.
    #[error("bad mould parameter {name}: {message}")]
    BadParameter {
        /// The parameter's name in [`MouldParams`].
        name: &'static str,
        /// Its value and what it must be.
        message: String,
    },
    /// A channel comes too close to the body surface to be cast.
    #[error(
        "the channel of cable {cable} (tube Ø {tube_mm} mm) comes within {skin_mm:.3} mm of the body surface at s = {s_mm:.2} mm \
         (|y_c| = {y_mm:.3} mm, r = {radius_mm} mm); it needs at least {min_skin_mm} mm of silicone: \
         use a routing with |y_c| ≤ {limit_mm:.3} mm (design --max-offset-mm), a thinner tube, or --min-skin-mm"
    )]
    ChannelTooClose { cable: usize, tube_mm: f64, skin_mm: f64, s_mm: f64, y_mm: f64, radius_mm: f64, min_skin_mm: f64, limit_mm: f64 },
    /// Two channels come too close to each other to be cast.
    #[error(
        "the channels of cables {first} and {second} (tube Ø {tube_mm} mm) keep only {gap_mm:.3} mm of silicone between them at s = {s_mm:.2} mm \
         (cable {first}'s s); they need at least {needed_mm:.3} mm: route them farther apart there, use a thinner tube \
         (--tube-diameter-mm), or a smaller --min-skin-mm"
    )]
    ChannelsTooClose { first: usize, second: usize, s_mm: f64, gap_mm: f64, needed_mm: f64, tube_mm: f64 },
    /// A lumen (spatial channel) comes too close to the body surface.
    #[error(
        "the lumen of cable {cable} (Ø {tube_mm} mm) comes within {skin_mm:.3} mm of the body surface at s = {s_mm:.2} mm \
         (its centre {distance_mm:.3} mm from the axis, r(s) = {radius_mm:.3} mm); it needs at least {min_skin_mm} mm of silicone: \
         move the channel nearer the axis there, use a thinner tube (--tube-diameter-mm), or a smaller --min-skin-mm"
    )]
    LumenTooClose { cable: usize, tube_mm: f64, skin_mm: f64, s_mm: f64, distance_mm: f64, radius_mm: f64, min_skin_mm: f64 },
    /// The actuator cannot be moulded in the style asked for.
    #[error("{0}")]
    Unsupported(String),
    /// The actuator is not a uniform cylinder with the cable knotted at the tip.
    #[error("moulds are made for uniform cylinders only, but this actuator has {0}: the two-part mould's tray and plate assume one radius, and every mould channels that leave through the tip and one material; cast such a body in a mould of your own (channel.csv gives the channel)")]
    NonUniformBody(String),
    /// The actuator's cables are invalid.
    #[error(transparent)]
    Actuator(#[from] crate::solver::spatial::SpatialError),
    /// The rod's parameters are invalid.
    #[error(transparent)]
    Rod(#[from] crate::model::ParameterError),
    /// Writing a file.
    #[error(transparent)]
    File(#[from] crate::io::FileError),
    /// Drawing the preview.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
}

