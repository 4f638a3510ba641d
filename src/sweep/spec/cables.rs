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
//! [solver]                         # optional: SpatialOptions
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
use crate::solver::spatial::{SpatialError, SpatialOptions};
use crate::model::{Actuator, Cable, Rod, MAX_CABLES};
use crate::shape::LengthBasis;
use crate::sweep::kind::{ChunkLayout, InvalidSpec, RowsCounted, RunSpec, MAX_CHUNK_ROWS, MAX_ROWS};
use crate::sweep::schema::{cable_batch, cable_schema, Axis, CableRow};
use crate::sweep::solve::{self, Stored, TensionCombinations};
use crate::sweep::SweepError;
use arrow::datatypes::SchemaRef;
use arrow::record_batch::RecordBatch;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

/// Most values in one tension grid.
pub const MAX_TENSION_COUNT: u32 = 10_000;

/// A cable sweep job: the actuator it varies, how each cable varies, the
/// solver settings and what to store. Reads and writes the TOML above (and
/// the same keys, in the same order, as the canonical JSON its hash covers).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "SpecFile", into = "SpecFile")]
pub struct CableSweepSpec {
    /// The actuator every routing varies: rod, torsion, gravity direction and
    /// each cable's fixed control points and anchor (its swept points at
    /// these values until a routing sets them), every tension 0 (a row's
    /// tensions come from [`Self::grids`]).
    pub actuator: Actuator,
    /// What the sweep varies of each cable, in the actuator's cable order.
    pub grids: Vec<CableGrid>,
    /// Numerical settings of the 3-D solver.
    pub solver: SpatialOptions,
    /// What each row stores; the map resolution.
    pub output: CableOutputSpec,
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

/// Output settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CableOutputSpec {
    /// Highest Legendre order stored (each of the three series).
    pub order: usize,
    /// Basis of the coefficients.
    pub length_basis: LengthBasis,
    /// Cell size of the reach maps, mm.
    pub cell_mm: f64,
    /// Routings per chunk file (each chunk is built in memory: at most
    /// [`MAX_CHUNK_ROWS`] rows with the tension combinations).
    pub chunk_routings: u32,
}

impl Default for CableOutputSpec {
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
struct SpecFile {
    #[serde(default)]
    rod: Rod,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    gj_n_mm2: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    gravity_direction: Option<[f64; 3]>,
    #[serde(default)]
    solver: SpatialOptions,
    #[serde(default)]
    output: CableOutputSpec,
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

impl TryFrom<SpecFile> for CableSweepSpec {
    type Error = CableSpecError;

    fn try_from(file: SpecFile) -> Result<Self, CableSpecError> {
        let SpecFile { rod, gj_n_mm2, gravity_direction, solver, output, cables } = file;
        let (cables, grids) = cables
            .into_iter()
            .enumerate()
            .map(|(i, c)| {
                let CableFile { y_mm, z_mm, anchor_mm, tension_n, displacement_mm, cable_ea_n, sweeps } = c;
                let (actuation, by_displacement) = match (tension_n, displacement_mm) {
                    (Some(t), None) => (t, false),
                    (None, Some(d)) => (d, true),
                    (t, _) => return Err(CableSpecError::Actuation { cable: i + 1, both: t.is_some() }),
                };
                Ok((Cable { anchor_mm, cable_ea_n, ..Cable::spatial(y_mm, z_mm, 0.0) }, CableGrid { actuation, by_displacement, sweeps }))
            })
            .collect::<Result<Vec<_>, CableSpecError>>()?
            .into_iter()
            .unzip();
        Ok(Self { actuator: Actuator { rod, gj_n_mm2, gravity_direction, cables }, grids, solver, output })
    }
}

impl From<CableSweepSpec> for SpecFile {
    fn from(spec: CableSweepSpec) -> Self {
        let CableSweepSpec { actuator, grids, solver, output } = spec;
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
        SpecFile { rod, gj_n_mm2, gravity_direction, solver, output, cables }
    }
}

/// What is wrong with a cable sweep spec: the cable and setting, and what
/// to do.
#[derive(Debug, thiserror::Error)]
pub enum CableSpecError {
    /// The TOML text does not parse, has unknown keys or a bad `[[cable]]`.
    #[error("{0}")]
    Toml(#[from] toml::de::Error),
    /// A cable with neither or both of a tension grid and a displacement grid.
    #[error(
        "cable {cable}: give {} of tension_n = {{ min, max, count }} (N) and displacement_mm = {{ min, max, count }} (mm)",
        if *both { "only one" } else { "one" }
    )]
    Actuation {
        /// The cable, from 1.
        cable: usize,
        /// Whether both were given (else neither).
        both: bool,
    },
    /// Too few or too many cables.
    #[error("give 1 to {MAX_CABLES} [[cable]] tables, got {count}")]
    CableCount {
        /// The cables given.
        count: usize,
    },
    /// A grid's range.
    #[error("cable {cable}: {key} needs 0 ≤ min ≤ max (finite), got min = {min}, max = {max}")]
    GridRange {
        /// The cable, from 1.
        cable: usize,
        /// `tension_n` or `displacement_mm`.
        key: &'static str,
        /// Its first value.
        min: f64,
        /// Its last value.
        max: f64,
    },
    /// A grid's count.
    #[error("cable {cable}: {key}.count = {count} must be 1 … {MAX_TENSION_COUNT}")]
    GridCount {
        /// The cable, from 1.
        cable: usize,
        /// `tension_n` or `displacement_mm`.
        key: &'static str,
        /// The count given.
        count: u32,
    },
    /// A displacement as long as the rod.
    #[error("cable {cable}: displacement_mm.max = {max_mm} is not shorter than the rod ({length_mm} mm): a cable cannot be pulled in by its length")]
    DisplacementBeyondRod {
        /// The cable, from 1.
        cable: usize,
        /// The largest displacement, mm.
        max_mm: f64,
        /// The rod's length, mm.
        length_mm: f64,
    },
    /// A cable stiffness that is not a stiffness.
    #[error("cable {cable}: cable_ea_n = {ea_n} must be a finite stiffness > 0 N (leave it out for an inextensible cable)")]
    CableStiffness {
        /// The cable, from 1.
        cable: usize,
        /// The stiffness given, N.
        ea_n: f64,
    },
    /// Displacement driving with the method that cannot meet it.
    #[error(
        "cable {cable} is driven by its displacement: [solver] method = \"rk4\" does not integrate the cables' paths; use the default \
         collocation"
    )]
    DisplacementWithRk4 {
        /// The cable, from 1.
        cable: usize,
    },
    /// An anchor off the rod.
    #[error(
        "cable {cable}: anchor_mm = {} must lie on the rod, in (0, {length_mm}] mm (the rod's length_mm; leave anchor_mm out for the tip)",
        crate::io::fmt_num(*anchor_mm)
    )]
    Anchor {
        /// The cable, from 1.
        cable: usize,
        /// The anchor given, mm.
        anchor_mm: f64,
        /// The rod's length, mm.
        length_mm: f64,
    },
    /// A sweep without finite levels.
    #[error("cable {cable}: a sweep needs at least one finite level in levels_mm")]
    NoLevels {
        /// The cable, from 1.
        cable: usize,
    },
    /// A sweep without control points.
    #[error("cable {cable}: a sweep needs at least one control point in points (0 … 4)")]
    NoPoints {
        /// The cable, from 1.
        cable: usize,
    },
    /// A control point that does not exist.
    #[error("cable {cable}: control point {point} does not exist (points are 0 … 4)")]
    NoSuchPoint {
        /// The cable, from 1.
        cable: usize,
        /// The point given.
        point: usize,
    },
    /// A control point swept twice.
    #[error("cable {cable}: {} control point {point} is swept twice", axis.name())]
    SweptTwice {
        /// The cable, from 1.
        cable: usize,
        /// The axis.
        axis: Axis,
        /// The point.
        point: usize,
    },
    /// An order the 3-D solver's settings do not resolve.
    #[error("{0}")]
    Order(#[source] SpatialError),
    /// A cell size that is not a length.
    #[error("output.cell_mm = {cell_mm} must be a positive length")]
    CellSize {
        /// The cell size given, mm.
        cell_mm: f64,
    },
    /// `chunk_routings = 0`.
    #[error("output.chunk_routings = 0: a chunk needs at least one routing")]
    NoChunkRoutings,
    /// More rows per routing than a chunk may hold.
    #[error(
        "{combinations} tension combinations per routing (the product of the cables' tension_n.count) is more than {MAX_CHUNK_ROWS} \
         rows per chunk: use fewer tensions"
    )]
    TooManyCombinations {
        /// Rows per routing.
        combinations: u64,
    },
    /// More rows per chunk than a chunk may hold.
    #[error(
        "output.chunk_routings = {chunk_routings} × {combinations} tension combinations gives {chunk_rows} rows per chunk, more than \
         {MAX_CHUNK_ROWS} (each chunk is built in memory): lower chunk_routings to ≤ {most}"
    )]
    ChunkRows {
        /// Routings per chunk.
        chunk_routings: u32,
        /// Rows per routing.
        combinations: u64,
        /// Rows per chunk.
        chunk_rows: u64,
        /// The most routings per chunk.
        most: u64,
    },
    /// The rod's parameters.
    #[error("{0}")]
    Rod(#[source] crate::model::ParameterError),
    /// A rod the 3-D solver does not model.
    #[error("[rod] {0}")]
    RodUnsupported(#[source] SpatialError),
    /// The gravity direction.
    #[error("{0}")]
    Gravity(#[source] SpatialError),
}

/// One swept dimension: cable, axis, control point, levels.
#[derive(Debug, Clone, PartialEq)]
struct Dimension {
    cable: usize,
    axis: Axis,
    point: usize,
    levels: Vec<f64>,
}

impl CableSweepSpec {
    /// Reads and checks a spec; `origin` names it in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<Self, SweepError> {
        let bad = |source| SweepError::BadCableSpec { origin: origin.into(), source };
        let spec: Self = toml::from_str(text).map_err(|e| bad(CableSpecError::Toml(e)))?;
        spec.validate().map_err(bad)?;
        Ok(spec)
    }

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

    /// Checks the spec; messages name the field.
    pub fn validate(&self) -> Result<(), CableSpecError> {
        let cables = &self.actuator.cables;
        if cables.is_empty() || cables.len() > MAX_CABLES {
            return Err(CableSpecError::CableCount { count: cables.len() });
        }
        let length_mm = self.actuator.rod.length_mm;
        for (i, (c, g)) in cables.iter().zip(&self.grids).enumerate() {
            let cable = i + 1;
            let t = &g.actuation;
            let key = if g.by_displacement { "displacement_mm" } else { "tension_n" };
            if !(t.min.is_finite() && t.max.is_finite() && t.min >= 0.0 && t.max >= t.min) {
                return Err(CableSpecError::GridRange { cable, key, min: t.min, max: t.max });
            }
            if t.count == 0 || t.count > MAX_TENSION_COUNT {
                return Err(CableSpecError::GridCount { cable, key, count: t.count });
            }
            if g.by_displacement && t.max >= length_mm {
                return Err(CableSpecError::DisplacementBeyondRod { cable, max_mm: t.max, length_mm });
            }
            if let Some(ea_n) = c.cable_ea_n.filter(|ea| !(ea.is_finite() && *ea > 0.0)) {
                return Err(CableSpecError::CableStiffness { cable, ea_n });
            }
            if g.by_displacement && self.solver.method == crate::solver::SolverMethod::Rk4 {
                return Err(CableSpecError::DisplacementWithRk4 { cable });
            }
            // The anchor is not swept: outside the rod, every routing's rows
            // would be invalid_routing.
            if let Some(anchor_mm) = c.anchor_mm {
                if !(anchor_mm.is_finite() && anchor_mm > 0.0 && anchor_mm <= length_mm) {
                    return Err(CableSpecError::Anchor { cable, anchor_mm, length_mm });
                }
            }
            let mut seen = std::collections::BTreeSet::new();
            for s in &g.sweeps {
                if s.levels_mm.is_empty() || s.levels_mm.iter().any(|v| !v.is_finite()) {
                    return Err(CableSpecError::NoLevels { cable });
                }
                if s.points.is_empty() {
                    return Err(CableSpecError::NoPoints { cable });
                }
                for &point in &s.points {
                    if point >= CONTROL_POINTS {
                        return Err(CableSpecError::NoSuchPoint { cable, point });
                    }
                    if !seen.insert((s.axis, point)) {
                        return Err(CableSpecError::SweptTwice { cable, axis: s.axis, point });
                    }
                }
            }
        }
        crate::solver::spatial::check_order(self.output.order, &self.solver).map_err(CableSpecError::Order)?;
        if !(self.output.cell_mm.is_finite() && self.output.cell_mm > 0.0) {
            return Err(CableSpecError::CellSize { cell_mm: self.output.cell_mm });
        }
        if self.output.chunk_routings == 0 {
            return Err(CableSpecError::NoChunkRoutings);
        }
        let combinations = self.actuation_combinations();
        let chunk_rows = u64::from(self.output.chunk_routings).saturating_mul(combinations);
        if chunk_rows > MAX_CHUNK_ROWS {
            return Err(if combinations > MAX_CHUNK_ROWS {
                CableSpecError::TooManyCombinations { combinations }
            } else {
                CableSpecError::ChunkRows {
                    chunk_routings: self.output.chunk_routings,
                    combinations,
                    chunk_rows,
                    most: MAX_CHUNK_ROWS / combinations,
                }
            });
        }
        // The base actuator (swept points at their first level) must be a
        // rod the 3-D solver models; a routing's own faults are its rows' status.
        let base = self.actuator_for(0, &self.dimensions());
        match crate::solver::spatial::validated_channels(&base, crate::solver::Backend::spatial(self.solver.method)) {
            Err(SpatialError::Actuator(crate::model::ActuatorError::Parameter(e))) => return Err(CableSpecError::Rod(e)),
            Err(e @ SpatialError::Unsupported(_)) => return Err(CableSpecError::RodUnsupported(e)),
            Err(e @ SpatialError::Actuator(crate::model::ActuatorError::GravityDirection(_))) => return Err(CableSpecError::Gravity(e)),
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
impl RunSpec for CableSweepSpec {
    const FORMAT: &'static str = crate::io::run_markers::CABLES_FORMAT;
    const KIND: &'static str = "cable sweep";
    type Worker = CableWorker;
    type Solved = Vec<CableRow>;

    fn check(&self) -> Result<(), InvalidSpec> {
        self.validate().map_err(InvalidSpec::Cables)
    }

    fn check_run_size(&self, allow_large: bool) -> Result<(), SweepError> {
        let (routings, per_routing) = (self.routings(), self.actuation_combinations());
        let rows = routings.saturating_mul(per_routing);
        if rows > MAX_ROWS && !allow_large {
            return Err(SweepError::TooLarge { rows, routings, per_routing, counted: RowsCounted::TensionCombinations });
        }
        Ok(())
    }

    fn canonical_json(&self) -> String {
        serde_json::to_string(self).expect("spec serialises")
    }

    fn hash_hex(&self) -> String {
        Sha256::digest(self.canonical_json().as_bytes()).iter().map(|b| format!("{b:02x}")).collect()
    }

    fn length_basis(&self) -> LengthBasis {
        self.output.length_basis
    }

    fn order(&self) -> usize {
        self.output.order
    }

    fn layout(&self) -> ChunkLayout {
        ChunkLayout::new(self.routings(), self.actuation_combinations(), u64::from(self.output.chunk_routings))
    }

    fn schema(&self) -> SchemaRef {
        cable_schema(self.actuator.cables.len(), self.output.order)
    }

    fn row_bytes(&self) -> u64 {
        // Per copy: the row (its cables' control points, tensions, pose and
        // three series) or its columns; three copies as for planar rows.
        let (cables, terms) = (self.actuator.cables.len() as u64, self.output.order as u64 + 1);
        3 * (256 + 96 * cables + 24 * terms)
    }

    fn worker(&self) -> Result<CableWorker, SweepError> {
        Ok(CableWorker { dims: self.dimensions(), combinations: self.combinations() })
    }

    fn solve(&self, worker: &mut CableWorker, id: u64) -> Result<Vec<CableRow>, SweepError> {
        let actuator = self.actuator_for(id, &worker.dims);
        let stored = Stored { order: self.output.order, length_basis: self.output.length_basis, centreline: false };
        Ok(solve::cable_routing(id, actuator, &self.solver, stored, &worker.combinations))
    }

    fn batch(&self, schema: &SchemaRef, solved: &[Vec<CableRow>]) -> RecordBatch {
        let rows: Vec<&CableRow> = solved.iter().flatten().collect();
        cable_batch(schema, &rows, self.actuator.cables.len(), self.output.order)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::effects::FRICTION;
    use crate::sweep::solve::combination_index;

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
        let spec = CableSweepSpec::from_toml(SPEC, "test").unwrap();
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
        let spec = CableSweepSpec::from_toml(&format!("gj_n_mm2 = 4000\ngravity_direction = [1, 0, 0]\n{SPEC}"), "test").unwrap();
        let json = spec.canonical_json();
        // The canonical order (the spec hash covers it): the actuator's
        // settings, solver, output, then the cables with their grids.
        let at = |key: &str| json.find(&format!("\"{key}\"")).unwrap_or_else(|| panic!("{key} in {json}"));
        let keys = ["rod", "gj_n_mm2", "gravity_direction", "solver", "output", "cable", "y_mm", "z_mm", "tension_n", "sweep"];
        assert!(keys.windows(2).all(|w| at(w[0]) < at(w[1])), "{json}");
        assert!(!json.contains("anchor_mm"), "no anchor, no key: {json}");
        let back: CableSweepSpec = serde_json::from_str(&json).unwrap();
        assert_eq!(back, spec);
        assert_eq!(back.actuator.gj_n_mm2, Some(4000.0));
        assert!(back.actuator.cables.iter().all(|c| c.tension_n == 0.0));
    }

    #[test]
    fn a_routings_rows_are_in_grid_order_and_actuator_at_rebuilds_each() {
        let spec = CableSweepSpec::from_toml(SPEC, "test").unwrap();
        let layout = spec.layout();
        assert_eq!((layout.routings, layout.tensions), (12, 6));
        let mut worker = spec.worker().unwrap();
        let rows = spec.solve(&mut worker, 7).unwrap();
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
        let schema = spec.schema();
        let batch = spec.batch(&schema, &[rows]);
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
            ("[rod]\n".to_string(), "cable"),
        ] {
            let e = CableSweepSpec::from_toml(&text, "spec.toml").unwrap_err().to_string();
            assert!(e.contains(needle) && e.contains("spec.toml"), "{needle}: {e}");
        }
    }
}
