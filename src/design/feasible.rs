//! The map's verdict on a target before any optimisation (thesis §4.2):
//! is the tip cell reachable, do the target coefficients lie within what
//! the sweep saw there, which characteristic mode the target falls in, and
//! which simulated designs are nearest.

use super::map::{map_error, Cell, MapDesign, MapDir, MapMismatch, CELL_STATS_ORDER, MODES};
use super::search::routing::Design;
use super::search::SeedSource;
use super::target::{target_key, Target, Weights};
use super::targets::Quantity;
use super::DesignError;
use crate::model::Cable;
use crate::shape::LengthBasis;
use serde::Serialize;
use std::fmt;
use std::path::Path;

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
    /// Not judged: the target asks for too little of what the map holds
    /// (a cable sweep's reach: fewer than two tip components).
    Unchecked,
}

impl Verdict {
    /// The machine-readable key: `feasible`, `borderline` or `unreachable`.
    pub fn as_str(&self) -> &'static str {
        match self {
            Verdict::Feasible => "feasible",
            Verdict::Borderline => "borderline",
            Verdict::Unreachable => "unreachable",
            Verdict::Unchecked => "unchecked",
        }
    }

    /// The reach tables' word for a tip (`reached`, `borderline`,
    /// `not_reached`, `unchecked`): what a tip verdict has always been called.
    pub fn reach_word(&self) -> &'static str {
        match self {
            Verdict::Feasible => "reached",
            Verdict::Borderline => "borderline",
            Verdict::Unreachable => "not_reached",
            Verdict::Unchecked => "unchecked",
        }
    }

    /// The verdict in words, for people: what the map saw, not more (the
    /// explorer page, `assets/explorer.html`, uses the same words).
    pub fn label(&self) -> &'static str {
        match self {
            Verdict::Feasible => "feasible",
            Verdict::Borderline => "borderline",
            Verdict::Unreachable => "not reached by any of the map's designs",
            Verdict::Unchecked => "unchecked",
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

/// A design of the map with its weighted distance to a target.
#[derive(Debug, Clone, PartialEq)]
pub struct NearDesign {
    /// The design (on a map of several cables: cable 1's routing and tension).
    pub design: MapDesign,
    /// √(Σ λ_j (c_j − t_j)²) over the target's components the map stores.
    pub distance: f64,
    /// On a map of several cables, the design's actuation; `None` on a map
    /// of one planar cable, whose routing and tension are `design`'s.
    pub cables: Option<DesignCables>,
}

/// Every cable of a design of a several-cable map, and the command that
/// solves it again.
#[derive(Debug, Clone, PartialEq)]
pub struct DesignCables {
    /// Each cable: its channel, tension and anchor (the actuator file's form).
    pub cables: Vec<Cable>,
    /// The `cablemap simulate` command that solves the design again.
    pub command: String,
}

impl NearDesign {
    /// As a starting design for the optimiser (a one-cable design's).
    pub fn seed(&self) -> Design {
        Design { routing_mm: self.design.routing_mm, tension_n: self.design.tension_n, source: SeedSource::Map }
    }
}

/// JSON with the names `design` uses (`routing_mm`, `tension_n`, `tip_x_mm`,
/// …); a design of a several-cable map adds `cables` (every cable, as in an
/// actuator file) and `command` (the `cablemap simulate` command).
impl Serialize for NearDesign {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let d = &self.design;
        let mut value = serde_json::json!({
            "routing_mm": d.routing_mm,
            "tension_n": d.tension_n,
            "tip_x_mm": d.tip_x_mm,
            "tip_y_mm": d.tip_y_mm,
            "tip_angle_rad": d.tip_angle_rad,
            "a": d.a,
            "ix": d.ix,
            "iy": d.iy,
            "routing_id": d.routing_id,
            "mirrored": d.mirrored,
            "distance": self.distance,
        });
        if let Some(c) = &self.cables {
            value["cables"] = serde_json::to_value(&c.cables).map_err(serde::ser::Error::custom)?;
            value["command"] = serde_json::json!(c.command);
        }
        value.serialize(s)
    }
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
    /// A several-cable map's cables, so that each design's line lists every
    /// cable (`None`: one planar cable).
    #[serde(skip)]
    pub cables: Option<crate::reduce::MapCables>,
}

/// Judges `target` against `map`; `nearest` designs are listed. The
/// target's coefficients are per unit of `basis`; a map made in the other
/// basis is refused when the target has coefficients (no exact conversion exists).
pub fn check(map: &MapDir, target: &Target, basis: LengthBasis, weights: &Weights, nearest: usize) -> Result<FeasibilityReport, DesignError> {
    check_length_basis(map, basis, target)?;
    let x = target.get(Quantity::TipX);
    let y = target.get(Quantity::TipY);
    let column = x.map(|x| cell_index(x, map.summary.x_min_mm, map.summary.cell_mm));
    let row = y.map(|y| cell_index(y, map.summary.y_min_mm, map.summary.cell_mm));
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
        if let Quantity::BendZ(k) = c {
            if *k <= stats_order {
                checked.push((*k, *v));
            } else {
                unchecked.push(target_key(*c));
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
        nearest: nearest_designs(map, target, weights, nearest),
        length_basis: map.summary.length_basis,
        cables: map.cables.clone(),
    })
}

/// Refuses a target whose coefficients are in another basis than the
/// map's. There is no exact conversion: a_i change by ℓ/L, and ℓ differs
/// from design to design within a cell, so percentiles do not convert.
/// A target without coefficients is judged in either basis.
fn check_length_basis(map: &MapDir, basis: LengthBasis, target: &Target) -> Result<(), DesignError> {
    let map_basis = map.summary.length_basis;
    if map_basis == basis || target.highest_order().is_none() {
        return Ok(());
    }
    Err(map_error(&map.path, MapMismatch::LengthBasis { map: map_basis, target: basis }))
}

/// The index of the cell containing coordinate `v` along an axis whose
/// cells of `cell_mm` start at `min_mm`. A coordinate far off the map gives
/// an index far off the grid: clamped to ±2³⁰, far outside every map (cells
/// lie in 0..[`crate::reduce::MAX_CELLS_PER_AXIS`]) and small enough that
/// index differences cannot overflow, never wrapped onto it.
fn cell_index(v: f64, min_mm: f64, cell_mm: f64) -> i32 {
    const FAR: i64 = 1 << 30;
    (((v - min_mm) / cell_mm).floor() as i64).clamp(-FAR, FAR) as i32
}

/// The value of `component` in a map design (None for an order the map does not store).
fn design_value(d: &MapDesign, component: Quantity) -> Option<f64> {
    match component {
        Quantity::TipX => Some(d.tip_x_mm),
        Quantity::TipY => Some(d.tip_y_mm),
        Quantity::BendZ(k) => d.a.get(k).copied(),
        _ => None,
    }
}

/// The `count` designs of the map nearest to `target` by the weighted
/// distance √(Σ λ_j (c_j − t_j)²) over the target components the map
/// stores (coefficients above the map's order are ignored); on a map of
/// several cables, each with every cable and its command.
fn nearest_designs(map: &MapDir, target: &Target, weights: &Weights, count: usize) -> Vec<NearDesign> {
    let distance = |d: &MapDesign| {
        target
            .components
            .iter()
            .filter_map(|(c, t)| design_value(d, *c).map(|v| weights.get(*c) * (v - t).powi(2)))
            .sum::<f64>()
            .sqrt()
    };
    let mut near: Vec<(f64, &MapDesign)> = map.designs.iter().map(|d| (distance(d), d)).collect();
    near.sort_by(|p, q| p.0.total_cmp(&q.0));
    near.truncate(count);
    near.into_iter()
        .map(|(distance, d)| NearDesign {
            design: d.clone(),
            distance,
            cables: map.cables.as_ref().map(|c| DesignCables {
                cables: c.actuator(d.routing_id).cables,
                command: c.command(d.routing_id).text,
            }),
        })
        .collect()
}

fn mode_check(map: &MapDir, target: &Target, cell: Option<&Cell>) -> ModeCheck {
    let b = &map.summary.mode_boundaries;
    // The reducer's ranges() takes both coefficients; a missing one gets a
    // placeholder whose range is then ignored.
    let i = target.get(Quantity::BendZ(0)).map(|a0| b.ranges(a0, 0.0).0);
    let j = target.get(Quantity::BendZ(1)).map(|a1| b.ranges(0.0, a1).1);
    let candidates: Vec<usize> =
        (0..MODES).filter(|m| i.is_none_or(|i| m / 3 == i) && j.is_none_or(|j| m % 3 == j)).collect();
    let mode = match (i, j) {
        (Some(i), Some(j)) => Some(3 * i + j),
        _ => None,
    };
    let count_in_cell = cell.map(|c| candidates.iter().map(|&m| c.modes[m]).sum());
    ModeCheck { mode, candidates, count_in_cell }
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
            if let Some(cables) = &near.cables {
                writeln!(f, "    {}", cables.command)?;
            }
        }
        Ok(())
    }
}

/// The command that designs for `target` with `map_dir`'s designs as seeds,
/// ready to paste: `cablemap design --target x=…,a0=… --map MAP_DIR`.
pub fn design_command(target: &Target, map_dir: &Path) -> String {
    let components: Vec<String> = target.components.iter().map(|(c, v)| format!("{}={v}", target_key(*c))).collect();
    format!("cablemap design --target {} --map {}", components.join(","), shell_word(&map_dir.display().to_string()))
}

/// `text` as one shell word: as it is when it holds only characters no shell
/// treats specially, else in single quotes.
pub(crate) fn shell_word(text: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "-_./,:=+@%".contains(c);
    if !text.is_empty() && text.chars().all(plain) {
        text.to_string()
    } else {
        format!("'{}'", text.replace('\'', r"'\''"))
    }
}

