//! Pass 2: the full rows of the simulations the map keeps (the designs per
//! cell and the modes' representatives).

use super::columns::RowColumns;
use super::mirror::Mirror;
use super::sample::RowRef;
use super::{Design, ReduceError};
use arrow::record_batch::RecordBatch;
use std::collections::HashMap;

/// The full rows fetched, by row number.
#[derive(Debug, Clone, Default)]
pub(crate) struct Fetched {
    rows: HashMap<u32, Option<Design>>,
}

impl Fetched {
    /// Reads the rows of the `wanted` simulations from the run's batches
    /// (the same rows in the same order as pass 1).
    pub fn read(
        order: usize,
        wanted: impl IntoIterator<Item = RowRef>,
        batches: impl Iterator<Item = Result<RecordBatch, ReduceError>>,
    ) -> Result<Self, ReduceError> {
        let mut rows: HashMap<u32, Option<Design>> = wanted.into_iter().map(|at| (at.row, None)).collect();
        let mut row = 0u32;
        for batch in batches {
            let cols = RowColumns::from_batch(&batch?, order)?;
            for i in 0..cols.len() {
                if let Some(slot) = rows.get_mut(&row) {
                    *slot = Some(cols.design(i));
                }
                row += 1;
            }
        }
        Ok(Self { rows })
    }

    /// The design of simulation `at` (mirrored if it is a mirror image), in
    /// cell (0, 0).
    pub fn design(&self, at: RowRef) -> Result<Design, ReduceError> {
        let d = self.rows.get(&at.row).and_then(Option::as_ref).ok_or(ReduceError::RunChanged)?;
        Ok(if at.mirrored { d.mirror() } else { d.clone() })
    }
}
