//! What is wrong with a study, or why it cannot be compared yet.

use super::axes::AxisError;
use std::path::PathBuf;

/// What is wrong with a study, or why it cannot be compared yet.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The spec text or its `[study]` section.
    #[error("bad study spec {origin}: {problem}")]
    Spec {
        /// The spec file.
        origin: String,
        /// What is wrong and what to do.
        problem: SpecProblem,
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
    #[error("{}: not a study record: {source}", path.display())]
    NotARecord {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        source: serde_json::Error,
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

/// What is wrong with a study spec as a whole.
#[derive(Debug, thiserror::Error)]
pub enum SpecProblem {
    /// The text is not TOML.
    #[error("{0}")]
    Toml(#[source] toml::de::Error),
    /// No `[study]` section.
    #[error("no [study] section: a study spec is a sweep spec with a [study] section naming its axes")]
    NoStudySection,
    /// The `[study]` section is malformed.
    #[error("[study] {0}")]
    StudySection(#[source] toml::de::Error),
    /// The base spec has no TOML text.
    #[error("{0}")]
    BaseText(#[source] toml::ser::Error),
    /// The base sweep spec is refused.
    #[error("the base sweep spec: {0}")]
    Base(#[source] Box<crate::sweep::SweepError>),
    /// A base spec of several or spatial cables.
    #[error("the base sweep spec has [[cable]] tables: a study varies a planar sweep spec")]
    CableBase,
    /// No axes.
    #[error("[study] has no [[study.axis]]: give at least one axis (name and values or scale)")]
    NoAxes,
    /// An axis given twice.
    #[error("[[study.axis]] {axis} is given twice: give each axis once, with all its values")]
    AxisTwice {
        /// The axis's name.
        axis: String,
    },
    /// A tension axis over a base spec driven by displacement.
    #[error(
        "[[study.axis]] {axis} varies the tension ladder, but the base spec drives the cable by its displacement ([displacement]): \
         vary its displacements in the base spec, or give the base spec a [tension] ladder"
    )]
    TensionOfDisplacement {
        /// The axis's name.
        axis: String,
    },
    /// Too many variants.
    #[error("the axes give more than {most} variants: use fewer values")]
    TooManyVariants {
        /// The most variants a study may have.
        most: usize,
    },
    /// A variant's settings do not make a sweep spec.
    #[error("variant {index} ({label}): {source}")]
    VariantSettings {
        /// Variant number.
        index: usize,
        /// Its settings.
        label: String,
        /// Why they do not make a spec.
        source: serde_json::Error,
    },
}
