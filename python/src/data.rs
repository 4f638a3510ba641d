//! Sweeps, reduces and the files they write: `cablemap.sweep`,
//! `cablemap.reduce`, and what `cablemap.read_run` and `cablemap.read_map`
//! read (`python/cablemap/_data.py`).
//!
//! `sweep` and `reduce` build the library's requests as `src/cli/sweep.rs`
//! and `src/cli/reduce.rs` do and return the library's report (its JSON,
//! as `--json` prints it, and its text, as the command prints it). The
//! readers take the list of files from the library (a run's checked chunk
//! files, a map's tables), so the Python side names no file itself.
//! `bench_routings` hands the benchmark script `cablemap bench`'s routings.

use super::{bad, from_json, to_json, Failure, Result};
use cablemap::job::{Job, JobError};
use cablemap::map::{self, MapError, ReduceRequest, Source};
use cablemap::reduce::tables::{map_tables as library_map_tables, ReadError};
use cablemap::io::SettingNames;
use cablemap::reduce::{MapSettingsFields, ReduceError};
use cablemap::sweep::progress::ProgressMode;
use cablemap::sweep::{open_run, Completeness, SweepError, SweepOptions};
use parquet::arrow::ArrowWriter;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use std::path::{Path, PathBuf};

// ---------------------------------------------------------------- errors

/// Whether a sweep error is about files on disk (a damaged or foreign
/// file, a directory without a run) rather than the request.
fn sweep_error_is_file(e: &SweepError) -> bool {
    match e {
        SweepError::After { source, .. } => sweep_error_is_file(source),
        SweepError::CorruptManifest { .. }
        | SweepError::ForeignFile { .. }
        | SweepError::ForeignChunk { .. }
        | SweepError::CorruptChunk { .. }
        | SweepError::DamagedChunks { .. }
        | SweepError::NoRun { .. }
        | SweepError::NoRunDir { .. }
        | SweepError::Parquet { .. }
        | SweepError::Arrow { .. }
        | SweepError::MoveAside { .. }
        | SweepError::File(_) => true,
        _ => false,
    }
}

/// Whether a reduce error is about files on disk rather than the request.
fn reduce_error_is_file(e: &ReduceError) -> bool {
    match e {
        ReduceError::Sweep(s) => sweep_error_is_file(s),
        ReduceError::MissingColumn { .. }
        | ReduceError::ColumnType { .. }
        | ReduceError::RunChanged
        | ReduceError::MapNotRun { .. }
        | ReduceError::MapDirUnreadable { .. }
        | ReduceError::CreateDir { .. }
        | ReduceError::Write { .. }
        | ReduceError::WriteParquet { .. }
        | ReduceError::WriteArrow { .. }
        | ReduceError::WriteJson { .. }
        | ReduceError::Replace { .. }
        | ReduceError::Scratch { .. }
        | ReduceError::Parts(_)
        | ReduceError::CablesFile { .. } => true,
        _ => false,
    }
}

/// The exception of a library error: `FileFormatError` when `file`, else
/// `BadInputError`; the message is the library's.
fn failure(message: String, file: bool) -> Failure {
    if file {
        Failure::File(message)
    } else {
        Failure::BadInput(message)
    }
}

impl From<SweepError> for Failure {
    fn from(e: SweepError) -> Self {
        let file = sweep_error_is_file(&e);
        failure(e.to_string(), file)
    }
}

impl From<JobError> for Failure {
    fn from(e: JobError) -> Self {
        let file = match &e {
            JobError::File(_) => true,
            JobError::Sweep(s) => sweep_error_is_file(s),
            _ => false,
        };
        failure(e.to_string(), file)
    }
}

impl From<MapError> for Failure {
    fn from(e: MapError) -> Self {
        let file = match &e {
            MapError::Job(JobError::File(_)) => true,
            MapError::Job(JobError::Sweep(s)) | MapError::Sweep(s) => sweep_error_is_file(s),
            MapError::Reduce { source, .. } | MapError::Write(source) => reduce_error_is_file(source),
            _ => false,
        };
        failure(e.to_string(), file)
    }
}

impl From<ReduceError> for Failure {
    fn from(e: ReduceError) -> Self {
        let file = reduce_error_is_file(&e);
        failure(e.to_string(), file)
    }
}

impl From<ReadError> for Failure {
    fn from(e: ReadError) -> Self {
        Failure::File(e.to_string())
    }
}

// ---------------------------------------------------------------- sweep

/// One shard of a spec's sweep into `out` (`cablemap sweep SPEC --out OUT
/// --shard SHARD --shards SHARDS`; the built-in thesis spec when `spec` is
/// `None`): `(report JSON as sweep --json prints it, report text, note)`.
/// Progress lines go to stderr when `progress`, as the command's do.
#[pyfunction]
#[pyo3(signature = (spec, out, shard, shards, threads, allow_large, progress))]
#[allow(clippy::too_many_arguments)]
fn sweep(
    py: Python<'_>,
    spec: Option<PathBuf>,
    out: PathBuf,
    shard: u64,
    shards: u64,
    threads: Option<usize>,
    allow_large: bool,
    progress: bool,
) -> PyResult<(String, String, Option<String>)> {
    let run = || -> Result<(String, String, Option<String>)> {
        if shards == 0 || shard >= shards {
            return Err(bad(format!(
                "shard {shard}/{shards}: shards are numbered 0..N-1 of N ≥ 1 (\"i/n\"), and every shard of a run needs the same N"
            )));
        }
        if threads == Some(0) {
            return Err(bad("threads = 0: at least 1 thread is needed (None: one per core)"));
        }
        let job = Job::load_or_thesis(spec.as_deref())?;
        let progress = if progress { ProgressMode::Auto } else { ProgressMode::Quiet };
        let options = SweepOptions { shard, shards, threads, progress, allow_large };
        let report = job.sweep(&out, &options)?;
        Ok((to_json(&report), report.to_string(), job.note()))
    };
    py.detach(run).map_err(|e| e.into_py(py))
}

// ---------------------------------------------------------------- reduce

/// A run directory of any kind reduced into the map directory `out`
/// (`cablemap reduce RUN --out OUT`, `partial` as `--partial`):
/// `(report JSON as reduce --json prints it, report text)`.
#[pyfunction]
fn reduce(py: Python<'_>, run: PathBuf, out: PathBuf, partial: bool, settings_json: &str) -> PyResult<(String, String)> {
    let go = || -> Result<(String, String)> {
        let fields: MapSettingsFields = from_json(settings_json, "reduce settings")?;
        let settings = fields.settings(SettingNames::Keys).map_err(|e| bad(e.to_string()))?;
        let request = ReduceRequest { run, out, source: Source::Run { partial }, settings };
        let report = map::reduce(&request)?;
        Ok((to_json(&report), report.to_string()))
    };
    py.detach(go).map_err(|e| e.into_py(py))
}

// ---------------------------------------------------------------- readers

/// A run's chunk files, checked as every reader checks them.
struct RunFiles {
    /// What status calls the kind (`planar sweep`, …).
    kind: &'static str,
    /// Its format tag.
    format: &'static str,
    /// The complete chunk files, in chunk order.
    files: Vec<PathBuf>,
    /// An empty Parquet file with the run's row schema (for a run with no chunk yet).
    empty: Vec<u8>,
    /// Rows in the files.
    rows_done: u64,
    /// Rows of the complete run.
    rows_total: u64,
}

/// Opens a run of any kind and lists its files.
fn open_run_files(dir: &Path, completeness: Completeness) -> Result<RunFiles> {
    let run = open_run(dir, completeness).map_err(cablemap::reduce::run_open_error)?;
    let mut empty = Vec::new();
    let writer = ArrowWriter::try_new(&mut empty, run.schema(), None).map_err(|e| Failure::File(format!("the run's schema as Parquet: {e}")))?;
    writer.close().map_err(|e| Failure::File(format!("the run's schema as Parquet: {e}")))?;
    let kind = run.spec().kind();
    Ok(RunFiles {
        kind: kind.name(),
        format: kind.format(),
        files: run.chunk_paths().into_iter().map(Path::to_path_buf).collect(),
        empty,
        rows_done: run.rows_done(),
        rows_total: run.rows_total(),
    })
}

/// The checked chunk files of run directory `run` (a complete run unless
/// `partial`), as a dict: `kind`, `format`, `files` (paths in row order),
/// `empty_parquet` (a file with no rows and the run's schema),
/// `rows_done`, `rows_total`.
#[pyfunction]
fn run_files<'py>(py: Python<'py>, run: PathBuf, partial: bool) -> PyResult<Bound<'py, PyDict>> {
    let completeness = if partial { Completeness::AllowPartial } else { Completeness::Complete };
    let open = || -> Result<RunFiles> { open_run_files(&run, completeness) };
    let files = py.detach(open).map_err(|e| e.into_py(py))?;
    let out = PyDict::new(py);
    out.set_item("kind", files.kind)?;
    out.set_item("format", files.format)?;
    out.set_item("files", files.files)?;
    out.set_item("empty_parquet", PyBytes::new(py, &files.empty))?;
    out.set_item("rows_done", files.rows_done)?;
    out.set_item("rows_total", files.rows_total)?;
    Ok(out)
}

/// The tables of map directory `path` as `(name, file)` pairs, from the
/// library's list (`reduce::tables::map_tables`): a feasibility map's
/// `cells`, `modes`, `designs`; a cable sweep's map's `reach_xy`,
/// `reach_xz`, `reach_yz`, `reach_3d` and its planar map's tables.
#[pyfunction]
fn map_tables(py: Python<'_>, path: PathBuf) -> PyResult<Vec<(String, PathBuf)>> {
    let tables = library_map_tables(&path).map_err(|e| Failure::from(e).into_py(py))?;
    Ok(tables.into_iter().map(|t| (t.name, t.path)).collect())
}

// ---------------------------------------------------------------- benchmark

/// The `count` thesis-grid routings `cablemap bench` samples for a rod of
/// radius `radius_mm` (`bench::sample_thesis_routings`), as rows of five
/// control points, mm: what `scripts/bench-python.py` times
/// `cablemap.solve_batch` on.
#[pyfunction]
fn bench_routings(py: Python<'_>, count: usize, radius_mm: f64) -> PyResult<Vec<[f64; 5]>> {
    if !(1..=cablemap::bench::MAX_ROUTINGS).contains(&count) {
        return Err(bad(format!("count {count} must be 1 … {} (the thesis grid's 9⁵ routings)", cablemap::bench::MAX_ROUTINGS)).into_py(py));
    }
    Ok(cablemap::bench::sample_thesis_routings(count, radius_mm).into_iter().map(|y| y.0).collect())
}

/// Adds this file's functions to the extension module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(reduce, m)?)?;
    m.add_function(wrap_pyfunction!(run_files, m)?)?;
    m.add_function(wrap_pyfunction!(map_tables, m)?)?;
    m.add_function(wrap_pyfunction!(bench_routings, m)?)?;
    Ok(())
}
