//! Progress reporting: an indicatif bar (rate, ETA) when stderr is a
//! terminal; plain log lines at most every few seconds otherwise (cluster
//! jobs and CI, where a bar would be hidden or garble the log).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How progress is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProgressMode {
    /// Bar on a terminal, log lines otherwise.
    Auto,
    /// Log lines every `interval`.
    Log(Duration),
    /// Nothing.
    Quiet,
}

/// Default interval of plain log lines.
pub const LOG_INTERVAL: Duration = Duration::from_secs(10);

/// Thread-safe progress of one shard's rows.
pub struct Progress {
    bar: Option<ProgressBar>,
    log_every: Option<Duration>,
    total: u64,
    done: AtomicU64,
    start_done: u64,
    started: Instant,
    last_log: Mutex<Instant>,
    label: String,
}

impl Progress {
    /// Progress over `total` rows of which `done` are already written.
    pub fn new(mode: ProgressMode, label: String, total: u64, done: u64) -> Self {
        let (bar, log_every) = match mode {
            ProgressMode::Auto if std::io::stderr().is_terminal() => {
                let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
                bar.set_style(
                    ProgressStyle::with_template("{prefix} [{wide_bar}] {human_pos}/{human_len} rows, {rate}, {elapsed} elapsed, ETA {eta}")
                        .expect("valid template")
                        .with_key("rate", |state: &ProgressState, w: &mut dyn std::fmt::Write| {
                            let _ = write!(w, "{:.0} solves/s", state.per_sec());
                        })
                        .progress_chars("=> "),
                );
                bar.set_prefix(label.clone());
                bar.set_position(done);
                (Some(bar), None)
            }
            ProgressMode::Auto => (None, Some(LOG_INTERVAL)),
            ProgressMode::Log(every) => (None, Some(every)),
            ProgressMode::Quiet => (None, None),
        };
        let now = Instant::now();
        Self { bar, log_every, total, done: AtomicU64::new(done), start_done: done, started: now, last_log: Mutex::new(now), label }
    }

    /// Whether log lines are printed (not a bar, not quiet).
    pub fn logs(&self) -> bool {
        self.log_every.is_some()
    }

    /// Records `rows` more rows done.
    pub fn add(&self, rows: u64) {
        let done = self.done.fetch_add(rows, Ordering::Relaxed) + rows;
        if let Some(bar) = &self.bar {
            bar.inc(rows);
        }
        let Some(every) = self.log_every else { return };
        let Ok(mut last) = self.last_log.try_lock() else { return };
        if last.elapsed() >= every {
            *last = Instant::now();
            let elapsed = self.started.elapsed().as_secs_f64();
            let rate = (done - self.start_done) as f64 / elapsed.max(1e-9);
            let eta = (self.total - done.min(self.total)) as f64 / rate.max(1e-9);
            eprintln!(
                "{}: {done}/{} rows ({:.1}%), {rate:.0} solves/s, ETA {eta:.0} s",
                self.label,
                self.total,
                100.0 * done as f64 / self.total.max(1) as f64
            );
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
