//! Studies over actuator variants (thesis §4.1: an actuator's specification
//! is chosen from maps of many variants). A study spec is a sweep spec with
//! a `[study]` section whose axes vary actuator parameters, the tension
//! range or the effects; every combination of the axes' values is one
//! variant, with its own resumable sweep and map:
//!
//! ```toml
//! [grid]                       # the base sweep spec, as for `cablemap sweep`
//! levels = 3
//! [study]
//! name = "length × stiffness"
//! [[study.axis]]
//! name = "length_mm"           # absolute values …
//! values = [55.0, 65.0, 75.0]
//! [[study.axis]]
//! name = "ei_n_mm2"            # … or factors on the base spec's value
//! scale = [0.8, 1.0, 1.25]
//! ```
//!
//! Axes: `length_mm`, `radius_mm`, `ei_n_mm2`, `ea_n`, `ga_n`,
//! `density_g_cm3` (numbers, or `scale`), `tension_n` (pairs [min, max] in
//! N), `effects` (tables of `[actuator.effects]` settings, laid over the
//! base spec's), and each effect parameter of the registry by its path
//! (`effects.friction_mu`, `gravity.scale`: numbers; see
//! [`crate::model::effects`]). Variants are numbered with the first axis
//! slowest.
//!
//! A study directory holds `study.json` (the study and its variants),
//! `v{i}/run` and `v{i}/map` per variant (each exactly what `cablemap map`
//! of the variant's spec, `v{i}/spec.toml`, writes), and once every
//! variant is mapped the comparison: `comparison.csv`, `comparison.json`
//! and `index.html` (the variants' maps side by side).

pub mod run;

pub use run::{run, StudyProgress, StudyReport, StudyRequest, StudyTask};

use crate::io::FileError;
use crate::reduce::tables::{read_cells, read_summary};
use crate::reduce::{CellStats, MapSummary, MODES};
use crate::sweep::SweepSpec;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The study's record in its directory.
pub const STUDY_FILE: &str = "study.json";
/// The comparison table, one row per variant.
pub const COMPARISON_CSV: &str = "comparison.csv";
/// The comparison as JSON.
pub const COMPARISON_JSON: &str = "comparison.json";
/// The page showing the variants' maps side by side.
pub const PAGE_FILE: &str = "index.html";
/// Format tag of `study.json`.
pub const STUDY_FORMAT: &str = "cablemap-study/1";
/// Most variants of a study (a typo in an axis should not start 10⁶ sweeps).
pub const MAX_VARIANTS: usize = 1000;

/// Axes whose values are numbers at `[actuator] NAME`.
pub const NUMBER_AXES: [&str; 6] = ["length_mm", "radius_mm", "ei_n_mm2", "ea_n", "ga_n", "density_g_cm3"];

/// What is wrong with a study, or why it cannot be compared yet.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The spec text or its `[study]` section.
    #[error("bad study spec {origin}: {message}")]
    Spec {
        /// The spec file.
        origin: String,
        /// What is wrong and what to do.
        message: String,
    },
    /// One variant's sweep spec is invalid.
    #[error("bad study spec {origin}: variant {index} ({label}): {source}")]
    Variant {
        /// The spec file.
        origin: String,
        /// Variant number.
        index: usize,
        /// Its settings.
        label: String,
        /// Why its spec is refused.
        source: crate::sweep::SweepError,
    },
    /// The directory holds another study.
    #[error("{} holds another study (its variants differ from this spec's): give a new directory, or the spec it was started with", dir.display())]
    OtherStudy {
        /// The study directory.
        dir: PathBuf,
    },
    /// The directory holds no study.
    #[error("{} holds no study ({} is missing): run the study first", dir.display(), dir.join(STUDY_FILE).display())]
    NoStudy {
        /// The study directory.
        dir: PathBuf,
    },
    /// Some variants have no map yet.
    #[error("{}: {} of {total} variants not mapped yet (variant {}): run the study (or those shards) to finish them", dir.display(), missing.len(), missing.iter().map(usize::to_string).collect::<Vec<_>>().join(", "))]
    NotMapped {
        /// The study directory.
        dir: PathBuf,
        /// Variants.
        total: usize,
        /// Variants without a map.
        missing: Vec<usize>,
    },
    /// A variant's map cannot be read.
    #[error("variant {index}: {source}")]
    Map {
        /// Variant number.
        index: usize,
        /// The read error.
        source: crate::reduce::tables::ReadError,
    },
    /// A variant's sweep failed.
    #[error("variant {index} ({label}): {source}")]
    Sweep {
        /// Variant number.
        index: usize,
        /// Its settings.
        label: String,
        /// The sweep's error.
        source: crate::sweep::SweepError,
    },
    /// A variant's reduce failed.
    #[error("variant {index} ({label}): {source}")]
    Reduce {
        /// Variant number.
        index: usize,
        /// Its settings.
        label: String,
        /// The reduce's error.
        source: crate::reduce::ReduceError,
    },
    /// A picture of the comparison page could not be drawn.
    #[error(transparent)]
    Plot(#[from] crate::plot::PlotError),
    /// A file operation.
    #[error(transparent)]
    File(#[from] FileError),
    /// `study.json` is not a study's record.
    #[error("{}: not a study record: {message}", path.display())]
    NotARecord {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A task index outside the split.
    #[error("task {shard} is not below the {shards} tasks of the split: tasks are numbered 0 to shards − 1 (shards ≥ 1)")]
    BadTask {
        /// The task asked for.
        shard: u64,
        /// Tasks in all.
        shards: u64,
    },
    /// Running a variant of the study in a directory.
    #[error("study {}: {source}", dir.display())]
    In {
        /// The study directory.
        dir: PathBuf,
        /// What went wrong.
        source: Box<StudyError>,
    },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StudySection {
    name: Option<String>,
    #[serde(default)]
    axis: Vec<AxisSection>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct AxisSection {
    name: String,
    values: Option<Vec<toml::Value>>,
    scale: Option<Vec<f64>>,
}

/// One setting of a variant: an axis and its value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Setting {
    /// The axis.
    pub axis: String,
    /// The value as written in the label (e.g. `55`, `×0.8`, `1–3 N`).
    pub value: String,
}

/// One variant: its settings and its complete sweep spec.
#[derive(Debug, Clone)]
pub struct Variant {
    /// Variant number (first axis slowest).
    pub index: usize,
    /// Its axis values.
    pub settings: Vec<Setting>,
    /// The sweep spec of the variant.
    pub spec: SweepSpec,
}

impl Variant {
    /// `axis=value, …`.
    pub fn label(&self) -> String {
        self.settings
            .iter()
            .map(|s| format!("{}={}", s.axis, s.value))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The variant's directory in the study directory `dir`.
    pub fn dir(&self, dir: &Path) -> PathBuf {
        dir.join(format!("v{}", self.index))
    }

    /// Its sweep run directory.
    pub fn run_dir(&self, dir: &Path) -> PathBuf {
        self.dir(dir).join("run")
    }

    /// Its map directory.
    pub fn map_dir(&self, dir: &Path) -> PathBuf {
        self.dir(dir).join("map")
    }
}

/// A study: a name and its variants.
#[derive(Debug, Clone)]
pub struct StudySpec {
    /// The study's name.
    pub name: String,
    /// The axes, in order, with their number of values.
    pub axes: Vec<(String, usize)>,
    /// Every variant.
    pub variants: Vec<Variant>,
}

/// How one axis changes the spec (as JSON, the spec's canonical form).
enum Change {
    Number { key: &'static str, value: f64 },
    /// A registry effect parameter at `[actuator.SECTION] KEY`.
    Effect { info: &'static crate::model::EffectInfo, value: f64 },
    Scale { key: &'static str, factor: f64 },
    Tension { min_n: f64, max_n: f64 },
    Effects(serde_json::Map<String, serde_json::Value>),
}

/// An axis value as a number (TOML integers count).
fn number(v: &toml::Value) -> Result<f64, String> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64)).ok_or_else(|| format!("value {v} is not a number"))
}

fn fmt(v: f64) -> String {
    crate::io::fmt_num(v)
}

impl StudySpec {
    /// Reads a study spec file.
    pub fn load(path: &Path) -> Result<Self, StudyError> {
        let text = crate::io::read_text(path, "reading")?;
        Self::from_toml(&text, &path.display().to_string())
    }

    /// Parses a study spec; `origin` names it in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, StudyError> {
        let bad = |message: String| StudyError::Spec {
            origin: origin.to_string(),
            message,
        };
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| bad(e.to_string()))?;
        Self::from_table(table, origin)
    }

    /// A study spec from its parsed TOML (see [`crate::job::Job::load`],
    /// which parses a spec once to tell its kind); `origin` names it in errors.
    pub fn from_table(mut table: toml::Table, origin: &str) -> Result<Self, StudyError> {
        let bad = |message: String| StudyError::Spec {
            origin: origin.to_string(),
            message,
        };
        let section = table
            .remove("study")
            .ok_or_else(|| bad("no [study] section: a study spec is a sweep spec with a [study] section naming its axes".into()))?;
        let section: StudySection = section.try_into().map_err(|e: toml::de::Error| bad(format!("[study] {e}")))?;
        let base_text = toml::to_string(&table).map_err(|e| bad(e.to_string()))?;
        let base = SweepSpec::from_toml(&base_text, origin).map_err(|e| bad(format!("the base sweep spec: {e}")))?;
        if section.axis.is_empty() {
            return Err(bad(
                "[study] has no [[study.axis]]: give at least one axis (name and values or scale)".into(),
            ));
        }
        let mut axes: Vec<(String, Vec<(String, Change)>)> = Vec::new();
        for a in &section.axis {
            let changes = Self::axis_changes(a).map_err(|m| bad(format!("[[study.axis]] {}: {m}", a.name)))?;
            if changes.is_empty() {
                return Err(bad(format!("[[study.axis]] {}: no values", a.name)));
            }
            if axes.iter().any(|(n, _)| *n == a.name) {
                return Err(bad(format!(
                    "[[study.axis]] {} is given twice: give each axis once, with all its values",
                    a.name
                )));
            }
            axes.push((a.name.clone(), changes));
        }
        let count = axes
            .iter()
            .try_fold(1usize, |n, (_, v)| n.checked_mul(v.len()))
            .filter(|&n| n <= MAX_VARIANTS);
        let Some(count) = count else {
            return Err(bad(format!("the axes give more than {MAX_VARIANTS} variants: use fewer values")));
        };
        let base_json: serde_json::Value = serde_json::from_str(&base.canonical_json()).expect("the spec's canonical JSON parses");
        let mut variants = Vec::with_capacity(count);
        for index in 0..count {
            // Mixed radix, first axis slowest.
            let mut rest = index;
            let mut picks = vec![0; axes.len()];
            for (slot, (_, values)) in picks.iter_mut().zip(&axes).rev() {
                *slot = rest % values.len();
                rest /= values.len();
            }
            let mut json = base_json.clone();
            let mut settings = Vec::new();
            for ((name, values), &pick) in axes.iter().zip(&picks) {
                let (value, change) = &values[pick];
                apply(&mut json, change);
                settings.push(Setting {
                    axis: name.clone(),
                    value: value.clone(),
                });
            }
            let label = settings
                .iter()
                .map(|s| format!("{}={}", s.axis, s.value))
                .collect::<Vec<_>>()
                .join(", ");
            let spec: SweepSpec = serde_json::from_value(json).map_err(|e| bad(format!("variant {index} ({label}): {e}")))?;
            spec.validate().map_err(|source| StudyError::Variant {
                origin: origin.to_string(),
                index,
                label: label.clone(),
                source: crate::sweep::SweepError::BadSpec {
                    origin: format!("variant {index}"),
                    source,
                },
            })?;
            variants.push(Variant { index, settings, spec });
        }
        let name = section
            .name
            .unwrap_or_else(|| axes.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>().join(" × "));
        Ok(Self {
            name,
            axes: axes.iter().map(|(n, v)| (n.clone(), v.len())).collect(),
            variants,
        })
    }

    /// The labelled changes of one axis.
    fn axis_changes(a: &AxisSection) -> Result<Vec<(String, Change)>, String> {
        let both = "give either values or scale, not both";
        if let Some(key) = NUMBER_AXES.iter().find(|k| **k == a.name) {
            return match (&a.values, &a.scale) {
                (Some(values), None) => values
                    .iter()
                    .map(|v| number(v).map(|x| (fmt(x), Change::Number { key, value: x })))
                    .collect(),
                (None, Some(scale)) => scale
                    .iter()
                    .map(|&f| {
                        if f.is_finite() && f > 0.0 {
                            Ok((format!("×{}", fmt(f)), Change::Scale { key, factor: f }))
                        } else {
                            Err(format!("scale {f} must be a positive factor"))
                        }
                    })
                    .collect(),
                (Some(_), Some(_)) => Err(both.into()),
                (None, None) => Err("give values = [...] or scale = [...]".into()),
            };
        }
        if let Some(info) = crate::model::REGISTRY.iter().copied().find(|e| e.path == a.name) {
            let values = a
                .values
                .as_ref()
                .filter(|_| a.scale.is_none())
                .ok_or("give values = [...] (numbers; an effect parameter has no scale)")?;
            return values
                .iter()
                .map(|v| number(v).map(|x| (fmt(x), Change::Effect { info, value: x })))
                .collect();
        }
        match a.name.as_str() {
            "tension_n" => {
                let values = a
                    .values
                    .as_ref()
                    .filter(|_| a.scale.is_none())
                    .ok_or("give values = [[min_n, max_n], ...] (no scale)")?;
                values
                    .iter()
                    .map(|v| {
                        let pair: Option<Vec<f64>> = v.as_array().map(|p| {
                            p.iter()
                                .filter_map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
                                .collect()
                        });
                        match pair.as_deref() {
                            Some(&[lo, hi]) if v.as_array().is_some_and(|p| p.len() == 2) => {
                                Ok((format!("{}–{} N", fmt(lo), fmt(hi)), Change::Tension { min_n: lo, max_n: hi }))
                            }
                            _ => Err(format!("value {v} is not a pair [min_n, max_n] of tensions")),
                        }
                    })
                    .collect()
            }
            "effects" => {
                let values = a
                    .values
                    .as_ref()
                    .filter(|_| a.scale.is_none())
                    .ok_or("give values = [{...}, ...] (tables of [actuator.effects] settings; no scale)")?;
                values
                    .iter()
                    .map(|v| {
                        let t = v
                            .as_table()
                            .ok_or_else(|| format!("value {v} is not a table of [actuator.effects] settings"))?;
                        let json = serde_json::to_value(t).map_err(|e| e.to_string())?;
                        let label = if t.is_empty() {
                            "none".to_string()
                        } else {
                            t.iter().map(|(k, v)| format!("{k}:{v}")).collect::<Vec<_>>().join(" ")
                        };
                        Ok((
                            format!("{{{label}}}"),
                            Change::Effects(json.as_object().cloned().unwrap_or_default()),
                        ))
                    })
                    .collect()
            }
            other => Err(format!(
                "unknown axis '{other}': use one of {}, tension_n, effects, or an effect parameter ({})",
                NUMBER_AXES.join(", "),
                crate::model::REGISTRY.iter().map(|e| e.path).collect::<Vec<_>>().join(", ")
            )),
        }
    }

    /// The record written as `study.json`.
    fn record(&self) -> serde_json::Value {
        serde_json::json!({
            "format": STUDY_FORMAT,
            "name": self.name,
            "axes": self.axes.iter().map(|(n, k)| serde_json::json!({ "name": n, "values": k })).collect::<Vec<_>>(),
            "variants": self.variants.iter().map(|v| serde_json::json!({
                "index": v.index, "settings": v.settings, "label": v.label(), "spec_sha256": v.spec.hash_hex(),
                "dir": format!("v{}", v.index),
            })).collect::<Vec<_>>(),
        })
    }

    /// Prepares the study directory `dir`: writes `study.json` and each
    /// variant's `spec.toml` (refusing a directory of another study).
    pub fn prepare(&self, dir: &Path) -> Result<(), StudyError> {
        let io = |op: &'static str, path: &Path| FileError::on(op, path);
        std::fs::create_dir_all(dir).map_err(io("creating", dir))?;
        let path = dir.join(STUDY_FILE);
        let record = self.record();
        match std::fs::read(&path) {
            Ok(bytes) => {
                let existing: serde_json::Value = serde_json::from_slice(&bytes).unwrap_or_default();
                if existing["variants"] != record["variants"] {
                    return Err(StudyError::OtherStudy { dir: dir.to_path_buf() });
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                let mut text = serde_json::to_string_pretty(&record).expect("serializes");
                text.push('\n');
                crate::io::write_atomic(&path, text.as_bytes()).map_err(io("writing", &path))?;
            }
            Err(e) => return Err(FileError::new("reading", path, e).into()),
        }
        for v in &self.variants {
            let vdir = v.dir(dir);
            std::fs::create_dir_all(&vdir).map_err(io("creating", &vdir))?;
            let spec_path = vdir.join("spec.toml");
            let text = format!(
                "# Variant {} of study '{}': {}\n# Written by `cablemap study`; `cablemap map` of this file gives the same run and map.\n{}",
                v.index,
                self.name,
                v.label(),
                toml::to_string(&v.spec).expect("a sweep spec serializes as TOML")
            );
            crate::io::write_atomic(&spec_path, text.as_bytes()).map_err(io("writing", &spec_path))?;
        }
        Ok(())
    }

    /// The variants that task `shard` of `shards` runs (every `shards`-th).
    pub fn variants_of_shard(&self, shard: u64, shards: u64) -> impl Iterator<Item = &Variant> {
        self.variants.iter().filter(move |v| v.index as u64 % shards.max(1) == shard)
    }
}

/// Sets `change` in the spec's JSON.
fn apply(json: &mut serde_json::Value, change: &Change) {
    let actuator = &mut json["actuator"];
    match change {
        Change::Number { key, value } => actuator[*key] = serde_json::json!(value),
        Change::Scale { key, factor } => {
            let base = actuator[*key].as_f64().expect("actuator numbers are numbers");
            actuator[*key] = serde_json::json!(base * factor);
        }
        Change::Tension { min_n, max_n } => {
            json["tension"]["min_n"] = serde_json::json!(min_n);
            json["tension"]["max_n"] = serde_json::json!(max_n);
        }
        Change::Effect { info, value } => {
            // Through the rod's own serde form, so that the parameter's
            // field (an optional one: the clamp) is written as the rod writes it.
            let mut rod: crate::model::Rod = serde_json::from_value(actuator.clone()).expect("the spec's actuator reads back");
            (info.set)(&mut rod, *value);
            let section = info.section.key();
            actuator[section] = serde_json::to_value(rod).expect("a rod serialises")[section].take();
        }
        Change::Effects(settings) => {
            for (k, v) in settings {
                actuator["effects"][k] = v.clone();
            }
        }
    }
}

/// What running one variant did.
#[derive(Debug, Clone)]
pub struct VariantRun {
    /// The sweep (rows solved now and before).
    pub sweep: crate::sweep::SweepSummary,
    /// The map's summary.
    pub map: crate::reduce::MapSummary,
    /// Seconds for the sweep and the map.
    pub wall_s: f64,
}

/// Runs variant `v` of the study in `dir`: its sweep (resumed where it
/// stopped, always as one shard: a cluster task runs whole variants) and
/// its map, exactly as `cablemap map` of its spec into `v{i}/`. The map's
/// scratch goes beside it unless `reduce.scratch_dir` says otherwise.
pub fn run_variant(
    v: &Variant,
    dir: &Path,
    sweep: &crate::sweep::SweepOptions,
    reduce: &crate::reduce::ReduceOptions,
) -> Result<VariantRun, StudyError> {
    let start = std::time::Instant::now();
    let options = crate::sweep::SweepOptions {
        shard: 0,
        shards: 1,
        ..sweep.clone()
    };
    let run = v.run_dir(dir);
    let summary = crate::sweep::run_sweep(&v.spec, &run, &options).map_err(|source| StudyError::Sweep {
        index: v.index,
        label: v.label(),
        source,
    })?;
    let reduce_err = |source| StudyError::Reduce {
        index: v.index,
        label: v.label(),
        source,
    };
    let mut reduce = reduce.clone();
    reduce.scratch_dir.get_or_insert_with(|| v.dir(dir));
    let (map, spec) = crate::reduce::reduce_run(&run, false, &reduce).map_err(reduce_err)?;
    crate::reduce::write_map_replacing(&v.map_dir(dir), &map, &spec.actuator, &spec.solver).map_err(reduce_err)?;
    Ok(VariantRun {
        sweep: summary,
        map: map.summary,
        wall_s: start.elapsed().as_secs_f64(),
    })
}

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
    if !dir.join(STUDY_FILE).is_file() {
        return Err(StudyError::NoStudy { dir: dir.to_path_buf() });
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

    /// The side-by-side page: the table, then each variant's reach (on
    /// common axes) and mode pictures (at one scale) in a row, linking to
    /// its map explorer.
    pub fn html(&self, pictures: &PagePictures) -> String {
        let esc = |t: &str| {
            t.replace('&', "&amp;")
                .replace('<', "&lt;")
                .replace('>', "&gt;")
                .replace('"', "&quot;")
        };
        let mut h = format!(
            "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Study: {name}</title>\n<style>\
             body{{font-family:sans-serif;margin:1.5em}} table{{border-collapse:collapse}} td,th{{border:1px solid #ccc;padding:3px 6px;text-align:right}}\
             td.l{{text-align:left}} .row{{display:flex;flex-wrap:wrap;gap:1em;align-items:flex-start}} .v{{flex:0 0 auto}} .v img{{border:1px solid #ddd}}\
             </style></head><body>\n<h1>Study: {name}</h1>\n<p>{n} variants, each a sweep and its feasibility map (<code>cablemap study</code>). \
             Areas are non-empty cells × cell area; mode areas count the cells where the mode occurs; a<sub>0</sub>, a<sub>1</sub> in mm⁻¹.</p>\n",
            name = esc(&self.name),
            n = self.variants.len()
        );
        h.push_str("<table><tr><th>variant</th><th>settings</th><th>reach mm²</th>");
        for m in 0..MODES {
            h.push_str(&format!("<th>mode {m} mm²</th>"));
        }
        h.push_str("<th>a0 range</th><th>a1 range</th><th>failed</th></tr>\n");
        for r in &self.variants {
            h.push_str(&format!(
                "<tr><td><a href=\"{}/index.html\">v{}</a></td><td class=\"l\">{}</td><td>{:.0}</td>",
                r.map,
                r.index,
                esc(&r.label),
                r.reach_area_mm2
            ));
            for a in r.mode_area_mm2 {
                h.push_str(&format!("<td>{a:.0}</td>"));
            }
            h.push_str(&format!(
                "<td>{:.4} … {:.4}</td><td>{:.4} … {:.4}</td><td>{} of {}</td></tr>\n",
                r.a0_range[0], r.a0_range[1], r.a1_range[0], r.a1_range[1], r.rows_failed, r.rows_total
            ));
        }
        h.push_str("</table>\n");
        let sections = [
            (
                "Reach (simulations per cell)",
                format!(
                    "Every variant on the same axes ({} px per mm) and the same log colour scale, so a smaller reach looks smaller; \
                     below each, its own map's reach.png.",
                    px(pictures.reach_px_per_mm)
                ),
                &pictures.reach,
            ),
            (
                "Characteristic modes",
                format!(
                    "Each variant's modes.png shown at one scale ({} px per mm in every map panel), so panel sizes compare; click for full size.",
                    px(pictures.modes_px_per_mm)
                ),
                &pictures.modes,
            ),
        ];
        for (k, (title, caption, shown)) in sections.into_iter().enumerate() {
            let is_reach = k == 0;
            h.push_str(&format!("<h2>{title}</h2>\n<p>{caption}</p>\n<div class=\"row\">\n"));
            for (r, p) in self.variants.iter().zip(shown.iter()) {
                // Reach: the picture opens the explorer, its own reach.png is linked below; modes: opens at full size.
                let (link, own) = if is_reach {
                    (format!("{}/index.html", r.map), format!(" · <a href=\"{}/reach.png\">own axes</a>", r.map))
                } else {
                    (p.file.clone(), String::new())
                };
                h.push_str(&format!(
                    "<div class=\"v\" style=\"width:{w}px\"><a href=\"{link}\"><img src=\"{file}\" width=\"{w}\" height=\"{ht}\" alt=\"{file} of variant {i}\"></a>\
                     <br>v{i}: {label}{own}</div>\n",
                    file = p.file,
                    w = p.shown_px.0,
                    ht = p.shown_px.1,
                    i = r.index,
                    label = esc(&r.label)
                ));
            }
            h.push_str("</div>\n");
        }
        h.push_str("</body></html>\n");
        h
    }

    /// Draws the page's reach pictures into `dir` from the variants' maps
    /// `maps` (summary and cells, in the order of the rows): every variant
    /// on common axes (the union of their frames at one mm per pixel) and
    /// one colour scale; and sizes their modes.png to one scale.
    pub fn draw_pictures(&self, dir: &Path, maps: &[(MapSummary, Vec<CellStats>)]) -> Result<PagePictures, StudyError> {
        use crate::reduce::plots::{draw_heatmap_laid_out, HeatmapLayout, MapFrame, ModesLayout, Scale};
        let frame = maps.iter().map(|(s, _)| MapFrame::of(s)).reduce(MapFrame::union);
        let most = maps.iter().flat_map(|(_, cells)| cells.iter().map(|c| c.count)).max().unwrap_or(1);
        let mut reach = Vec::new();
        let mut reach_px_per_mm = 0.0;
        if let Some(frame) = frame {
            let layout = HeatmapLayout { frame, plot_w_px: STUDY_REACH_PLOT_W, value_range: Some((1.0, most as f64)) };
            reach_px_per_mm = frame.px_per_mm(STUDY_REACH_PLOT_W);
            for (r, (summary, cells)) in self.variants.iter().zip(maps) {
                let file = reach_picture_file(r.index);
                let counts: Vec<(i32, i32, f64)> = cells.iter().map(|c| (c.ix, c.iy, c.count as f64)).collect();
                let title = format!("v{}: simulations per cell", r.index);
                let label = "simulations per cell (log scale, all variants)";
                let size = draw_heatmap_laid_out(&dir.join(&file), summary, &layout, &title, label, &counts, Scale::Log)?;
                reach.push(PagePicture { file, shown_px: size });
            }
        }
        // modes.png keeps each map's own frame: shown at k px per mm, its
        // display width is its width × k / (its own px per mm); k puts the
        // widest at MODES_SHOWN_MAX_W.
        let layouts: Vec<ModesLayout> = maps.iter().map(|(s, _)| ModesLayout::of(s)).collect();
        let widest_mm = layouts.iter().map(|l| f64::from(l.size_px.0) / l.px_per_mm).fold(0.0, f64::max);
        let modes_px_per_mm = if widest_mm > 0.0 { f64::from(MODES_SHOWN_MAX_W) / widest_mm } else { 0.0 };
        let modes = self
            .variants
            .iter()
            .zip(&layouts)
            .map(|(r, l)| {
                let k = modes_px_per_mm / l.px_per_mm;
                let shown = |n: u32| (f64::from(n) * k).round() as u32;
                PagePicture { file: format!("{}/modes.png", r.map), shown_px: (shown(l.size_px.0), shown(l.size_px.1)) }
            })
            .collect();
        Ok(PagePictures { reach, reach_px_per_mm, modes, modes_px_per_mm })
    }

    /// Writes comparison.csv, comparison.json, the page's reach pictures
    /// and index.html into `dir` (reading the variants' maps again).
    pub fn write(&self, dir: &Path) -> Result<(), StudyError> {
        let mut maps = Vec::with_capacity(self.variants.len());
        for r in &self.variants {
            let map = dir.join(&r.map);
            let err = |source| StudyError::Map { index: r.index, source };
            let summary = read_summary(&map).map_err(err)?;
            let cells = read_cells(&map, summary.order).map_err(err)?;
            maps.push((summary, cells));
        }
        let pictures = self.draw_pictures(dir, &maps)?;
        let json = serde_json::to_string_pretty(self).expect("serializes") + "\n";
        for (file, text) in [(COMPARISON_CSV, self.csv()), (COMPARISON_JSON, json), (PAGE_FILE, self.html(&pictures))] {
            let path = dir.join(file);
            crate::io::write_atomic(&path, text.as_bytes()).map_err(FileError::on("writing", &path))?;
        }
        Ok(())
    }
}

/// Width of the plot of every reach picture on the study page, pixels (for
/// the lateral extent common to all variants).
pub const STUDY_REACH_PLOT_W: u32 = 400;
/// Display width of the widest variant's modes.png on the study page, pixels.
pub const MODES_SHOWN_MAX_W: u32 = 720;

/// The study page's reach picture of variant `index`, in the study directory.
pub fn reach_picture_file(index: usize) -> String {
    format!("reach-v{index}.png")
}

/// A picture on the study page: its file (relative to the study
/// directory) and the size it is shown at, pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct PagePicture {
    /// File, relative to the study directory.
    pub file: String,
    /// Display size (width, height), pixels.
    pub shown_px: (u32, u32),
}

/// The pictures of the study page, one per variant in each list.
#[derive(Debug, Clone, PartialEq)]
pub struct PagePictures {
    /// Reach on common axes (shown at their own size).
    pub reach: Vec<PagePicture>,
    /// Pixels per mm of every reach picture.
    pub reach_px_per_mm: f64,
    /// The variants' modes.png, sized to one scale.
    pub modes: Vec<PagePicture>,
    /// Pixels per mm of every modes panel as shown.
    pub modes_px_per_mm: f64,
}

/// A scale in px per mm as the page states it.
fn px(px_per_mm: f64) -> String {
    format!("{px_per_mm:.2}")
}

/// Reads the study record of `dir` and the spec it was made from: the
/// variants' map directories, in order, with their labels.
pub fn mapped_variants(dir: &Path) -> Result<Vec<(usize, String, PathBuf)>, StudyError> {
    let path = dir.join(STUDY_FILE);
    let bytes = match std::fs::read(&path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(StudyError::NoStudy { dir: dir.to_path_buf() }),
        Err(source) => return Err(FileError::new("reading", path, source).into()),
    };
    let v: serde_json::Value =
        serde_json::from_slice(&bytes).map_err(|e| StudyError::NotARecord { path: path.clone(), message: e.to_string() })?;
    Ok(v["variants"]
        .as_array()
        .into_iter()
        .flatten()
        .map(|x| {
            let index = x["index"].as_u64().unwrap_or(0) as usize;
            (
                index,
                x["label"].as_str().unwrap_or("").to_string(),
                dir.join(format!("v{index}")).join("map"),
            )
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    const STUDY: &str = "[grid]\nlevels = 3\n[tension]\ncount = 5\n[study]\nname = \"t\"\n\
        [[study.axis]]\nname = \"length_mm\"\nvalues = [55, 65.0]\n\
        [[study.axis]]\nname = \"ei_n_mm2\"\nscale = [0.8, 1.25]\n";

    #[test]
    fn variants_are_every_combination_first_axis_slowest() {
        let s = StudySpec::from_toml(STUDY, "t").unwrap();
        assert_eq!(s.variants.len(), 4);
        let v = &s.variants[1];
        assert_eq!(v.label(), "length_mm=55, ei_n_mm2=×1.25");
        assert_eq!(v.spec.actuator.length_mm, 55.0);
        assert_eq!(v.spec.actuator.ei_n_mm2, 115.117 * 1.25);
        assert_eq!(v.spec.grid.levels, 3);
        assert_eq!(s.variants[2].spec.actuator.length_mm, 65.0);
        // The variant's spec.toml reads back as the same spec (same hash: same run).
        let text = toml::to_string(&v.spec).unwrap();
        assert_eq!(SweepSpec::from_toml(&text, "v").unwrap().hash_hex(), v.spec.hash_hex());
    }

    #[test]
    fn tension_and_effects_axes() {
        let s = StudySpec::from_toml(
            "[study]\n[[study.axis]]\nname = \"tension_n\"\nvalues = [[1.0, 2.0], [1, 3]]\n\
             [[study.axis]]\nname = \"effects\"\nvalues = [{}, { friction_mu = 0.1 }]\n",
            "t",
        )
        .unwrap();
        assert_eq!(s.variants.len(), 4);
        assert_eq!(s.variants[3].spec.tension.max_n, 3.0);
        assert_eq!(s.variants[3].spec.actuator.effects.friction_mu, 0.1);
        assert_eq!(s.variants[2].spec.actuator.effects.friction_mu, 0.0);
        assert_eq!(s.variants[3].label(), "tension_n=1–3 N, effects={friction_mu:0.1}");
    }

    #[test]
    fn every_registry_effect_parameter_is_an_axis() {
        for info in crate::model::REGISTRY.iter() {
            let v = if info.default == 0.0 { 0.25 } else if info.default.is_finite() { info.default * 0.5 } else { 40.0 };
            // Without mirror_dedup: a tilt or an offset breaks the mirror symmetry.
            let text = format!("[grid]\nmirror_dedup = false\n[study]\n[[study.axis]]\nname = \"{}\"\nvalues = [{v}]\n", info.path);
            let s = StudySpec::from_toml(&text, "t").unwrap_or_else(|e| panic!("{}: {e}", info.path));
            assert_eq!((info.get)(&s.variants[0].spec.actuator), v, "{}", info.path);
        }
    }

    #[test]
    fn the_page_draws_every_reach_on_common_axes_and_modes_at_one_scale() {
        use crate::reduce::plots::tests::{bounding_box, cell, pixels_of, summary};
        let small = summary();
        // A reach twice as large each way, from a rod twice as long.
        let large = MapSummary { nx: 20, ny: 32, y_min_mm: -80.0, length_mm: 130.0, ..summary() };
        let busiest = |ix, iy| cell(ix, iy, 50, 0);
        let maps = vec![(small, vec![cell(0, 0, 1, 0), busiest(3, 4)]), (large, vec![cell(0, 0, 1, 0), busiest(12, 20)])];
        let row = |index: usize| VariantRow {
            index,
            label: format!("length_mm={}", maps[index].0.length_mm),
            reach_area_mm2: 50.0,
            mode_area_mm2: [0.0; MODES],
            a0_range: [0.0, 0.0],
            a1_range: [0.0, 0.0],
            rows_total: 51,
            rows_failed: 0,
            cell_mm: 5.0,
            map: format!("v{index}/map"),
        };
        let comparison = Comparison { name: "t".into(), variants: vec![row(0), row(1)] };
        let dir = tempfile::tempdir().unwrap();
        let pictures = comparison.draw_pictures(dir.path(), &maps).unwrap();
        // Same axes: the same image size, and a 5 mm cell takes as many pixels in both.
        assert_eq!(pictures.reach[0].shown_px, pictures.reach[1].shown_px);
        use plotters::prelude::ColorMap;
        let top = plotters::style::colors::colormaps::ViridisRGB.get_color_normalized(1.0, 0.0, 1.0);
        let cell_px: Vec<(u32, u32)> = pictures
            .reach
            .iter()
            .map(|p| {
                let img = image::open(dir.path().join(&p.file)).unwrap().to_rgb8();
                let ((x0, x1), (y0, y1)) = bounding_box(&pixels_of(&img, top, 80));
                (x1 - x0 + 1, y1 - y0 + 1)
            })
            .collect();
        // (Cell edges round to whole pixels: ±1 px.)
        let expected = (5.0 * pictures.reach_px_per_mm).round() as u32;
        for (w, h) in &cell_px {
            assert!(w.abs_diff(expected) <= 1 && h.abs_diff(expected) <= 1, "busiest cells {cell_px:?} px, {expected} px expected in both");
        }
        // modes.png keeps each map's frame: shown widths follow the maps' mm extents.
        let layouts: Vec<_> = maps.iter().map(|(s, _)| crate::reduce::plots::ModesLayout::of(s)).collect();
        for (p, l) in pictures.modes.iter().zip(&layouts) {
            let shown_px_per_mm = f64::from(p.shown_px.0) / f64::from(l.size_px.0) * l.px_per_mm;
            assert!((shown_px_per_mm - pictures.modes_px_per_mm).abs() < 0.01, "{p:?}");
        }
        assert!(pictures.modes[1].shown_px.0 > pictures.modes[0].shown_px.0);
        // The page shows them at those sizes and states the scales.
        let page = comparison.html(&pictures);
        for p in pictures.reach.iter().chain(&pictures.modes) {
            assert!(page.contains(&format!("src=\"{}\" width=\"{}\" height=\"{}\"", p.file, p.shown_px.0, p.shown_px.1)), "{p:?}");
        }
        assert!(page.contains(&format!("same axes ({:.2} px per mm)", pictures.reach_px_per_mm)), "{page}");
    }

    #[test]
    fn bad_studies_name_the_problem() {
        let err = |t: &str| StudySpec::from_toml(t, "s.toml").unwrap_err().to_string();
        assert!(err("[grid]\nlevels = 3\n").contains("no [study] section"));
        assert!(err("[study]\n").contains("no [[study.axis]]"));
        assert!(err("[study]\n[[study.axis]]\nname = \"colour\"\nvalues = [1]\n").contains("unknown axis 'colour'"));
        assert!(err("[study]\n[[study.axis]]\nname = \"length_mm\"\nvalues = [1]\nscale = [2.0]\n").contains("not both"));
        assert!(err("[study]\n[[study.axis]]\nname = \"length_mm\"\nvalues = [\"a\"]\n").contains("not a number"));
        assert!(err("[study]\n[[study.axis]]\nname = \"ei_n_mm2\"\nscale = [-1.0]\n").contains("positive"));
        assert!(err("[study]\n[[study.axis]]\nname = \"tension_n\"\nvalues = [[1.0]]\n").contains("pair"));
        let e = err("[study]\n[[study.axis]]\nname = \"length_mm\"\nvalues = [65, -5]\n");
        assert!(e.contains("variant 1 (length_mm=-5)") && e.contains("length_mm"), "{e}");
        assert!(err("[grid]\nlevles = 3\n[study]\n[[study.axis]]\nname = \"length_mm\"\nvalues = [65]\n").contains("levles"));
    }
}
