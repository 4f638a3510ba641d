//! `cablemap sweep` and `cablemap status`: front ends of [`cablemap::sweep`].

use cablemap::job::Job;
use cablemap::sweep::progress::ProgressMode;
use cablemap::sweep::SweepOptions;
use clap::Args;
use std::path::PathBuf;
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

/// Worker threads: `threads`, else $SLURM_CPUS_PER_TASK, else one per core (None).
pub fn thread_count(threads: Option<usize>) -> anyhow::Result<Option<usize>> {
    let (threads, source) = match threads {
        Some(t) => (Some(t), "--threads"),
        None => (env_number::<usize>("SLURM_CPUS_PER_TASK")?, "environment variable SLURM_CPUS_PER_TASK"),
    };
    anyhow::ensure!(threads != Some(0), "{source} = 0: at least 1 thread is needed");
    Ok(threads)
}

/// Says, on Ctrl-C or SIGTERM, that the chunks written are kept and how to
/// resume: this very command line again.
pub fn resume_hint_on_interrupt() {
    let again: Vec<String> = std::env::args().collect();
    say_how_to_resume_on_interrupt(format!(
        "\ninterrupted: every chunk already written is kept; resume with the same command:\n  {}\n",
        again.join(" ")
    ));
}

/// Runs `cablemap sweep`.
pub fn run(args: &SweepArgs) -> anyhow::Result<()> {
    let job = Job::load_or_thesis(args.spec.as_deref())?;
    if let Some(note) = job.note() {
        eprintln!("{note}");
    }
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
    resume_hint_on_interrupt();
    let report = job.sweep(&args.out, &options)?;
    if args.json {
        println!("{}", serde_json::to_value(&report)?);
    } else {
        print!("{report}");
        // Only here: `map` reduces by itself, so the hint belongs to `sweep` alone.
        if report.status.complete {
            println!("next: cablemap reduce {} --out MAP_DIR", args.out.display());
        }
    }
    Ok(())
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

/// Runs `cablemap status`.
pub fn run_status_command(args: &StatusArgs) -> anyhow::Result<()> {
    let report = cablemap::map::status(&args.dir)?;
    if args.json {
        println!("{}", report.to_json_value());
    } else {
        print!("{report}");
    }
    Ok(())
}
