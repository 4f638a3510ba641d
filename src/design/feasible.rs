//! The map's verdict on a target before any optimisation (thesis §4.2):
//! is the tip cell reachable, do the target coefficients lie within what
//! the sweep saw there, which characteristic mode the target falls in, and
//! which simulated designs are nearest.

use super::map::{Cell, MapDir, NearDesign, CELL_STATS_ORDER, MODES};
use super::target::{Component, Target, Weights};
use super::DesignError;
use crate::shape::LengthBasis;
use serde::Serialize;
use std::fmt;
use std::path::{Path, PathBuf};

/// The three verdicts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// The tip cell was reached and every checked coefficient lies within the
    /// cell's 10th–90th percentiles, in a mode the cell has seen.
    Feasible,
    /// Reached only at the edge: the tip cell is empty but a neighbour is
    /// not, or a coefficient lies outside the cell's percentiles but within
    /// the extremes of the cell and its 8 neighbours, or the target's mode
    /// was not seen in the tip cell.
    Borderline,
    /// Not reached by any of the map's designs: none put the tip in or next
    /// to the cell, or a coefficient lies outside the range its designs
    /// reached there. The map samples a grid of routings, so this does not
    /// prove the target unreachable: `design` may still meet it between the
    /// grid points (Table 5.1's Target I on the thesis map). Serialised
    /// `unreachable`, the key JSON outputs have always used.
    Unreachable,
}

impl Verdict {
    /// The machine-readable key: `feasible`, `borderline` or `unreachable`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Verdict::Feasible => "feasible",
            Verdict::Borderline => "borderline",
            Verdict::Unreachable => "unreachable",
        }
    }

    /// The verdict in words, for people: what the map saw, not more (the
    /// explorer page, `assets/explorer.html`, uses the same words).
    pub fn label(&self) -> &'static str {
        match self {
            Verdict::Feasible => "feasible",
            Verdict::Borderline => "borderline",
            Verdict::Unreachable => "not reached by any of the map's designs",
        }
    }
}

/// The cells a target's tip selects.
#[derive(Debug, Clone, Serialize)]
pub struct TipCell {
    /// Column (None when the target gives no x).
    pub ix: Option<i32>,
    /// Row (None when the target gives no y).
    pub iy: Option<i32>,
    /// Simulations in the selected cell(s).
    pub count: i64,
    /// Simulations in the selected cell(s) and their neighbours.
    pub neighbourhood_count: i64,
}

/// How one target coefficient compares with the map.
#[derive(Debug, Clone, Serialize)]
pub struct CoefficientCheck {
    /// `a0`, `a1`, ….
    pub component: String,
    /// Target value, 1/mm.
    pub target: f64,
    /// The tip cell's 10th and 90th percentiles (single tip cell only).
    pub cell_p10: Option<f64>,
    /// See `cell_p10`.
    pub cell_p90: Option<f64>,
    /// Smallest value seen in the cell(s) and their neighbours.
    pub neighbourhood_min: Option<f64>,
    /// Largest value seen in the cell(s) and their neighbours.
    pub neighbourhood_max: Option<f64>,
    /// Within the 10th–90th percentiles of some selected cell.
    pub within_percentiles: bool,
    /// Within the neighbourhood's extremes.
    pub within_extremes: bool,
}

/// The characteristic mode of the target (map's `mode_boundaries`).
#[derive(Debug, Clone, Serialize)]
pub struct ModeCheck {
    /// Mode index 3·i + j, when both a0 and a1 are given.
    pub mode: Option<usize>,
    /// The modes consistent with the given a0 / a1 (all 12 when neither is given).
    pub candidates: Vec<usize>,
    /// Simulations of the tip cell in each candidate mode (single tip cell only).
    pub count_in_cell: Option<i64>,
}

/// The full answer of `feasible`.
#[derive(Debug, Clone, Serialize)]
pub struct FeasibilityReport {
    /// The verdict.
    pub verdict: Verdict,
    /// Why, one sentence per finding.
    pub reasons: Vec<String>,
    /// The tip cell(s).
    pub tip_cell: TipCell,
    /// Per target coefficient the map has statistics for.
    pub coefficients: Vec<CoefficientCheck>,
    /// Target components the map cannot judge (coefficients above order 2 or the map's order).
    pub unchecked: Vec<String>,
    /// The target's characteristic mode.
    pub mode: ModeCheck,
    /// Nearest simulated designs (weighted distance), nearest first.
    pub nearest: Vec<NearDesign>,
    /// The length the coefficients (target, map, designs) are per unit of.
    pub length_basis: LengthBasis,
    /// A several-cable map's cables, so that each design lists every cable
    /// and the command that solves it again (`None`: one planar cable).
    #[serde(skip)]
    pub cables: Option<crate::reduce::MapCables>,
}

/// Judges `target` against `map`; `nearest` designs are listed. The
/// target's coefficients are per unit of `basis`; a map made in the other
/// basis is refused when the target has coefficients ([`MapDir::check_length_basis`]).
pub fn check(map: &MapDir, target: &Target, basis: LengthBasis, weights: &Weights, nearest: usize) -> Result<FeasibilityReport, DesignError> {
    map.check_length_basis(basis, target)?;
    let x = target.get(Component::TipX);
    let y = target.get(Component::TipY);
    let column = map.column_of(x);
    let row = map.row_of(y);
    let within = |c: &Cell, reach: i32| {
        column.is_none_or(|ix| (c.ix - ix).abs() <= reach) && row.is_none_or(|iy| (c.iy - iy).abs() <= reach)
    };
    let selected: Vec<&Cell> = map.cells.iter().filter(|c| within(c, 0) && c.count > 0).collect();
    let neighbourhood: Vec<&Cell> = map.cells.iter().filter(|c| within(c, 1) && c.count > 0).collect();
    let single = x.is_some() && y.is_some();
    let tip_cell = TipCell {
        ix: column,
        iy: row,
        count: selected.iter().map(|c| c.count).sum(),
        neighbourhood_count: neighbourhood.iter().map(|c| c.count).sum(),
    };
    let where_ = match (x, y) {
        (Some(x), Some(y)) => format!("tip cell ({}, {}) at x = {x} mm, y = {y} mm", column.unwrap(), row.unwrap()),
        (Some(x), None) => format!("cells at x = {x} mm"),
        (None, Some(y)) => format!("cells at y = {y} mm"),
        (None, None) => "any cell".to_string(),
    };
    let mut reasons = Vec::new();
    let stats_order = map.summary.order.min(CELL_STATS_ORDER);
    let mut unchecked = Vec::new();
    let mut checked: Vec<(usize, f64)> = Vec::new();
    for (c, v) in &target.components {
        if let Component::A(k) = c {
            if *k <= stats_order {
                checked.push((*k, *v));
            } else {
                unchecked.push(c.key());
            }
        }
    }
    if !unchecked.is_empty() {
        reasons.push(format!(
            "the map has statistics for a0…a{stats_order} only: {} not checked",
            unchecked.join(", ")
        ));
    }
    let in_percentiles = |c: &Cell, k: usize, v: f64| c.coefficients[k].p10 <= v && v <= c.coefficients[k].p90;
    let coefficients: Vec<CoefficientCheck> = checked
        .iter()
        .map(|&(k, v)| {
            let lo = neighbourhood.iter().map(|c| c.coefficients[k].min).fold(f64::INFINITY, f64::min);
            let hi = neighbourhood.iter().map(|c| c.coefficients[k].max).fold(f64::NEG_INFINITY, f64::max);
            let cell = if single { selected.first().map(|c| c.coefficients[k]) } else { None };
            CoefficientCheck {
                component: format!("a{k}"),
                target: v,
                cell_p10: cell.map(|s| s.p10),
                cell_p90: cell.map(|s| s.p90),
                neighbourhood_min: lo.is_finite().then_some(lo),
                neighbourhood_max: hi.is_finite().then_some(hi),
                within_percentiles: selected.iter().any(|c| in_percentiles(c, k, v)),
                within_extremes: lo <= v && v <= hi,
            }
        })
        .collect();
    // Jointly within percentiles in one selected cell (not just each in some cell).
    let joint = selected.iter().any(|c| checked.iter().all(|&(k, v)| in_percentiles(c, k, v)));
    let mode = mode_check(map, target, if single { selected.first().copied() } else { None });

    let verdict = if tip_cell.neighbourhood_count == 0 {
        reasons.insert(0, format!("no simulation of the map put the tip in or next to the {where_}: outside the area the map's designs reach"));
        Verdict::Unreachable
    } else if let Some(out) = coefficients.iter().find(|c| !c.within_extremes) {
        reasons.insert(
            0,
            format!(
                "{} = {} is outside the range the map's designs reached in and around the {where_} ([{:.5}, {:.5}]); \
                 the map samples a grid of designs, so a design between its grid points may still reach it: `design` will tell",
                out.component,
                out.target,
                out.neighbourhood_min.unwrap_or(f64::NAN),
                out.neighbourhood_max.unwrap_or(f64::NAN)
            ),
        );
        Verdict::Unreachable
    } else {
        let mut edge = Vec::new();
        if tip_cell.count == 0 {
            edge.push(format!("the {where_} was never reached, but a neighbouring cell was (edge of the reach)"));
        }
        for c in coefficients.iter().filter(|c| !c.within_percentiles) {
            edge.push(format!(
                "{} = {} is outside the 10th–90th percentiles of the {where_} but within the extremes of it and its neighbours",
                c.component, c.target
            ));
        }
        if edge.is_empty() && !joint {
            edge.push(format!("each coefficient is within some cell's percentiles, but no single cell of the {where_} holds all of them"));
        }
        if let (Some(m), Some(0)) = (mode.mode, mode.count_in_cell) {
            edge.push(format!("the target's mode {m} was never seen in the tip cell (its percentile range spans other modes)"));
        }
        if edge.is_empty() {
            reasons.insert(0, format!("the {where_} was reached {} times and every checked coefficient lies within its 10th–90th percentiles", tip_cell.count));
            Verdict::Feasible
        } else {
            reasons.splice(0..0, edge);
            Verdict::Borderline
        }
    };
    let length = map.summary.length_mm;
    if x.is_some_and(|x| x.abs() > length) {
        reasons.push(format!("the rod is {length} mm long: no tip lies {} mm from the clamp along its axis", x.unwrap_or(0.0)));
    }
    Ok(FeasibilityReport {
        verdict,
        reasons,
        tip_cell,
        coefficients,
        unchecked,
        mode,
        nearest: map.nearest_designs(target, weights, nearest)?,
        length_basis: map.summary.length_basis,
        cables: crate::reduce::MapCables::open(&map.path)
            .map_err(|e| DesignError::Map { path: map.path.display().to_string(), message: e.to_string() })?,
    })
}

fn mode_check(map: &MapDir, target: &Target, cell: Option<&Cell>) -> ModeCheck {
    let b = &map.summary.mode_boundaries;
    // The reducer's ranges() takes both coefficients; a missing one gets a
    // placeholder whose range is then ignored.
    let i = target.get(Component::A(0)).map(|a0| b.ranges(a0, 0.0).0);
    let j = target.get(Component::A(1)).map(|a1| b.ranges(0.0, a1).1);
    let candidates: Vec<usize> =
        (0..MODES).filter(|m| i.is_none_or(|i| m / 3 == i) && j.is_none_or(|j| m % 3 == j)).collect();
    let mode = match (i, j) {
        (Some(i), Some(j)) => Some(3 * i + j),
        _ => None,
    };
    let count_in_cell = cell.map(|c| candidates.iter().map(|&m| c.modes[m]).sum());
    ModeCheck { mode, candidates, count_in_cell }
}

/// What `feasible` judges the target against.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MapSource {
    /// One feasibility map directory (`cablemap reduce` output).
    Map(PathBuf),
    /// A study directory (`cablemap study` output): every variant's map.
    Study(PathBuf),
}

/// Everything a feasibility check needs.
#[derive(Debug, Clone)]
pub struct FeasibleRequest {
    /// The map, or the study's maps.
    pub source: MapSource,
    /// The target.
    pub target: Target,
    /// Weights of the distance to the nearest designs (checked against the target here).
    pub weights: Weights,
    /// The length the target's coefficients are per unit of.
    pub length_basis: LengthBasis,
    /// Nearest simulated designs to list.
    pub nearest: usize,
}

/// One study variant's verdict.
#[derive(Debug, Clone)]
pub struct VariantVerdict {
    /// Variant number.
    pub index: usize,
    /// Its settings, `axis=value, …`.
    pub label: String,
    /// Its map's verdict.
    pub report: FeasibilityReport,
}

/// The answer of `feasible`.
#[derive(Debug, Clone)]
pub enum FeasibleReport {
    /// One map's verdict.
    Map {
        /// The verdict and its evidence.
        report: FeasibilityReport,
        /// The command that designs for the target with the map's designs as seeds.
        next: String,
    },
    /// Every variant's verdict of a study.
    Study {
        /// The study directory.
        dir: PathBuf,
        /// One verdict per variant.
        variants: Vec<VariantVerdict>,
    },
}

impl FeasibleReport {
    /// The variants of a study whose maps reach the target feasibly (`v0`, …).
    pub fn feasible_variants(&self) -> Vec<String> {
        match self {
            FeasibleReport::Map { .. } => Vec::new(),
            FeasibleReport::Study { variants, .. } => {
                variants.iter().filter(|v| v.report.verdict == Verdict::Feasible).map(|v| format!("v{}", v.index)).collect()
            }
        }
    }
}

impl Serialize for FeasibleReport {
    /// The JSON `feasible --json` prints.
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            FeasibleReport::Map { report, .. } => report.serialize(serializer),
            FeasibleReport::Study { dir, variants } => {
                let rows: Vec<_> = variants
                    .iter()
                    .map(|v| serde_json::json!({ "variant": v.index, "label": v.label, "verdict": v.report.verdict, "report": v.report }))
                    .collect();
                serde_json::json!({ "study": dir, "feasible_variants": self.feasible_variants(), "variants": rows }).serialize(serializer)
            }
        }
    }
}

impl fmt::Display for FeasibleReport {
    /// The text `feasible` prints.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FeasibleReport::Map { report, next } => {
                write!(f, "{report}")?;
                writeln!(f, "next      {next}")
            }
            FeasibleReport::Study { variants, .. } => {
                for v in variants {
                    let first = v.report.reasons.first().map_or(String::new(), |s| format!(": {s}"));
                    writeln!(f, "v{:<3} {}: {}{first}", v.index, v.label, v.report.verdict.label())?;
                }
                let reach = self.feasible_variants();
                if reach.is_empty() {
                    writeln!(f, "no variant reaches the target feasibly (see the borderline ones, or widen the study)")
                } else {
                    writeln!(f, "reach the target: {} of {} variants ({})", reach.len(), variants.len(), reach.join(", "))
                }
            }
        }
    }
}

impl fmt::Display for FeasibilityReport {
    /// The verdict, its reasons, the tip cell, the coefficients, the mode and the nearest designs.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let r = self;
        writeln!(f, "verdict   {}", r.verdict.label())?;
        for reason in &r.reasons {
            writeln!(f, "          - {reason}")?;
        }
        let t = &r.tip_cell;
        let idx = |v: Option<i32>| v.map_or("any".to_string(), |v| v.to_string());
        writeln!(f, "tip cell  ix = {}, iy = {}: {} simulation(s) ({} with its neighbours)", idx(t.ix), idx(t.iy), t.count, t.neighbourhood_count)?;
        if !r.coefficients.is_empty() {
            writeln!(f, "basis     a_i in 1/mm, {} (the map's basis)", r.length_basis.describe())?;
            writeln!(f, "{:<6}{:>12}{:>12}{:>12}{:>12}{:>12}", "", "target", "cell p10", "cell p90", "near min", "near max")?;
            let v = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.5}"));
            for c in &r.coefficients {
                writeln!(
                    f,
                    "{:<6}{:>12.5}{:>12}{:>12}{:>12}{:>12}",
                    c.component,
                    c.target,
                    v(c.cell_p10),
                    v(c.cell_p90),
                    v(c.neighbourhood_min),
                    v(c.neighbourhood_max)
                )?;
            }
        }
        let m = &r.mode;
        match (m.mode, m.count_in_cell) {
            (Some(mode), Some(n)) => writeln!(f, "mode      {mode} (a0 range {}, a1 range {}); {n} simulations of the tip cell in it", mode / 3, mode % 3)?,
            (Some(mode), None) => writeln!(f, "mode      {mode} (a0 range {}, a1 range {})", mode / 3, mode % 3)?,
            (None, _) => writeln!(f, "mode      one of {:?} (give a0 and a1 to pin it down)", m.candidates)?,
        }
        writeln!(f, "nearest simulated designs (weighted distance):")?;
        for near in &r.nearest {
            let d = &near.design;
            writeln!(
                f,
                "  {} → tip ({:.2}, {:.2}) mm, a = [{}]  (distance {:.4})",
                crate::reduce::design_actuation(r.cables.as_ref(), d.routing_id, &d.routing_mm, d.tension_n),
                d.tip_x_mm,
                d.tip_y_mm,
                d.a.iter().map(|v| format!("{v:.4}")).collect::<Vec<_>>().join(", "),
                near.distance
            )?;
            if let Some(cables) = &r.cables {
                writeln!(f, "    {}", cables.command(d.routing_id).text)?;
            }
        }
        Ok(())
    }
}

/// The command that designs for `target` with `map_dir`'s designs as seeds,
/// ready to paste: `cablemap design --target x=…,a0=… --map MAP_DIR`.
pub fn design_command(target: &Target, map_dir: &Path) -> String {
    let components: Vec<String> = target.components.iter().map(|(c, v)| format!("{}={v}", c.key())).collect();
    format!("cablemap design --target {} --map {}", components.join(","), shell_word(&map_dir.display().to_string()))
}

/// `text` as one shell word: as it is when it holds only characters no shell
/// treats specially, else in single quotes.
fn shell_word(text: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "-_./,:=+@%".contains(c);
    if !text.is_empty() && text.chars().all(plain) {
        text.to_string()
    } else {
        format!("'{}'", text.replace('\'', r"'\''"))
    }
}

/// Runs `feasible`: the map's verdict on the target, or every study variant's.
pub fn run(request: &FeasibleRequest) -> Result<FeasibleReport, DesignError> {
    let FeasibleRequest { source, target, weights, length_basis, nearest } = request;
    weights.check_against(target)?;
    match source {
        MapSource::Map(dir) => {
            let map = MapDir::open(dir)?;
            let report = check(&map, target, *length_basis, weights, *nearest)?;
            Ok(FeasibleReport::Map { report, next: design_command(target, dir) })
        }
        MapSource::Study(dir) => {
            let mut variants = Vec::new();
            for (index, label, map_dir) in crate::study::mapped_variants(dir).map_err(Box::new)? {
                let map = MapDir::open(&map_dir).map_err(|e| DesignError::Variant { index, label: label.clone(), source: Box::new(e) })?;
                let report = check(&map, target, *length_basis, weights, *nearest)?;
                variants.push(VariantVerdict { index, label, report });
            }
            Ok(FeasibleReport::Study { dir: dir.clone(), variants })
        }
    }
}
