"""Type stubs of cablemap (the Python package over the Rust library)."""

import os
from typing import Any, Dict, List, Optional, Sequence, Union

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
