//! Reduce: a sweep run of any kind into its map (thesis Ch. 4, model-notes
//! §5; the output contract is docs/maps.md). One pipeline ([`pipeline`]):
//! a planar sweep becomes a feasibility map; a cable sweep its reach counts
//! (`reach`) and, when every cable lies in the plane, a feasibility map by
//! the same stages, its rows read as planar rows (`source`, `columns`).
//!
//! [`reduce_batches`] runs the stages in order, each in its own module:
//! - `samples` (pass 1): tip and a_0…a_2 of every converged row (`sample`),
//!   written to a scratch file (`spill`), the mirrored half restored on
//!   reading (the mirror rule lives in `mirror`);
//! - `modes::split`: mode boundaries, given or by exact quantiles (`select`:
//!   a counting pass and selection passes over the scratch file);
//! - `grid`: the cells over the reach;
//! - `partition`: the samples split by cell range into partitions that fit
//!   in memory; per partition, `cells` (count, percentiles, mode counts and
//!   the designs kept) and `modes::Nearest` (the simulation nearest each
//!   mode's median);
//! - `fetch` (pass 2): the full rows of the kept designs and representatives;
//! - assembly into [`MapData`] (`map_data`: what a map holds).
//!
//! Memory is bounded by [`ReduceOptions::memory_samples`], whatever the
//! run's size, and the tables are the same for any bound (docs/maps.md).
//! [`parts`] splits pass 1 across processes (cluster tasks) and merges.
//!
//! The map format (file and column names, writer, reader) is [`tables`];
//! [`output`] writes a whole map directory, [`drawings`] the modes' bodies,
//! [`map_cables`] a several-cable map's cables.

mod cells;
mod density;
mod columns;
pub mod drawings;
mod error;
pub mod explorer;
mod fetch;
mod grid;
pub mod map_cables;
mod map_data;
mod mirror;
mod modes;
pub mod options;
pub mod output;
pub mod parts;
mod partition;
pub mod pipeline;

mod reach;
mod sample;
mod samples;
mod select;
mod source;
mod spill;
pub mod stats;
pub mod tables;

pub use density::Density;
pub use error::{PartsError, ReduceError};
pub use map_cables::{design_actuation, MapCables};
pub use map_data::{
    ReachMapSummary, CellStats, CoefficientStats, Design, MapBody, MapData, MapSummary, ModeStats, CELL_STATS_ORDER, COEFFICIENT_UNIT,
    MAX_CELLS_PER_AXIS, MODES,
};
pub use options::{MapSettings, MapSettingsError, MapSettingsFields, ModeBoundaries, ReduceOptions, DEFAULT_CELL_MM, DEFAULT_MEMORY_SAMPLES};
pub use output::{check_map_out, write_map, write_map_replacing};
pub use pipeline::{map_given_as_run, reduce_batches, reduce_cable_run, reduce_run, run_open_error, ReachMap};
pub use source::RunInfo;
