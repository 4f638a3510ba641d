//! The comparison of a study's variants: one row per variant (reach and
//! mode areas, coefficient ranges, failures), read from their maps;
//! written as `comparison.csv` and `comparison.json`.

use super::error::StudyError;
use super::record::STUDY_FILE;
use super::spec::{StudySpec, Variant};
use crate::reduce::tables::{read_cells, read_summary};
use crate::reduce::MODES;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The comparison table, one row per variant.
pub const COMPARISON_CSV: &str = "comparison.csv";
/// The comparison as JSON.
pub const COMPARISON_JSON: &str = "comparison.json";

/// One row of the comparison table.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct VariantRow {
    /// Variant number.
    pub index: usize,
    /// Its settings, `axis=value, …`.
    pub label: String,
    /// Area of the reach: non-empty cells × cell area, mm².
    pub reach_area_mm2: f64,
    /// Per mode, the area of the cells where it occurs, mm².
    pub mode_area_mm2: [f64; MODES],
    /// Smallest and largest a_0 over the map, mm⁻¹.
    pub a0_range: [f64; 2],
    /// Smallest and largest a_1 over the map, mm⁻¹.
    pub a1_range: [f64; 2],
    /// Simulations (mirror images included).
    pub rows_total: u64,
    /// Failed simulations.
    pub rows_failed: u64,
    /// Cell size, mm.
    pub cell_mm: f64,
    /// The variant's map directory, relative to the study directory.
    pub map: String,
}

/// The study's comparison.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Comparison {
    /// The study's name.
    pub name: String,
    /// One row per variant.
    pub variants: Vec<VariantRow>,
}

/// Compares the variants' maps of the study in `dir` (every variant must
/// be mapped).
pub fn compare(study: &StudySpec, dir: &Path) -> Result<Comparison, StudyError> {
    let record = dir.join(STUDY_FILE);
    if !record.is_file() {
        return Err(StudyError::NoStudy { dir: dir.to_path_buf(), record });
    }
    let mapped = |v: &Variant| read_summary(&v.map_dir(dir)).is_ok_and(|s| s.spec_hash == v.spec.hash_hex());
    let missing: Vec<usize> = study.variants.iter().filter(|v| !mapped(v)).map(|v| v.index).collect();
    if !missing.is_empty() {
        return Err(StudyError::NotMapped {
            dir: dir.to_path_buf(),
            total: study.variants.len(),
            missing,
        });
    }
    let mut rows = Vec::new();
    for v in &study.variants {
        let map = v.map_dir(dir);
        let err = |source| StudyError::Map { index: v.index, source };
        let s = read_summary(&map).map_err(err)?;
        let cells = read_cells(&map, s.order).map_err(err)?;
        let area = s.cell_mm * s.cell_mm;
        let range = |k: usize| {
            cells.iter().fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], c| {
                [lo.min(c.coefficients[k].min), hi.max(c.coefficients[k].max)]
            })
        };
        rows.push(VariantRow {
            index: v.index,
            label: v.label(),
            reach_area_mm2: cells.len() as f64 * area,
            mode_area_mm2: std::array::from_fn(|m| cells.iter().filter(|c| c.modes[m] > 0).count() as f64 * area),
            a0_range: range(0),
            a1_range: range(1),
            rows_total: s.rows_total,
            rows_failed: s.rows_failed,
            cell_mm: s.cell_mm,
            map: format!("v{}/map", v.index),
        });
    }
    Ok(Comparison {
        name: study.name.clone(),
        variants: rows,
    })
}

impl Comparison {
    /// The table as CSV (one row per variant; mode areas as mode_0_area_mm2 …).
    pub fn csv(&self) -> String {
        let mut s = String::from("variant,label,reach_area_mm2");
        for m in 0..MODES {
            s.push_str(&format!(",mode_{m}_area_mm2"));
        }
        s.push_str(",a0_min,a0_max,a1_min,a1_max,rows_total,rows_failed,cell_mm,map\n");
        for r in &self.variants {
            s.push_str(&format!("{},\"{}\",{}", r.index, r.label.replace('"', "'"), r.reach_area_mm2));
            for a in r.mode_area_mm2 {
                s.push_str(&format!(",{a}"));
            }
            s.push_str(&format!(
                ",{},{},{},{},{},{},{},{}\n",
                r.a0_range[0], r.a0_range[1], r.a1_range[0], r.a1_range[1], r.rows_total, r.rows_failed, r.cell_mm, r.map
            ));
        }
        s
    }
}
