//! Command-line front ends: argument structs (clap) and the functions that
//! run each command. `main.rs` only parses and dispatches.

pub mod bench;
pub mod calibrate;
pub mod design;
pub mod diagnose;
pub mod feasible;
pub mod mould;
pub mod reduce;
pub mod simulate;
pub mod study;
pub mod sweep;
pub mod synth;

use cablemap::model::{EffectInfo, Rod, SolverOptions, REGISTRY};
use cablemap::shape::LengthBasis;
use clap::Args;

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
    pub actuator_file: Option<std::path::PathBuf>,
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

impl EffectArgs {
    /// Sets the given parameters on `rod`.
    pub fn apply(&self, rod: &mut Rod) {
        for (info, value) in &self.values {
            (info.set)(rod, *value);
        }
    }
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
    /// Applies the overrides on top of `base`.
    pub fn apply(&self, base: &Rod) -> Rod {
        let mut a = base.clone();
        let set = |slot: &mut f64, v: Option<f64>| {
            if let Some(v) = v {
                *slot = v;
            }
        };
        set(&mut a.length_mm, self.length_mm);
        set(&mut a.radius_mm, self.radius_mm);
        set(&mut a.ea_n, self.ea_n);
        set(&mut a.ga_n, self.ga_n);
        set(&mut a.ei_n_mm2, self.ei_n_mm2);
        set(&mut a.density_g_cm3, self.density_g_cm3);
        self.effects.apply(&mut a);
        if self.no_gravity {
            a.gravity.enabled = false;
        }
        if let Some(p) = &self.radius_profile_mm {
            a.radius_profile_mm = p.0.clone();
        }
        if self.cable_anchor_mm.is_some() {
            a.cable_anchor_mm = self.cable_anchor_mm;
        }
        a
    }

    /// The actuator: `--actuator-file` if given, else `from_data` (the one a
    /// measurement file gives), else the thesis's; with the flags applied.
    pub fn resolve(&self, from_data: Option<&Rod>) -> anyhow::Result<Rod> {
        let base = match (&self.actuator_file, from_data) {
            (Some(path), _) => Rod::from_toml_file(path).map_err(anyhow::Error::msg).map_err(|e| e.context("--actuator-file"))?,
            (None, Some(a)) => a.clone(),
            (None, None) => Rod::default(),
        };
        Ok(self.apply(&base))
    }

    /// Solver options with the step override.
    pub fn solver_options(&self, base: &SolverOptions) -> SolverOptions {
        let mut o = base.clone();
        if let Some(n) = self.steps_per_span {
            o.steps_per_span = n;
        }
        if let Some(m) = self.nodes_per_span {
            o.nodes_per_span = m;
        }
        if let Some(m) = self.method {
            o.method = match m {
                MethodArg::Collocation => cablemap::model::SolverMethod::Collocation,
                MethodArg::Rk4 => cablemap::model::SolverMethod::Rk4,
            };
        }
        o
    }
}

/// The length the curvature coefficients a_i are per unit of, shared by
/// every command that prints or compares coefficients.
#[derive(Debug, Clone, Copy, Args)]
pub struct LengthBasisArgs {
    /// Curvature coefficients a_i per unit `rest` length L (the thesis's basis, eq. 3.2: the
    /// default) or per unit `deformed` length ℓ (a_i·L/ℓ) [default: rest].
    #[arg(long, value_name = "rest|deformed", default_value = "rest")]
    pub length_basis: LengthBasis,
}

/// An error and its causes on one line, each cause once: library errors
/// already print their cause ("reading X: No such file"), so a cause whose
/// text is already in the line is not repeated.
pub fn error_text(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !text.contains(&c) {
            text.push_str(": ");
            text.push_str(&c);
        }
    }
    text
}

/// Parses the command line like `T::parse()`, except that an unknown
/// `--flag` is answered with the subcommand's flag nearest by edit distance
/// (a swap of two neighbours counts as one edit): `--pgn` suggests `--png`.
/// Clap ranks by Jaro similarity, which matches letters only within a window
/// that is empty for three-letter words, so it found no letter of `pgn` in
/// `png` beyond the first and suggested `--ga-n` instead.
pub fn parse_args<T: clap::Parser>() -> T {
    let args: Vec<std::ffi::OsString> = std::env::args_os().collect();
    T::try_parse_from(&args).unwrap_or_else(|e| nearer_suggestion(e, T::command(), &args).exit())
}

/// `e` with the suggestion of [`parse_args`] when it names an unknown flag
/// and a flag is within a third of its length in edits; otherwise `e`.
fn nearer_suggestion(mut e: clap::Error, mut cmd: clap::Command, args: &[std::ffi::OsString]) -> clap::Error {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    if e.kind() != ErrorKind::UnknownArgument {
        return e;
    }
    let Some(ContextValue::String(given)) = e.get(ContextKind::InvalidArg) else { return e };
    let Some(given) = given.strip_prefix("--").map(str::to_string) else { return e };
    cmd.build();
    // The subcommand is the first argument naming one (flags of `cablemap` itself come before it).
    let Some(name) = args.iter().skip(1).filter_map(|a| a.to_str()).find(|a| cmd.find_subcommand(a).is_some()) else { return e };
    let Some(sub) = cmd.find_subcommand_mut(name) else { return e };
    let longs: Vec<String> = sub.get_arguments().filter(|a| !a.is_hide_set()).filter_map(|a| a.get_long().map(str::to_string)).collect();
    let Some((distance, nearest)) = longs.iter().map(|l| (edit_distance(&given, l), l)).min_by_key(|(d, _)| *d) else { return e };
    let clap_choice = match e.get(ContextKind::SuggestedArg) {
        Some(ContextValue::String(s)) => s.strip_prefix("--").map(str::to_string),
        _ => None,
    };
    let tied_with_clap = clap_choice.as_deref().is_some_and(|c| edit_distance(&given, c) == distance);
    if distance > (given.chars().count() / 3).max(1) || tied_with_clap {
        return e;
    }
    if clap_choice.is_none() {
        // Clap's "to pass '--x' as a value, use '-- --x'", which it gives only when it has no flag to suggest.
        e.remove(ContextKind::Suggested);
    }
    e.insert(ContextKind::SuggestedArg, ContextValue::String(format!("--{nearest}")));
    // Clap's usage line shows its own suggestion as if given; show the plain usage.
    e.insert(ContextKind::Usage, ContextValue::StyledStr(sub.render_usage()));
    e
}

/// Edits (insert, delete, substitute, swap two neighbours) from `a` to `b`:
/// the optimal string alignment distance.
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    // d[i][j]: distance between the first i letters of a and the first j of b.
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for j in 0..=b.len() {
        d[0][j] = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            d[i][j] = (d[i - 1][j] + 1).min(d[i][j - 1] + 1).min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                d[i][j] = d[i][j].min(d[i - 2][j - 2] + 1);
            }
        }
    }
    d[a.len()][b.len()]
}

/// Parses "a,b,c" into numbers, naming the offending item.
pub fn parse_list(text: &str, what: &str) -> anyhow::Result<Vec<f64>> {
    text.split(',')
        .map(|item| {
            item.trim()
                .parse::<f64>()
                .map_err(|_| anyhow::anyhow!("{what}: '{}' is not a number (expected a comma-separated list like 1,-2,0.5,0,3)", item.trim()))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::edit_distance;

    #[test]
    fn a_swap_of_neighbours_is_one_edit() {
        assert_eq!(edit_distance("pgn", "png"), 1);
        assert_eq!(edit_distance("pgn", "ga-n"), 3);
        assert_eq!(edit_distance("tension", "tension-n"), 2);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("same", "same"), 0);
    }
}
