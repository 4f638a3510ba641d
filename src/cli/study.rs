//! `cablemap study` (and `cablemap map` on a study spec): one resumable
//! sweep and map per actuator variant, then the comparison.

use super::reduce::MapOptionArgs;
use anyhow::Context;
use cablemap::study::{compare, run_variant, StudySpec};
use cablemap::sweep::progress::ProgressMode;
use cablemap::sweep::SweepOptions;
use clap::Args;
use std::path::{Path, PathBuf};

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
    run_study(
        &study,
        &args.spec,
        &args.out,
        args.shards.map(|n| (args.shard, n)),
        args.compare,
        threads,
        args.allow_large,
        &args.map,
    )
}

/// Runs a study: the variants of one task (`shards` = Some((I, N))), or all
/// of them and the comparison, or (`compare_only`) only the comparison.
#[allow(clippy::too_many_arguments)]
pub fn run_study(
    study: &StudySpec,
    spec_path: &Path,
    out: &Path,
    shards: Option<(Option<u64>, u64)>,
    compare_only: bool,
    threads: Option<usize>,
    allow_large: bool,
    map: &MapOptionArgs,
) -> anyhow::Result<()> {
    study.prepare(out)?;
    let (shard, shards, from) = match shards {
        Some((shard, n)) => {
            anyhow::ensure!(n >= 1, "--shards must be at least 1");
            let (i, from) = super::sweep::shard_from_env(shard)?;
            anyhow::ensure!(
                i < n,
                "task {i} (from {from}) is not below --shards {n}: tasks are numbered 0 to {}",
                n - 1
            );
            (i, n, Some(from))
        }
        None => (0, 1, None),
    };
    if !compare_only {
        let sweep = SweepOptions {
            shard: 0,
            shards: 1,
            threads,
            progress: ProgressMode::Quiet,
            allow_large,
        };
        let reduce = map.options()?;
        let mine: Vec<_> = study.variants_of_shard(shard, shards).collect();
        // With --json, stdout carries only the comparison; progress goes to stderr.
        let say = |line: String| if map.json { eprintln!("{line}") } else { println!("{line}") };
        say(format!(
            "study '{}': {} variants{}; this task runs {}",
            study.name,
            study.variants.len(),
            from.map_or(String::new(), |f| format!(", task {shard} of {shards} ({f})")),
            mine.len()
        ));
        for v in mine {
            let r = run_variant(v, out, &sweep, &reduce).with_context(|| format!("study {}", out.display()))?;
            let s = &r.map;
            say(format!(
                "v{} {}: {} rows solved ({} already done), {} simulations ({} failed), {} cells of {} mm; {:.1} s; map {}",
                v.index,
                v.label(),
                r.sweep.rows_written,
                r.sweep.rows_skipped,
                s.rows_total,
                s.rows_failed,
                s.cells,
                s.cell_mm,
                r.wall_s,
                v.map_dir(out).display()
            ));
        }
        if from.is_some() {
            say(format!("when every task is done: cablemap study {} --out {} --compare", spec_path.display(), out.display()));
            return Ok(());
        }
    }
    let comparison = compare(study, out)?;
    comparison.write(out)?;
    if map.json {
        println!("{}", serde_json::to_string(&comparison)?);
    } else {
        println!(
            "{:>4}  {:>10}  {:>17}  {:>17}  {:>8}  settings",
            "v", "reach mm²", "a0 range", "a1 range", "failed"
        );
        for r in &comparison.variants {
            println!(
                "{:>4}  {:>10.0}  {:>8.4}…{:<8.4}  {:>8.4}…{:<8.4}  {:>8}  {}",
                format!("v{}", r.index),
                r.reach_area_mm2,
                r.a0_range[0],
                r.a0_range[1],
                r.a1_range[0],
                r.a1_range[1],
                r.rows_failed,
                r.label
            );
        }
        println!(
            "comparison: {} and {}; the maps side by side: {}",
            out.join(cablemap::study::COMPARISON_CSV).display(),
            out.join(cablemap::study::COMPARISON_JSON).display(),
            out.join(cablemap::study::PAGE_FILE).display()
        );
    }
    Ok(())
}
