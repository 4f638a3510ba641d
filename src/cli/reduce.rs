//! `cablemap reduce` and `cablemap map` (sweep then reduce: the main job).

use cablemap::reduce::{reduce_run, write_map_replacing, MapData, ModeBoundaries, ReduceError, ReduceOptions};
use anyhow::Context;
use cablemap::sweep::progress::ProgressMode;
use cablemap::sweep::SweepOptions;
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Map options shared by `reduce` and `map`.
#[derive(Debug, Clone, Args)]
pub struct MapOptionArgs {
    /// Grid cell size, mm [default: 1; a cable sweep: its spec's output.cell_mm].
    #[arg(long, value_name = "MM")]
    pub cell_mm: Option<f64>,
    /// Explicit a_0 boundaries of the modes: three ascending values (mm⁻¹)
    /// [default: 25/50/75 % quantiles of the data].
    #[arg(long, value_name = "B1,B2,B3", allow_hyphen_values = true)]
    pub a0_bounds: Option<String>,
    /// Explicit a_1 boundaries of the modes: two ascending values (mm⁻¹)
    /// [default: 1/3 and 2/3 quantiles of the data].
    #[arg(long, value_name = "C1,C2", allow_hyphen_values = true)]
    pub a1_bounds: Option<String>,
    /// Simulated designs kept per cell in designs.parquet.
    #[arg(long, value_name = "N", default_value_t = 16)]
    pub designs_per_cell: usize,
    /// Samples held in memory at once (48 bytes each): bounds the reduce's
    /// memory whatever the run's size; the maps do not depend on it.
    #[arg(long, value_name = "N", default_value_t = cablemap::reduce::DEFAULT_MEMORY_SAMPLES)]
    pub memory_samples: usize,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

impl MapOptionArgs {
    /// The reduce options these arguments give.
    pub fn options(&self) -> anyhow::Result<ReduceOptions> {
        let mode_boundaries = match (&self.a0_bounds, &self.a1_bounds) {
            (None, None) => None,
            (Some(a0), Some(a1)) => {
                let a0 = super::parse_list(a0, "--a0-bounds")?;
                let a1 = super::parse_list(a1, "--a1-bounds")?;
                anyhow::ensure!(a0.len() == 3, "--a0-bounds needs three values (4 ranges of a_0), got {}", a0.len());
                anyhow::ensure!(a1.len() == 2, "--a1-bounds needs two values (3 ranges of a_1), got {}", a1.len());
                Some(ModeBoundaries { a0: [a0[0], a0[1], a0[2]], a1: [a1[0], a1[1]] })
            }
            _ => anyhow::bail!("give both --a0-bounds and --a1-bounds, or neither (quantiles of the data)"),
        };
        anyhow::ensure!(self.memory_samples >= 1, "--memory-samples must be at least 1");
        Ok(ReduceOptions {
            cell_mm: self.cell_mm.unwrap_or(1.0),
            mode_boundaries,
            designs_per_cell: self.designs_per_cell,
            memory_samples: self.memory_samples,
            scratch_dir: None,
        })
    }
}

/// Arguments of `cablemap reduce`.
#[derive(Debug, Clone, Args)]
pub struct ReduceArgs {
    /// Run directory of a sweep.
    #[arg(value_name = "RUN_DIR")]
    pub run: PathBuf,
    /// Map directory to write (tables, PNGs, index.html).
    #[arg(long, value_name = "MAP_DIR")]
    pub out: PathBuf,
    /// Map an unfinished run (only its complete chunks).
    #[arg(long)]
    pub partial: bool,
    /// Write only part I of the reduce (0-based; with --shards) into
    /// MAP_DIR.parts/, for a cluster array task
    /// [default: $SLURM_ARRAY_TASK_ID, else $JOB_COMPLETION_INDEX, else 0].
    #[arg(long, value_name = "I", requires = "shards")]
    pub shard: Option<u64>,
    /// Split the reduce into N parts (see --shard; then --merge, which takes
    /// the map options such as --cell-mm).
    #[arg(long, value_name = "N", conflicts_with_all = ["merge", "partial"])]
    pub shards: Option<u64>,
    /// Write the map from the parts in MAP_DIR.parts/ (all N of them).
    #[arg(long, conflicts_with = "partial")]
    pub merge: bool,
    #[command(flatten)]
    pub map: MapOptionArgs,
}

/// Reduces `run` (either kind of sweep) into `out` and prints a summary.
pub fn reduce_any_into(run: &Path, out: &Path, partial: bool, args: &MapOptionArgs) -> anyhow::Result<()> {
    match cablemap::sweep::run_kind(run)? {
        cablemap::sweep::RunKind::Planar => reduce_into(run, out, partial, args).map(|_| ()),
        cablemap::sweep::RunKind::Cables => super::cable_map::reduce_cables_into(run, out, partial, args.cell_mm, &args.options()?, args.json),
    }
}

/// How `reduce_into` gets the map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// Reduce the run in this process (`partial`: an unfinished run).
    Run {
        /// Map only the complete chunks of an unfinished run.
        partial: bool,
    },
    /// Merge the parts written by `--shard I --shards N`.
    Parts,
}

/// Reduces `run` into `out` and prints a summary.
pub fn reduce_into(run: &Path, out: &Path, partial: bool, args: &MapOptionArgs) -> anyhow::Result<MapData> {
    reduce_from(run, out, Source::Run { partial }, args)
}

/// Reduces `run` (or merges its parts) into `out` and prints a summary.
pub fn reduce_from(run: &Path, out: &Path, source: Source, args: &MapOptionArgs) -> anyhow::Result<MapData> {
    let mut options = args.options()?;
    cablemap::reduce::check_map_out(out)?;
    // Scratch beside the map: on the same disk as the results, not in a
    // RAM-backed /tmp.
    options.scratch_dir = Some(out.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new(".")).to_path_buf());
    let start = Instant::now();
    let reduced = match source {
        Source::Run { partial } => reduce_run(run, partial, &options),
        Source::Parts => cablemap::reduce::parts::merge_parts(run, out, &options),
    };
    let (map, spec) = reduced.map_err(|e| with_flags(e, run, out)).with_context(|| format!("reducing {}", run.display()))?;
    let reduced_s = start.elapsed().as_secs_f64();
    let pictures = write_map_replacing(out, &map, &spec.actuator, &spec.solver)?;
    let total_s = start.elapsed().as_secs_f64();
    let s = &map.summary;
    if args.json {
        println!(
            "{}",
            serde_json::json!({ "summary": s, "map_dir": out, "pictures": pictures.iter().map(|p| &p.file).collect::<Vec<_>>(),
                "reduce_s": reduced_s, "total_s": total_s })
        );
    } else {
        println!(
            "map {}: {} simulations ({} converged, {} failed{}) in {} cells of {} mm; modes by {}: a0 {}, a1 {} (mm⁻¹, {} basis)",
            out.display(),
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
        );
        println!("reduced in {reduced_s:.2} s, tables and {} pictures written in {total_s:.2} s; open {}", pictures.len(), out.join("index.html").display());
    }
    // With --json on stderr: stdout stays the JSON object alone.
    if let Some(note) = cablemap::reduce::plots::Density::sparse_note(s, &map.cells) {
        if args.json {
            eprintln!("{note}");
        } else {
            println!("{note}");
        }
    }
    Ok(map)
}

/// Mode boundaries to 4 significant digits, `[-0.02, -0.0134, 0.0071]`:
/// enough to tell the modes apart; summary.json keeps full precision.
fn boundaries_text(bounds: &[f64]) -> String {
    let values: Vec<String> = bounds.iter().map(|&b| cablemap::io::fmt_sig(b, 4)).collect();
    format!("[{}]", values.join(", "))
}

/// The library's error, with the flag that fixes it where there is one.
fn with_flags(e: ReduceError, run: &Path, out: &Path) -> anyhow::Error {
    use cablemap::reduce::parts::PartsError;
    let part = |i: String, n: String| format!("cablemap reduce {} --out {} --shard {i} --shards {n}", run.display(), out.display());
    match &e {
        ReduceError::CellTooSmall { smallest_cell_mm, .. } => anyhow::anyhow!("{e} (use --cell-mm ≥ {})", cablemap::io::fmt_num(*smallest_cell_mm)),
        ReduceError::CellTooLarge { largest_cell_mm, .. } => anyhow::anyhow!("{e} (--cell-mm {} or less)", cablemap::io::fmt_num(*largest_cell_mm)),
        ReduceError::ModesNotSplit { .. } => anyhow::anyhow!("{e}: --a0-bounds B1,B2,B3 and --a1-bounds C1,C2"),
        ReduceError::Parts(PartsError::Missing { shards, missing, .. }) => {
            if let [one] = missing.as_slice() {
                anyhow::anyhow!("{e}: `{}`", part(one.to_string(), shards.to_string()))
            } else {
                anyhow::anyhow!("{e}: `{}` for each missing I", part("I".into(), shards.to_string()))
            }
        }
        ReduceError::Parts(PartsError::Damaged { shard, shards, .. }) => {
            anyhow::anyhow!("{e}: `{}`", part(shard.to_string(), shards.to_string()))
        }
        ReduceError::Parts(PartsError::NoParts { .. }) => anyhow::anyhow!("{e}: `{}` for I = 0 … N-1", part("I".into(), "N".into())),
        _ => e.into(),
    }
}

/// Runs `cablemap reduce`.
pub fn run(args: &ReduceArgs) -> anyhow::Result<()> {
    if matches!(cablemap::sweep::run_kind(&args.run), Ok(cablemap::sweep::RunKind::Cables)) {
        anyhow::ensure!(
            args.shards.is_none() && args.shard.is_none() && !args.merge,
            "{} is a cable sweep: its reduce streams the chunks in one process and has no parts; drop --shard/--shards/--merge",
            args.run.display()
        );
        return reduce_any_into(&args.run, &args.out, args.partial, &args.map);
    }
    if let Some(shards) = args.shards {
        anyhow::ensure!(shards >= 1, "--shards must be at least 1");
        let (shard, from) = super::sweep::shard_from_env(args.shard)?;
        anyhow::ensure!(shard < shards, "part {shard} (from {from}) is not below --shards {shards}: parts are numbered 0 to {}", shards - 1);
        let start = Instant::now();
        let report = cablemap::reduce::parts::write_part(&args.run, &args.out, shard, shards)
            .map_err(|e| with_flags(e, &args.run, &args.out))
            .with_context(|| format!("reducing part {shard} of {shards} of {}", args.run.display()))?;
        let s = start.elapsed().as_secs_f64();
        if args.map.json {
            println!(
                "{}",
                serde_json::json!({ "part": shard, "parts": shards, "record": report.record, "chunks": report.chunks,
                    "rows": report.rows, "samples": report.samples, "reduce_s": s })
            );
        } else {
            println!(
                "reduce part {shard} of {shards} ({from}): {} chunk files, {} rows, {} converged samples in {s:.2} s; written {}",
                report.chunks,
                report.rows,
                report.samples,
                report.record.display()
            );
            println!("when all {shards} parts are written: cablemap reduce {} --out {} --merge", args.run.display(), args.out.display());
        }
        return Ok(());
    }
    anyhow::ensure!(args.shard.is_none(), "--shard needs --shards N");
    let source = if args.merge { Source::Parts } else { Source::Run { partial: args.partial } };
    reduce_from(&args.run, &args.out, source, &args.map).map(|_| ())
}

/// Arguments of `cablemap map`.
#[derive(Debug, Clone, Args)]
pub struct MapArgs {
    /// Job spec (TOML); the built-in thesis spec (jobs/thesis.toml) when omitted.
    #[arg(value_name = "SPEC")]
    pub spec: Option<PathBuf>,
    /// Output directory: the sweep goes to DIR/run, the maps to DIR/map.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Worker threads [default: one per core].
    #[arg(long, value_name = "T")]
    pub threads: Option<usize>,
    /// Run a sweep of more than 10⁹ rows (refused otherwise, as a likely typo).
    #[arg(long)]
    pub allow_large: bool,
    #[command(flatten)]
    pub map: MapOptionArgs,
}

/// Runs `cablemap map`: the sweep (resumable) then the reduction.
pub fn run_map(args: &MapArgs) -> anyhow::Result<()> {
    if let Some(path) = args.spec.as_deref().filter(|p| std::fs::read_to_string(p).is_ok_and(|t| cablemap::study::is_study_toml(&t))) {
        // A study spec: one sweep and map per variant, then the comparison.
        let study = cablemap::study::StudySpec::load(path)?;
        let threads = super::sweep::thread_count(args.threads)?;
        return super::study::run_study(&study, path, &args.out, None, false, threads, args.allow_large, &args.map);
    }
    let spec = super::sweep::load_any_spec(args.spec.as_deref())?;
    let threads = super::sweep::thread_count(args.threads)?;
    let options = SweepOptions { shard: 0, shards: 1, threads, progress: ProgressMode::Auto, allow_large: args.allow_large };
    match &spec {
        super::sweep::AnySpec::Planar(spec) => super::sweep::sweep_and_report(spec, &args.out.join("run"), &options, false)?,
        super::sweep::AnySpec::Cables(spec) => super::sweep::sweep_and_report(spec, &args.out.join("run"), &options, false)?,
    };
    reduce_any_into(&args.out.join("run"), &args.out.join("map"), false, &args.map)
}
