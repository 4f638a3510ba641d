//! Printable moulds for a designed actuator (thesis §5.2, Fig. 5.2).
//!
//! The thesis casts the silicone body in two steps: half of it in a first
//! mould whose inner surface carries a protrusion along the cable routing
//! (leaving a groove), then, with a PTFE tube laid in the groove, the other
//! half in a second mould; pulling the tube out leaves the channel.
//!
//! Here every part is an open tray or plate, printable face up without
//! supports and free of undercuts, built as a heightfield solid
//! ([`mesh::heightfield_solid`]). Frame: x along the body (the clamp face at
//! x = 0, the tip at x = L, the clamp block at −c … 0), y the model's lateral
//! axis (the bending plane), z normal to the cutting plane z = 0 that holds
//! the channel centreline y = y_c(x).
//!
//! - **Tray** (`T`): the half-cylinder trough z = −√(r² − y²) over −c < x < L,
//!   three registration pins, a pour opening (sprue) through the clamp-end
//!   wall and a notch for the tube through the tip-end wall. Used in both castings.
//! - **Lid 1** (`1`): a plate with the channel's protrusion, a half tube of
//!   the tube's radius whose centreline follows y_c(s) in the cutting plane
//!   (straight along x in the clamp block and beyond the ends). Tray + lid
//!   are mould 1: the cavity is the half body with its groove.
//! - **Cover 2** (`2`): a second half-cylinder trough with pin holes, the same
//!   sprue and notch. Tray + cover are mould 2: the full cylinder cavity that
//!   takes the half body (still in the tray) with the tube in its groove.
//!
//! Lid and cover are printed mating face up, i.e. turned 180° about the x axis
//! from their place in the assembly: their print frame has y and z negated.
//! Orientation marks are engraved in each part's mating face: "CL" at the
//! clamp end, an arrow and "+Y" in the margin on the +y side, and the part's
//! letter; a mirrored print reads backwards.
//!
//! Several planar channels get a protrusion each on the lid and a notch
//! each in the tip-end walls. Channels in space (or a tapered body) get a
//! printed body with lumens and the lumens' castable cores instead
//! ([`lumens`]); [`request`] picks the style for any actuator
//! ([`for_actuator`], the one entry point of `mould --actuator` and
//! `design --moulds`).

pub mod error;
mod font;
pub mod lumens;
pub mod mesh;
pub mod moulds;
pub mod params;
pub mod polygon;
pub mod request;
pub mod set;
pub mod stl;
mod write;

pub use error::{BodyFeature, MouldError, ParameterProblem};
pub use moulds::{volume_below_face_mm3, Moulds, Part, PartKind};
pub use params::{check_uniform_body, MouldParams, MouldSettings, MAX_SIZE_MM, MAX_TRIANGLES};
pub use lumens::{LumenSummary, Lumens};
pub use request::{build, check, check_body, for_actuator, resolve_style, ActuatorMoulds, MouldOptions, MouldReport, MouldStyle};
pub use set::{MouldFile, MouldSet, MouldSummary, PlacedPart};

/// The file every mould directory holds: an output directory that has it
/// (or is new or empty) may be replaced.
pub const SUMMARY_FILE: &str = "mould.json";

