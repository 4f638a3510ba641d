//! Pass 1: the tip and a_0…a_2 of every converged row of the run (and of
//! its mirror image when the run dropped mirror images), and the tallies of
//! rows and failures. Everything the cells and modes are computed from.
//! The samples go to a scratch file (`spill`), not to memory.

use super::columns::RowColumns;
use super::mirror::{copies, Mirror};
use super::sample::{RowRef, Sample};
use super::source::RunInfo;
use super::spill::{Extent, SampleOut};
use super::{ReduceError, CELL_STATS_ORDER};
use arrow::record_batch::RecordBatch;
use std::collections::BTreeMap;

/// Rows counted by pass 1 (after mirroring).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct Tally {
    /// Every simulation.
    pub rows_total: u64,
    /// Failed simulations by status.
    pub failed_by_status: BTreeMap<String, u64>,
}

impl Tally {
    /// Failed simulations.
    pub fn rows_failed(&self) -> u64 {
        self.failed_by_status.values().sum()
    }
}

impl Tally {
    /// Adds `other`'s counts.
    pub fn merge(&mut self, other: &Tally) {
        self.rows_total += other.rows_total;
        for (status, n) in &other.failed_by_status {
            *self.failed_by_status.entry(status.clone()).or_default() += n;
        }
    }
}

/// What pass 1 learns besides the samples themselves.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct Pass1 {
    /// Rows and failures.
    pub tally: Tally,
    /// Extent of the converged tips.
    pub extent: Extent,
    /// Converged simulations (mirror images included).
    pub samples: u64,
    /// Stored rows read.
    pub rows_read: u64,
}

impl Pass1 {
    /// Adds another part of the run.
    pub fn merge(&mut self, other: &Pass1) {
        self.tally.merge(&other.tally);
        self.extent.merge(&other.extent);
        self.samples += other.samples;
        self.rows_read += other.rows_read;
    }
}

/// Reads pass 1 from the run's batches, whose first row is row number
/// `first_row` of the run, writing the samples to `out`.
pub(crate) fn spill_samples(
    info: &RunInfo,
    batches: impl Iterator<Item = Result<RecordBatch, ReduceError>>,
    first_row: u32,
    out: &mut impl SampleOut,
) -> Result<Pass1, ReduceError> {
    let nk = info.order.min(CELL_STATS_ORDER) + 1;
    let mut pass = Pass1::default();
    let mut row = first_row;
    for batch in batches {
        let cols = RowColumns::from_batch(&batch?, info.order)?;
        for i in 0..cols.len() {
            let copies = copies(info.mirrored, cols.routing_mm.iter().map(|y| y.value(i)));
            pass.tally.rows_total += copies;
            if !cols.converged(i) {
                *pass.tally.failed_by_status.entry(cols.status_of(i).to_string()).or_default() += copies;
            } else {
                let mut a = [0.0; CELL_STATS_ORDER + 1];
                for (k, slot) in a.iter_mut().enumerate().take(nk) {
                    *slot = cols.a[k].value(i);
                }
                let s = Sample { x_mm: cols.tip_x_mm.value(i), y_mm: cols.tip_y_mm.value(i), a, at: RowRef { row, mirrored: false } };
                out.push(&s, copies == 2)?;
                pass.extent.add(&s);
                pass.samples += 1;
                if copies == 2 {
                    pass.extent.add(&s.mirror());
                    pass.samples += 1;
                }
            }
            row += 1;
            pass.rows_read += 1;
        }
    }
    Ok(pass)
}
