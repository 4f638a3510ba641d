//! Writing a map directory: its tables (`tables`), pictures and explorer
//! page, put in place as a whole; a cable sweep's map with its reach tables
//! and picture and, for a planar run, its feasibility map.

use super::drawings::ModeDrawings;
use crate::plot::{draw_heatmap, draw_modes, Picture, Scale};
use super::reach::{Reach, PLANES};
use super::tables::PLANAR_MAP_DIR;
use super::{explorer, tables, ReachMapSummary, CoefficientStats, MapCables, MapData, ReduceError, COEFFICIENT_UNIT};
use crate::model::Rod;
use crate::plot::{draw_reach_maps, ReachPlane};
use std::path::Path;

/// The picture of a cable sweep's reach: the three planes side by side.
pub const REACH_PICTURE: &str = "reach.png";

/// Writes the map directory `dir` as a whole: everything is written into a
/// staging directory beside it (`.NAME.tmp-TOKEN`), which then replaces
/// `dir` by rename, so a reader sees the old map or the new one, never a
/// mix (an interrupted reduce leaves the old map untouched). `dir` must be
/// new, empty, or an earlier map (its summary.json names the map format);
/// it must not be, or lie inside, a sweep run directory.
pub fn write_map_replacing(
    dir: &Path,
    map: &MapData,
    rod: &crate::model::Rod,
    solver: &crate::solver::SolverOptions,
) -> Result<Vec<Picture>, ReduceError> {
    write_dir_replacing(dir, |staging| write_map(staging, map, rod, solver))
}

/// Writes the map directory `dir` as a whole by `write` (given the staging
/// directory to fill), with [`write_map_replacing`]'s guarantees: a reader
/// sees the old directory or the new one, never a mix.
pub fn write_dir_replacing<T>(dir: &Path, write: impl FnOnce(&Path) -> Result<T, ReduceError>) -> Result<T, ReduceError> {
    let name = check_map_out(dir)?;
    crate::io::write_dir_replacing(dir, &name, write, |step, path, source| match step {
        crate::io::DirStep::Create => ReduceError::CreateDir { path, source },
        crate::io::DirStep::Replace => ReduceError::Replace { path, source },
    })
}

/// Checks that `dir` can take a map (see [`write_map_replacing`]) before
/// any work is done; returns its file name.
pub fn check_map_out(dir: &Path) -> Result<String, ReduceError> {
    crate::io::check_outside_run_dir(dir, "the map directory").map_err(ReduceError::MapInRun)?;
    let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).filter(|n| n != "." && n != "..");
    let Some(name) = name else {
        return Err(ReduceError::MapDirUnnamed { path: dir.to_path_buf() });
    };
    match std::fs::read_dir(dir) {
        Ok(mut entries) => {
            if entries.next().is_some() && !is_map_dir(dir) {
                return Err(ReduceError::NotAMap { path: dir.to_path_buf() });
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(source) => return Err(ReduceError::MapDirUnreadable { path: dir.to_path_buf(), source }),
    }
    Ok(name)
}

/// Whether `dir` holds a map written by cablemap: its summary.json names
/// the map format ([`tables::MAP_FORMAT`]). File names alone prove nothing
/// (any folder may hold a `summary.json`), and replacing a map deletes
/// everything in it.
fn is_map_dir(dir: &Path) -> bool {
    let path = dir.join(tables::SUMMARY_FILE);
    // A summary is a few kB; a huge file is not one (and is not read whole).
    if !std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_file() && m.len() < 1 << 20) {
        return false;
    }
    let Some(summary) = std::fs::read(&path).ok().and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok()) else {
        return false;
    };
    if summary["format"].as_str().is_some_and(|f| f.starts_with(tables::MAP_FORMAT_PREFIX)) {
        return true;
    }
    // Maps written before the marker existed: replaced only when the summary
    // reads as a map summary and the folder holds nothing but the kinds of
    // file a map consists of, so a user's own files are never deleted.
    let legacy_summary = summary.get("format").is_none()
        && (serde_json::from_value::<super::MapSummary>(summary.clone()).is_ok()
            || serde_json::from_value::<ReachMapSummary>(summary).is_ok());
    legacy_summary && holds_only_map_files(dir, 0)
}

/// Whether every entry below `dir` is a regular file of a kind maps are
/// made of (tables, pictures, the page, summaries), in at most one level of
/// sub-folders (a cable map's `planar/`).
fn holds_only_map_files(dir: &Path, depth: usize) -> bool {
    const MAP_FILE_ENDINGS: [&str; 6] = [".parquet", ".png", ".json", ".html", ".csv", ".js"];
    let Ok(entries) = std::fs::read_dir(dir) else { return false };
    entries.into_iter().all(|entry| {
        let Ok(entry) = entry else { return false };
        let Ok(kind) = entry.file_type() else { return false };
        let name = entry.file_name().to_string_lossy().into_owned();
        if kind.is_dir() {
            depth == 0 && holds_only_map_files(&entry.path(), depth + 1)
        } else {
            kind.is_file() && MAP_FILE_ENDINGS.iter().any(|e| name.ends_with(e))
        }
    })
}

/// Writes the whole map directory: tables, pictures and index.html.
/// `rod` and `solver` re-simulate the mode representatives for drawing
/// ([`ModeDrawings`]). Writes in place; [`write_map_replacing`] is what the
/// commands use.
pub fn write_map(
    dir: &Path,
    map: &MapData,
    rod: &crate::model::Rod,
    solver: &crate::solver::SolverOptions,
) -> Result<Vec<Picture>, ReduceError> {
    write_map_drawn(dir, map, rod, &ModeDrawings::of_map(map, rod, solver), None)
}

/// [`write_map`] with the mode representatives' bodies already drawn (a
/// cable sweep draws them with the solver of several cables). A map of
/// several cables (`cables`) also gets their spec ([`MapCables`]), and its
/// captions, page and designs show every cable.
pub fn write_map_drawn(
    dir: &Path,
    map: &MapData,
    rod: &crate::model::Rod,
    drawings: &ModeDrawings,
    cables: Option<&MapCables>,
) -> Result<Vec<Picture>, ReduceError> {
    std::fs::create_dir_all(dir).map_err(|source| ReduceError::CreateDir { path: dir.to_path_buf(), source })?;
    tables::write_tables(dir, map)?;
    if let Some(cables) = cables {
        cables.write(dir)?;
    }
    let mut pictures = coefficient_pictures(dir, map)?;
    draw_modes(&dir.join("modes.png"), map, &drawings.shapes, cables)?;
    pictures.push(Picture {
        file: "modes.png".into(),
        title: "Characteristic modes (thesis Fig. 4.4)".into(),
        explanation: format!(
            "a0 split into 4 ranges (rows) and a1 into 3 (columns), a_i {}; each panel maps where that combination occurs and draws the simulation nearest the mode's median coefficients.{}",
            map.summary.length_basis.describe(),
            drawings.failure_note()
        ),
    });
    explorer::write_explorer(dir, map, rod, &drawings.shapes, &pictures, cables)?;
    Ok(pictures)
}

/// Writes a cable sweep's map directory `dir` as a whole (with
/// [`write_map_replacing`]'s guarantees): the reach tables and picture,
/// summary.json and, for a planar run (`planar`: its map, its modes drawn
/// with all their cables, the cables), its feasibility map in
/// [`PLANAR_MAP_DIR`]. Returns the planar map and its pictures.
pub(crate) fn write_cable_map(
    dir: &Path,
    summary: &ReachMapSummary,
    reach: &Reach,
    planar: Option<(MapData, ModeDrawings, MapCables)>,
    rod: &Rod,
) -> Result<Option<(MapData, Vec<Picture>)>, ReduceError> {
    write_dir_replacing(dir, |dir| {
        tables::write_reach(dir, reach)?;
        draw_reach(&dir.join(REACH_PICTURE), reach)?;
        tables::write_cable_summary(dir, summary)?;
        planar
            .map(|(map, drawings, cables)| {
                let pictures = write_map_drawn(&dir.join(PLANAR_MAP_DIR), &map, rod, &drawings, Some(&cables))?;
                Ok((map, pictures))
            })
            .transpose()
    })
}

/// Draws the three reach planes side by side: x down the page, the other
/// coordinate across; y–z with y across and z down.
fn draw_reach(path: &Path, reach: &Reach) -> Result<(), ReduceError> {
    let planes: Vec<ReachPlane> = PLANES
        .iter()
        .zip(&reach.planes)
        .map(|((_, names), counts)| {
            if names[0] == "x" {
                ReachPlane { axes: (names[1], "x"), cells: counts.iter().map(|(c, &n)| (c[1], c[0], n)).collect() }
            } else {
                ReachPlane { axes: (names[0], names[1]), cells: counts.iter().map(|(c, &n)| (c[0], c[1], n)).collect() }
            }
        })
        .collect();
    let title = format!("reach: {} solutions, cells of {} mm", reach.tips, reach.cell_mm);
    Ok(draw_reach_maps(path, &title, &planes, reach.cell_mm)?)
}

/// Draws reach.png and the per-cell pictures of each coefficient.
fn coefficient_pictures(dir: &Path, map: &MapData) -> Result<Vec<Picture>, ReduceError> {
    let s = &map.summary;
    let mut pictures = Vec::new();
    let reach: Vec<(i32, i32, f64)> = map.cells.iter().map(|c| (c.ix, c.iy, c.count as f64)).collect();
    draw_heatmap(&dir.join("reach.png"), s, "Reachable tip positions: simulations per cell", "simulations per cell (log scale)", &reach, Scale::Log)?;
    pictures.push(Picture {
        file: "reach.png".into(),
        title: "Reach (thesis Fig. 4.1)".into(),
        explanation: format!(
            "Every {} mm cell that some routing and tension puts the tip in; the colour counts the simulations, so dark cells are reached by few configurations.",
            s.cell_mm
        ),
    });
    let nk = map.cells.first().map_or(0, |c| c.coefficients.len());
    for k in 0..nk {
        let stats = |f: &dyn Fn(&CoefficientStats) -> f64| -> Vec<(i32, i32, f64)> {
            map.cells.iter().map(|c| (c.ix, c.iy, f(&c.coefficients[k]))).collect()
        };
        let unit = format!("a{k} ({COEFFICIENT_UNIT}, {} basis)", s.length_basis);
        for (name, what, values, scale) in [
            ("p10", "10th percentile", stats(&|c| c.p10), Scale::Symmetric),
            ("p90", "90th percentile", stats(&|c| c.p90), Scale::Symmetric),
            ("gap", "90th − 10th percentile", stats(&|c| c.p90 - c.p10), Scale::Linear),
        ] {
            let file = format!("a{k}_{name}.png");
            let title = format!("a{k}: {what} per cell");
            draw_heatmap(&dir.join(&file), s, &title, &unit, &values, scale)?;
            // Thesis Fig. 4.2 shows a0, Fig. 4.3 a1; the thesis has no a2 map.
            let figure = match k {
                0 => " (as thesis Fig. 4.2)",
                1 => " (as thesis Fig. 4.3)",
                _ => "",
            };
            let basis = s.length_basis.describe();
            let explanation = match name {
                "gap" => format!("Spread of a{k} ({COEFFICIENT_UNIT}, {basis}) among the configurations reaching each cell: a large gap means more than one mode of deformation reaches it{figure}."),
                _ => format!("The {what} of a{k} ({COEFFICIENT_UNIT}, {basis}) over the simulations whose tip falls in each cell{figure}."),
            };
            pictures.push(Picture { file, title, explanation });
        }
    }
    Ok(pictures)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reduce::{reduce_batches, MapBody, ReduceOptions, RunInfo};
    use crate::shape::LengthBasis;
    use arrow::record_batch::RecordBatch;
    use crate::model::{Rod, Routing};
    use crate::solver::{Simulator, SolverOptions};
    use arrow::array::{ArrayRef, Float64Array, Int64Array, StringArray};
    use arrow::datatypes::{DataType, Field, Schema};
    use std::sync::Arc;

    /// A small real run: 3 levels per control point, 4 tensions, as one batch.
    fn small_run() -> RecordBatch {
        let actuator = Rod::default();
        let mut sim = Simulator::for_rod(&actuator, &SolverOptions::default()).unwrap();
        let (mut ids, mut status, mut ys, mut t, mut out) = (vec![], vec![], vec![[0.0; 5]; 0], vec![], vec![]);
        for id in 0..243i64 {
            let mut k = id;
            let y: [f64; 5] = std::array::from_fn(|_| {
                let level = (k % 3) as f64 - 1.0;
                k /= 3;
                level * 3.0
            });
            sim.set_routing(&Routing::new(&y, 65.0, 5.0).unwrap());
            for tension in [1.0, 1.3, 1.6, 2.0] {
                let pose = sim.solve(tension).unwrap();
                let mut a = [0.0; 3];
                sim.coefficients_into(crate::shape::LengthBasis::default(), &mut a);
                ids.push(id);
                status.push("ok");
                ys.push(y);
                t.push(tension);
                out.push([pose.tip_x_mm, pose.tip_y_mm, pose.tip_angle_rad, a[0], a[1], a[2]]);
            }
        }
        let mut fields = vec![Field::new("routing_id", DataType::Int64, false), Field::new("status", DataType::Utf8, false)];
        let mut cols: Vec<ArrayRef> = vec![Arc::new(Int64Array::from(ids)), Arc::new(StringArray::from(status))];
        for k in 0..5 {
            fields.push(Field::new(format!("y{k}_mm"), DataType::Float64, false));
            cols.push(Arc::new(Float64Array::from(ys.iter().map(|y| y[k]).collect::<Vec<_>>())));
        }
        fields.push(Field::new("tension_n", DataType::Float64, false));
        cols.push(Arc::new(Float64Array::from(t)));
        for (j, name) in ["tip_x_mm", "tip_y_mm", "tip_angle_rad", "a0", "a1", "a2"].iter().enumerate() {
            fields.push(Field::new(*name, DataType::Float64, true));
            cols.push(Arc::new(Float64Array::from(out.iter().map(|o| o[j]).collect::<Vec<_>>())));
        }
        RecordBatch::try_new(Arc::new(Schema::new(fields)), cols).unwrap()
    }

    #[test]
    fn map_directory_has_tables_and_non_blank_pictures() {
        let b = small_run();
        let info = RunInfo {
            mirrored: false,
            order: 2,
            tension_range_n: [1.0, 2.0],
            tensions_found: false,
            radius_mm: 5.0,
            length_mm: 65.0,
            run_dir: "small".into(),
            spec_hash: "h".into(),
            length_basis: LengthBasis::Rest,
            body: MapBody::default(),
        };
        let map = reduce_batches(&info, &ReduceOptions::default(), || Ok(vec![Ok(b.clone())].into_iter())).unwrap();
        let dir = std::env::var_os("CABLEMAP_KEEP_MAP").map(std::path::PathBuf::from);
        let tmp = tempfile::tempdir().unwrap();
        let dir = dir.unwrap_or_else(|| tmp.path().to_path_buf());
        let pictures = write_map(&dir, &map, &Rod::default(), &SolverOptions::default()).unwrap();
        assert_eq!(pictures.len(), 1 + 3 * 3 + 1);
        for p in &pictures {
            let img = image::open(dir.join(&p.file)).unwrap().to_rgb8();
            // Sized from the map's extent at equal aspect (plot/heatmap.rs checks the aspect).
            let (w, h) = img.dimensions();
            assert!(w >= 600 && h >= 400 && w <= 2400 && h <= 4000, "{}: {w}×{h}", p.file);
            // Not blank: many distinct colours and a good share of non-white pixels.
            let non_white = img.pixels().filter(|px| px.0 != [255, 255, 255]).count();
            let mut colours: Vec<[u8; 3]> = img.pixels().map(|px| px.0).collect();
            colours.sort_unstable();
            colours.dedup();
            assert!(non_white * 50 > img.pixels().len(), "{}: {non_white} non-white pixels", p.file);
            assert!(colours.len() > 20, "{}: only {} colours", p.file, colours.len());
        }
        let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
        assert!(html.contains("<script src=\"explorer-data.js\">"));
        let data = std::fs::read_to_string(dir.join(explorer::DATA_FILE)).unwrap();
        let json = data.trim().strip_prefix("// Written by `cablemap reduce`: the map explorer's data (index.html).\nwindow.CABLEMAP_MAP = ").unwrap();
        let v: serde_json::Value = serde_json::from_str(json.strip_suffix(';').unwrap()).unwrap();
        for p in &pictures {
            assert!(v["pictures"].as_array().unwrap().iter().any(|f| f["file"] == p.file.as_str()), "{}", p.file);
        }
        assert_eq!(v["cells"]["ix"].as_array().unwrap().len(), map.cells.len());
        assert_eq!(v["designs"]["ix"].as_array().unwrap().len(), map.designs.len());
        // Every a_i is a curvature (mm⁻¹) and the page names the basis.
        assert!(!html.contains("mm⁻²") && !data.contains("mm⁻²"));
        assert_eq!(v["length_basis_description"], "per unit rest length L (the thesis's basis)");
        assert!(pictures.iter().filter(|p| p.file.starts_with("a2")).all(|p| !p.explanation.contains("Fig.")));
        for table in ["cells.parquet", "modes.parquet", "designs.parquet", "summary.json"] {
            assert!(dir.join(table).exists(), "{table}");
        }
    }
}
