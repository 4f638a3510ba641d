"""cablemap from Python: the Rust library's requests and reports, in process.

The Rust crate is the one implementation; this package builds the same
requests as the ``cablemap`` commands (``src/cli/``) from keyword arguments
and returns the library's records:

- :class:`Actuator`: the rod and its cables (keyword arguments, an actuator
  TOML file, to TOML; :meth:`Actuator.thesis` is the thesis's rod).
- :func:`simulate`: one solve, as ``cablemap simulate --json`` (the same
  fields), with the centreline as a numpy array.
- :func:`solve_batch`: many routings, each stepped through a tension ladder,
  solved in parallel in Rust with the GIL released.
- :func:`sweep`, :func:`reduce`: a sweep spec into a run directory, a run
  into a map (``cablemap sweep``, ``cablemap reduce``); :func:`read_run`,
  :func:`read_map`: their files as polars data frames.

Errors are :mod:`cablemap.errors`' exceptions carrying the library's messages.
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, Iterable, List, Optional, Sequence, Union

import numpy as np

from . import _native
from ._record import Record
from .errors import BadInputError, CablemapError, FileFormatError, SolveError

__all__ = [
    "Actuator",
    "Simulation",
    "simulate",
    "solve_batch",
    "CablemapError",
    "BadInputError",
    "SolveError",
    "FileFormatError",
]
from ._data import *  # noqa: E402,F401,F403 (sweep, reduce, read_run, read_map: _data.py)
__all__ += _data.__all__  # type: ignore[name-defined]  # noqa: F405

PathLike = Union[str, "os.PathLike[str]"]


def _dumps(value: Any) -> str:
    """JSON of plain values, numpy scalars and arrays included (floats exactly)."""

    def default(o: Any) -> Any:
        if hasattr(o, "tolist"):
            return o.tolist()
        if isinstance(o, os.PathLike):
            return os.fspath(o)
        raise BadInputError(f"cannot pass {type(o).__name__} {o!r} to cablemap: give numbers, lists or dicts")

    return json.dumps(value, default=default, allow_nan=True)


class Actuator:
    """An actuator: the rod (thesis defaults) and 0–8 cables.

    ``Actuator(**fields)`` sets fields on the thesis's actuator: any field
    of the rod by its TOML name (``length_mm``, ``radius_mm``, ``ea_n``,
    ``ga_n``, ``ei_n_mm2``, ``density_g_cm3``, ``radius_profile_mm``,
    ``segments``, ``cable_anchor_mm``, ``rest_curvature_per_mm``,
    ``effects={...}``; ``gravity=False`` as ``--no-gravity``, or a table),
    an effect by its flag's name (``stiffening_alpha``,
    ``clamp_stiffness_n_mm_per_rad``, ...), and the actuator's
    ``gj_n_mm2``, ``gravity_direction`` and ``cables`` (a list of
    ``[[cable]]`` tables: ``y_mm``, ``z_mm``, ``tension_n`` or
    ``displacement_mm``, ``cable_ea_n``, ``anchor_mm``). Unknown fields are
    refused with the list of known ones (:class:`BadInputError`).
    """

    __slots__ = ("_json",)

    def __init__(self, **fields: Any) -> None:
        self._json = _native.actuator_from_fields(None, _dumps(fields))

    @classmethod
    def _from_json(cls, text: str) -> "Actuator":
        a = cls.__new__(cls)
        a._json = text
        return a

    @classmethod
    def thesis(cls) -> "Actuator":
        """The thesis's actuator: its rod (Table 2.1), gravity on, no cables."""
        return cls()

    @classmethod
    def read(cls, path: PathLike) -> "Actuator":
        """Reads and checks an actuator file (``--actuator FILE.toml``: ``[rod]``, ``[[cable]]``)."""
        return cls._from_json(_native.actuator_read(os.fspath(path), False))

    @classmethod
    def read_rod(cls, path: PathLike) -> "Actuator":
        """Reads a rod file (``--actuator-file FILE``: the rod's fields at the top level)."""
        return cls._from_json(_native.actuator_read(os.fspath(path), True))

    def with_fields(self, **fields: Any) -> "Actuator":
        """A copy with ``fields`` set (the names of :class:`Actuator`)."""
        return Actuator._from_json(_native.actuator_from_fields(self._json, _dumps(fields)))

    def to_dict(self) -> Dict[str, Any]:
        """The actuator as plain values (``rod``, ``cable``, ...; the file's tables)."""
        return json.loads(self._json)

    def to_toml(self) -> str:
        """The actuator as the TOML of an actuator file (``--actuator FILE.toml``)."""
        return _native.actuator_to_toml(self._json)

    def write(self, path: PathLike) -> None:
        """Writes :meth:`to_toml` to ``path``."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.to_toml())

    @property
    def rod(self) -> Dict[str, Any]:
        """The rod's fields."""
        return self.to_dict()["rod"]

    @property
    def cables(self) -> List[Dict[str, Any]]:
        """The cables' tables."""
        return self.to_dict()["cable"]

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Actuator) and self.to_dict() == other.to_dict()

    def __repr__(self) -> str:
        d = self.to_dict()
        rod = d["rod"]
        thesis = Actuator.thesis().to_dict()["rod"]
        changed = {k: v for k, v in rod.items() if thesis.get(k) != v}
        parts = [f"{k}={v!r}" for k, v in changed.items()]
        for k in ("gj_n_mm2", "gravity_direction"):
            if k in d:
                parts.append(f"{k}={d[k]!r}")
        parts.append(f"cables={len(d.get('cable', []))}")
        return f"Actuator({', '.join(parts) if changed else 'thesis rod, ' + ', '.join(parts)})"


def _actuator(actuator: Union[Actuator, PathLike, None], fields: Dict[str, Any]) -> Actuator:
    """The actuator of a request: ``actuator`` (an :class:`Actuator` or an
    actuator file's path; the thesis's when None) with ``fields`` set."""
    if actuator is None:
        base = Actuator.thesis()
    elif isinstance(actuator, Actuator):
        base = actuator
    elif isinstance(actuator, (str, os.PathLike)):
        base = Actuator.read(actuator)
    else:
        raise BadInputError(f"actuator: expected an Actuator or an actuator file's path, got {type(actuator).__name__}")
    fields = {k: v for k, v in fields.items() if v is not None}
    return base.with_fields(**fields) if fields else base


def _solver(method: Optional[str], nodes_per_span: Optional[int], steps_per_span: Optional[int]) -> Dict[str, Any]:
    solver: Dict[str, Any] = {}
    if method is not None:
        solver["method"] = method
    if nodes_per_span is not None:
        solver["nodes_per_span"] = int(nodes_per_span)
    if steps_per_span is not None:
        solver["steps_per_span"] = int(steps_per_span)
    return solver


class Simulation(Record):
    """One solve: the fields of ``cablemap simulate --json`` as attributes.

    With ``routing_mm`` (one planar cable) these are the planar record's
    (``status``, ``routing_mm``, ``tension_n``, ``displacement_mm``,
    ``tip_x_mm``, ``tip_y_mm``, ``tip_angle_rad``, ``tip_frame_angle_rad``,
    ``base_angle_rad``, ``length_mm``, ``iterations``, ``a``,
    ``length_basis``); with cables, the actuator record's (``cables``,
    ``tension_n`` and ``displacement_mm`` per cable, ``tip_z_mm``,
    ``tip_tangent``, ``a_bend_z``, ``a_bend_y``, ``a_twist``, ...;
    docs/schema.md). ``centreline`` is an array of the solver's nodes, one
    row each, columns ``centreline_columns`` (``s_mm``, ``x_mm``, ``y_mm``,
    ``z_mm``, ``frame_angle_rad``, ``tangent_angle_rad``, ``arc_length_mm``,
    ``u_y_per_mm``, ``u_z_per_mm``).
    """

    def __init__(self, record: Dict[str, Any], centreline: np.ndarray, columns: Sequence[str]) -> None:
        super().__init__(record)
        self.centreline = centreline
        self.centreline_columns = list(columns)

    def __repr__(self) -> str:
        r = self._record
        tip = f"tip=({r['tip_x_mm']:.4f}, {r['tip_y_mm']:.4f}"
        tip += f", {r['tip_z_mm']:.4f}) mm" if "tip_z_mm" in r else ") mm"
        a = ", ".join(f"{v:.5g}" for v in r["a"])
        return f"Simulation({r['status']}, tension_n={r['tension_n']}, {tip}, a=[{a}] mm^-1 ({r['length_basis']} basis))"


def simulate(
    routing_mm: Optional[Sequence[float]] = None,
    tension_n: Optional[float] = None,
    *,
    displacement_mm: Optional[float] = None,
    cable_ea_n: Optional[float] = None,
    cables: Optional[List[Dict[str, Any]]] = None,
    actuator: Union[Actuator, PathLike, None] = None,
    gravity_direction: Optional[Sequence[float]] = None,
    order: int = 3,
    length_basis: str = "rest",
    method: Optional[str] = None,
    nodes_per_span: Optional[int] = None,
    steps_per_span: Optional[int] = None,
    direction: Optional[str] = None,
    dwell_s: Optional[float] = None,
    **actuator_fields: Any,
) -> Simulation:
    """Solves one actuator, as ``cablemap simulate --json`` does.

    - ``routing_mm`` (5 control points y0..y4, mm) with ``tension_n`` (N) or
      ``displacement_mm`` (mm pulled in; ``cable_ea_n`` the cable's
      stiffness): one planar cable (``--routing``, ``--tension-n``,
      ``--displacement-mm``, ``--cable-ea-n``).
    - ``cables=[{"y_mm": [...], "z_mm": [...], "tension_n": T}, ...]``
      (``--cable``, 1–8 cables; ``displacement_mm`` in place of
      ``tension_n``), or ``actuator`` with cables (``--actuator FILE.toml``):
      the actuator's solve (3-D unless one in-plane cable).
    - ``actuator``: an :class:`Actuator` or an actuator file's path (the
      thesis's rod when left out); ``**actuator_fields`` set fields on it
      (``ei_n_mm2=...``, ``gravity=False``, ``stiffening_alpha=...``; see
      :class:`Actuator`), ``gravity_direction`` as ``--gravity-direction``.
    - ``order``, ``length_basis`` (``"rest"`` or ``"deformed"``),
      ``method`` (``"collocation"`` or ``"rk4"``), ``nodes_per_span``,
      ``steps_per_span``, ``direction`` (``"load"``/``"unload"``),
      ``dwell_s``: as the flags of the same names.

    Raises :class:`BadInputError` for input the library refuses and
    :class:`SolveError` (with ``status``) for a failed solve.
    """
    fields = dict(actuator_fields)
    if cables is not None:
        fields["cables"] = cables
    if gravity_direction is not None:
        fields["gravity_direction"] = gravity_direction
    act = _actuator(actuator, fields)
    request = {
        "actuator": act.to_dict(),
        "routing_mm": None if routing_mm is None else [float(y) for y in np.asarray(routing_mm, dtype=float).ravel()],
        "tension_n": None if tension_n is None else float(tension_n),
        "displacement_mm": None if displacement_mm is None else float(displacement_mm),
        "cable_ea_n": None if cable_ea_n is None else float(cable_ea_n),
        "order": int(order),
        "length_basis": length_basis,
        "direction": direction,
        "dwell_s": None if dwell_s is None else float(dwell_s),
        "solver": _solver(method, nodes_per_span, steps_per_span),
    }
    record_json, centreline, columns = _native.simulate(_dumps(request))
    values = np.frombuffer(centreline, dtype=np.float64).reshape(-1, len(columns)).copy()
    return Simulation(json.loads(record_json), values, columns)


def solve_batch(
    routings_mm: Any,
    tensions_n: Any,
    *,
    actuator: Union[Actuator, PathLike, None] = None,
    order: int = 3,
    length_basis: str = "rest",
    method: Optional[str] = None,
    nodes_per_span: Optional[int] = None,
    steps_per_span: Optional[int] = None,
    threads: Optional[int] = None,
    **actuator_fields: Any,
) -> Dict[str, np.ndarray]:
    """Solves every routing (rows of the (n, 5) ``routings_mm``, mm) at every
    tension of the (m,) ``tensions_n`` (N), each routing stepped through the
    tensions in order from a cold start (each solve warm-started from the
    previous one: the sweep's ladder), routings in parallel on ``threads``
    threads (all cores when None) with the GIL released.

    Returns a dict of numpy arrays: ``tension_n``, ``displacement_mm``,
    ``tip_x_mm``, ``tip_y_mm``, ``tip_angle_rad``, ``tip_frame_angle_rad``,
    ``base_angle_rad``, ``length_mm`` (float, (n, m)), ``iterations`` (int,
    (n, m)), ``a`` ((n, m, order + 1), mm⁻¹ in ``length_basis``) and
    ``status`` ((n, m) strings: ``ok``, a failed solve's status, or
    ``invalid_routing`` for a routing outside the rod). Values of solves
    that are not ``ok`` are NaN. The actuator is a rod alone (planar): the
    thesis's, ``actuator=``, and ``**actuator_fields`` as for :func:`simulate`.
    """
    routings = np.ascontiguousarray(routings_mm, dtype=np.float64)
    if routings.ndim == 1 and routings.size == 5:
        routings = routings.reshape(1, 5)
    if routings.ndim != 2 or routings.shape[1] != 5:
        raise BadInputError(f"routings_mm: expected an (n, 5) array of control points y0..y4 (mm), got shape {routings.shape}")
    tensions = np.ascontiguousarray(tensions_n, dtype=np.float64)
    if tensions.ndim != 1:
        raise BadInputError(f"tensions_n: expected an (m,) array of tensions (N), got shape {tensions.shape}")
    act = _actuator(actuator, actuator_fields)
    out = _native.solve_batch(
        act._json,
        routings.ravel().tolist(),
        tensions.tolist(),
        int(order),
        length_basis,
        _dumps(_solver(method, nodes_per_span, steps_per_span)),
        threads,
    )
    n, m, k = out.pop("shape")
    result: Dict[str, np.ndarray] = {}
    for name in _native.BATCH_FIELDS:
        values = np.frombuffer(out[name], dtype=np.float64).reshape(n, m)
        if name == "iterations":
            values = np.where(np.isnan(values), 0, values).astype(np.int64)
        result[name] = values.copy()
    result["a"] = np.frombuffer(out["a"], dtype=np.float64).reshape(n, m, k).copy()
    result["status"] = np.array(out["status"], dtype=object).reshape(n, m)
    return result

from ._reports import *  # noqa: E402,F401,F403  reports: design, feasible, calibrate, diagnose, predict (_reports.py)
from ._reports import __all__ as _reports_all  # noqa: E402

__all__ += _reports_all
