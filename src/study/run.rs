//! The study workflow behind `cablemap study` (and `cablemap map` of a
//! study spec): the variants of one task, or all of them and the
//! comparison, or only the comparison. Request in, report out; each
//! variant done is told to a progress callback as it finishes, since a
//! study runs for hours.

use super::comparison::{compare, Comparison, COMPARISON_CSV, COMPARISON_JSON};
use super::error::StudyError;
use super::page::PAGE_FILE;
use super::spec::{StudySpec, Variant};
use crate::io::FileError;
use crate::reduce::MapSettings;
use crate::reduce::tables::{read_cells, read_summary};
use crate::reduce::ReduceOptions;
use crate::sweep::progress::ProgressMode;
use crate::sweep::SweepOptions;
use serde::Serialize;
use std::fmt;
use std::path::{Path, PathBuf};

/// One task of a study split among `shards` tasks (a cluster array).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StudyTask {
    /// This task, 0-based.
    pub shard: u64,
    /// Tasks in all (≥ 1).
    pub shards: u64,
    /// Where the task's index came from (`--shard`, an environment variable).
    pub source: String,
}

/// Everything a study run needs.
#[derive(Debug, Clone)]
pub struct StudyRequest {
    /// The study.
    pub study: StudySpec,
    /// Its spec file (named in the command that finishes a split study).
    pub spec_path: PathBuf,
    /// The study directory.
    pub out: PathBuf,
    /// Only this task's variants, without the comparison; `None`: every variant.
    pub task: Option<StudyTask>,
    /// Only the comparison (every variant must be mapped).
    pub compare_only: bool,
    /// Worker threads per sweep; `None`: one per core.
    pub threads: Option<usize>,
    /// Run variants whose sweeps exceed 10⁹ rows.
    pub allow_large: bool,
    /// Map settings of every variant.
    pub settings: MapSettings,
}

/// What a study tells as it runs.
#[derive(Debug, Clone)]
pub enum StudyProgress {
    /// Before the first variant.
    Start {
        /// The study's name.
        name: String,
        /// Variants of the study.
        variants: usize,
        /// This task, when split.
        task: Option<StudyTask>,
        /// Variants this run does.
        runs: usize,
    },
    /// A variant swept and mapped.
    Variant {
        /// Variant number.
        index: usize,
        /// Its settings, `axis=value, …`.
        label: String,
        /// What was done.
        run: VariantRun,
        /// Its map directory.
        map_dir: PathBuf,
    },
}

impl fmt::Display for StudyProgress {
    /// One line, without its newline.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StudyProgress::Start { name, variants, task, runs } => write!(
                f,
                "study '{name}': {variants} variants{}; this task runs {runs}",
                task.as_ref().map_or(String::new(), |t| format!(", task {} of {} ({})", t.shard, t.shards, t.source))
            ),
            StudyProgress::Variant { index, label, run, map_dir } => {
                let s = &run.map;
                write!(
                    f,
                    "v{index} {label}: {} rows solved ({} already done), {} simulations ({} failed), {} cells of {} mm; {:.1} s; map {}",
                    run.sweep.rows_written,
                    run.sweep.rows_skipped,
                    s.rows_total,
                    s.rows_failed,
                    s.cells,
                    s.cell_mm,
                    run.wall_s,
                    map_dir.display()
                )
            }
        }
    }
}

/// What a study run did.
#[derive(Debug, Clone)]
pub enum StudyReport {
    /// One task's variants are mapped; the comparison waits for the others.
    TaskDone {
        /// The study's spec file.
        spec_path: PathBuf,
        /// The study directory.
        out: PathBuf,
    },
    /// Every variant is mapped and compared.
    Compared {
        /// The comparison (also in comparison.csv, comparison.json, index.html).
        comparison: Comparison,
        /// The study directory.
        out: PathBuf,
    },
}

impl Serialize for StudyReport {
    /// The comparison, as `study --json` prints it (`null` for a task's part).
    fn serialize<Se: serde::Serializer>(&self, serializer: Se) -> Result<Se::Ok, Se::Error> {
        match self {
            StudyReport::TaskDone { .. } => serializer.serialize_none(),
            StudyReport::Compared { comparison, .. } => comparison.serialize(serializer),
        }
    }
}

impl fmt::Display for StudyReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StudyReport::TaskDone { spec_path, out } => {
                writeln!(f, "when every task is done: cablemap study {} --out {} --compare", spec_path.display(), out.display())
            }
            StudyReport::Compared { comparison, out } => {
                writeln!(f, "{:>4}  {:>10}  {:>17}  {:>17}  {:>8}  settings", "v", "reach mm²", "a0 range", "a1 range", "failed")?;
                for r in &comparison.variants {
                    writeln!(
                        f,
                        "{:>4}  {:>10.0}  {:>8.4}…{:<8.4}  {:>8.4}…{:<8.4}  {:>8}  {}",
                        format!("v{}", r.index),
                        r.reach_area_mm2,
                        r.a0_range[0],
                        r.a0_range[1],
                        r.a1_range[0],
                        r.a1_range[1],
                        r.rows_failed,
                        r.label
                    )?;
                }
                writeln!(
                    f,
                    "comparison: {} and {}; the maps side by side: {}",
                    out.join(COMPARISON_CSV).display(),
                    out.join(COMPARISON_JSON).display(),
                    out.join(PAGE_FILE).display()
                )
            }
        }
    }
}

/// Runs a study: the variants of one task (`task`), or all of them and the
/// comparison, or (`compare_only`) only the comparison. Each variant done is
/// told to `progress` as it finishes.
pub fn run(request: &StudyRequest, progress: &mut dyn FnMut(&StudyProgress)) -> Result<StudyReport, StudyError> {
    let (study, out) = (&request.study, &request.out);
    study.prepare(out)?;
    if let Some(t) = &request.task {
        if t.shards == 0 || t.shard >= t.shards {
            return Err(StudyError::BadTask { shard: t.shard, shards: t.shards });
        }
    }
    if !request.compare_only {
        let sweep = SweepOptions { shard: 0, shards: 1, threads: request.threads, progress: ProgressMode::Quiet, allow_large: request.allow_large };
        // Scratch in each variant's directory (run_variant's default).
        let reduce = ReduceOptions { scratch_dir: None, ..request.settings.options(out) };
        let (shard, shards) = request.task.as_ref().map_or((0, 1), |t| (t.shard, t.shards));
        let mine: Vec<_> = study.variants_of_shard(shard, shards).collect();
        progress(&StudyProgress::Start { name: study.name.clone(), variants: study.variants.len(), task: request.task.clone(), runs: mine.len() });
        for v in mine {
            let run = run_variant(v, out, &sweep, &reduce).map_err(|e| StudyError::In { dir: out.clone(), source: Box::new(e) })?;
            progress(&StudyProgress::Variant { index: v.index, label: v.label(), run, map_dir: v.map_dir(out) });
        }
        if request.task.is_some() {
            return Ok(StudyReport::TaskDone { spec_path: request.spec_path.clone(), out: out.clone() });
        }
    }
    let comparison = compare(study, out)?;
    write_comparison(&comparison, out)?;
    Ok(StudyReport::Compared { comparison, out: out.clone() })
}

/// Writes comparison.csv, comparison.json, the page's reach pictures and
/// index.html into `dir` (reading the variants' maps again).
fn write_comparison(comparison: &Comparison, dir: &Path) -> Result<(), StudyError> {
    let mut maps = Vec::with_capacity(comparison.variants.len());
    for r in &comparison.variants {
        let map = dir.join(&r.map);
        let err = |source| StudyError::Map { index: r.index, source };
        let summary = read_summary(&map).map_err(err)?;
        let cells = read_cells(&map, summary.order).map_err(err)?;
        maps.push((summary, cells));
    }
    let pictures = comparison.draw_pictures(dir, &maps)?;
    let json = serde_json::to_string_pretty(comparison).expect("serializes") + "\n";
    for (file, text) in [(COMPARISON_CSV, comparison.csv()), (COMPARISON_JSON, json), (PAGE_FILE, comparison.html(&pictures))] {
        let path = dir.join(file);
        crate::io::write_atomic(&path, text.as_bytes()).map_err(FileError::on("writing", &path))?;
    }
    Ok(())
}

/// What running one variant did.
#[derive(Debug, Clone)]
pub struct VariantRun {
    /// The sweep (rows solved now and before).
    pub sweep: crate::sweep::SweepSummary,
    /// The map's summary.
    pub map: crate::reduce::MapSummary,
    /// Seconds for the sweep and the map.
    pub wall_s: f64,
}

/// Runs variant `v` of the study in `dir`: its sweep (resumed where it
/// stopped, always as one shard: a cluster task runs whole variants) and
/// its map, exactly as `cablemap map` of its spec into `v{i}/`. The map's
/// scratch goes beside it unless `reduce.scratch_dir` says otherwise.
pub fn run_variant(
    v: &Variant,
    dir: &Path,
    sweep: &crate::sweep::SweepOptions,
    reduce: &crate::reduce::ReduceOptions,
) -> Result<VariantRun, StudyError> {
    let start = std::time::Instant::now();
    let options = crate::sweep::SweepOptions {
        shard: 0,
        shards: 1,
        ..sweep.clone()
    };
    let run = v.run_dir(dir);
    let summary = crate::sweep::run_sweep(&v.spec, &run, &options).map_err(|source| StudyError::Sweep {
        index: v.index,
        label: v.label(),
        source,
    })?;
    let reduce_err = |source| StudyError::Reduce {
        index: v.index,
        label: v.label(),
        source,
    };
    let mut reduce = reduce.clone();
    reduce.scratch_dir.get_or_insert_with(|| v.dir(dir));
    let (map, grid, solver) = crate::reduce::reduce_run(&run, false, &reduce).map_err(reduce_err)?;
    crate::reduce::write_map_replacing(&v.map_dir(dir), &map, &grid.actuator, &solver).map_err(reduce_err)?;
    Ok(VariantRun {
        sweep: summary,
        map: map.summary,
        wall_s: start.elapsed().as_secs_f64(),
    })
}
