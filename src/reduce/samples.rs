//! Pass 1: the tip and a_0…a_2 of every converged row of the run (and of
//! its mirror image when the run dropped mirror images), and the tallies of
//! rows and failures. Everything the cells and modes are computed from.

use super::columns::RowColumns;
use super::mirror::{copies, Mirror};
use super::{ReduceError, RunInfo, CELL_STATS_ORDER};
use arrow::record_batch::RecordBatch;
use std::collections::BTreeMap;

/// A simulation of the run: a stored row by its number in pass order, or
/// that row's mirror image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(crate) struct RowRef {
    /// Row number in pass order.
    pub row: u32,
    /// Whether the simulation is the row's mirror image.
    pub mirrored: bool,
}

/// One converged simulation as pass 1 keeps it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sample {
    /// Tip, mm.
    pub x_mm: f64,
    /// Tip, mm.
    pub y_mm: f64,
    /// a_0 … a_min(order, 2) (higher entries 0).
    pub a: [f64; CELL_STATS_ORDER + 1],
    /// Which simulation.
    pub at: RowRef,
}

/// Rows counted by pass 1 (after mirroring).
#[derive(Debug, Clone, Default)]
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

/// Reads pass 1 from the run's batches.
pub(crate) fn read_samples(
    info: &RunInfo,
    batches: impl Iterator<Item = Result<RecordBatch, ReduceError>>,
) -> Result<(Vec<Sample>, Tally), ReduceError> {
    let nk = info.order.min(CELL_STATS_ORDER) + 1;
    let mut samples = Vec::new();
    let mut tally = Tally::default();
    let mut row = 0u32;
    for batch in batches {
        let cols = RowColumns::from_batch(&batch?, info.order)?;
        for i in 0..cols.len() {
            let copies = copies(info.mirrored, cols.routing_mm.iter().map(|y| y.value(i)));
            tally.rows_total += copies;
            if !cols.converged(i) {
                *tally.failed_by_status.entry(cols.status_of(i).to_string()).or_default() += copies;
            } else {
                let mut a = [0.0; CELL_STATS_ORDER + 1];
                for (k, slot) in a.iter_mut().enumerate().take(nk) {
                    *slot = cols.a[k].value(i);
                }
                let s = Sample { x_mm: cols.tip_x_mm.value(i), y_mm: cols.tip_y_mm.value(i), a, at: RowRef { row, mirrored: false } };
                samples.push(s);
                if copies == 2 {
                    samples.push(s.mirror());
                }
            }
            row += 1;
        }
    }
    Ok((samples, tally))
}
