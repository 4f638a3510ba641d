//! `cablemap feasible`: the map's verdict on a target (thesis §4.2).

use anyhow::Context;
use cablemap::design::feasible::{check, FeasibilityReport, Verdict};
use cablemap::design::map::MapDir;
use cablemap::design::{Target, Weights};
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `cablemap feasible`.
#[derive(Debug, Clone, Args)]
pub struct FeasibleArgs {
    /// Feasibility map directory (`cablemap reduce` output).
    #[arg(long, value_name = "MAP_DIR", required_unless_present = "study", conflicts_with = "study")]
    pub map: Option<PathBuf>,
    /// A study directory (`cablemap study` output): the verdict of every variant's map.
    #[arg(long, value_name = "DIR")]
    pub study: Option<PathBuf>,
    /// Target, any subset of x, y (tip, mm) and a0, a1, … (1/mm),
    /// e.g. x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015.
    #[arg(long, value_name = "K=V,…", allow_hyphen_values = true)]
    pub target: String,
    /// Weights λ for the distance to the nearest designs [defaults x=1,y=1,a0=100,a1=50,a2=25].
    #[arg(long, value_name = "K=V,…")]
    pub weights: Option<String>,
    /// How many nearest simulated designs to list.
    #[arg(long, default_value_t = 5)]
    pub nearest: usize,
    /// Print one JSON object instead of a report.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub basis: super::LengthBasisArgs,
}

/// Runs `cablemap feasible`.
pub fn run(args: &FeasibleArgs) -> anyhow::Result<()> {
    let target = Target::parse(&args.target)?;
    let weights = match &args.weights {
        Some(w) => Weights::parse(w)?,
        None => Weights::default(),
    };
    weights.check_against(&target)?;
    let Some(map_dir) = &args.map else {
        let study = args.study.as_ref().expect("clap requires --map or --study");
        return run_study(study, &target, &weights, args);
    };
    let map = MapDir::open(map_dir)?;
    let report = check(&map, &target, args.basis.length_basis, &weights, args.nearest)?;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        writeln!(out, "{}", serde_json::to_value(&report)?)?;
    } else {
        write!(out, "{}", text(&report, cablemap::reduce::MapCables::open(map_dir)?.as_ref()))?;
        writeln!(out, "next      {}", design_command(&target, map_dir))?;
    }
    Ok(())
}

/// The command that designs for `target` with `map_dir`'s designs as seeds,
/// ready to paste: `cablemap design --target x=…,a0=… --map MAP_DIR`.
pub fn design_command(target: &Target, map_dir: &std::path::Path) -> String {
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

/// `feasible --study DIR`: every variant's verdict, and which reach the target.
fn run_study(dir: &std::path::Path, target: &Target, weights: &Weights, args: &FeasibleArgs) -> anyhow::Result<()> {
    let variants = cablemap::study::mapped_variants(dir)?;
    let mut rows = Vec::new();
    for (index, label, map_dir) in variants {
        let map = MapDir::open(&map_dir).with_context(|| format!("variant {index} ({label}): run the study to finish its map"))?;
        let report = check(&map, target, args.basis.length_basis, weights, args.nearest)?;
        rows.push((index, label, report));
    }
    let reach: Vec<String> = rows.iter().filter(|r| r.2.verdict == Verdict::Feasible).map(|r| format!("v{}", r.0)).collect();
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if args.json {
        let variants: Vec<_> = rows
            .iter()
            .map(|(i, label, r)| serde_json::json!({ "variant": i, "label": label, "verdict": r.verdict, "report": r }))
            .collect();
        writeln!(out, "{}", serde_json::json!({ "study": dir, "feasible_variants": reach, "variants": variants }))?;
    } else {
        for (i, label, r) in &rows {
            let first = r.reasons.first().map_or(String::new(), |s| format!(": {s}"));
            writeln!(out, "v{i:<3} {label}: {}{first}", r.verdict.label())?;
        }
        if reach.is_empty() {
            writeln!(out, "no variant reaches the target feasibly (see the borderline ones, or widen the study)")?;
        } else {
            writeln!(out, "reach the target: {} of {} variants ({})", reach.len(), rows.len(), reach.join(", "))?;
        }
    }
    Ok(())
}

/// The text report; a map of several cables (`cables`) lists every cable
/// of each design and the command that solves it again.
pub fn text(r: &FeasibilityReport, cables: Option<&cablemap::reduce::MapCables>) -> String {
    let mut s = format!("verdict   {}\n", r.verdict.label());
    for reason in &r.reasons {
        s.push_str(&format!("          - {reason}\n"));
    }
    let t = &r.tip_cell;
    let idx = |v: Option<i32>| v.map_or("any".to_string(), |v| v.to_string());
    s.push_str(&format!(
        "tip cell  ix = {}, iy = {}: {} simulation(s) ({} with its neighbours)\n",
        idx(t.ix),
        idx(t.iy),
        t.count,
        t.neighbourhood_count
    ));
    if !r.coefficients.is_empty() {
        s.push_str(&format!("basis     a_i in 1/mm, {} (the map's basis)\n", r.length_basis.describe()));
        s.push_str(&format!("{:<6}{:>12}{:>12}{:>12}{:>12}{:>12}\n", "", "target", "cell p10", "cell p90", "near min", "near max"));
        let f = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.5}"));
        for c in &r.coefficients {
            s.push_str(&format!(
                "{:<6}{:>12.5}{:>12}{:>12}{:>12}{:>12}\n",
                c.component,
                c.target,
                f(c.cell_p10),
                f(c.cell_p90),
                f(c.neighbourhood_min),
                f(c.neighbourhood_max)
            ));
        }
    }
    let m = &r.mode;
    match (m.mode, m.count_in_cell) {
        (Some(mode), Some(n)) => s.push_str(&format!("mode      {mode} (a0 range {}, a1 range {}); {n} simulations of the tip cell in it\n", mode / 3, mode % 3)),
        (Some(mode), None) => s.push_str(&format!("mode      {mode} (a0 range {}, a1 range {})\n", mode / 3, mode % 3)),
        (None, _) => s.push_str(&format!("mode      one of {:?} (give a0 and a1 to pin it down)\n", m.candidates)),
    }
    s.push_str("nearest simulated designs (weighted distance):\n");
    for near in &r.nearest {
        let d = &near.design;
        s.push_str(&format!(
            "  {} → tip ({:.2}, {:.2}) mm, a = [{}]  (distance {:.4})\n",
            cablemap::reduce::design_actuation(cables, d.routing_id, &d.routing_mm, d.tension_n),
            d.tip_x_mm,
            d.tip_y_mm,
            d.a.iter().map(|v| format!("{v:.4}")).collect::<Vec<_>>().join(", "),
            near.distance
        ));
        if let Some(cables) = cables {
            s.push_str(&format!("    {}\n", cables.command(d.routing_id).text));
        }
    }
    s
}
