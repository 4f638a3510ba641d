//! The map explorer: `index.html` (a self-contained page, `assets/explorer.html`)
//! and `explorer-data.js` beside it, which holds the map's numbers as one
//! JavaScript object (`window.CABLEMAP_MAP`). A `<script src>` beside the page
//! loads from `file://` with no server and no network, which a `fetch` of the
//! Parquet tables could not.
//!
//! The data are the tables' own numbers (cells, modes, designs, summary) plus
//! what the page shows that the tables lack: the actuator's parameters and the
//! representative shapes of the modes. Numbers keep 7 significant digits,
//! enough for every value a person reads off the page (the tables keep all).

use super::density::Density;
use crate::plot::Picture;
use super::{MapCables, MapData, ReduceError, MODES};
use crate::model::Rod;
use crate::plot::BodyDrawing;
use serde_json::{json, Value};
use std::path::Path;

/// The page (HTML, CSS and script in one file).
const PAGE: &str = include_str!("../../assets/explorer.html");

/// File name of the data beside the page.
pub const DATA_FILE: &str = "explorer-data.js";

/// A number rounded to 7 significant digits (shorter files); non-finite
/// values become null (open mode bounds).
fn num(v: f64) -> Value {
    if !v.is_finite() {
        return Value::Null;
    }
    let rounded: f64 = format!("{v:.6e}").parse().expect("a formatted f64 parses");
    json!(rounded)
}

fn nums(values: impl IntoIterator<Item = f64>) -> Value {
    Value::Array(values.into_iter().map(num).collect())
}

fn points(pts: &[(f64, f64)]) -> Value {
    Value::Array(pts.iter().map(|&(x, y)| json!([num(x), num(y)])).collect())
}

/// Every cable of a design of a several-cable map: `[{y, tension_n,
/// displacement_mm, anchor_mm}, …]` (a displacement-driven cable's command
/// is its `displacement_mm`, its `tension_n` null: it was found per row).
fn design_cables(cables: &MapCables, routing_id: i64) -> Value {
    let actuator = cables.actuator(routing_id);
    Value::Array(
        actuator.cables.iter().map(|c| json!({
            "y": nums(c.y_mm),
            "tension_n": if c.displacement_mm.is_some() { serde_json::Value::Null } else { num(c.tension_n) },
            "displacement_mm": c.displacement_mm,
            "anchor_mm": c.anchor_mm,
        })).collect(),
    )
}

/// The data object the page reads. A map of several cables (`cables`) adds
/// `cables` (their count, one sentence each, what the commands cannot
/// give) and, per design and mode representative, every cable's routing
/// and tension and the `cablemap simulate` command that solves it again.
fn data(
    map: &MapData,
    rod: &Rod,
    shapes: &[Option<BodyDrawing>],
    pictures: &[Picture],
    written_utc: &str,
    cables: Option<&MapCables>,
) -> Value {
    let c = &map.cells;
    let nk = c.first().map_or(0, |c| c.coefficients.len());
    let stats: Vec<Value> = (0..nk)
        .map(|k| {
            json!({
                "p10": nums(c.iter().map(|c| c.coefficients[k].p10)),
                "p90": nums(c.iter().map(|c| c.coefficients[k].p90)),
                "min": nums(c.iter().map(|c| c.coefficients[k].min)),
                "max": nums(c.iter().map(|c| c.coefficients[k].max)),
            })
        })
        .collect();
    let d = &map.designs;
    let modes: Vec<Value> = map
        .modes
        .iter()
        .map(|m| {
            let rep = m.representative.as_ref().zip(shapes.get(m.mode).and_then(Option::as_ref)).map(|(r, shape)| {
                let (left, right) = shape.outline();
                let mut rep = json!({
                    "routing_mm": nums(r.routing_mm.0),
                    "tension_n": num(r.tension_n),
                    "tip_x_mm": num(r.tip_x_mm),
                    "tip_y_mm": num(r.tip_y_mm),
                    "a": nums(r.a.iter().copied()),
                    "left": points(&left),
                    "right": points(&right),
                    "cable": points(&shape.cable),
                });
                // Several cables only: single-cable maps keep their data as it was.
                if !shape.further_cables.is_empty() {
                    rep["further_cables"] = shape.further_cables.iter().map(|c| points(c)).collect();
                }
                if let Some(cables) = cables {
                    rep["cables"] = design_cables(cables, r.routing_id);
                    rep["command"] = json!(cables.command(r.routing_id).text);
                }
                rep
            });
            json!({
                "mode": m.mode,
                "a0_lo": num(m.a0_bounds.0), "a0_hi": num(m.a0_bounds.1),
                "a1_lo": num(m.a1_bounds.0), "a1_hi": num(m.a1_bounds.1),
                "count": m.count,
                "cells": m.cells,
                "rep": rep,
            })
        })
        .collect();
    let mut value = json!({
        "summary": map.summary,
        "length_basis_description": map.summary.length_basis.describe(),
        "sparse_note": Density::sparse_note(&map.summary, &map.cells),
        "actuator": rod,
        "effects_in_use": effects_in_use(rod),
        "written_utc": written_utc,
        "pictures": pictures.iter().map(|p| json!({"file": p.file, "title": p.title, "explanation": p.explanation})).collect::<Vec<_>>(),
        "cells": {
            "ix": c.iter().map(|c| c.ix).collect::<Vec<_>>(),
            "iy": c.iter().map(|c| c.iy).collect::<Vec<_>>(),
            "count": c.iter().map(|c| c.count).collect::<Vec<_>>(),
            "stats": stats,
            "modes": c.iter().map(|c| c.modes.to_vec()).collect::<Vec<_>>(),
        },
        "designs": {
            "ix": d.iter().map(|d| d.ix).collect::<Vec<_>>(),
            "iy": d.iter().map(|d| d.iy).collect::<Vec<_>>(),
            "y": d.iter().map(|d| nums(d.routing_mm.0)).collect::<Vec<_>>(),
            "tension_n": nums(d.iter().map(|d| d.tension_n)),
            "tip_x_mm": nums(d.iter().map(|d| d.tip_x_mm)),
            "tip_y_mm": nums(d.iter().map(|d| d.tip_y_mm)),
            "a": d.iter().map(|d| nums(d.a.iter().copied())).collect::<Vec<_>>(),
        },
        "modes": modes,
        "mode_count": MODES,
    });
    if let Some(cables) = cables {
        // The rod and solver are the same for every design: what no flag
        // gives is said once.
        let missing = d.first().map(|d| cables.command(d.routing_id).missing).unwrap_or_default();
        value["cables"] = json!({ "count": cables.count(), "describe": cables.describe(), "command_missing": missing });
        value["designs"]["cables"] = d.iter().map(|d| design_cables(cables, d.routing_id)).collect();
        value["designs"]["command"] = d.iter().map(|d| json!(cables.command(d.routing_id).text)).collect();
    }
    value
}

/// The effects whose settings differ from the thesis model's (name, value).
fn effects_in_use(rod: &Rod) -> Vec<(String, Value)> {
    let used = serde_json::to_value(&rod.effects).expect("effects serialise");
    let default = serde_json::to_value(crate::model::Effects::default()).expect("effects serialise");
    let (Some(used), Some(default)) = (used.as_object(), default.as_object()) else { return Vec::new() };
    used.iter().filter(|(k, v)| default.get(*k) != Some(v)).map(|(k, v)| (k.clone(), v.clone())).collect()
}

/// Now as `YYYY-MM-DD HH:MM UTC` (civil date from days since the epoch,
/// H. Hinnant's algorithm: a dependency for one date would be overkill).
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs()) as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1_460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02} {:02}:{:02} UTC", rem / 3600, rem % 3600 / 60)
}

/// Writes `index.html` and `explorer-data.js` into `dir` (each atomically).
/// `shapes` are the modes' representative bodies (index = mode), `pictures`
/// the PNGs the page links to; `cables` those of a map of several cables.
pub fn write_explorer(
    dir: &Path,
    map: &MapData,
    rod: &Rod,
    shapes: &[Option<BodyDrawing>],
    pictures: &[Picture],
    cables: Option<&MapCables>,
) -> Result<(), ReduceError> {
    let write = |name: &str, bytes: &[u8]| super::tables::write_file(&dir.join(name), bytes);
    let value = data(map, rod, shapes, pictures, &utc_now(), cables);
    let script = format!("// Written by `cablemap reduce`: the map explorer's data (index.html).\nwindow.CABLEMAP_MAP = {value};\n");
    write(DATA_FILE, script.as_bytes())?;
    write("index.html", PAGE.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_keep_seven_significant_digits_and_infinities_become_null() {
        assert_eq!(num(0.012345678901), json!(0.01234568));
        assert_eq!(num(-123456.789), json!(-123456.8));
        assert_eq!(num(f64::INFINITY), Value::Null);
        assert_eq!(num(0.0), json!(0.0));
    }

    /// The page words its verdicts as `cablemap feasible` does: a target no
    /// map design reached is "not reached by any of the map's designs" (not
    /// UNREACHABLE: `design` may still meet it), with the CLI's hint and the
    /// next command, the target filled in.
    #[test]
    fn the_page_says_what_the_map_saw_and_what_to_run_next() {
        use crate::design::feasible::Verdict;
        for v in [Verdict::Feasible, Verdict::Borderline, Verdict::Unreachable] {
            assert!(PAGE.contains(&format!("{}: \"{}\"", v.as_str(), v.label())), "{} labelled as in Verdict::label", v.as_str());
        }
        assert!(!PAGE.contains("toUpperCase"), "no verdict in capitals");
        assert!(!PAGE.contains("lies outside everything"));
        assert!(PAGE.contains("so a design between its grid points may still reach it: `design` will tell"));
        assert!(PAGE.contains("`cablemap design --target ${parts.join(\",\")} --map ${mapDir()}`"));
        assert!(PAGE.contains(r#"<code id="verdict-next">${esc(r.next)}</code>"#));
    }

    #[test]
    fn utc_date_is_well_formed() {
        let d = utc_now();
        assert_eq!(d.len(), "2026-11-30 05:00 UTC".len(), "{d}");
        assert!(d.starts_with("20") && d.ends_with(" UTC"), "{d}");
    }
}
