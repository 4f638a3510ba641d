//! `cablemap study` (and `cablemap map` on a study spec): one resumable
//! sweep and map per actuator variant, then the comparison.

use super::output::Output;
use super::reduce::MapOptionArgs;
use cablemap::study::{StudyRequest, StudySpec, StudyTask};
use clap::Args;
use std::path::PathBuf;

/// Arguments of `cablemap study`.
#[derive(Debug, Clone, Args)]
pub struct StudyArgs {
    /// Study spec (TOML): a sweep spec with a [study] section of axes (jobs/study.toml).
    #[arg(value_name = "SPEC")]
    pub spec: PathBuf,
    /// Study directory: v{i}/run and v{i}/map per variant, comparison.csv, index.html.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Run only the variants of task I (every N-th variant from I; with --shards),
    /// for a cluster array [default: $SLURM_ARRAY_TASK_ID, else $JOB_COMPLETION_INDEX, else 0].
    #[arg(long, value_name = "I", requires = "shards")]
    pub shard: Option<u64>,
    /// Split the variants among N tasks (see --shard; then --compare).
    #[arg(long, value_name = "N", conflicts_with = "compare")]
    pub shards: Option<u64>,
    /// Only write the comparison of the variants' maps (all must be mapped).
    #[arg(long)]
    pub compare: bool,
    /// Worker threads per sweep [default: $SLURM_CPUS_PER_TASK, else one per core].
    #[arg(long, value_name = "T")]
    pub threads: Option<usize>,
    /// Run variants whose sweeps exceed 10⁹ rows.
    #[arg(long)]
    pub allow_large: bool,
    #[command(flatten)]
    pub map: MapOptionArgs,
}

/// Runs `cablemap study`.
pub fn run(args: &StudyArgs) -> anyhow::Result<()> {
    let study = StudySpec::load(&args.spec)?;
    let threads = super::sweep::thread_count(args.threads)?;
    let task = match args.shards {
        Some(n) => {
            anyhow::ensure!(n >= 1, "--shards must be at least 1");
            let (i, from) = super::sweep::shard_from_env(args.shard)?;
            anyhow::ensure!(i < n, "task {i} (from {from}) is not below --shards {n}: tasks are numbered 0 to {}", n - 1);
            Some(StudyTask { shard: i, shards: n, source: from.to_string() })
        }
        None => None,
    };
    let request = StudyRequest {
        study,
        spec_path: args.spec.clone(),
        out: args.out.clone(),
        task,
        compare_only: args.compare,
        threads,
        allow_large: args.allow_large,
        settings: args.map.settings()?,
    };
    let output = Output::of_json_flag(args.map.json);
    let report = cablemap::study::run(&request, &mut |p| output.progress(p))?;
    output.study(&report)
}
