//! Writing a map directory: its tables (`tables`), pictures and explorer
//! page, put in place as a whole.

use super::drawings::ModeDrawings;
use super::plots::{self, draw_heatmap, Picture, Scale};
use super::{explorer, tables, CoefficientStats, MapCables, MapData, ReduceError, COEFFICIENT_UNIT};
use std::path::Path;

/// Writes the map directory `dir` as a whole: everything is written into a
/// staging directory beside it (`.NAME.tmp-TOKEN`), which then replaces
/// `dir` by rename, so a reader sees the old map or the new one, never a
/// mix (an interrupted reduce leaves the old map untouched). `dir` must be
/// new, empty, or an earlier map (its summary.json names the map format);
/// it must not be, or lie inside, a sweep run directory.
pub fn write_map_replacing(
    dir: &Path,
    map: &MapData,
    actuator: &crate::model::Rod,
    solver: &crate::model::SolverOptions,
) -> Result<Vec<Picture>, ReduceError> {
    write_dir_replacing(dir, |staging| write_map(staging, map, actuator, solver))
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
    crate::io::check_outside_run_dir(dir, "the map directory").map_err(|e| ReduceError::MapInRun(e.to_string()))?;
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
            || serde_json::from_value::<super::cables::CableMapSummary>(summary).is_ok());
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
/// `actuator` and `solver` re-simulate the mode representatives for drawing
/// ([`ModeDrawings`]). Writes in place; [`write_map_replacing`] is what the
/// commands use.
pub fn write_map(
    dir: &Path,
    map: &MapData,
    actuator: &crate::model::Rod,
    solver: &crate::model::SolverOptions,
) -> Result<Vec<Picture>, ReduceError> {
    write_map_drawn(dir, map, actuator, &ModeDrawings::of_map(map, actuator, solver), None)
}

/// [`write_map`] with the mode representatives' bodies already drawn (a
/// cable sweep draws them with the solver of several cables). A map of
/// several cables (`cables`) also gets their spec ([`MapCables`]), and its
/// captions, page and designs show every cable.
pub fn write_map_drawn(
    dir: &Path,
    map: &MapData,
    actuator: &crate::model::Rod,
    drawings: &ModeDrawings,
    cables: Option<&MapCables>,
) -> Result<Vec<Picture>, ReduceError> {
    std::fs::create_dir_all(dir).map_err(|source| ReduceError::CreateDir { path: dir.to_path_buf(), source })?;
    tables::write_tables(dir, map)?;
    if let Some(cables) = cables {
        cables.write(dir)?;
    }
    let mut pictures = coefficient_pictures(dir, map)?;
    plots::draw_modes(&dir.join("modes.png"), map, &drawings.shapes, cables)?;
    pictures.push(Picture {
        file: "modes.png".into(),
        title: "Characteristic modes (thesis Fig. 4.4)".into(),
        explanation: format!(
            "a0 split into 4 ranges (rows) and a1 into 3 (columns), a_i {}; each panel maps where that combination occurs and draws the simulation nearest the mode's median coefficients.{}",
            map.summary.length_basis.describe(),
            drawings.failure_note()
        ),
    });
    explorer::write_explorer(dir, map, actuator, &drawings.shapes, &pictures, cables)?;
    Ok(pictures)
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
