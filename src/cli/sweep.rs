//! `cablemap sweep` and `cablemap status`: front ends of [`cablemap::sweep`].

use cablemap::sweep::progress::ProgressMode;
use cablemap::sweep::cables::CableSweepSpec;
use cablemap::sweep::{run_kind, run_status_of, run_sweep_of, RunKind, RunSpec, RunStatus, SweepOptions, SweepSpec, SweepSummary};
use anyhow::Context;
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Arguments of `cablemap sweep`.
#[derive(Debug, Clone, Args)]
pub struct SweepArgs {
    /// Job spec (TOML); the built-in thesis spec (jobs/thesis.toml) when omitted. A spec with
    /// [[cable]] tables is a sweep of several or spatial cables (docs/schema.md, "Cable sweeps").
    #[arg(value_name = "SPEC")]
    pub spec: Option<PathBuf>,
    /// Run directory: manifest.json and shards/*.parquet. Re-running resumes.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// This process's shard, 0-based [default: $SLURM_ARRAY_TASK_ID, else $JOB_COMPLETION_INDEX, else 0].
    #[arg(long, value_name = "I")]
    pub shard: Option<u64>,
    /// Number of shards the sweep is split into (the same for every shard and every resume).
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    pub shards: u64,
    /// Worker threads [default: $SLURM_CPUS_PER_TASK, else one per core].
    #[arg(long, value_name = "T")]
    pub threads: Option<usize>,
    /// Seconds between progress lines when stderr is not a terminal [default: 10].
    #[arg(long, value_name = "S")]
    pub log_interval_s: Option<f64>,
    /// No progress output.
    #[arg(long)]
    pub quiet: bool,
    /// Run a sweep of more than 10⁹ rows (refused otherwise, as a likely typo).
    #[arg(long)]
    pub allow_large: bool,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `cablemap status`.
#[derive(Debug, Clone, Args)]
pub struct StatusArgs {
    /// Run directory of a sweep.
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// Print the status as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Reads a non-negative integer from an environment variable, naming it on error.
fn env_number<T: std::str::FromStr>(name: &str) -> anyhow::Result<Option<T>> {
    match std::env::var(name) {
        Ok(v) if !v.trim().is_empty() => v
            .trim()
            .parse()
            .map(Some)
            .map_err(|_| anyhow::anyhow!("environment variable {name} = '{v}' is not a non-negative integer")),
        _ => Ok(None),
    }
}

/// Shard index and where it came from: `--shard`, else SLURM's array task
/// id, else the Kubernetes Indexed Job's completion index, else 0.
fn shard_index(args: &SweepArgs) -> anyhow::Result<(u64, &'static str)> {
    shard_from_env(args.shard)
}

/// `shard` if given, else SLURM's array task id, else the Kubernetes
/// Indexed Job's completion index, else 0; and where it came from.
pub fn shard_from_env(shard: Option<u64>) -> anyhow::Result<(u64, &'static str)> {
    if let Some(s) = shard {
        return Ok((s, "--shard"));
    }
    for name in ["SLURM_ARRAY_TASK_ID", "JOB_COMPLETION_INDEX"] {
        if let Some(s) = env_number(name)? {
            return Ok((s, name));
        }
    }
    Ok((0, "default"))
}

/// A job spec of either kind.
pub enum AnySpec {
    /// A planar single-cable sweep.
    Planar(SweepSpec),
    /// A sweep of several or spatial cables.
    Cables(CableSweepSpec),
}

/// The spec at `path` (a cable sweep when it has `[[cable]]` tables), or
/// the built-in thesis spec.
pub fn load_any_spec(path: Option<&Path>) -> anyhow::Result<AnySpec> {
    if let Some(path) = path {
        if std::fs::read_to_string(path).is_ok_and(|t| cablemap::sweep::is_cable_spec_toml(&t)) {
            return Ok(AnySpec::Cables(cablemap::sweep::cables::load_spec(path)?));
        }
    }
    load_spec(path).map(AnySpec::Planar)
}

/// The sweep spec at `path`, or the built-in thesis spec.
pub fn load_spec(path: Option<&Path>) -> anyhow::Result<SweepSpec> {
    Ok(match path {
        Some(path) => {
            let spec = SweepSpec::load(path)?;
            if std::fs::read_to_string(path).is_ok_and(|t| SweepSpec::is_blank_toml(&t)) {
                eprintln!(
                    "note: {} sets nothing: running the built-in thesis sweep (jobs/thesis.toml) with every default",
                    path.display()
                );
            }
            spec
        }
        None => SweepSpec::thesis(),
    })
}

/// Worker threads: `threads`, else $SLURM_CPUS_PER_TASK, else one per core (None).
pub fn thread_count(threads: Option<usize>) -> anyhow::Result<Option<usize>> {
    let (threads, source) = match threads {
        Some(t) => (Some(t), "--threads"),
        None => (env_number::<usize>("SLURM_CPUS_PER_TASK")?, "environment variable SLURM_CPUS_PER_TASK"),
    };
    anyhow::ensure!(threads != Some(0), "{source} = 0: at least 1 thread is needed");
    Ok(threads)
}

/// Runs one shard of `spec` into `out`, saying how to resume when
/// interrupted, and prints the summary and the run's state. Returns whether
/// the run is complete.
pub fn sweep_and_report<S: RunSpec>(spec: &S, out: &Path, options: &SweepOptions, json: bool) -> anyhow::Result<bool> {
    let again: Vec<String> = std::env::args().collect();
    say_how_to_resume_on_interrupt(format!(
        "\ninterrupted: every chunk already written is kept; resume with the same command:\n  {}\n",
        again.join(" ")
    ));
    let summary = run_sweep_of(spec, out, options)?;
    let status = run_status_of::<S>(out).with_context(|| format!("checking {} after the sweep", out.display()))?;
    if json {
        println!("{}", serde_json::json!({ "summary": summary, "run": status.to_json_value() }));
    } else {
        print_summary(&summary, &status);
    }
    Ok(status.complete)
}

/// Runs `cablemap sweep`.
pub fn run(args: &SweepArgs) -> anyhow::Result<()> {
    let spec = load_any_spec(args.spec.as_deref())?;
    let threads = thread_count(args.threads)?;
    let progress = if args.quiet {
        ProgressMode::Quiet
    } else if let Some(s) = args.log_interval_s {
        anyhow::ensure!(s.is_finite() && s >= 0.0, "--log-interval-s must be a number of seconds ≥ 0");
        // Anything over a year means "practically never"; Duration cannot hold 1e20 s.
        ProgressMode::Log(Duration::from_secs_f64(s.min(3.2e7)))
    } else {
        ProgressMode::Auto
    };
    let (shard, source) = shard_index(args)?;
    anyhow::ensure!(
        shard < args.shards,
        "shard {shard} (from {source}) is out of range for --shards {}: shards are numbered 0..N-1 and every shard \
         needs the same --shards N (for a SLURM array use --array=0-{{N-1}})",
        args.shards
    );
    let options = SweepOptions { shard, shards: args.shards, threads, progress, allow_large: args.allow_large };
    let complete = match &spec {
        AnySpec::Planar(spec) => sweep_and_report(spec, &args.out, &options, args.json)?,
        AnySpec::Cables(spec) => sweep_and_report(spec, &args.out, &options, args.json)?,
    };
    // Only here: `map` reduces by itself, so the hint belongs to `sweep` alone.
    if complete && !args.json {
        println!("next: cablemap reduce {} --out MAP_DIR", args.out.display());
    }
    Ok(())
}

/// The closing lines, each short enough for an 80-column terminal.
fn print_summary<S: RunSpec>(s: &SweepSummary, status: &RunStatus<S>) {
    println!("shard {}/{}: {} rows solved and written, {} already done", s.shard, s.shards, s.rows_written, s.rows_skipped);
    if s.partial_chunks_removed + s.damaged_chunks_redone > 0 {
        println!("  {} abandoned partial chunks removed, {} damaged chunks redone", s.partial_chunks_removed, s.damaged_chunks_redone);
    }
    println!("  {:.2} s wall, {:.0} solves/s, {} thread{}", s.wall_s, s.solves_per_s, s.threads, if s.threads == 1 { "" } else { "s" });
    println!("shard {}/{} statuses: {}", s.shard, s.shards, fmt_counts(&s.status_counts));
    println!(
        "run {}: {}/{} rows, {}",
        status.dir.display(),
        status.rows_done,
        status.rows_total,
        if status.complete { "complete" } else { "partial (other shards not done yet)" }
    );
}

/// On Ctrl-C (SIGINT) or SIGTERM: say what is kept and how to resume, then
/// end as the signal would. Written chunks are complete files (renamed into
/// place), so stopping loses only the chunks in flight, which a resume redoes.
#[cfg(unix)]
fn say_how_to_resume_on_interrupt(resume: String) {
    use std::sync::OnceLock;
    static MESSAGE: OnceLock<Vec<u8>> = OnceLock::new();
    extern "C" fn on_signal(signal: libc::c_int) {
        // Only async-signal-safe calls here: write(2) and _exit(2).
        if let Some(m) = MESSAGE.get() {
            // SAFETY: writing an immutable, initialised buffer to stderr.
            unsafe { libc::write(2, m.as_ptr().cast(), m.len()) };
        }
        // SAFETY: ends the process without running anything else.
        unsafe { libc::_exit(128 + signal) };
    }
    if MESSAGE.set(resume.into_bytes()).is_ok() {
        for signal in [libc::SIGINT, libc::SIGTERM] {
            // SAFETY: installs a handler that only calls async-signal-safe functions.
            unsafe { libc::signal(signal, on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t) };
        }
    }
}

#[cfg(not(unix))]
fn say_how_to_resume_on_interrupt(_resume: String) {}

/// The coefficients a run stores, as people write them: `a_0…a_3` (not the
/// Rust range `0..=3`).
fn coefficient_range(order: usize) -> String {
    if order == 0 {
        "a_0".into()
    } else {
        format!("a_0…a_{order}")
    }
}

fn fmt_counts(counts: &std::collections::BTreeMap<String, u64>) -> String {
    if counts.is_empty() {
        return "(no rows)".into();
    }
    counts.iter().map(|(s, n)| format!("{s} {n}")).collect::<Vec<_>>().join(", ")
}

/// Runs `cablemap status`.
pub fn run_status_command(args: &StatusArgs) -> anyhow::Result<()> {
    // A map given for its run is named as such (the reduce layer knows maps).
    let kind = run_kind(&args.dir)
        .map_err(|e| cablemap::reduce::map_given_as_run(&e).map_or_else(|| anyhow::Error::from(e), anyhow::Error::from))?;
    match kind {
        RunKind::Planar => print_status(&run_status_of::<SweepSpec>(&args.dir)?, args.json),
        RunKind::Cables => print_status(&run_status_of::<CableSweepSpec>(&args.dir)?, args.json),
    }
}

/// Most shards listed one per line by `status`; beyond, the table lists
/// the unfinished ones up to this many and counts the rest (`--json` has
/// every shard).
const SHARD_LINES: usize = 32;

/// The per-shard table of `status`: every shard for a few dozen, else a
/// count of finished shards and the first unfinished ones.
fn print_shard_table(shards: &[cablemap::sweep::status::ShardStatus]) {
    let line = |sh: &cablemap::sweep::status::ShardStatus| {
        println!(
            "{:>6} {:>14} {:>22} {:>9}",
            sh.shard,
            format!("{}/{}", sh.chunks_done, sh.chunks_total),
            format!("{}/{}", sh.rows_done, sh.rows_total),
            sh.failures
        )
    };
    println!("{:>6} {:>14} {:>22} {:>9}", "shard", "chunks", "rows", "failures");
    if shards.len() <= SHARD_LINES {
        shards.iter().for_each(line);
        return;
    }
    let unfinished: Vec<_> = shards.iter().filter(|sh| sh.chunks_done < sh.chunks_total).collect();
    unfinished.iter().take(SHARD_LINES).for_each(|sh| line(sh));
    let finished = shards.len() - unfinished.len();
    let more = unfinished.len().saturating_sub(SHARD_LINES);
    println!(
        "  ({} shards: {finished} finished{}; `status --json` lists every shard)",
        shards.len(),
        if more > 0 {
            format!(", {} unfinished listed, {more} more unfinished", SHARD_LINES)
        } else {
            format!(", {} unfinished listed", unfinished.len())
        }
    );
}

fn print_status<S: RunSpec>(s: &RunStatus<S>, json: bool) -> anyhow::Result<()> {
    if json {
        println!("{}", s.to_json_value());
        return Ok(());
    }
    let m = &s.manifest;
    println!("run        {}", s.dir.display());
    if S::FORMAT != SweepSpec::FORMAT {
        println!("kind       {} ({})", S::KIND, S::FORMAT);
    }
    println!("spec       sha256 {} (cablemap {})", m.spec_sha256, m.tool_version);
    println!(
        "sweep      {} routings x {} {} = {} rows in {} chunks, {} shard(s)",
        m.routings,
        m.tensions,
        if S::FORMAT == SweepSpec::FORMAT { "tensions" } else { "tension combinations" },
        m.total_rows,
        m.chunks,
        m.shards
    );
    println!("a_i        {}, {}", coefficient_range(m.spec.order()), m.length_basis.describe());
    print_shard_table(&s.shards);
    println!("statuses   {}", fmt_counts(&s.status_counts));
    for d in &s.damaged {
        println!("damaged    {} ({}): rerun its shard's sweep command to move it aside and recompute it", d.path.display(), d.reason);
    }
    if s.chunks_in_progress > 0 {
        println!("in flight  {} chunk(s) being written or left by an interrupted run (redone on resume)", s.chunks_in_progress);
    }
    println!(
        "state      {}: {}/{} rows",
        if s.complete { "complete" } else { "partial" },
        s.rows_done,
        s.rows_total
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::coefficient_range;

    #[test]
    fn coefficient_ranges_read_as_written_by_hand() {
        assert_eq!(coefficient_range(0), "a_0");
        assert_eq!(coefficient_range(3), "a_0…a_3");
    }
}
