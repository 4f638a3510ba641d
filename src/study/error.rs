//! What is wrong with a study, or why it cannot be compared yet.

use super::axes::AxisError;
use std::path::PathBuf;

/// What is wrong with a study, or why it cannot be compared yet.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The spec text or its `[study]` section.
    #[error("bad study spec {origin}: {message}")]
    Spec {
        /// The spec file.
        origin: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// One of the spec's axes.
    #[error("bad study spec {origin}: [[study.axis]] {axis}: {source}")]
    Axis {
        /// The spec file.
        origin: String,
        /// The axis's name.
        axis: String,
        /// What is wrong with it and what to do.
        source: AxisError,
    },
    /// One variant's sweep spec is invalid.
    #[error("bad study spec {origin}: variant {index} ({label}): {source}")]
    Variant {
        /// The spec file.
        origin: String,
        /// Variant number.
        index: usize,
        /// Its settings.
        label: String,
        /// Why its spec is refused.
        source: crate::sweep::SweepError,
    },
    /// The directory holds another study.
    #[error("{} holds another study (its variants differ from this spec's): give a new directory, or the spec it was started with", dir.display())]
    OtherStudy {
        /// The study directory.
        dir: PathBuf,
    },
    /// The directory holds no study.
    #[error("{} holds no study ({} is missing): run the study first", dir.display(), record.display())]
    NoStudy {
        /// The study directory.
        dir: PathBuf,
        /// Its record that is missing (`study.json`).
        record: PathBuf,
    },
    /// Some variants have no map yet.
    #[error("{}: {} of {total} variants not mapped yet (variant {}): run the study (or those shards) to finish them", dir.display(), missing.len(), missing.iter().map(usize::to_string).collect::<Vec<_>>().join(", "))]
    NotMapped {
        /// The study directory.
        dir: PathBuf,
        /// Variants.
        total: usize,
        /// Variants without a map.
        missing: Vec<usize>,
    },
    /// A variant's map cannot be read.
    #[error("variant {index}: {source}")]
    Map {
        /// Variant number.
        index: usize,
        /// The read error.
        source: crate::reduce::tables::ReadError,
    },
    /// A variant's sweep failed.
    #[error("variant {index} ({label}): {source}")]
    Sweep {
        /// Variant number.
        index: usize,
        /// Its settings.
        label: String,
        /// The sweep's error.
        source: crate::sweep::SweepError,
    },
    /// A variant's reduce failed.
    #[error("variant {index} ({label}): {source}")]
    Reduce {
        /// Variant number.
        index: usize,
        /// Its settings.
        label: String,
        /// The reduce's error.
        source: crate::reduce::ReduceError,
    },
    /// A picture of the comparison page could not be drawn.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
    /// A file operation.
    #[error(transparent)]
    File(#[from] crate::io::FileError),
    /// `study.json` is not a study's record.
    #[error("{}: not a study record: {message}", path.display())]
    NotARecord {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A task index outside the split.
    #[error("task {shard} is not below the {shards} tasks of the split: tasks are numbered 0 to shards − 1 (shards ≥ 1)")]
    BadTask {
        /// The task asked for.
        shard: u64,
        /// Tasks in all.
        shards: u64,
    },
    /// Running a variant of the study in a directory.
    #[error("study {}: {source}", dir.display())]
    In {
        /// The study directory.
        dir: PathBuf,
        /// What went wrong.
        source: Box<StudyError>,
    },
}
