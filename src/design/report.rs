//! What a design run returns ([`DesignRun`]) and the text `design` prints:
//! a table in the form of the thesis's Table 5.1, the design, and which
//! components (if any) could not be met. Its JSON is the record
//! ([`super::record::DesignRecord`]).

use super::feasible::FeasibilityReport;
use super::objective::Objective;
use super::objective::Evaluation;
use super::search::Found;
use super::record::DesignRecord;
use super::targets::ComponentOutcome;
use crate::mould::MouldSummary;
use std::fmt;
use std::path::PathBuf;

/// A finished design.
#[derive(Debug, Clone)]
pub struct DesignRun {
    /// The objective searched.
    pub objective: Objective,
    /// The search's result.
    pub outcome: Found<Evaluation>,
    /// Each target component, achieved vs asked.
    pub results: Vec<ComponentOutcome>,
    /// A component counts as met within this many percent.
    pub tolerance_pct: f64,
    /// The map's verdict, when a map was given.
    pub feasibility: Option<FeasibilityReport>,
    /// design.json's content.
    pub record: DesignRecord,
    /// The export directory, when asked for.
    pub out: Option<PathBuf>,
    /// The names of the design's files written into `out` (design.json,
    /// channel.csv, mould.svg for a uniform body, shape.png), in order;
    /// empty without `out`. The moulds' files are in `moulds`.
    pub exported: Vec<String>,
    /// The moulds written, when asked for.
    pub moulds: Option<MouldSummary>,
}

impl fmt::Display for DesignRun {
    /// The map's verdict (with a map), the table, the design, the verdict
    /// on the components, and what was written.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(m) = &self.feasibility {
            writeln!(f, "map verdict  {}: {}\n", m.verdict.label(), m.reasons.join("; "))?;
        }
        self.write_table(f)?;
        self.write_design(f)?;
        if let Some(dir) = &self.out {
            writeln!(f, "exported {} to {}", self.exported.join(", "), dir.display())?;
            if let Some(summary) = &self.moulds {
                write!(f, "{}", summary.report(dir))?;
            }
        }
        Ok(())
    }
}

impl DesignRun {
    /// Target, achieved and error per component, in the form of Table 5.1.
    fn write_table(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let results = &self.results;
        let col = 14;
        write!(f, "{:<10}", "")?;
        for r in results {
            write!(f, "{:>col$}", format!("{} [{}]", r.quantity, r.quantity.unit()))?;
        }
        writeln!(f)?;
        let digits = |r: &ComponentOutcome| if r.quantity.is_coefficient() { 6 } else { 4 };
        write!(f, "{:<10}", "Target")?;
        for r in results {
            write!(f, "{:>col$.*}", digits(r), r.target)?;
        }
        writeln!(f)?;
        write!(f, "{:<10}", "Achieved")?;
        for r in results {
            write!(f, "{:>col$.*}", digits(r), r.achieved)?;
        }
        writeln!(f)?;
        write!(f, "{:<10}", "Error")?;
        for r in results {
            let e = r.error_pct.map_or("n/a (t=0)".to_string(), |e| format!("{e:.3}%"));
            write!(f, "{e:>col$}")?;
        }
        writeln!(f)
    }

    /// The design (pasteable into `simulate` and `design`), its shape, the
    /// search and the verdict.
    fn write_design(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (objective, outcome, tolerance_pct) = (&self.objective, &self.outcome, self.tolerance_pct);
        let e = &outcome.solution;
        writeln!(f)?;
        // Pasteable into `simulate` and `design`: --routing takes a plain comma list.
        writeln!(
            f,
            "routing      y0..y4 (mm): --routing {} --tension-n {:.4}",
            e.routing_mm.iter().map(|y| format!("{y:.4}")).collect::<Vec<_>>().join(","),
            e.tension_n
        )?;
        writeln!(f, "tension      {:.4} N   (bounds {} … {} N)", e.tension_n, objective.bounds.tension_min_n, objective.bounds.tension_max_n)?;
        writeln!(f, "shape        a = [{}] 1/mm", e.a.iter().map(|a| format!("{a:.6}")).collect::<Vec<_>>().join(", "))?;
        writeln!(f, "basis        a_i {} (--length-basis {})", objective.length_basis.describe(), objective.length_basis)?;
        writeln!(
            f,
            "objective    {:.3e}   ({} seed designs simulated, {} refined, {:.2} s)",
            outcome.cost,
            outcome.seeds_simulated,
            outcome.starts.len(),
            outcome.seconds
        )?;
        let unmet: Vec<&ComponentOutcome> = self.results.iter().filter(|r| !r.met).collect();
        if unmet.is_empty() {
            writeln!(f, "verdict      every component met within {tolerance_pct}%")
        } else {
            writeln!(
                f,
                "verdict      NOT REACHABLE as asked: {} could not be met within {tolerance_pct}%; the design above is the closest achievable (least eq. 3.17 cost)",
                unmet.iter().map(|r| r.quantity.to_string()).collect::<Vec<_>>().join(", ")
            )
        }
    }
}
