//! The options of a reduction: cell size, mode boundaries, designs kept,
//! and the memory bound.

use super::ReduceError;
use crate::io::SettingNames;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Boundaries of the characteristic modes: a_0 split into 4 ranges by three
/// values, a_1 into 3 by two (both mm⁻¹, in the run's length basis).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModeBoundaries {
    /// Ascending a_0 boundaries.
    pub a0: [f64; 3],
    /// Ascending a_1 boundaries.
    pub a1: [f64; 2],
}

impl ModeBoundaries {
    /// Checks that both lists are finite and ascending.
    pub fn validate(&self) -> Result<(), ReduceError> {
        let ok = |v: &[f64]| v.iter().all(|x| x.is_finite()) && v.windows(2).all(|w| w[0] < w[1]);
        if ok(&self.a0) && ok(&self.a1) {
            Ok(())
        } else {
            Err(ReduceError::Boundaries { a0: self.a0, a1: self.a1 })
        }
    }

    /// (a_0 range, a_1 range) of a coefficient pair.
    pub fn ranges(&self, a0: f64, a1: f64) -> (usize, usize) {
        (self.a0.iter().filter(|&&b| a0 >= b).count(), self.a1.iter().filter(|&&b| a1 >= b).count())
    }

    /// Mode index 3·i + j.
    pub fn mode(&self, a0: f64, a1: f64) -> usize {
        let (i, j) = self.ranges(a0, a1);
        3 * i + j
    }

    /// Bounds (lo, hi) of range `i` of a list (open ends are ±inf).
    pub(crate) fn bounds(list: &[f64], i: usize) -> (f64, f64) {
        let lo = if i == 0 { f64::NEG_INFINITY } else { list[i - 1] };
        let hi = if i == list.len() { f64::INFINITY } else { list[i] };
        (lo, hi)
    }
}

/// Options of a reduction.
#[derive(Debug, Clone)]
pub struct ReduceOptions {
    /// Cell size of the grid, mm.
    pub cell_mm: f64,
    /// Explicit mode boundaries; `None` takes quantiles of the data.
    pub mode_boundaries: Option<ModeBoundaries>,
    /// Designs kept per cell in designs.parquet.
    pub designs_per_cell: usize,
    /// Samples (48 bytes each) held in memory at once: the bound on the
    /// reduction's memory, whatever the run's size (one cell's samples are
    /// always held together). The tables do not depend on it.
    pub memory_samples: usize,
    /// Where the scratch files go (about 48 bytes per converged row);
    /// `None` for the system's temporary directory.
    pub scratch_dir: Option<PathBuf>,
}

/// Default of [`ReduceOptions::memory_samples`]: 8 Mi samples, 384 MiB.
pub const DEFAULT_MEMORY_SAMPLES: usize = 8 << 20;

impl Default for ReduceOptions {
    fn default() -> Self {
        Self { cell_mm: 1.0, mode_boundaries: None, designs_per_cell: 16, memory_samples: DEFAULT_MEMORY_SAMPLES, scratch_dir: None }
    }
}

impl ReduceOptions {
    /// The directory scratch files go in.
    pub(crate) fn scratch_parent(&self) -> PathBuf {
        self.scratch_dir.clone().unwrap_or_else(std::env::temp_dir)
    }
}

/// Cell size of a planar map when none is asked for, mm.
pub const DEFAULT_CELL_MM: f64 = 1.0;

/// The map settings shared by `reduce`, `map` and `study`.
#[derive(Debug, Clone, PartialEq)]
pub struct MapSettings {
    /// Cell size, mm; `None`: [`DEFAULT_CELL_MM`], a cable sweep its spec's `output.cell_mm`.
    pub cell_mm: Option<f64>,
    /// Explicit mode boundaries; `None` takes quantiles of the data.
    pub mode_boundaries: Option<ModeBoundaries>,
    /// Designs kept per cell in designs.parquet.
    pub designs_per_cell: usize,
    /// Samples held in memory at once (bounds the reduce's memory).
    pub memory_samples: usize,
}

/// The map settings as a user gives them (`cablemap reduce`'s flags,
/// `cablemap.reduce`'s keywords), each optional one at its default when
/// not given; [`Self::settings`] checks them once for both.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapSettingsFields {
    /// Cell size, mm; `None`: [`DEFAULT_CELL_MM`], a cable sweep its spec's `output.cell_mm`.
    pub cell_mm: Option<f64>,
    /// Explicit a_0 boundaries of the modes: three values.
    pub a0_bounds: Option<Vec<f64>>,
    /// Explicit a_1 boundaries of the modes: two values.
    pub a1_bounds: Option<Vec<f64>>,
    /// Designs kept per cell in designs.parquet.
    pub designs_per_cell: usize,
    /// Samples held in memory at once; `None`: [`DEFAULT_MEMORY_SAMPLES`].
    pub memory_samples: Option<usize>,
}

/// Why [`MapSettingsFields`] make no map settings.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MapSettingsError {
    /// Not three a_0 boundaries.
    #[error("{} needs three values (4 ranges of a_0), got {count}", names.name("a0_bounds"))]
    A0Bounds {
        /// The values given.
        count: usize,
        /// How the setting is named.
        names: SettingNames,
    },
    /// Not two a_1 boundaries.
    #[error("{} needs two values (3 ranges of a_1), got {count}", names.name("a1_bounds"))]
    A1Bounds {
        /// The values given.
        count: usize,
        /// How the setting is named.
        names: SettingNames,
    },
    /// One list of boundaries without the other.
    #[error("give both {} and {}, or neither (quantiles of the data)", names.name("a0_bounds"), names.name("a1_bounds"))]
    OneOfTheBounds {
        /// How the settings are named.
        names: SettingNames,
    },
    /// No sample held in memory.
    #[error("{} must be at least 1", names.name("memory_samples"))]
    NoMemorySamples {
        /// How the setting is named.
        names: SettingNames,
    },
}

impl MapSettingsFields {
    /// The map settings these fields give; a refusal names each setting
    /// as `names` says.
    pub fn settings(self, names: SettingNames) -> Result<MapSettings, MapSettingsError> {
        let mode_boundaries = match (self.a0_bounds, self.a1_bounds) {
            (None, None) => None,
            (Some(a0), Some(a1)) => {
                let a0: [f64; 3] = a0.try_into().map_err(|a: Vec<f64>| MapSettingsError::A0Bounds { count: a.len(), names })?;
                let a1: [f64; 2] = a1.try_into().map_err(|a: Vec<f64>| MapSettingsError::A1Bounds { count: a.len(), names })?;
                Some(ModeBoundaries { a0, a1 })
            }
            _ => return Err(MapSettingsError::OneOfTheBounds { names }),
        };
        let memory_samples = self.memory_samples.unwrap_or(DEFAULT_MEMORY_SAMPLES);
        if memory_samples == 0 {
            return Err(MapSettingsError::NoMemorySamples { names });
        }
        Ok(MapSettings { cell_mm: self.cell_mm, mode_boundaries, designs_per_cell: self.designs_per_cell, memory_samples })
    }
}

impl MapSettings {
    /// The reduce options of a planar map (scratch beside the map: on the
    /// same disk as the results, not a RAM-backed /tmp).
    pub fn options(&self, out: &Path) -> ReduceOptions {
        ReduceOptions {
            cell_mm: self.cell_mm.unwrap_or(DEFAULT_CELL_MM),
            mode_boundaries: self.mode_boundaries,
            designs_per_cell: self.designs_per_cell,
            memory_samples: self.memory_samples,
            scratch_dir: Some(scratch_beside(out)),
        }
    }
}

/// The directory `out` lies in (`.` for a bare name).
fn scratch_beside(out: &Path) -> PathBuf {
    out.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new(".")).to_path_buf()
}
