//! `cablemap reduce` / `cablemap map` of a cable sweep run (see
//! [`cablemap::reduce::cables`]).

use anyhow::Context;
use cablemap::reduce::cables::reduce_cable_run;
use cablemap::reduce::ReduceOptions;
use std::path::Path;
use std::time::Instant;

/// Reduces the cable sweep `run` into `out` and prints a summary.
pub fn reduce_cables_into(run: &Path, out: &Path, partial: bool, cell_mm: Option<f64>, options: &ReduceOptions, json: bool) -> anyhow::Result<()> {
    let start = Instant::now();
    // Scratch of the planar map beside the map, as for planar runs (same
    // disk as the results, not a RAM-backed /tmp).
    let mut options = options.clone();
    if options.scratch_dir.is_none() {
        options.scratch_dir = Some(out.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new(".")).to_path_buf());
    }
    let map = reduce_cable_run(run, partial, cell_mm, &options, out).with_context(|| format!("reducing {}", run.display()))?;
    let total_s = start.elapsed().as_secs_f64();
    let s = &map.summary;
    if json {
        let pictures: Vec<&str> = map.planar.iter().flat_map(|(_, p)| p.iter().map(|p| p.file.as_str())).collect();
        println!(
            "{}",
            serde_json::json!({ "summary": s, "map_dir": out, "planar_summary": map.planar.as_ref().map(|(m, _)| &m.summary),
                "planar_pictures": pictures, "total_s": total_s })
        );
        return Ok(());
    }
    println!(
        "map {}: {} rows of {} cable(s) ({} solved, {} failed, {} of rejected routings); reach cells of {} mm: x-y {}, x-z {}, y-z {}, 3-D {}",
        out.display(),
        s.rows,
        s.cables,
        s.ok,
        s.failed,
        s.invalid_rows,
        s.cell_mm,
        s.cells[0],
        s.cells[1],
        s.cells[2],
        s.cells[3]
    );
    match &map.planar {
        Some((planar, pictures)) => println!(
            "planar run: feasibility map in {} cells, {} pictures; open {}",
            planar.summary.cells,
            pictures.len(),
            out.join(cablemap::reduce::cables::PLANAR_MAP_DIR).join("index.html").display()
        ),
        None if s.planar => println!("planar run of order 0: no planar map (it needs a0 and a1; set output.order ≥ 1)"),
        None => {}
    }
    println!("written in {total_s:.2} s");
    Ok(())
}
