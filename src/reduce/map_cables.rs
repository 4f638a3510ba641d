//! Every cable of a several-cable map's designs. The planar reducer stores
//! a design's `y0_mm`…`y4_mm` and `tension_n` (cable 1's) and, as its
//! `routing_id`, the row key of its cable run's row ([`row_key`]). The
//! cable sweep spec, written beside the
//! map's tables as [`CABLES_FILE`], turns that key back into the whole
//! actuator: every cable's routing and tension, the rod, the solver settings.
//! From it come the explorer's rows and pasteable commands, `feasible`'s
//! list, the modes' captions and the explorer's header, so a design shown
//! anywhere is one a user can solve again to the map's tip.

use super::ReduceError;
use crate::model::routing::CONTROL_POINTS;
use crate::solver::record::{simulate_command, SimulateCommand};
use crate::model::Actuator;
use crate::sweep::schema::Axis;
use crate::solver::SolverOptions;
use crate::sweep::spec::{CablesGrid, OutputSpec, RoutingGrid, SweepSpec};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The row key of a cable sweep's row in its planar map (the map's
/// `routing_id`): routing_id × tension combinations + the combination's
/// index in grid order (cable 1's tension slowest). [`row_of_key`] inverts it.
pub fn row_key(routing_id: u64, combination: u64, combinations: u64) -> u64 {
    routing_id * combinations + combination
}

/// (routing_id, combination index) of a planar map's `routing_id` (see [`row_key`]).
pub fn row_of_key(key: u64, combinations: u64) -> (u64, usize) {
    (key / combinations, (key % combinations) as usize)
}

/// The cable sweep spec beside a several-cable map's tables.
pub const CABLES_FILE: &str = "cables.json";

/// What [`CABLES_FILE`] holds.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct CablesFile {
    /// Why the file is there, for a reader of the folder.
    about: String,
    /// The run's spec, every default filled in.
    spec: SweepSpec,
}

/// The cables of a several-cable map: the run's spec, and from it each
/// design's actuator.
#[derive(Debug, Clone, PartialEq)]
pub struct MapCables {
    spec: CablesGrid,
    solver: SolverOptions,
    output: OutputSpec,
}

/// A [`CABLES_FILE`] holding a planar sweep's spec.
#[derive(Debug, thiserror::Error)]
#[error("it holds a planar sweep's spec, not a cable sweep's")]
struct NotCables;

impl MapCables {
    /// The cables of the map of a run of `spec`.
    pub fn of_spec(spec: &CablesGrid, solver: &SolverOptions, output: &OutputSpec) -> Self {
        Self { spec: spec.clone(), solver: solver.clone(), output: output.clone() }
    }

    /// The cables of the map in `map_dir`: `None` for a map of one planar
    /// cable (which has no [`CABLES_FILE`]).
    pub fn open(map_dir: &Path) -> Result<Option<Self>, ReduceError> {
        let path = map_dir.join(CABLES_FILE);
        let text = match crate::io::read_utf8(&path) {
            Ok(text) => text,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(ReduceError::CablesFile { path, source: Box::new(e) }),
        };
        let file: CablesFile = serde_json::from_str(&text).map_err(|e| ReduceError::CablesFile { path: path.clone(), source: Box::new(e) })?;
        match file.spec.routings {
            RoutingGrid::Cables(spec) => Ok(Some(Self { spec, solver: file.spec.solver, output: file.spec.output })),
            RoutingGrid::Planar(_) => Err(ReduceError::CablesFile { path, source: Box::new(NotCables) }),
        }
    }

    /// Writes [`CABLES_FILE`] into `dir`.
    pub(crate) fn write(&self, dir: &Path) -> Result<(), ReduceError> {
        let file = CablesFile {
            about: "the cable sweep spec of this map: a design's routing_id (routing × tension combinations + combination) \
                    and this spec give every cable's routing and tension"
                .into(),
            spec: SweepSpec { routings: RoutingGrid::Cables(self.spec.clone()), solver: self.solver.clone(), output: self.output.clone() },
        };
        let path = dir.join(CABLES_FILE);
        let json = serde_json::to_string_pretty(&file).map_err(|source| ReduceError::WriteJson { path: path.clone(), source })? + "\n";
        super::tables::write_file(&path, json.as_bytes())
    }

    /// The run's cables and their grids.
    pub fn spec(&self) -> &CablesGrid {
        &self.spec
    }

    /// The run's solver settings.
    pub fn solver(&self) -> &SolverOptions {
        &self.solver
    }

    /// What the run's rows store.
    pub fn output(&self) -> &OutputSpec {
        &self.output
    }

    /// Cables per actuator.
    pub fn count(&self) -> usize {
        self.spec.actuator.cables.len()
    }

    /// The actuator of the design whose `routing_id` is `row_key`.
    pub fn actuator(&self, row_key: i64) -> Actuator {
        let (id, k) = row_of_key(row_key as u64, self.spec.actuation_combinations());
        self.spec.actuator_at(id, k)
    }

    /// The `cablemap simulate` command that solves the design whose
    /// `routing_id` is `row_key` again, with the map's rod and solver.
    pub fn command(&self, row_key: i64) -> SimulateCommand {
        simulate_command(&self.actuator(row_key), &self.solver)
    }

    /// Every cable's actuation of a design, e.g. `1.80, 0.80 N` (a
    /// displacement-driven cable's in mm: `2.50 mm, 0.80 N`).
    pub fn tensions_text(&self, row_key: i64) -> String {
        let cables = self.actuator(row_key).cables;
        if cables.iter().all(|c| c.displacement_mm.is_none()) {
            let tensions: Vec<String> = cables.iter().map(|c| format!("{:.2}", c.tension_n)).collect();
            return format!("{} N", tensions.join(", "));
        }
        let each: Vec<String> = cables.iter().map(|c| c.displacement_mm.map_or(format!("{:.2} N", c.tension_n), |d| format!("{d:.2} mm"))).collect();
        each.join(", ")
    }

    /// Every cable's routing and tension of a design, for a line of text:
    /// `cable 1 y = [3.00, …] mm at 1.800 N, cable 2 y = […] mm at 0.800 N`.
    pub fn design_text(&self, row_key: i64) -> String {
        let cables: Vec<String> = self
            .actuator(row_key)
            .cables
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let at = c.displacement_mm.map_or(format!("{:.3} N", c.tension_n), |d| format!("a displacement of {d:.3} mm"));
                format!("cable {} y = [{}] mm at {at}", i + 1, points(&c.y_mm))
            })
            .collect();
        cables.join(", ")
    }

    /// One sentence per cable for a map's header: its channel, which
    /// control points are swept over which levels, its tension grid and
    /// where it is knotted.
    pub fn describe(&self) -> Vec<String> {
        let list = |v: &[f64]| v.iter().map(|x| crate::io::fmt_num(*x)).collect::<Vec<_>>().join(", ");
        self.spec
            .actuator
            .cables
            .iter()
            .zip(&self.spec.grids)
            .enumerate()
            .map(|(i, (c, g))| {
                let mut s = format!("cable {}: y = [{}] mm", i + 1, list(&c.y_mm));
                for sweep in &g.sweeps {
                    let axis = if sweep.axis == Axis::Y { "y" } else { "z" };
                    let indices: Vec<String> = sweep.points.iter().map(|p| format!("{axis}{p}")).collect();
                    s.push_str(&format!(", {} swept over {} mm", indices.join(", "), list(&sweep.levels_mm)));
                }
                let t = &g.actuation;
                let (what, unit) = if g.by_displacement { ("displacement", "mm") } else { ("tension", "N") };
                if t.count <= 1 {
                    s.push_str(&format!("; {what} {} {unit}", crate::io::fmt_num(t.min)));
                } else {
                    s.push_str(&format!("; {what} {} … {} {unit} ({} values)", crate::io::fmt_num(t.min), crate::io::fmt_num(t.max), t.count));
                }
                match c.anchor_mm {
                    Some(anchor) => s.push_str(&format!("; knotted at s = {} mm", crate::io::fmt_num(anchor))),
                    None => s.push_str("; knotted at the tip"),
                }
                s
            })
            .collect()
    }
}

/// Control points to two decimals, as `feasible` prints a routing.
fn points(y: &[f64; CONTROL_POINTS]) -> String {
    y.iter().map(|v| format!("{v:.2}")).collect::<Vec<_>>().join(", ")
}

/// A map design's actuation for a line of text: `y = [..] mm, τ = .. N`
/// for a map of one cable, every cable's routing and tension for a map of
/// several (`cables`, [`MapCables::open`]).
pub fn design_actuation(cables: Option<&MapCables>, routing_id: i64, routing_mm: &[f64; CONTROL_POINTS], tension_n: f64) -> String {
    match cables {
        Some(cables) => cables.design_text(routing_id),
        None => format!("y = [{}] mm, τ = {tension_n:.3} N", points(routing_mm)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: &str = r#"
[rod.gravity]
enabled = false
[[cable]]
y_mm = [3, 3, 3, 3, 3]
tension_n = { min = 0.0, max = 2.0, count = 11 }
[[cable.sweep]]
axis = "y"
points = [1, 2]
levels_mm = [1.0, 2.5]
[[cable]]
y_mm = [-3, -3, -3, -3, -3]
anchor_mm = 40
tension_n = { min = 0.0, max = 2.0, count = 11 }
"#;

    #[test]
    fn row_keys_round_trip() {
        for (id, k, n) in [(0, 0, 1), (3, 5, 6), (12, 120, 121)] {
            assert_eq!(row_of_key(row_key(id, k, n), n), (id, k as usize));
        }
    }

    #[test]
    fn a_designs_row_key_gives_every_cable_and_the_file_reads_back() {
        let spec = SweepSpec::from_toml(SPEC, "test").unwrap();
        let cables = MapCables::of_spec(spec.cables().unwrap(), &spec.solver, &spec.output);
        // Routing 1 (y1 at its second level), combination 9·11 + 4: 1.8 N and 0.8 N.
        let key = row_key(1, 9 * 11 + 4, 121) as i64;
        let a = cables.actuator(key);
        assert_eq!(a.cables[0].y_mm, [3.0, 2.5, 1.0, 3.0, 3.0]);
        assert_eq!(a.cables.iter().map(|c| c.tension_n).collect::<Vec<_>>(), [1.8, 0.8]);
        assert_eq!(cables.tensions_text(key), "1.80, 0.80 N");
        assert_eq!(
            cables.design_text(key),
            "cable 1 y = [3.00, 2.50, 1.00, 3.00, 3.00] mm at 1.800 N, cable 2 y = [-3.00, -3.00, -3.00, -3.00, -3.00] mm at 0.800 N"
        );
        assert_eq!(
            cables.command(key).text,
            r#"cablemap simulate --no-gravity --cable "y=3,2.5,1,3,3 tension=1.8" --cable "y=-3,-3,-3,-3,-3 tension=0.8 anchor=40""#
        );
        let header = cables.describe();
        assert_eq!(header.len(), 2);
        assert!(header[0].contains("y1, y2 swept over 1, 2.5 mm; tension 0 … 2 N (11 values); knotted at the tip"), "{}", header[0]);
        assert!(header[1].ends_with("knotted at s = 40 mm"), "{}", header[1]);
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(MapCables::open(dir.path()).unwrap(), None, "a map of one cable");
        cables.write(dir.path()).unwrap();
        assert_eq!(MapCables::open(dir.path()).unwrap(), Some(cables));
    }
}
