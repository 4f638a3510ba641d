//! The spec of a sweep of several or spatial cables
//! (`cablemap-cables/1` runs): the actuator file's settings, each cable's
//! tension grid and which of its control points (y or z) are swept over
//! which levels. Every routing is solved through the product of the tension
//! grids by the 3-D solver; the rows carry one tension column per cable and
//! the 3-D tip (docs/schema.md, "Cable sweeps").
//!
//! ```toml
//! gravity_direction = [1, 0, 0]   # optional, as in the actuator file
//! [rod]                            # optional: model::Rod
//! [solver]                         # optional: SolverOptions (its spatial keys)
//! [output]
//! order = 3                        # a0…a3, a_bend_y0…, a_twist0…
//! cell_mm = 1.0                    # reach-map cell / voxel size
//! chunk_routings = 64              # routings per chunk file (engine chunks)
//!
//! [[cable]]                        # an antagonistic pair
//! y_mm = [2, 2, 2, 2, 2]           # fixed values (swept points override them)
//! tension_n = { min = 0.0, max = 2.0, count = 11 }
//! [[cable.sweep]]
//! axis = "y"
//! points = [1, 2, 3]               # each swept independently over the levels
//! levels_mm = [1.0, 2.5, 4.0]
//!
//! [[cable]]
//! y_mm = [-2, -2, -2, -2, -2]
//! tension_n = { min = 0.0, max = 2.0, count = 11 }
//! # or driven by its displacement (mm pulled in at the base; its tension
//! # found), with an optional stiffness:
//! # displacement_mm = { min = 0.0, max = 4.0, count = 9 }
//! # cable_ea_n = 2000.0
//! ```
//!
//! In memory the spec holds the model's own [`Actuator`] (every setting of
//! an actuator file is a setting of the sweep) and, per cable, what the
//! sweep varies ([`CableGrid`]). Routing ids are the mixed-radix numbers of
//! the swept levels (the first swept point fastest), and each routing's rows
//! are its tension combinations in grid order (cable 1's tension slowest),
//! solved in snake order for warm starts ([`solve::cable_routing`]); a chunk
//! holds `output.chunk_routings` routings.

use crate::model::routing::CONTROL_POINTS;
use crate::solver::spatial::SpatialError;
use crate::solver::SolverOptions;
use crate::model::{Actuator, Cable, Rod, MAX_CABLES};
use crate::shape::LengthBasis;
use crate::sweep::kind::{ChunkLayout, RowsCounted, RunKind, RunSpec, MAX_CHUNK_ROWS};
use crate::sweep::schema::{cable_batch, cable_schema, Axis, CableRow};
use crate::sweep::solve::{self, Stored, TensionCombinations};
use crate::sweep::spec::{OutputSpec, RoutingGrid, SpecError, SweepSpec};
use crate::sweep::SweepError;
use arrow::datatypes::SchemaRef;
use arrow::record_batch::RecordBatch;
use serde::{Deserialize, Serialize};

/// Most values in one tension grid.
pub const MAX_TENSION_COUNT: u32 = 10_000;

/// The kind of sweep of several or spatial cables: the actuator it varies,
/// how each cable varies and the solver settings. Its spec file is the TOML
/// above (and the same keys, in the same order, are the canonical JSON its
/// hash covers).
#[derive(Debug, Clone, PartialEq)]
pub struct CablesGrid {
    /// The actuator every routing varies: rod, torsion, gravity direction and
    /// each cable's fixed control points and anchor (its swept points at
    /// these values until a routing sets them), every tension 0 (a row's
    /// tensions come from [`Self::grids`]).
    pub actuator: Actuator,
    /// What the sweep varies of each cable, in the actuator's cable order.
    pub grids: Vec<CableGrid>,
}

/// What a sweep varies of one cable: its actuation (tension or
/// displacement) over a grid, and control points over levels.
#[derive(Debug, Clone, PartialEq)]
pub struct CableGrid {
    /// The grid of the cable's command: tensions, N, or (when
    /// `by_displacement`) displacements, mm.
    pub actuation: ValueGrid,
    /// Whether the cable is driven by its displacement (its tension found).
    pub by_displacement: bool,
    /// Its swept control points.
    pub sweeps: Vec<PointSweep>,
}

/// Control points of one axis of a cable, each swept over `levels_mm`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointSweep {
    /// `y` or `z`.
    pub axis: Axis,
    /// Control-point indices 0…4; each is swept independently (a product).
    pub points: Vec<usize>,
    /// The levels, mm.
    pub levels_mm: Vec<f64>,
}

/// `count` values evenly spaced from `min` to `max`: a cable's tensions (N)
/// or displacements (mm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ValueGrid {
    /// First value (≥ 0).
    pub min: f64,
    /// Last value (≥ min).
    pub max: f64,
    /// Number of values (1: `min` only).
    pub count: u32,
}

impl ValueGrid {
    /// The values.
    pub fn values(&self) -> Vec<f64> {
        if self.count <= 1 {
            return vec![self.min];
        }
        (0..self.count).map(|k| self.min + (self.max - self.min) * k as f64 / (self.count - 1) as f64).collect()
    }
}

/// The `[output]` table of a cable sweep spec: no centreline; the reach
/// maps' cell size.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct Output {
    order: usize,
    length_basis: LengthBasis,
    cell_mm: f64,
    chunk_routings: u32,
}

impl Default for Output {
    fn default() -> Self {
        Self { order: 3, length_basis: LengthBasis::Rest, cell_mm: 1.0, chunk_routings: 64 }
    }
}

/// The file layout of a cable sweep spec: an actuator file's keys, with each
/// `[[cable]]`'s tension a grid and its swept points, and `[solver]`,
/// `[output]`. The key order is the canonical JSON's, which the spec hash
/// of every run covers, so it is written out here rather than taken from
/// [`Actuator`]'s (whose cables come last); the conversions take
/// [`Actuator`] and [`Cable`] apart field by field, so a field added to
/// either does not compile until the format says where it goes.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SpecFile {
    #[serde(default)]
    rod: Rod,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    gj_n_mm2: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    gravity_direction: Option<[f64; 3]>,
    #[serde(default, with = "crate::solver::options::spatial_table")]
    solver: SolverOptions,
    #[serde(default)]
    output: Output,
    #[serde(rename = "cable")]
    cables: Vec<CableFile>,
}

/// One `[[cable]]` of [`SpecFile`]: a [`Cable`] whose tension is a grid,
/// with its swept points.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CableFile {
    y_mm: [f64; CONTROL_POINTS],
    #[serde(default)]
    z_mm: [f64; CONTROL_POINTS],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    anchor_mm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    tension_n: Option<ValueGrid>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    displacement_mm: Option<ValueGrid>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    cable_ea_n: Option<f64>,
    #[serde(default, rename = "sweep")]
    sweeps: Vec<PointSweep>,
}

impl SpecFile {
    /// The layout of a cable spec.
    pub(super) fn of(grid: &CablesGrid, solver: &SolverOptions, output: &OutputSpec) -> Self {
        let CablesGrid { actuator, grids } = grid.clone();
        let solver = solver.clone();
        let Actuator { rod, gj_n_mm2, gravity_direction, cables } = actuator;
        let cables = cables
            .into_iter()
            .zip(grids)
            .map(|(cable, grid)| {
                // The actuation is the grid's; the actuator's tension is always 0.
                let Cable { y_mm, z_mm, anchor_mm, cable_ea_n, .. } = cable;
                let (tension_n, displacement_mm) = if grid.by_displacement { (None, Some(grid.actuation)) } else { (Some(grid.actuation), None) };
                CableFile { y_mm, z_mm, anchor_mm, tension_n, displacement_mm, cable_ea_n, sweeps: grid.sweeps }
            })
            .collect();
        let OutputSpec { order, length_basis, cell_mm, chunk_routings, centreline: _ } = output.clone();
        let output = Output { order, length_basis, cell_mm: cell_mm.unwrap_or(Output::default().cell_mm), chunk_routings };
        SpecFile { rod, gj_n_mm2, gravity_direction, solver, output, cables }
    }

    /// The spec it lays out.
    pub(super) fn into_spec(self) -> Result<SweepSpec, SpecError> {
        let SpecFile { rod, gj_n_mm2, gravity_direction, solver, output, cables } = self;
        let (cables, grids) = cables
            .into_iter()
            .enumerate()
            .map(|(i, c)| {
                let CableFile { y_mm, z_mm, anchor_mm, tension_n, displacement_mm, cable_ea_n, sweeps } = c;
                let (actuation, by_displacement) = match (tension_n, displacement_mm) {
                    (Some(t), None) => (t, false),
                    (None, Some(d)) => (d, true),
                    (t, _) => return Err(SpecError::Actuation { cable: i + 1, both: t.is_some() }),
                };
                Ok((Cable { anchor_mm, cable_ea_n, ..Cable::spatial(y_mm, z_mm, 0.0) }, CableGrid { actuation, by_displacement, sweeps }))
            })
            .collect::<Result<Vec<_>, SpecError>>()?
            .into_iter()
            .unzip();
        let Output { order, length_basis, cell_mm, chunk_routings } = output;
        let grid = CablesGrid { actuator: Actuator { rod, gj_n_mm2, gravity_direction, cables }, grids };
        let output = OutputSpec { order, length_basis, centreline: false, cell_mm: Some(cell_mm), chunk_routings };
        Ok(SweepSpec { routings: RoutingGrid::Cables(grid), solver, output })
    }
}

/// Parses a cable spec's TOML (unchecked).
pub(super) fn from_toml(text: &str) -> Result<SweepSpec, SpecError> {
    toml::from_str::<SpecFile>(text)?.into_spec()
}

/// One swept dimension: cable, axis, control point, levels.
#[derive(Debug, Clone, PartialEq)]
struct Dimension {
    cable: usize,
    axis: Axis,
    point: usize,
    levels: Vec<f64>,
}

impl CablesGrid {
    fn dimensions(&self) -> Vec<Dimension> {
        let mut dims = Vec::new();
        for (cable, g) in self.grids.iter().enumerate() {
            for s in &g.sweeps {
                for &point in &s.points {
                    dims.push(Dimension { cable, axis: s.axis, point, levels: s.levels_mm.clone() });
                }
            }
        }
        dims
    }

    /// Number of routings (the product of the swept levels).
    pub fn routings(&self) -> u64 {
        self.dimensions().iter().map(|d| d.levels.len() as u64).product()
    }

    /// Number of actuation combinations per routing (rows per routing).
    pub fn actuation_combinations(&self) -> u64 {
        self.grids.iter().map(|g| u64::from(g.actuation.count.max(1))).product()
    }

    /// Checks the spec with its `output`; messages name the field.
    fn validate(&self, solver: &SolverOptions, output: &OutputSpec) -> Result<(), SpecError> {
        let cables = &self.actuator.cables;
        if cables.is_empty() || cables.len() > MAX_CABLES {
            return Err(SpecError::CableCount { count: cables.len() });
        }
        let length_mm = self.actuator.rod.length_mm;
        for (i, (c, g)) in cables.iter().zip(&self.grids).enumerate() {
            let cable = i + 1;
            let t = &g.actuation;
            let key = if g.by_displacement { "displacement_mm" } else { "tension_n" };
            if !(t.min.is_finite() && t.max.is_finite() && t.min >= 0.0 && t.max >= t.min) {
                return Err(SpecError::GridRange { cable, key, min: t.min, max: t.max });
            }
            if t.count == 0 || t.count > MAX_TENSION_COUNT {
                return Err(SpecError::GridCount { cable, key, count: t.count });
            }
            if g.by_displacement && t.max >= length_mm {
                return Err(SpecError::DisplacementBeyondRod { cable: Some(cable), max_mm: t.max, length_mm });
            }
            if let Some(ea_n) = c.cable_ea_n.filter(|ea| !(ea.is_finite() && *ea > 0.0)) {
                return Err(SpecError::CableStiffness { cable: Some(cable), ea_n });
            }
            if g.by_displacement && solver.method == crate::solver::SolverMethod::Rk4 {
                return Err(SpecError::DisplacementWithRk4 { cable: Some(cable) });
            }
            // The anchor is not swept: outside the rod, every routing's rows
            // would be invalid_routing.
            if let Some(anchor_mm) = c.anchor_mm {
                if !(anchor_mm.is_finite() && anchor_mm > 0.0 && anchor_mm <= length_mm) {
                    return Err(SpecError::Anchor { cable, anchor_mm, length_mm });
                }
            }
            let mut seen = std::collections::BTreeSet::new();
            for s in &g.sweeps {
                if s.levels_mm.is_empty() || s.levels_mm.iter().any(|v| !v.is_finite()) {
                    return Err(SpecError::NoLevels { cable });
                }
                if s.points.is_empty() {
                    return Err(SpecError::NoPoints { cable });
                }
                for &point in &s.points {
                    if point >= CONTROL_POINTS {
                        return Err(SpecError::NoSuchPoint { cable, point });
                    }
                    if !seen.insert((s.axis, point)) {
                        return Err(SpecError::SweptTwice { cable, axis: s.axis, point });
                    }
                }
            }
        }
        crate::solver::spatial::check_order(output.order, &solver).map_err(SpecError::SpatialOrder)?;
        if let Some(cell_mm) = output.cell_mm.filter(|c| !(c.is_finite() && *c > 0.0)) {
            return Err(SpecError::CellSize { cell_mm });
        }
        if output.chunk_routings == 0 {
            return Err(SpecError::NoChunkRoutings { cables: true });
        }
        let combinations = self.actuation_combinations();
        let chunk_rows = u64::from(output.chunk_routings).saturating_mul(combinations);
        if chunk_rows > MAX_CHUNK_ROWS {
            return Err(if combinations > MAX_CHUNK_ROWS {
                SpecError::TooManyCombinations { combinations }
            } else {
                SpecError::CombinationChunkRows {
                    chunk_routings: output.chunk_routings,
                    combinations,
                    chunk_rows,
                    most: MAX_CHUNK_ROWS / combinations,
                }
            });
        }
        // The base actuator (swept points at their first level) must be a
        // rod the backend serving it models; a routing's own faults are its
        // rows' status.
        let base = self.actuator_for(0, &self.dimensions());
        let served = base.channels().map_err(SpatialError::from).and_then(|_| Ok(crate::solver::Backend::serving(&base, solver, crate::solver::Given::default())?));
        match served {
            Err(SpatialError::Actuator(crate::model::ActuatorError::Parameter(e))) => return Err(SpecError::Rod(e)),
            Err(e @ SpatialError::Unsupported(_)) => return Err(SpecError::RodUnsupported(e)),
            Err(e @ SpatialError::Actuator(crate::model::ActuatorError::GravityDirection(_))) => return Err(SpecError::Gravity(e)),
            _ => {}
        }
        Ok(())
    }

    /// The actuator of routing `id` (mixed radix over the dimensions, the
    /// first fastest), tensions at zero.
    fn actuator_for(&self, id: u64, dims: &[Dimension]) -> Actuator {
        let mut actuator = self.actuator.clone();
        let mut k = id;
        for d in dims {
            let n = d.levels.len() as u64;
            let level = d.levels[(k % n) as usize];
            k /= n;
            let c = &mut actuator.cables[d.cable];
            match d.axis {
                Axis::Y => c.y_mm[d.point] = level,
                Axis::Z => c.z_mm[d.point] = level,
            }
        }
        actuator
    }

    /// Each cable's actuation grid: tensions, N, or displacements, mm.
    pub fn actuation_grids(&self) -> Vec<Vec<f64>> {
        self.grids.iter().map(|g| g.actuation.values()).collect()
    }

    /// Each cable's actuation grid, and which cables are driven by their displacement.
    pub fn combinations(&self) -> TensionCombinations {
        TensionCombinations::new(self.actuation_grids(), self.grids.iter().map(|g| g.by_displacement).collect())
    }

    /// Whether the run is planar: every cable and its swept points lie in
    /// the x–y plane (z ≡ 0) and gravity has no z component. Planar runs also
    /// get the planar feasibility maps.
    pub fn is_planar(&self) -> bool {
        self.actuator.cables.iter().all(Cable::is_planar)
            && self.grids.iter().all(|g| g.sweeps.iter().all(|s| s.axis == Axis::Y))
            && self.actuator.gravity_direction.is_none_or(|g| g[2] == 0.0)
    }

    /// Routing `id` and the tensions of its `k`-th combination (grid order):
    /// the actuator of the row with `routing_id = id` at that combination,
    /// e.g. to solve it again.
    pub fn actuator_at(&self, id: u64, k: usize) -> Actuator {
        let mut actuator = self.actuator_for(id, &self.dimensions());
        let grids = self.actuation_grids();
        let mut rest = k;
        for ((c, g), spec) in actuator.cables.iter_mut().zip(&grids).zip(&self.grids).rev() {
            let value = g[rest % g.len()];
            if spec.by_displacement {
                c.displacement_mm = Some(value);
            } else {
                c.tension_n = value;
            }
            rest /= g.len();
        }
        actuator
    }
}

/// What a worker of a cable sweep holds: the swept dimensions and the
/// tension combinations (computed once per worker).
#[derive(Debug, Clone)]
pub struct CableWorker {
    dims: Vec<Dimension>,
    combinations: TensionCombinations,
}

/// The sweep of several or spatial cables: each routing is solved by its
/// own 3-D solver through its tension combinations ([`solve::cable_routing`]).
impl RunSpec for CablesGrid {
    const KIND: RunKind = RunKind::Cables;
    type Worker = CableWorker;
    type Solved = Vec<CableRow>;

    fn check(&self, solver: &SolverOptions, output: &OutputSpec) -> Result<(), SpecError> {
        self.validate(solver, output)
    }

    fn rows_counted(&self) -> RowsCounted {
        RowsCounted::TensionCombinations
    }

    fn layout(&self, output: &OutputSpec) -> ChunkLayout {
        ChunkLayout::new(self.routings(), self.actuation_combinations(), u64::from(output.chunk_routings))
    }

    fn schema(&self, output: &OutputSpec) -> SchemaRef {
        cable_schema(self.actuator.cables.len(), output.order)
    }

    fn row_bytes(&self, _solver: &SolverOptions, output: &OutputSpec) -> u64 {
        // Per copy: the row (its cables' control points, tensions, pose and
        // three series) or its columns; three copies as for planar rows.
        let (cables, terms) = (self.actuator.cables.len() as u64, output.order as u64 + 1);
        3 * (256 + 96 * cables + 24 * terms)
    }

    fn worker(&self, _solver: &SolverOptions) -> Result<CableWorker, SweepError> {
        Ok(CableWorker { dims: self.dimensions(), combinations: self.combinations() })
    }

    fn solve(&self, solver: &SolverOptions, output: &OutputSpec, worker: &mut CableWorker, id: u64) -> Result<Vec<CableRow>, SweepError> {
        let actuator = self.actuator_for(id, &worker.dims);
        let stored = Stored { order: output.order, length_basis: output.length_basis, centreline: false };
        Ok(solve::cable_routing(id, actuator, solver, stored, &worker.combinations))
    }

    fn batch(&self, output: &OutputSpec, schema: &SchemaRef, solved: &[Vec<CableRow>]) -> RecordBatch {
        let rows: Vec<&CableRow> = solved.iter().flatten().collect();
        cable_batch(schema, &rows, self.actuator.cables.len(), output.order)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::effects::FRICTION;
    use crate::sweep::solve::combination_index;

    fn grid(text: &str) -> CablesGrid {
        SweepSpec::from_toml(text, "test").unwrap().cables().unwrap().clone()
    }

    const SPEC: &str = r#"
[rod.gravity]
enabled = false
[[cable]]
y_mm = [2, 2, 2, 2, 2]
tension_n = { min = 0.0, max = 1.0, count = 3 }
[[cable.sweep]]
axis = "y"
points = [1, 3]
levels_mm = [1.0, 3.0]
[[cable]]
y_mm = [-2, -2, -2, -2, -2]
tension_n = { min = 0.5, max = 1.0, count = 2 }
[[cable.sweep]]
axis = "z"
points = [4]
levels_mm = [0.0, 1.5, -1.5]
"#;

    #[test]
    fn spec_counts_routings_and_tensions() {
        let spec = grid(SPEC);
        assert_eq!(spec.routings(), 2 * 2 * 3);
        assert_eq!(spec.actuation_combinations(), 6);
        let dims = spec.dimensions();
        // Id 0: every swept point at its first level; id 1 moves the first dimension.
        let a0 = spec.actuator_for(0, &dims);
        assert_eq!(a0.cables[0].y_mm, [2.0, 1.0, 2.0, 1.0, 2.0]);
        assert_eq!(a0.cables[1].z_mm, [0.0; 5]);
        let a1 = spec.actuator_for(1, &dims);
        assert_eq!(a1.cables[0].y_mm, [2.0, 3.0, 2.0, 1.0, 2.0]);
        let last = spec.actuator_for(11, &dims);
        assert_eq!(last.cables[0].y_mm, [2.0, 3.0, 2.0, 3.0, 2.0]);
        assert_eq!(last.cables[1].z_mm, [0.0, 0.0, 0.0, 0.0, -1.5]);
    }

    #[test]
    fn the_file_layout_round_trips_in_its_key_order() {
        let spec = SweepSpec::from_toml(&format!("gj_n_mm2 = 4000\ngravity_direction = [1, 0, 0]\n{SPEC}"), "test").unwrap();
        let json = spec.canonical_json();
        // The canonical order (the spec hash covers it): the actuator's
        // settings, solver, output, then the cables with their grids.
        let at = |key: &str| json.find(&format!("\"{key}\"")).unwrap_or_else(|| panic!("{key} in {json}"));
        let keys = ["rod", "gj_n_mm2", "gravity_direction", "solver", "output", "cable", "y_mm", "z_mm", "tension_n", "sweep"];
        assert!(keys.windows(2).all(|w| at(w[0]) < at(w[1])), "{json}");
        assert!(!json.contains("anchor_mm"), "no anchor, no key: {json}");
        let back: SweepSpec = serde_json::from_str(&json).unwrap();
        assert_eq!(back, spec);
        let back = back.cables().unwrap();
        assert_eq!(back.actuator.gj_n_mm2, Some(4000.0));
        assert!(back.actuator.cables.iter().all(|c| c.tension_n == 0.0));
    }

    #[test]
    fn a_routings_rows_are_in_grid_order_and_actuator_at_rebuilds_each() {
        let whole = SweepSpec::from_toml(SPEC, "test").unwrap();
        let (spec, output) = (whole.cables().unwrap(), &whole.output);
        let layout = whole.layout();
        assert_eq!((layout.routings, layout.tensions), (12, 6));
        let mut worker = spec.worker(&whole.solver).unwrap();
        let rows = spec.solve(&whole.solver, output, &mut worker, 7).unwrap();
        assert_eq!(rows.len(), 6);
        let grids = spec.actuation_grids();
        for (k, row) in rows.iter().enumerate() {
            assert_eq!(row.routing_id, 7);
            let combo: Vec<usize> = row.tensions.iter().zip(&grids).map(|(t, g)| g.iter().position(|v| v == t).unwrap()).collect();
            assert_eq!(combination_index(&combo, &grids), k, "grid order, cable 1 slowest");
            let actuator = spec.actuator_at(7, k);
            assert_eq!(actuator.cables.iter().map(|c| c.tension_n).collect::<Vec<_>>(), row.tensions);
            assert_eq!(actuator.cables.iter().map(|c| (c.y_mm, c.z_mm)).collect::<Vec<_>>(), row.cables);
        }
        // The batch has the fixed schema whatever the rows' nulls.
        let schema = whole.schema();
        let batch = spec.batch(output, &schema, &[rows]);
        assert_eq!(batch.schema(), schema);
        assert_eq!(batch.num_rows(), 6);
    }

    #[test]
    fn bad_specs_name_the_problem() {
        for (text, needle) in [
            (SPEC.replace("points = [1, 3]", "points = [1, 5]"), "control point 5"),
            (SPEC.replace("points = [1, 3]", "points = [1, 1]"), "swept twice"),
            (SPEC.replace("count = 3", "count = 0"), "count = 0"),
            (SPEC.replace("min = 0.5", "min = -0.5"), "0 ≤ min"),
            (SPEC.replace("levels_mm = [1.0, 3.0]", "levels_mm = []"), "levels_mm"),
            (
                format!("{}\n[solver]\nmethod = \"rk4\"\n", SPEC.replace("[rod.gravity]", &format!("[rod.effects]\n{} = 0.1\n[rod.gravity]", FRICTION.key))),
                FRICTION.key,
            ),
            (format!("{SPEC}\n[output]\norder = 7\n[solver]\nmethod = \"rk4\"\n"), "steps_per_span"),
            (format!("{SPEC}\n[output]\norder = 9\n"), "highest order 8"),
            (SPEC.replace("axis = \"z\"", "axis = \"x\""), "unknown variant"),
            (
                SPEC.replace("y_mm = [2, 2, 2, 2, 2]", "y_mm = [2, 2, 2, 2, 2]\nanchor_mm = -1"),
                "cable 1: anchor_mm = -1 must lie on the rod",
            ),
            (SPEC.replace("y_mm = [-2, -2, -2, -2, -2]", "y_mm = [-2, -2, -2, -2, -2]\nanchor_mm = 70"), "cable 2: anchor_mm = 70"),
        ] {
            let e = SweepSpec::from_toml(&text, "spec.toml").unwrap_err().to_string();
            assert!(e.contains(needle) && e.contains("spec.toml"), "{needle}: {e}");
        }
        // Without a cable, the layout of a cable spec has nothing to sweep.
        assert!(from_toml("cable = []\n[rod]\n").is_ok_and(|s| s.validate().unwrap_err().to_string().contains("[[cable]]")));
        assert!(from_toml("[rod]\n").unwrap_err().to_string().contains("cable"));
    }
}
