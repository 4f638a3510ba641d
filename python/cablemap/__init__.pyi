"""Type stubs of cablemap (the Python package over the Rust library)."""

import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from .errors import BadInputError as BadInputError
from .errors import CablemapError as CablemapError
from .errors import FileFormatError as FileFormatError
from .errors import SolveError as SolveError

PathLike = Union[str, os.PathLike[str]]

class Actuator:
    """The rod (thesis defaults) and 0–8 cables; fields by their TOML names."""

    def __init__(self, **fields: Any) -> None: ...
    @classmethod
    def thesis(cls) -> Actuator: ...
    @classmethod
    def read(cls, path: PathLike) -> Actuator: ...
    @classmethod
    def read_rod(cls, path: PathLike) -> Actuator: ...
    def with_fields(self, **fields: Any) -> Actuator: ...
    def to_dict(self) -> Dict[str, Any]: ...
    def to_toml(self) -> str: ...
    def write(self, path: PathLike) -> None: ...
    @property
    def rod(self) -> Dict[str, Any]: ...
    @property
    def cables(self) -> List[Dict[str, Any]]: ...

class Simulation:
    """One solve: `cablemap simulate --json`'s fields as attributes."""

    centreline: np.ndarray
    centreline_columns: List[str]
    status: str
    tension_n: Any
    displacement_mm: Any
    tip_x_mm: float
    tip_y_mm: float
    tip_angle_rad: float
    length_mm: float
    iterations: int
    a: List[float]
    length_basis: str
    def __getattr__(self, name: str) -> Any: ...
    def to_dict(self) -> Dict[str, Any]: ...

def simulate(
    routing_mm: Optional[Sequence[float]] = ...,
    tension_n: Optional[float] = ...,
    *,
    displacement_mm: Optional[float] = ...,
    cable_ea_n: Optional[float] = ...,
    cables: Optional[List[Dict[str, Any]]] = ...,
    actuator: Union[Actuator, PathLike, None] = ...,
    gravity_direction: Optional[Sequence[float]] = ...,
    order: int = ...,
    length_basis: str = ...,
    method: Optional[str] = ...,
    nodes_per_span: Optional[int] = ...,
    steps_per_span: Optional[int] = ...,
    direction: Optional[str] = ...,
    dwell_s: Optional[float] = ...,
    **actuator_fields: Any,
) -> Simulation: ...
def solve_batch(
    routings_mm: Any,
    tensions_n: Any,
    *,
    actuator: Union[Actuator, PathLike, None] = ...,
    order: int = ...,
    length_basis: str = ...,
    method: Optional[str] = ...,
    nodes_per_span: Optional[int] = ...,
    steps_per_span: Optional[int] = ...,
    threads: Optional[int] = ...,
    **actuator_fields: Any,
) -> Dict[str, np.ndarray]: ...

# ---------------------------------------------------------------- data: sweep, reduce, read_run, read_map (_data.py)

import polars as _pl

Shard = Union[str, Tuple[int, int], None]

class SweepReport:
    """What one shard's sweep did: `cablemap sweep --json`'s object as
    attributes (`summary`: this call's rows, chunks, wall time, statuses;
    `run`: the run directory's state after it, as `cablemap status --json`),
    `text` (what the command prints) and `note` (the command's note about
    the spec, or None)."""

    text: str
    note: Optional[str]
    summary: Dict[str, Any]
    run: Dict[str, Any]
    @property
    def run_dir(self) -> str:
        """The run directory written."""
    @property
    def rows_written(self) -> int:
        """Rows solved and written by this call."""
    @property
    def wall_s(self) -> float:
        """Wall time of this call, s."""
    @property
    def complete(self) -> bool:
        """Every row of the run is written (all shards done)."""
    def __getattr__(self, name: str) -> Any: ...
    def to_dict(self) -> Dict[str, Any]:
        """The report as `cablemap sweep --json` prints it."""

class ReduceReport:
    """A map written: `cablemap reduce --json`'s object as attributes
    (`summary`, `map_dir`, `total_s`, `pictures`; a cable sweep's map:
    `planar_summary`, `planar_pictures`), `text` (what the command prints)
    and `tables` (the tables written, name to file)."""

    text: str
    tables: Dict[str, str]
    summary: Dict[str, Any]
    map_dir: str
    total_s: float
    @property
    def rows(self) -> int:
        """Rows mapped (a planar map: mirror images included)."""
    def __getattr__(self, name: str) -> Any: ...
    def to_dict(self) -> Dict[str, Any]:
        """The report as `cablemap reduce --json` prints it."""

def sweep(
    spec: Optional[PathLike],
    out: PathLike,
    shard: Shard = ...,
    *,
    threads: Optional[int] = ...,
    allow_large: bool = ...,
    progress: bool = ...,
) -> SweepReport:
    """Runs a sweep spec (the thesis spec when None) into the run directory
    `out`, as `cablemap sweep SPEC --out OUT` (GIL released; re-running
    resumes). `shard`: "i/n" or (i, n) for `--shard i --shards n`, None the
    whole sweep. Raises BadInputError / FileFormatError with the library's
    messages."""

def reduce(
    run: PathLike,
    out: PathLike,
    *,
    partial: bool = ...,
    cell_mm: Optional[float] = ...,
    a0_bounds: Optional[Sequence[float]] = ...,
    a1_bounds: Optional[Sequence[float]] = ...,
    designs_per_cell: int = ...,
    memory_samples: Optional[int] = ...,
) -> ReduceReport:
    """Reduces a run directory (either kind) into the map directory `out`,
    as `cablemap reduce RUN --out OUT`; the keywords are its flags."""

def read_run(run: PathLike, *, partial: bool = ...) -> _pl.DataFrame:
    """A run's rows as one polars DataFrame in row order, the columns of
    docs/schema.md; the chunk files are those the library checks and lists.
    An unfinished run is refused unless `partial`."""

def read_map(path: PathLike) -> Dict[str, _pl.DataFrame]:
    """Every table of a map directory, keyed by table name: `cells`, `modes`,
    `designs` (a cable sweep's map: `reach_xy`, `reach_xz`, `reach_yz`,
    `reach_3d`, and its planar map's `cells`, `modes`, `designs`)."""

# ---------------------------------------------------------------- reports
# design, feasible, calibrate, diagnose, predict (python/cablemap/_reports.py)

from typing import Iterable, Mapping

class Report:
    """A workflow's report: the command's `--json` fields as attributes.

    `to_dict()` is exactly that object; `text` (and `str(report)`) the report
    the command prints without `--json`; `pictures` the paths of the pictures
    the workflow wrote (PNG, SVG), embedded by `_repr_html_` in notebooks.
    """

    text: str
    pictures: List[str]
    def __getattr__(self, name: str) -> Any: ...
    def to_dict(self) -> Dict[str, Any]:
        """The command's `--json` object, exactly."""
    def _repr_html_(self) -> str:
        """The summary, the pictures (PNG as base64, SVG inline) and the text report."""

class DesignReport(Report):
    """`cablemap design --json`: routing_mm, tension_n, tip_x_mm, tip_y_mm, a, error_pct, met, unmet, cost, …
    (with targets=: cables, targets, met, unmet, cost, method, …)."""

    met: bool
    unmet: List[str]
    cost: float

class FeasibleReport(Report):
    """`cablemap feasible --json`: verdict, reasons, tip_cell, coefficients, mode, nearest, …"""

class CalibrateReport(Report):
    """`cablemap calibrate --json`: the fitted parameters with standard errors, correlation, RMS errors, …"""

class DiagnoseReport(Report):
    """`cablemap diagnose --json`: verdict, reason, effects, parameter, candidates, baseline/extended/best fits, report."""

    verdict: str
    reason: str

class PredictReport(Report):
    """`cablemap predict --json`: actuator, captures (each capture's marker errors), rms_by_marker_mm, rms_mm."""

    rms_mm: float

def design(
    target: Union[str, Mapping[str, float], None] = ...,
    *,
    targets: Optional[PathLike] = ...,
    actuator: Union[Actuator, PathLike, None] = ...,
    weights: Union[str, Mapping[str, float], None] = ...,
    map: Optional[PathLike] = ...,
    tension_min_n: Optional[float] = ...,
    tension_max_n: Optional[float] = ...,
    max_offset_mm: Optional[float] = ...,
    length_basis: str = ...,
    starts: Optional[int] = ...,
    max_evaluations: Optional[int] = ...,
    tolerance_pct: Optional[float] = ...,
    out: Optional[PathLike] = ...,
    moulds: bool = ...,
    wall_mm: Optional[float] = ...,
    tube_diameter_mm: Optional[float] = ...,
    clearance_mm: Optional[float] = ...,
    clamp_mm: Optional[float] = ...,
    min_skin_mm: Optional[float] = ...,
    method: Optional[str] = ...,
    nodes_per_span: Optional[int] = ...,
    steps_per_span: Optional[int] = ...,
    **actuator_fields: Any,
) -> DesignReport:
    """`cablemap design --json`: target= (one planar cable, eq. 3.17) or targets=FILE.toml (several cables, actuator=FILE.toml)."""

def feasible(
    target: Union[str, Mapping[str, float], None] = ...,
    *,
    map: Optional[PathLike] = ...,
    study: Optional[PathLike] = ...,
    targets: Optional[PathLike] = ...,
    weights: Union[str, Mapping[str, float], None] = ...,
    nearest: int = ...,
    length_basis: str = ...,
) -> FeasibleReport:
    """`cablemap feasible --json`: a map's (map=) or a study's (study=) verdict on a target, or a cable sweep's map on targets=FILE.toml."""

def calibrate(
    data: PathLike,
    *,
    actuator: Optional[PathLike] = ...,
    markers: Optional[PathLike] = ...,
    centrelines: Optional[PathLike] = ...,
    out: Optional[PathLike] = ...,
    effects: Union[str, Iterable[str], None] = ...,
    fix: Union[Mapping[str, float], Iterable[str], None] = ...,
    holdout: Optional[str] = ...,
    holdout_cable: Optional[int] = ...,
    noise_mm: float = ...,
    noise_deg: float = ...,
    loss: Optional[str] = ...,
    huber_k: float = ...,
    max_iterations: int = ...,
    angle_weight: float = ...,
    actuator_file: Optional[PathLike] = ...,
    method: Optional[str] = ...,
    nodes_per_span: Optional[int] = ...,
    steps_per_span: Optional[int] = ...,
    **rod_fields: Any,
) -> CalibrateReport:
    """`cablemap calibrate DATA --json`: planar measurements, or captures and 3-D markers with actuator=FILE.toml."""

def diagnose(
    data: PathLike,
    *,
    actuator: Optional[PathLike] = ...,
    markers: Optional[PathLike] = ...,
    centrelines: Optional[PathLike] = ...,
    out: Optional[PathLike] = ...,
    report: bool = ...,
    fix: Union[Mapping[str, float], Iterable[str], None] = ...,
    holdout: Optional[str] = ...,
    holdout_cable: Optional[int] = ...,
    noise_mm: float = ...,
    noise_deg: float = ...,
    loss: Optional[str] = ...,
    huber_k: float = ...,
    max_iterations: int = ...,
    angle_weight: float = ...,
    alpha: float = ...,
    threshold: float = ...,
    margin: float = ...,
    max_effects: int = ...,
    actuator_file: Optional[PathLike] = ...,
    method: Optional[str] = ...,
    nodes_per_span: Optional[int] = ...,
    steps_per_span: Optional[int] = ...,
    **rod_fields: Any,
) -> DiagnoseReport:
    """`cablemap diagnose DATA --json`: the effect the model misses; report.md and plots in out= (planar)."""

def predict(
    captures: PathLike,
    actuator: PathLike,
    *,
    markers: Optional[PathLike] = ...,
    method: Optional[str] = ...,
    nodes_per_span: Optional[int] = ...,
    steps_per_span: Optional[int] = ...,
) -> PredictReport:
    """`cablemap predict CAPTURES --actuator A.toml --json`: the markers' 3-D errors, no fitting."""
