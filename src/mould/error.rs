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
    /// The channel comes too close to the body surface to be cast.
    #[error(
        "the channel (tube Ø {tube_mm} mm) comes within {skin_mm:.3} mm of the body surface at s = {s_mm:.2} mm \
         (|y_c| = {y_mm:.3} mm, r = {radius_mm} mm); it needs at least {min_skin_mm} mm of silicone: \
         use a routing with |y_c| ≤ {limit_mm:.3} mm (design --max-offset-mm), a thinner tube, or --min-skin-mm"
    )]
    ChannelTooClose { tube_mm: f64, skin_mm: f64, s_mm: f64, y_mm: f64, radius_mm: f64, min_skin_mm: f64, limit_mm: f64 },
    /// The actuator is not a uniform cylinder with the cable knotted at the tip.
    #[error("moulds are made for uniform cylinders only, but this actuator has {0}: the two-part mould's tray and plate assume one radius and a channel to the tip; cast a tapered or segmented body in a mould of your own (channel.csv gives the channel)")]
    NonUniformBody(String),
    /// Writing a file.
    #[error(transparent)]
    File(#[from] crate::io::FileError),
    /// Drawing the preview.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
}

