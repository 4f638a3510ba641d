//! The specs of the kinds of sweep, each declaring its kind once (its
//! `impl RunSpec`: format tag, layout, schema, how a routing is solved):
//!
//! - [`planar`]: one planar cable over a grid of routings and a tension
//!   ladder ([`SweepSpec`], `cablemap-sweep/2` runs);
//! - [`cables`]: several or spatial cables, swept control points and a
//!   tension grid per cable ([`CableSweepSpec`], `cablemap-cables/1` runs),
//!   recognised by its `[[cable]]` tables (`job::Job::load` tells a spec
//!   file's kind).
//!
//! Both keep the limits every kind shares ([`MAX_CHUNK_ROWS`], [`MAX_ROWS`]).

pub mod cables;
pub mod planar;

pub use super::kind::{MAX_CHUNK_ROWS, MAX_ROWS};
pub use cables::{CableGrid, CableOutputSpec, CableSpecError, CableSweepSpec, CableWorker, PointSweep, ValueGrid, MAX_TENSION_COUNT};
pub use planar::{
    ChunkBytesFix, DisplacementSpec, GridSpec, Ladder, OutputSpec, SpecError, SweepSpec, TensionSpec, MAX_CHUNK_BYTES, MAX_LEVELS, MAX_ORDER, MAX_STEPS_PER_SPAN, MAX_TENSIONS,
    THESIS_SPEC_TOML,
};
