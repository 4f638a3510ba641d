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
    #[error("bad mould parameter {name}: {problem}")]
    BadParameter {
        /// The parameter's name in [`MouldParams`].
        name: &'static str,
        /// Its value and what it must be.
        problem: ParameterProblem,
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
    /// A cable out of the plane the two-part mould casts in.
    #[error(
        "cable {cable} leaves the bending plane (z0..z4 = {z_mm:?} mm): the two-part mould casts channels in one plane only; print the \
         body with lumens instead (--style lumens)"
    )]
    CableOutOfPlane {
        /// The cable, from 1.
        cable: usize,
        /// Its z control points, mm.
        z_mm: [f64; 5],
    },
    /// A cable's channel is not a routing of the body.
    #[error("cable {cable}: {source}")]
    CableRouting {
        /// The cable, from 1.
        cable: usize,
        /// Why.
        source: crate::model::RoutingError,
    },
    /// An actuator without cables.
    #[error("the actuator has no cables: give [[cable]] tables (or --cable)")]
    NoCables,
    /// An end face of the lumens' body cannot be triangulated.
    #[error("the end face at x = {x_mm} mm: {source}")]
    EndFace {
        /// Where along the body, mm.
        x_mm: f64,
        /// Why.
        source: super::polygon::PolygonError,
    },
    /// The actuator is not a uniform cylinder with the cable knotted at the tip.
    #[error("moulds are made for uniform cylinders only, but this actuator has {}: the two-part mould's tray and plate assume one radius, and every mould channels that leave through the tip and one material; cast such a body in a mould of your own (channel.csv gives the channel)", features_text(features))]
    NonUniformBody {
        /// What makes it non-uniform.
        features: Vec<BodyFeature>,
    },
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

/// What a mould parameter's value is refused for.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParameterProblem {
    /// No channel.
    #[error("no channel given: the moulds need at least one cable")]
    NoChannel,
    /// Channels of different lengths.
    #[error(
        "cable {cable} spans {} mm, cable 1 {} mm: every channel must run from the clamp to the tip (no cable_anchor_mm before the tip)",
        crate::io::fmt_num(*length_mm),
        crate::io::fmt_num(*first_mm)
    )]
    ChannelLengths {
        /// The cable, from 1.
        cable: usize,
        /// Its channel's length, mm.
        length_mm: f64,
        /// Cable 1's, mm.
        first_mm: f64,
    },
    /// Not a number.
    #[error("{value} is not a number of mm: give a finite size")]
    NotFinite {
        /// The value given.
        value: f64,
    },
    /// Beyond any printer.
    #[error("{} mm is larger than {} mm, beyond any printer: give the size in mm", crate::io::fmt_num(*value), super::MAX_SIZE_MM)]
    TooLarge {
        /// The value given, mm.
        value: f64,
    },
    /// A tube not positive or wider than the radius.
    #[error("{tube_mm} mm must be positive and at most the radius {radius_mm} mm{}", if *pour { " (the pour opening is r/2 deep)" } else { "" })]
    Tube {
        /// The tube's diameter, mm.
        tube_mm: f64,
        /// The body's radius, mm.
        radius_mm: f64,
        /// Whether the mould has a pour opening r/2 deep (the two-part mould).
        pour: bool,
    },
    /// A clearance out of range.
    #[error("{clearance_mm} mm must be between 0 and 0.5")]
    Clearance {
        /// The clearance, mm.
        clearance_mm: f64,
    },
    /// A wall thinner than the lid's pin holes.
    #[error("{wall_mm} mm is too thin: the lid's pin holes are {holes_mm} mm deep; use at least {least_mm} mm")]
    WallTooThin {
        /// The wall, mm.
        wall_mm: f64,
        /// The pin holes' depth, mm.
        holes_mm: f64,
        /// The thinnest wall, mm.
        least_mm: f64,
    },
    /// A wall that is not positive.
    #[error("{wall_mm} mm must be positive (the cores reach that far beyond the body)")]
    WallNotPositive {
        /// The wall, mm.
        wall_mm: f64,
    },
    /// A negative size.
    #[error("{value} mm must be ≥ 0")]
    Negative {
        /// The value given, mm.
        value: f64,
    },
    /// A station step out of range.
    #[error("{step_mm} mm must be between 0.01 and 2")]
    StationStep {
        /// The step, mm.
        step_mm: f64,
    },
    /// A body and clamp block too short for the marks and pins.
    #[error("body of {length_mm} mm plus clamp block {clamp_mm} mm is too short for the marks and pins (needs {needed_mm} mm)")]
    ClampTooShort {
        /// The body's length, mm.
        length_mm: f64,
        /// The clamp block, mm.
        clamp_mm: f64,
        /// The least body and clamp block together, mm.
        needed_mm: f64,
    },
    /// A channel's protrusion reaching the body surface.
    #[error(
        "the protrusion of cable {cable} (half-width {half_width_mm:.3} mm in x-sections) at |y_c| = {y_mm:.3} mm reaches the body surface \
         r = {radius_mm} mm at s = {s_mm:.2} mm; use a routing further from the surface or a thinner tube"
    )]
    Protrusion {
        /// The cable, from 1.
        cable: usize,
        /// The protrusion's half-width, mm.
        half_width_mm: f64,
        /// The channel's |y_c|, mm.
        y_mm: f64,
        /// The body's radius, mm.
        radius_mm: f64,
        /// Where, mm.
        s_mm: f64,
    },
}

/// What makes a body other than a uniform cylinder with its cables knotted
/// at the tip.
#[derive(Debug, Clone, PartialEq)]
pub enum BodyFeature {
    /// A radius profile; `lumens` says that a printed body with lumens follows it.
    RadiusProfile {
        /// Whether to point at `--style lumens`.
        lumens: bool,
    },
    /// Segments of their own material.
    Segments,
    /// The rod's cable anchored before the tip.
    CableAnchored,
    /// A cable knotted before the tip.
    CableKnotted {
        /// The cable, from 1.
        cable: usize,
        /// Where it is knotted, mm.
        anchor_mm: f64,
    },
}

impl std::fmt::Display for BodyFeature {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BodyFeature::RadiusProfile { lumens: true } => {
                write!(f, "a radius profile (radius_profile_mm; a printed body with lumens follows it: --style lumens)")
            }
            BodyFeature::RadiusProfile { lumens: false } => write!(f, "a radius profile (radius_profile_mm)"),
            BodyFeature::Segments => write!(f, "segments of their own material"),
            BodyFeature::CableAnchored => write!(f, "a cable anchored before the tip (cable_anchor_mm)"),
            BodyFeature::CableKnotted { cable, anchor_mm } => write!(
                f,
                "cable {cable} knotted before the tip (anchor_mm = {} mm; its tube must leave through the tip)",
                crate::io::fmt_num(*anchor_mm)
            ),
        }
    }
}

/// The features of a non-uniform body, for a sentence.
fn features_text(features: &[BodyFeature]) -> String {
    features.iter().map(ToString::to_string).collect::<Vec<_>>().join(" and ")
}
