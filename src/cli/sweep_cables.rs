//! `cablemap sweep-cables`: a sweep of several or spatial cables (see
//! [`cablemap::sweep::cables`]).

use cablemap::reduce::cables::run_cable_sweep;
use cablemap::sweep::cables::CableSweepSpec;
use anyhow::Context;
use clap::Args;
use std::path::PathBuf;

/// Arguments of `cablemap sweep-cables`.
#[derive(Debug, Clone, Args)]
pub struct SweepCablesArgs {
    /// The spec (TOML: `[[cable]]` tables with tension grids and `[[cable.sweep]]` control points; docs/schema.md).
    pub spec: PathBuf,
    /// New or empty output directory: rows.parquet, maps/reach_*.parquet, spec.toml, summary.json.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Worker threads [default: one per core].
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
}

/// Runs the cable sweep and prints its summary.
pub fn run(args: &SweepCablesArgs) -> anyhow::Result<()> {
    anyhow::ensure!(args.threads != Some(0), "--threads must be at least 1");
    let text = std::fs::read_to_string(&args.spec).with_context(|| format!("reading spec {}", args.spec.display()))?;
    let spec = CableSweepSpec::from_toml(&text, &args.spec.display().to_string())?;
    let s = run_cable_sweep(&spec, &args.out, args.threads)?;
    println!(
        "{} routings ({} rejected) x {} tension combinations: {} rows, {} solved, {} failed",
        s.routings,
        s.invalid_routings,
        spec.tension_combinations(),
        s.rows,
        s.ok,
        s.failed
    );
    println!("reach cells: x-y {}, x-z {}, y-z {}, 3-D {}{}", s.cells[0], s.cells[1], s.cells[2], s.cells[3], if s.planar { " (planar run)" } else { "" });
    println!("{:.2} s wall, {} thread{}; wrote {}", s.wall_s, s.threads, if s.threads == 1 { "" } else { "s" }, args.out.display());
    Ok(())
}
