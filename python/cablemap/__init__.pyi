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
