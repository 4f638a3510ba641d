//! `cablemap reduce` and `cablemap map` (sweep then reduce: the main job).

use super::output::Output;
use cablemap::job::{Job, JobSpec};
use cablemap::map::{self, MapError, MapReport, MapRequest, MapSettings, PartRequest, ReduceRequest, Source};
use cablemap::io::SettingNames;
use cablemap::reduce::{MapSettingsFields, ReduceError};
use clap::Args;
use std::path::{Path, PathBuf};

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
    /// The map settings these arguments give.
    pub fn settings(&self) -> anyhow::Result<MapSettings> {
        let fields = MapSettingsFields {
            cell_mm: self.cell_mm,
            a0_bounds: self.a0_bounds.as_deref().map(|a0| super::parse_list(a0, "--a0-bounds")).transpose()?,
            a1_bounds: self.a1_bounds.as_deref().map(|a1| super::parse_list(a1, "--a1-bounds")).transpose()?,
            designs_per_cell: self.designs_per_cell,
            memory_samples: Some(self.memory_samples),
        };
        Ok(fields.settings(SettingNames::Flags)?)
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

/// The library's error, with the flag that fixes it where there is one.
fn with_flags(e: MapError, run: &Path, out: &Path) -> anyhow::Error {
    match e {
        MapError::Reduce { source, run: reduced } => flagged(source, run, out).context(format!("reducing {}", reduced.display())),
        e => e.into(),
    }
}

/// A reduce error, with the flag that fixes it where there is one.
fn flagged(e: ReduceError, run: &Path, out: &Path) -> anyhow::Error {
    use cablemap::reduce::PartsError;
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
    if let Some(shards) = args.shards {
        anyhow::ensure!(shards >= 1, "--shards must be at least 1");
        let (shard, from) = super::sweep::shard_from_env(args.shard)?;
        anyhow::ensure!(shard < shards, "part {shard} (from {from}) is not below --shards {shards}: parts are numbered 0 to {}", shards - 1);
        let part = PartRequest { run: args.run.clone(), out: args.out.clone(), shard, shards, shard_source: from.to_string() };
        let written = map::reduce_part(&part).map_err(|e| match e {
            MapError::Reduce { source, .. } => {
                flagged(source, &args.run, &args.out).context(format!("reducing part {shard} of {shards} of {}", args.run.display()))
            }
            e => e.into(),
        })?;
        if args.map.json {
            println!("{}", serde_json::to_value(&written)?);
        } else {
            print!("{written}");
        }
        return Ok(());
    }
    anyhow::ensure!(args.shard.is_none(), "--shard needs --shards N");
    let source = if args.merge { Source::Parts } else { Source::Run { partial: args.partial } };
    let request = ReduceRequest { run: args.run.clone(), out: args.out.clone(), source, settings: args.map.settings()? };
    let report = map::reduce(&request).map_err(|e| with_flags(e, &args.run, &args.out))?;
    Output::of_json_flag(args.map.json).map(&report)
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

/// Runs `cablemap map`: the sweep (resumable) then the reduction; a study
/// spec's study.
pub fn run_map(args: &MapArgs) -> anyhow::Result<()> {
    let job = Job::load_or_thesis(args.spec.as_deref())?;
    if let Some(note) = job.note() {
        eprintln!("{note}");
    }
    let request = MapRequest {
        job,
        out: args.out.clone(),
        threads: super::sweep::thread_count(args.threads)?,
        allow_large: args.allow_large,
        settings: args.map.settings()?,
    };
    let output = Output::of_json_flag(args.map.json);
    if !matches!(request.job.spec, JobSpec::Study(_)) {
        super::sweep::resume_hint_on_interrupt();
    }
    let report = map::run(&request, &mut |p| output.progress(p)).map_err(|e| with_flags(e, &request.out.join("run"), &request.out.join("map")))?;
    match &report {
        // The sweep's lines stay text beside --json, as they always were.
        MapReport::Swept { sweep, map } => {
            print!("{sweep}");
            output.map(map)
        }
        MapReport::Study(study) => output.study(study),
    }
}
