//! The map workflow behind `cablemap map` and `cablemap reduce`: a job's
//! sweep (resumable) then its reduction into a map directory, for every
//! kind of spec ([`crate::job::Job`]); a study spec runs the study
//! ([`crate::study::run`]). Requests in, reports out: each report
//! serialises itself (the JSON `--json` prints) and displays itself (what
//! the command line prints).
//!
//! A run directory's kind ([`RunKind`]) picks its code in one place,
//! [`reduce`].

use crate::job::{Job, JobError, JobSpec};
use crate::reduce::parts::PartReport;
use crate::reduce::tables::PLANAR_MAP_DIR;
use crate::reduce::{reduce_cable_run, reduce_run, write_map_replacing, ReachMapSummary, MapSummary, ReduceError};
use crate::study::{StudyError, StudyProgress, StudyReport, StudyRequest};
use crate::sweep::progress::ProgressMode;
use crate::sweep::{run_kind, run_status, RunKind, StatusReport, SweepError, SweepOptions, SweepReport};
use serde::Serialize;
use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Instant;

pub use crate::reduce::{MapSettings, DEFAULT_CELL_MM};

/// Why a map could not be made.
#[derive(Debug, thiserror::Error)]
pub enum MapError {
    /// The job's spec, or its sweep.
    #[error(transparent)]
    Job(#[from] JobError),
    /// The run directory holds no sweep, or cannot be read.
    #[error(transparent)]
    Sweep(#[from] SweepError),
    /// Reducing the run failed.
    #[error("reducing {}: {source}", run.display())]
    Reduce {
        /// The run directory.
        run: PathBuf,
        /// Why.
        #[source]
        source: ReduceError,
    },
    /// The map directory is unusable or could not be written.
    #[error(transparent)]
    Write(ReduceError),
    /// Parts (`--shard`, `--shards`, `--merge`) asked of a cable sweep's reduce.
    #[error("{} is a cable sweep: its reduce streams the chunks in one process and has no parts; drop --shard/--shards/--merge", run.display())]
    CablesHaveNoParts {
        /// The run directory.
        run: PathBuf,
    },
    /// A study spec's study.
    #[error(transparent)]
    Study(#[from] StudyError),
}

/// Where a reduce takes its rows from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// The run itself (`partial`: only the complete chunks of an unfinished run).
    Run {
        /// Map an unfinished run.
        partial: bool,
    },
    /// The parts `reduce --shard I --shards N` wrote (planar runs only).
    Parts,
}

/// A reduce of a run directory of any kind into a map directory.
#[derive(Debug, Clone, PartialEq)]
pub struct ReduceRequest {
    /// The run directory.
    pub run: PathBuf,
    /// The map directory.
    pub out: PathBuf,
    /// Where the rows come from.
    pub source: Source,
    /// The map settings.
    pub settings: MapSettings,
}

/// A planar map written.
#[derive(Debug, Clone)]
pub struct PlanarMapReport {
    /// summary.json.
    pub summary: MapSummary,
    /// The map directory.
    pub map_dir: PathBuf,
    /// The pictures' file names, in order.
    pub pictures: Vec<String>,
    /// Seconds to reduce.
    pub reduce_s: f64,
    /// Seconds to reduce and write.
    pub total_s: f64,
    /// Says the map is sparse and which cell size to try; printed on
    /// stdout after the text, on stderr beside `--json`.
    pub sparse_note: Option<String>,
}

/// A cable sweep's map written.
#[derive(Debug, Clone)]
pub struct ReachMapReport {
    /// summary.json.
    pub summary: ReachMapSummary,
    /// The map directory.
    pub map_dir: PathBuf,
    /// The planar map (planar runs of order ≥ 1) and its pictures' file names.
    pub planar: Option<(MapSummary, Vec<String>)>,
    /// Seconds to reduce and write.
    pub total_s: f64,
}

/// A map of either kind of run.
#[derive(Debug, Clone)]
pub enum ReduceReport {
    /// A planar single-cable run's map.
    Planar(PlanarMapReport),
    /// A cable sweep's reach map (and planar map).
    Cables(ReachMapReport),
}

impl ReduceReport {
    /// What to say beside the report: on stdout after the text, on stderr
    /// beside `--json` (stdout then holds the JSON alone).
    pub fn note(&self) -> Option<&str> {
        match self {
            ReduceReport::Planar(p) => p.sparse_note.as_deref(),
            ReduceReport::Cables(_) => None,
        }
    }
}

impl Serialize for ReduceReport {
    fn serialize<Se: serde::Serializer>(&self, serializer: Se) -> Result<Se::Ok, Se::Error> {
        let value = match self {
            ReduceReport::Planar(p) => serde_json::json!({ "summary": p.summary, "map_dir": p.map_dir, "pictures": p.pictures,
                "reduce_s": p.reduce_s, "total_s": p.total_s }),
            ReduceReport::Cables(c) => serde_json::json!({ "summary": c.summary, "map_dir": c.map_dir,
                "planar_summary": c.planar.as_ref().map(|(m, _)| m),
                "planar_pictures": c.planar.as_ref().map_or(&[][..], |(_, p)| p.as_slice()), "total_s": c.total_s }),
        };
        value.serialize(serializer)
    }
}

/// Mode boundaries to 4 significant digits, `[-0.02, -0.0134, 0.0071]`:
/// enough to tell the modes apart; summary.json keeps full precision.
fn boundaries_text(bounds: &[f64]) -> String {
    let values: Vec<String> = bounds.iter().map(|&b| crate::io::fmt_sig(b, 4)).collect();
    format!("[{}]", values.join(", "))
}

impl fmt::Display for ReduceReport {
    /// The summary lines, and a planar map's sparse note.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ReduceReport::Planar(p) => {
                let s = &p.summary;
                writeln!(
                    f,
                    "map {}: {} simulations ({} converged, {} failed{}) in {} cells of {} mm; modes by {}: a0 {}, a1 {} (mm⁻¹, {} basis)",
                    p.map_dir.display(),
                    s.rows_total,
                    s.rows_converged,
                    s.rows_failed,
                    if s.mirrored { ", mirrored half restored" } else { "" },
                    s.cells,
                    s.cell_mm,
                    s.mode_boundaries_source,
                    boundaries_text(&s.mode_boundaries.a0),
                    boundaries_text(&s.mode_boundaries.a1),
                    s.length_basis
                )?;
                writeln!(
                    f,
                    "reduced in {:.2} s, tables and {} pictures written in {:.2} s; open {}",
                    p.reduce_s,
                    p.pictures.len(),
                    p.total_s,
                    p.map_dir.join("index.html").display()
                )?;
                match &p.sparse_note {
                    Some(note) => writeln!(f, "{note}"),
                    None => Ok(()),
                }
            }
            ReduceReport::Cables(c) => {
                let s = &c.summary;
                writeln!(
                    f,
                    "map {}: {} rows of {} cable(s) ({} solved, {} failed, {} of rejected routings); reach cells of {} mm: x-y {}, x-z {}, y-z {}, 3-D {}",
                    c.map_dir.display(),
                    s.rows,
                    s.cables,
                    s.ok,
                    s.failed,
                    s.invalid_rows,
                    s.cell_mm,
                    s.cells[0],
                    s.cells[1],
                    s.cells[2],
                    s.cells[3]
                )?;
                match &c.planar {
                    Some((planar, pictures)) => writeln!(
                        f,
                        "planar run: feasibility map in {} cells, {} pictures; open {}",
                        planar.cells,
                        pictures.len(),
                        c.map_dir.join(PLANAR_MAP_DIR).join("index.html").display()
                    )?,
                    None if s.planar => writeln!(f, "planar run of order 0: no planar map (it needs a0 and a1; set output.order ≥ 1)")?,
                    None => {}
                }
                writeln!(f, "written in {:.2} s", c.total_s)
            }
        }
    }
}

/// Reduces a planar run (or the parts of its reduce) into a map.
fn reduce_planar(request: &ReduceRequest) -> Result<ReduceReport, MapError> {
    let (run, out) = (&request.run, &request.out);
    let options = request.settings.options(out);
    crate::reduce::check_map_out(out).map_err(MapError::Write)?;
    let start = Instant::now();
    let reduced = match request.source {
        Source::Run { partial } => reduce_run(run, partial, &options),
        Source::Parts => crate::reduce::parts::merge_parts(run, out, &options),
    };
    let (map, grid, solver) = reduced.map_err(|source| MapError::Reduce { run: run.clone(), source })?;
    let reduce_s = start.elapsed().as_secs_f64();
    let pictures = write_map_replacing(out, &map, &grid.actuator, &solver).map_err(MapError::Write)?;
    let total_s = start.elapsed().as_secs_f64();
    let sparse_note = crate::reduce::Density::sparse_note(&map.summary, &map.cells);
    Ok(ReduceReport::Planar(PlanarMapReport {
        summary: map.summary,
        map_dir: out.clone(),
        pictures: pictures.into_iter().map(|p| p.file).collect(),
        reduce_s,
        total_s,
        sparse_note,
    }))
}

/// Reduces a cable sweep into its reach map (and planar map).
fn reduce_cables(request: &ReduceRequest) -> Result<ReduceReport, MapError> {
    let (run, out) = (&request.run, &request.out);
    let Source::Run { partial } = request.source else {
        return Err(MapError::CablesHaveNoParts { run: run.clone() });
    };
    let start = Instant::now();
    let options = request.settings.options(out);
    let map = reduce_cable_run(run, partial, request.settings.cell_mm, &options, out)
        .map_err(|source| MapError::Reduce { run: run.clone(), source })?;
    Ok(ReduceReport::Cables(ReachMapReport {
        summary: map.summary,
        map_dir: out.clone(),
        planar: map.planar.map(|(m, p)| (m.summary, p.into_iter().map(|p| p.file).collect())),
        total_s: start.elapsed().as_secs_f64(),
    }))
}

/// The kind of the run directory `dir`, a map given in its place named as
/// such; a directory without a manifest is read as planar, whose reader
/// then says what the directory is instead (a map, missing, the parent of
/// runs).
fn kind_or_planar(dir: &Path) -> RunKind {
    run_kind(dir).unwrap_or(RunKind::Planar)
}

/// The state of the run directory `dir`, of any kind (`cablemap status`).
pub fn status(dir: &Path) -> Result<StatusReport, MapError> {
    run_kind(dir).map_err(|e| crate::reduce::map_given_as_run(&e).map_or(MapError::Sweep(e), MapError::Write))?;
    Ok(StatusReport::new(&run_status(dir)?))
}

/// Reduces a run directory of any kind into a map (`cablemap reduce`): the
/// one place a run directory's kind picks its code.
pub fn reduce(request: &ReduceRequest) -> Result<ReduceReport, MapError> {
    match kind_or_planar(&request.run) {
        RunKind::Planar => reduce_planar(request),
        RunKind::Cables => reduce_cables(request),
    }
}

/// One part of a planar run's reduce (`reduce --shard I --shards N`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PartRequest {
    /// The run directory.
    pub run: PathBuf,
    /// The map directory the parts are for.
    pub out: PathBuf,
    /// This part.
    pub shard: u64,
    /// Parts in all.
    pub shards: u64,
    /// Where the part's index came from (`--shard`, an environment variable).
    pub shard_source: String,
}

/// One part written.
#[derive(Debug, Clone)]
pub struct PartWritten {
    /// What was asked.
    pub request: PartRequest,
    /// What was written.
    pub part: PartReport,
    /// Seconds.
    pub reduce_s: f64,
}

/// Writes one part of the reduce of a planar run into its map's parts
/// directory (a cable sweep's reduce has no parts).
pub fn reduce_part(request: &PartRequest) -> Result<PartWritten, MapError> {
    if kind_or_planar(&request.run) == RunKind::Cables {
        return Err(MapError::CablesHaveNoParts { run: request.run.clone() });
    }
    let PartRequest { run, out, shard, shards, .. } = request;
    let start = Instant::now();
    let part = crate::reduce::parts::write_part(run, out, *shard, *shards).map_err(|source| MapError::Reduce { run: run.clone(), source })?;
    Ok(PartWritten { request: request.clone(), part, reduce_s: start.elapsed().as_secs_f64() })
}

impl Serialize for PartWritten {
    fn serialize<Se: serde::Serializer>(&self, serializer: Se) -> Result<Se::Ok, Se::Error> {
        let r = &self.part;
        serde_json::json!({ "part": self.request.shard, "parts": self.request.shards, "record": r.record, "chunks": r.chunks,
            "rows": r.rows, "samples": r.samples, "reduce_s": self.reduce_s })
        .serialize(serializer)
    }
}

impl fmt::Display for PartWritten {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (r, q) = (&self.part, &self.request);
        writeln!(
            f,
            "reduce part {} of {} ({}): {} chunk files, {} rows, {} converged samples in {:.2} s; written {}",
            q.shard,
            q.shards,
            q.shard_source,
            r.chunks,
            r.rows,
            r.samples,
            self.reduce_s,
            r.record.display()
        )?;
        writeln!(f, "when all {} parts are written: cablemap reduce {} --out {} --merge", q.shards, q.run.display(), q.out.display())
    }
}

/// A map of a job: its sweep into `OUT/run`, its map into `OUT/map`; a
/// study's variants and comparison into `OUT`.
#[derive(Debug, Clone)]
pub struct MapRequest {
    /// The job.
    pub job: Job,
    /// The output directory.
    pub out: PathBuf,
    /// Worker threads; `None`: one per core.
    pub threads: Option<usize>,
    /// Run a sweep of more than 10⁹ rows.
    pub allow_large: bool,
    /// The map settings.
    pub settings: MapSettings,
}

/// What a map of a job did.
#[derive(Debug, Clone)]
pub enum MapReport {
    /// One sweep and its map.
    Swept {
        /// The sweep.
        sweep: SweepReport,
        /// The map.
        map: ReduceReport,
    },
    /// A study's variants and comparison.
    Study(StudyReport),
}

impl Serialize for MapReport {
    /// The map's record (a study's comparison), as `map --json` prints it.
    fn serialize<Se: serde::Serializer>(&self, serializer: Se) -> Result<Se::Ok, Se::Error> {
        match self {
            MapReport::Swept { map, .. } => map.serialize(serializer),
            MapReport::Study(s) => s.serialize(serializer),
        }
    }
}

impl fmt::Display for MapReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MapReport::Swept { sweep, map } => write!(f, "{sweep}{map}"),
            MapReport::Study(s) => write!(f, "{s}"),
        }
    }
}

/// Runs a map: the sweep (resumed where it stopped) and its map; for a
/// study spec, the whole study, with `progress` told of each variant.
pub fn run(request: &MapRequest, progress: &mut dyn FnMut(&StudyProgress)) -> Result<MapReport, MapError> {
    if let JobSpec::Study(study) = &request.job.spec {
        let study = StudyRequest {
            study: study.clone(),
            spec_path: request.job.path.clone().unwrap_or_default(),
            out: request.out.clone(),
            task: None,
            compare_only: false,
            threads: request.threads,
            allow_large: request.allow_large,
            settings: request.settings.clone(),
        };
        return Ok(MapReport::Study(crate::study::run(&study, progress)?));
    }
    let options =
        SweepOptions { shard: 0, shards: 1, threads: request.threads, progress: ProgressMode::Auto, allow_large: request.allow_large };
    let run_dir = request.out.join("run");
    let sweep = request.job.sweep(&run_dir, &options)?;
    let map = reduce(&ReduceRequest {
        run: run_dir,
        out: request.out.join("map"),
        source: Source::Run { partial: false },
        settings: request.settings.clone(),
    })?;
    Ok(MapReport::Swept { sweep, map })
}
