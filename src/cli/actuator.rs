//! The rod and solver flags every command that simulates shares, and the
//! decisions they make: the rod's overrides (a library
//! [`RodOverrides`]) and the solver options.

use anyhow::Context;
use cablemap::model::{Actuator, EffectInfo, Rod, RodOverrides, REGISTRY};
use cablemap::solver::{SolverMethod, SolverOptions, SolverSettings};
use clap::Args;
use std::path::{Path, PathBuf};

/// Rod parameter overrides shared by every command that simulates.
/// Defaults are the thesis's (model-notes §1).
#[derive(Debug, Clone, Args, Default)]
pub struct ActuatorArgs {
    /// Rod length L, mm [default: 65].
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub length_mm: Option<f64>,
    /// Rod radius r, mm [default: 5].
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub radius_mm: Option<f64>,
    /// Axial rigidity EA, N [default: 26.6964].
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    pub ea_n: Option<f64>,
    /// Shear rigidity GA, N [default: 1.70866].
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    pub ga_n: Option<f64>,
    /// Bending rigidity EI, N·mm² [default: 115.117].
    #[arg(long, value_name = "N_MM2", allow_hyphen_values = true)]
    pub ei_n_mm2: Option<f64>,
    /// Material density, g/cm³ [default: 1.07].
    #[arg(long, value_name = "G_CM3", allow_hyphen_values = true)]
    pub density_g_cm3: Option<f64>,
    /// Turn self-weight off (the thesis's rod hangs: gravity is on by default).
    #[arg(long)]
    pub no_gravity: bool,
    /// The effect parameters' flags, one per registry entry
    /// (`cablemap::model::effects::REGISTRY`).
    #[command(flatten)]
    pub effects: EffectArgs,
    /// Rod TOML file (the fields of a sweep spec's [actuator] section, docs/model.md); the
    /// flags above and below override it [default: the thesis's actuator].
    #[arg(long, value_name = "FILE")]
    pub actuator_file: Option<PathBuf>,
    /// Radius profile r(s): points s:r in mm, piecewise linear from s = 0 to L, e.g.
    /// "0:15.4,305:6.4,360:4.8" (a cone is two points). EA, GA, EI stay those of a section of
    /// radius --radius-mm and scale with r(s) [default: uniform radius].
    #[arg(long, value_name = "S:R,...", value_parser = parse_radius_profile_arg)]
    pub radius_profile_mm: Option<RadiusProfileArg>,
    /// Where the cable is knotted, 0 < s_k ≤ L, mm; the routing spans [0, s_k] [default: the tip].
    #[arg(long, value_name = "MM", allow_hyphen_values = true)]
    pub cable_anchor_mm: Option<f64>,
    /// Solver method: `collocation` (spectral, the default) or `rk4` (the previous method).
    #[arg(long, value_enum, value_name = "METHOD")]
    pub method: Option<MethodArg>,
    /// Collocation: Chebyshev–Lobatto intervals per knot span (4–64; more resolve higher orders) [default: 10].
    #[arg(long, value_name = "M")]
    pub nodes_per_span: Option<usize>,
    /// RK4 steps per knot span (even); with collocation, the centreline's resolution
    /// (2·N + 1 points) [default: 24].
    #[arg(long, value_name = "N")]
    pub steps_per_span: Option<usize>,
}

/// The effect flags, generated from the effect registry: each entry's
/// flag, value name, help and default, so that a new effect gets its flag
/// by its entry alone.
#[derive(Debug, Clone, Default)]
pub struct EffectArgs {
    /// The values given, by registry entry.
    values: Vec<(&'static EffectInfo, f64)>,
}

impl clap::FromArgMatches for EffectArgs {
    fn from_arg_matches(matches: &clap::ArgMatches) -> Result<Self, clap::Error> {
        let mut args = Self::default();
        args.update_from_arg_matches(matches)?;
        Ok(args)
    }

    fn update_from_arg_matches(&mut self, matches: &clap::ArgMatches) -> Result<(), clap::Error> {
        for info in REGISTRY.iter() {
            if let Some(&v) = matches.get_one::<f64>(info.name) {
                self.values.retain(|(i, _)| i.name != info.name);
                self.values.push((*info, v));
            }
        }
        Ok(())
    }
}

impl clap::Args for EffectArgs {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        cmd.args(REGISTRY.iter().map(|info| {
            let long = info.flag.trim_start_matches("--");
            clap::Arg::new(info.name)
                .long(long)
                .aliases(info.flag_aliases.iter().map(|a| a.trim_start_matches("--")))
                .value_name(info.value_name)
                .allow_hyphen_values(true)
                .value_parser(clap::value_parser!(f64))
                .help(info.flag_help())
        }))
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}

/// A radius profile given on the command line.
#[derive(Debug, Clone, PartialEq)]
pub struct RadiusProfileArg(pub Vec<(f64, f64)>);

fn parse_radius_profile_arg(text: &str) -> Result<RadiusProfileArg, String> {
    cablemap::model::body::parse_radius_profile(text).map(RadiusProfileArg).map_err(|e| e.to_string())
}

/// Solver method on the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Spectral collocation per knot span (the default solver).
    Collocation,
    /// The previous method: RK4 per span with secant shooting on gravity's moment.
    Rk4,
}

impl ActuatorArgs {
    /// The rod the flags describe, as overrides on a base rod.
    pub fn overrides(&self) -> RodOverrides {
        RodOverrides {
            file: self.actuator_file.clone(),
            length_mm: self.length_mm,
            radius_mm: self.radius_mm,
            ea_n: self.ea_n,
            ga_n: self.ga_n,
            ei_n_mm2: self.ei_n_mm2,
            density_g_cm3: self.density_g_cm3,
            no_gravity: self.no_gravity,
            effects: self.effects.values.clone(),
            radius_profile_mm: self.radius_profile_mm.as_ref().map(|p| p.0.clone()),
            cable_anchor_mm: self.cable_anchor_mm,
        }
    }

    /// Applies the overrides on top of `base` (`--actuator-file` aside).
    pub fn apply(&self, base: &Rod) -> Rod {
        self.overrides().apply(base)
    }

    /// The actuator: `--actuator-file` if given, else the thesis's; with the
    /// flags applied. (A workflow that reads measurements takes the
    /// [`ActuatorArgs::overrides`] and resolves them on the data's rod.)
    pub fn resolve(&self) -> anyhow::Result<Rod> {
        self.overrides().resolve(None).map_err(|e| anyhow::Error::new(e).context("--actuator-file"))
    }

    /// The actuator of `--actuator FILE.toml` (`actuator_file`) with the
    /// rod flags applied to its rod, else [`ActuatorArgs::resolve`]'s rod
    /// without cables: the rod is given once, by one file or the other.
    pub fn actuator(&self, actuator_file: Option<&Path>) -> anyhow::Result<Actuator> {
        let Some(path) = actuator_file else {
            return Ok(Actuator::with_cables(self.resolve()?, Vec::new()));
        };
        anyhow::ensure!(self.actuator_file.is_none(), "give the rod either in --actuator FILE's [rod] table or by --actuator-file, not both");
        let mut actuator = Actuator::read(path).with_context(|| format!("--actuator {}", path.display()))?;
        actuator.rod = self.apply(&actuator.rod);
        Ok(actuator)
    }

    /// The solver settings given by flags.
    pub fn solver_settings(&self) -> SolverSettings {
        let method = self.method.map(|m| match m {
            MethodArg::Collocation => SolverMethod::Collocation,
            MethodArg::Rk4 => SolverMethod::Rk4,
        });
        SolverSettings { method, nodes_per_span: self.nodes_per_span, steps_per_span: self.steps_per_span }
    }

    /// `base` with the solver settings given by flags.
    pub fn solver_options(&self, base: &SolverOptions) -> SolverOptions {
        self.solver_settings().applied_to(base)
    }
}
