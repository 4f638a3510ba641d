//! The sharded, resumable sweep: every routing of a spec solved through its
//! tensions, written as Parquet chunks (thesis Ch. 4, model-notes §5). One
//! engine serves every kind of sweep; a spec declares its kind once.
//!
//! - [`spec`]: the TOML job spec and its hash: one [`SweepSpec`] whose
//!   routing grid is of a kind ([`RunSpec`]): the thesis's planar grid, or a
//!   grid of several or spatial cables.
//! - [`kind`]: what a kind of sweep provides the engine, and the limits every
//!   kind keeps.
//! - [`enumerate`]: planar routing ids, mirror de-duplication, chunks and shards.
//! - [`solve`]: one routing solved into its rows, for each kind.
//! - [`schema`]: the columns of every run format (`docs/schema.md`) and batch building.
//! - [`store`]: the run directory: manifest, atomic chunk files, checks.
//! - [`run`]: the engine (parallel solving, resume, progress, summary).
//! - [`status`]: done/total per shard, failures, completeness.
//! - [`report`]: what `sweep` and `status` print, for every kind.
//! - [`read`]: **the reader other stages use**: [`read::open_run`] checks a
//!   run directory and streams its rows as Arrow record batches.

pub mod enumerate;
pub mod error;
pub mod kind;
pub mod progress;
pub mod read;
pub mod report;
pub mod run;
pub mod schema;
pub mod solve;
pub mod spec;
pub mod status;
pub mod store;

pub use enumerate::SweepPlan;
pub use error::SweepError;
pub use kind::{ChunkLayout, RunKind, RunSpec};
pub use read::{open_run, Completeness, SweepRun};
pub use report::{StatusReport, SweepReport};
pub use run::{run_sweep, SweepOptions, SweepSummary, MAX_SHARDS};
pub use spec::{OutputSpec, RoutingGrid, SweepSpec};
pub use status::{run_status, RunStatus};
pub use store::run_kind;
