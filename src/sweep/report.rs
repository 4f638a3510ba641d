//! What a sweep and a status query report, for every kind of sweep: the
//! JSON `--json` prints ([`serde::Serialize`]) and the text the command
//! line prints ([`std::fmt::Display`]).

use super::run::SweepSummary;
use super::status::{RunStatus, ShardStatus};
use super::store::{failures, DamagedChunk};
use crate::shape::LengthBasis;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt;
use std::path::PathBuf;

/// The state of a run directory of any kind, as `cablemap status` reports it.
#[derive(Debug, Clone, PartialEq)]
pub struct StatusReport {
    /// The run directory.
    pub dir: PathBuf,
    /// What status calls this kind of run ([`super::RunKind::name`]).
    pub kind: &'static str,
    /// The run's format tag ([`super::RunKind::format`]).
    pub format: &'static str,
    /// A planar single-cable run: its status names no kind (the thesis's runs) and counts tensions.
    pub planar: bool,
    /// SHA-256 of the spec.
    pub spec_sha256: String,
    /// Version of cablemap that created the run.
    pub tool_version: String,
    /// Routings of the complete sweep.
    pub routings: u64,
    /// Tensions (or tension combinations) per routing.
    pub tensions: u64,
    /// Rows of the complete sweep.
    pub total_rows: u64,
    /// Chunk files of the complete sweep.
    pub chunks: u64,
    /// Shards the run is split into.
    pub shard_count: u64,
    /// Highest Legendre order stored.
    pub order: usize,
    /// The length the a_i are per unit of.
    pub length_basis: LengthBasis,
    /// One entry per shard.
    pub shards: Vec<ShardStatus>,
    /// Written rows per status.
    pub status_counts: BTreeMap<String, u64>,
    /// Damaged chunk files.
    pub damaged: Vec<DamagedChunk>,
    /// Temporary chunk files (being written, or left by a killed run).
    pub chunks_in_progress: u64,
    /// Rows written.
    pub rows_done: u64,
    /// Rows of the complete sweep.
    pub rows_total: u64,
    /// Every row is written.
    pub complete: bool,
    /// The record `--json` prints ([`RunStatus::to_json_value`]).
    json: serde_json::Value,
}

impl StatusReport {
    /// The report of a run's status.
    pub fn new(s: &RunStatus) -> Self {
        let m = &s.manifest;
        let kind = m.spec.kind();
        Self {
            dir: s.dir.clone(),
            kind: kind.name(),
            format: kind.format(),
            planar: kind == super::RunKind::Planar,
            spec_sha256: m.spec_sha256.clone(),
            tool_version: m.tool_version.clone(),
            routings: m.routings,
            tensions: m.tensions,
            total_rows: m.total_rows,
            chunks: m.chunks,
            shard_count: m.shards,
            order: m.spec.output.order,
            length_basis: m.length_basis,
            shards: s.shards.clone(),
            status_counts: s.status_counts.clone(),
            damaged: s.damaged.clone(),
            chunks_in_progress: s.chunks_in_progress,
            rows_done: s.rows_done,
            rows_total: s.rows_total,
            complete: s.complete,
            json: s.to_json_value(),
        }
    }

    /// Written rows whose solve failed.
    pub fn failures(&self) -> u64 {
        failures(&self.status_counts)
    }

    /// The record `cablemap status --json` prints.
    pub fn to_json_value(&self) -> &serde_json::Value {
        &self.json
    }
}

impl Serialize for StatusReport {
    fn serialize<Se: serde::Serializer>(&self, serializer: Se) -> Result<Se::Ok, Se::Error> {
        self.json.serialize(serializer)
    }
}

/// Most shards listed one per line by `status`; beyond, the table lists
/// the unfinished ones up to this many and counts the rest (`--json` has
/// every shard).
const SHARD_LINES: usize = 32;

/// The per-shard table of `status`: every shard for a few dozen, else a
/// count of finished shards and the first unfinished ones.
fn shard_table(f: &mut fmt::Formatter<'_>, shards: &[ShardStatus]) -> fmt::Result {
    let line = |f: &mut fmt::Formatter<'_>, sh: &ShardStatus| {
        writeln!(
            f,
            "{:>6} {:>14} {:>22} {:>9}",
            sh.shard,
            format!("{}/{}", sh.chunks_done, sh.chunks_total),
            format!("{}/{}", sh.rows_done, sh.rows_total),
            sh.failures
        )
    };
    writeln!(f, "{:>6} {:>14} {:>22} {:>9}", "shard", "chunks", "rows", "failures")?;
    if shards.len() <= SHARD_LINES {
        return shards.iter().try_for_each(|sh| line(f, sh));
    }
    let unfinished: Vec<_> = shards.iter().filter(|sh| sh.chunks_done < sh.chunks_total).collect();
    unfinished.iter().take(SHARD_LINES).try_for_each(|sh| line(f, sh))?;
    let finished = shards.len() - unfinished.len();
    let more = unfinished.len().saturating_sub(SHARD_LINES);
    writeln!(
        f,
        "  ({} shards: {finished} finished{}; `status --json` lists every shard)",
        shards.len(),
        if more > 0 {
            format!(", {} unfinished listed, {more} more unfinished", SHARD_LINES)
        } else {
            format!(", {} unfinished listed", unfinished.len())
        }
    )
}

/// The coefficients a run stores, as people write them: `a_0…a_3` (not the
/// Rust range `0..=3`).
fn coefficient_range(order: usize) -> String {
    if order == 0 {
        "a_0".into()
    } else {
        format!("a_0…a_{order}")
    }
}

/// Status counts on one line, `ok 610, diverged 2`.
fn fmt_counts(counts: &BTreeMap<String, u64>) -> String {
    if counts.is_empty() {
        return "(no rows)".into();
    }
    counts.iter().map(|(s, n)| format!("{s} {n}")).collect::<Vec<_>>().join(", ")
}

impl fmt::Display for StatusReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "run        {}", self.dir.display())?;
        if !self.planar {
            writeln!(f, "kind       {} ({})", self.kind, self.format)?;
        }
        writeln!(f, "spec       sha256 {} (cablemap {})", self.spec_sha256, self.tool_version)?;
        writeln!(
            f,
            "sweep      {} routings x {} {} = {} rows in {} chunks, {} shard(s)",
            self.routings,
            self.tensions,
            if self.planar { "tensions" } else { "tension combinations" },
            self.total_rows,
            self.chunks,
            self.shard_count
        )?;
        writeln!(f, "a_i        {}, {}", coefficient_range(self.order), self.length_basis.describe())?;
        shard_table(f, &self.shards)?;
        writeln!(f, "statuses   {}", fmt_counts(&self.status_counts))?;
        for d in &self.damaged {
            writeln!(f, "damaged    {} ({}): rerun its shard's sweep command to move it aside and recompute it", d.path.display(), d.reason)?;
        }
        if self.chunks_in_progress > 0 {
            writeln!(f, "in flight  {} chunk(s) being written or left by an interrupted run (redone on resume)", self.chunks_in_progress)?;
        }
        writeln!(f, "state      {}: {}/{} rows", if self.complete { "complete" } else { "partial" }, self.rows_done, self.rows_total)
    }
}

/// What one shard's sweep did, and the run's state after it.
#[derive(Debug, Clone)]
pub struct SweepReport {
    /// This invocation's summary.
    pub summary: SweepSummary,
    /// The run directory's state after it.
    pub status: StatusReport,
}

impl SweepReport {
    /// The report of `summary` with the run's `status` after it.
    pub fn new(summary: SweepSummary, status: &RunStatus) -> Self {
        Self { summary, status: StatusReport::new(status) }
    }
}

impl Serialize for SweepReport {
    /// `{ "summary": …, "run": … }`, as `sweep --json` prints it.
    fn serialize<Se: serde::Serializer>(&self, serializer: Se) -> Result<Se::Ok, Se::Error> {
        serde_json::json!({ "summary": self.summary, "run": self.status.to_json_value() }).serialize(serializer)
    }
}

impl fmt::Display for SweepReport {
    /// The closing lines, each short enough for an 80-column terminal.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (s, status) = (&self.summary, &self.status);
        writeln!(f, "shard {}/{}: {} rows solved and written, {} already done", s.shard, s.shards, s.rows_written, s.rows_skipped)?;
        if s.partial_chunks_removed + s.damaged_chunks_redone > 0 {
            writeln!(f, "  {} abandoned partial chunks removed, {} damaged chunks redone", s.partial_chunks_removed, s.damaged_chunks_redone)?;
        }
        writeln!(f, "  {:.2} s wall, {:.0} solves/s, {} thread{}", s.wall_s, s.solves_per_s, s.threads, if s.threads == 1 { "" } else { "s" })?;
        writeln!(f, "shard {}/{} statuses: {}", s.shard, s.shards, fmt_counts(&s.status_counts))?;
        writeln!(
            f,
            "run {}: {}/{} rows, {}",
            status.dir.display(),
            status.rows_done,
            status.rows_total,
            if status.complete { "complete" } else { "partial (other shards not done yet)" }
        )
    }
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
