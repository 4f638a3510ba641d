//! `cablemap design`: routing and tension for a target shape (eq. 3.17).

use super::{ActuatorArgs, LengthBasisArgs};
use anyhow::Context;
use cablemap::design::cables::search::CableSearch;
use cablemap::design::cables::spec::{self, DesignActuator};
use cablemap::design::cables::targets::TargetSet;
use cablemap::design::cables::CableDesignRequest;
use cablemap::design::run::DesignRequest;
use cablemap::design::{self, DesignError, SearchOptions, Target, Weights};
use cablemap::solver::SolverOptions;
use clap::Args;
use std::path::PathBuf;

/// Arguments of `cablemap design`.
#[derive(Debug, Clone, Args)]
pub struct DesignArgs {
    /// Target, any subset of x, y (tip, mm) and a0, a1, … (curvature coefficients, 1/mm),
    /// e.g. x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015.
    #[arg(long, value_name = "K=V,…", allow_hyphen_values = true, required_unless_present = "targets", conflicts_with = "targets")]
    pub target: Option<String>,
    /// Targets file (TOML: [[target]] tables or a [trajectory]; docs/design.md,
    /// "Several cables"): designs the channels of every cable of --actuator and
    /// one actuation per target.
    #[arg(long, value_name = "FILE.toml")]
    pub targets: Option<PathBuf>,
    /// The actuator to design (the `simulate --actuator` file; a [[cable]]
    /// without y_mm/z_mm has a free channel, `free = ["y", "z"]` frees a given one,
    /// `tension_max_n` bounds its tension) [default with --targets: one cable free in y].
    #[arg(long = "actuator", value_name = "FILE.toml", requires = "targets")]
    pub design_actuator: Option<PathBuf>,
    /// Weights λ of eq. 3.17 for target components, e.g. a2=50
    /// [defaults x=1,y=1,a0=100,a1=50,a2=25, higher orders 25].
    #[arg(long, value_name = "K=V,…")]
    pub weights: Option<String>,
    /// Feasibility map directory (`cablemap reduce` output): seeds the search with
    /// its nearest designs and supplies the tension bounds.
    #[arg(long, value_name = "MAP_DIR")]
    pub map: Option<PathBuf>,
    /// Lower tension bound τ_l, N [default: 1.0, or the map's].
    #[arg(long, value_name = "N")]
    pub tension_min_n: Option<f64>,
    /// Upper tension bound τ_u, N [default: 2.0, or the map's].
    #[arg(long, value_name = "N")]
    pub tension_max_n: Option<f64>,
    /// Largest |y_i| of a control point, mm [default: 0.999 r: the thesis's −r < y_i < r;
    /// with --moulds at most what the moulds can cast]. A channel of diameter d breaks
    /// the surface beyond r − d/2.
    #[arg(long, value_name = "MM")]
    pub max_offset_mm: Option<f64>,
    #[command(flatten)]
    pub basis: LengthBasisArgs,
    /// Number of seeds refined to convergence (3× as many are explored briefly)
    /// [default: 8; with --targets 4].
    #[arg(long)]
    pub starts: Option<usize>,
    /// Most simulator evaluations per converging start.
    #[arg(long, default_value_t = SearchOptions::default().max_evaluations)]
    pub max_evaluations: usize,
    /// A component counts as met when its error is within this many percent.
    /// [default: 5; with --targets, each target's tolerance_pct, else 5]
    #[arg(long)]
    pub tolerance_pct: Option<f64>,
    /// Print one JSON object instead of a report.
    #[arg(long)]
    pub json: bool,
    /// Write design.json, channel.csv, mould.svg (1:1, mm; uniform bodies only) and shape.png into this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// With --out: design within the channel offset the moulds can cast (tube and skin,
    /// see `cablemap mould`) and write the printable moulds too (mould1.stl, mould2.stl,
    /// previews, mould.json), with the mould options below.
    #[arg(long, requires = "out")]
    pub moulds: bool,
    #[command(flatten)]
    pub mould: super::mould::MouldParamArgs,
    #[command(flatten)]
    pub actuator: ActuatorArgs,
}

/// The design request the arguments describe.
fn request(args: &DesignArgs) -> anyhow::Result<DesignRequest> {
    let weights = match &args.weights {
        Some(w) => Weights::parse(w).context("--weights")?,
        None => Weights::default(),
    };
    Ok(DesignRequest {
        actuator: args.actuator.resolve()?,
        options: args.actuator.solver_options(&SolverOptions::default()),
        target: Target::parse(args.target.as_deref().unwrap_or_default()).context("--target")?,
        weights,
        tension_min_n: args.tension_min_n,
        tension_max_n: args.tension_max_n,
        max_offset_mm: args.max_offset_mm,
        length_basis: args.basis.length_basis,
        map: args.map.clone(),
        search: SearchOptions { starts: args.starts.unwrap_or(8), max_evaluations: args.max_evaluations, ..SearchOptions::default() },
        tolerance_pct: args.tolerance_pct.unwrap_or(5.0),
        out: args.out.clone(),
        mould: args.mould.params(),
        write_moulds: args.moulds,
    })
}

/// The several-cable request of `--targets` (with `--actuator`).
fn cables_request(args: &DesignArgs, targets: &std::path::Path) -> anyhow::Result<CableDesignRequest> {
    for (given, flag, instead) in [
        (args.weights.is_some(), "--weights", "weights = { … } in each [[target]]"),
        (args.tension_min_n.is_some(), "--tension-min-n", "tension_min_n in each [[cable]] of --actuator"),
        (args.tension_max_n.is_some(), "--tension-max-n", "tension_max_n in each [[cable]] of --actuator"),
        (args.max_offset_mm.is_some(), "--max-offset-mm", "max_offset_mm in each [[cable]] of --actuator"),
    ] {
        anyhow::ensure!(!given, "{flag} does not apply to --targets: give {instead}");
    }
    let design = match &args.design_actuator {
        Some(path) => {
            anyhow::ensure!(args.actuator.actuator_file.is_none(), "give the rod either in --actuator FILE's [rod] table or by --actuator-file, not both");
            DesignActuator::read(path, |rod| args.actuator.apply(rod)).context("--actuator")?
        }
        None => DesignActuator::planar(args.actuator.resolve()?, spec::default_tension_min_n(1), spec::DEFAULT_TENSION_MAX_N, None),
    };
    let mut targets = TargetSet::read(targets, design.actuator.rod.length_mm).context("--targets")?;
    if let Some(tol) = args.tolerance_pct {
        targets.targets.iter_mut().for_each(|t| t.tolerance_pct = tol);
    }
    Ok(CableDesignRequest {
        design,
        targets,
        options: args.actuator.solver_options(&SolverOptions::default()),
        length_basis: args.basis.length_basis,
        search: CableSearch { starts: args.starts.unwrap_or(CableSearch::default().starts), max_evaluations: args.max_evaluations },
        map: args.map.clone(),
        out: args.out.clone(),
        moulds: args.moulds.then(|| cablemap::mould::MouldOptions { params: args.mould.params(), ..Default::default() }),
    })
}

/// Runs `cablemap design`.
pub fn run(args: &DesignArgs) -> anyhow::Result<()> {
    if let Some(targets) = &args.targets {
        let request = cables_request(args, targets)?;
        let done = cablemap::design::cables::run(&request).map_err(|e| match e {
            DesignError::ExportDir { .. } => anyhow::Error::new(e).context("--out"),
            DesignError::BadSearch(_) => anyhow::Error::new(e).context("--starts"),
            e => anyhow::Error::new(e),
        })?;
        if args.json {
            println!("{}", done.to_json());
        } else {
            print!("{done}");
        }
        return Ok(());
    }
    let request = request(args)?;
    if let Some(bound) = request.mould_bound_exceeded() {
        // Before the search, on stderr (stdout may be --json).
        eprintln!("note: {bound}");
    }
    let done = design::run::run(&request).map_err(|e| match e {
        DesignError::ExportDir { .. } => anyhow::Error::new(e).context("--out"),
        DesignError::BadSearch(_) => anyhow::Error::new(e).context("--starts / --tolerance-pct"),
        DesignError::Mould(m) => super::mould::with_flag(m),
        e => anyhow::Error::new(e),
    })?;
    if args.json {
        println!("{}", done.record.to_json_line());
    } else {
        print!("{done}");
    }
    Ok(())
}
