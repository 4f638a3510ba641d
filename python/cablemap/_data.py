"""Sweeps, maps and their files as data frames: :func:`sweep`, :func:`reduce`,
:func:`read_run` and :func:`read_map`.

``sweep`` and ``reduce`` run the library's requests (as ``cablemap sweep``
and ``cablemap reduce`` do, GIL released) and return its reports. The
readers ask the library which files to read (a run's checked chunk files,
a map's tables) and read them with polars; ``.to_pandas()`` on a frame
gives pandas (with pyarrow installed).
"""

from __future__ import annotations

import io
import json
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

from . import _native
from ._record import Record
from .errors import BadInputError

PathLike = Union[str, "os.PathLike[str]"]
Shard = Union[str, Tuple[int, int], None]


class _Report(Record):
    """A library report: its fields (the command's ``--json`` object) as
    attributes and :meth:`to_dict`, the command's text as :attr:`text`."""

    def __init__(self, record: Dict[str, Any], text: str) -> None:
        super().__init__(record)
        #: What the command prints.
        self.text = text

    def __str__(self) -> str:
        return self.text


class SweepReport(_Report):
    """What one shard's sweep did (``cablemap sweep --json``): ``summary``
    (this call: ``rows_written``, ``rows_skipped`` (already done),
    ``chunks_written``, ``wall_s``, ``solves_per_s``, ``status_counts``, ...)
    and ``run`` (the run directory's state after it, as ``cablemap status
    --json``: ``rows_done``, ``rows_total``, ``complete``, ...). ``note``
    is what the command says before running (a spec that sets nothing)."""

    def __init__(self, record: Dict[str, Any], text: str, note: Optional[str]) -> None:
        super().__init__(record, text)
        #: The command's note about the spec, or None.
        self.note = note

    @property
    def run_dir(self) -> str:
        """The run directory written."""
        return self._record["summary"]["dir"]

    @property
    def rows_written(self) -> int:
        """Rows solved and written by this call."""
        return self._record["summary"]["rows_written"]

    @property
    def wall_s(self) -> float:
        """Wall time of this call, s."""
        return self._record["summary"]["wall_s"]

    @property
    def complete(self) -> bool:
        """Every row of the run is written (all shards done)."""
        return self._record["run"]["complete"]

    def __repr__(self) -> str:
        s, r = self._record["summary"], self._record["run"]
        state = "complete" if r["complete"] else "partial"
        return (
            f"SweepReport({s['dir']}: shard {s['shard']}/{s['shards']} wrote {s['rows_written']} rows in "
            f"{s['chunks_written']} chunks ({s['rows_skipped']} already done) in {s['wall_s']:.2f} s; "
            f"run {state}, {r['rows_done']}/{r['rows_total']} rows)"
        )


class ReduceReport(_Report):
    """A map written (``cablemap reduce --json``): ``summary`` (the map's
    ``summary.json``), ``map_dir``, ``total_s``, and the pictures
    (``pictures``; a cable sweep's map: ``planar_summary`` and
    ``planar_pictures`` of its planar map, if any). :attr:`tables` names
    the tables written (``read_map`` reads them)."""

    def __init__(self, record: Dict[str, Any], text: str) -> None:
        super().__init__(record, text)
        #: The tables written, name to file (as :func:`read_map` reads them).
        self.tables: Dict[str, str] = {name: os.fspath(path) for name, path in _native.map_tables(record["map_dir"])}

    @property
    def rows(self) -> int:
        """Rows mapped: a planar map's simulations (its mirror images
        included when the run dropped them), a cable map's rows read."""
        s = self._record["summary"]
        return s["rows"] if s.get("kind") == "cables" else s["rows_total"]

    def __repr__(self) -> str:
        r = self._record
        s = r["summary"]
        pictures = len(r.get("pictures") or r.get("planar_pictures") or [])
        if s.get("kind") == "cables":
            what = f"cable map of {s['rows']} rows ({s['ok']} solved), reach cells x-y {s['cells'][0]}, 3-D {s['cells'][3]}"
        else:
            what = f"map of {s['rows_total']} rows ({s['rows_converged']} converged) in {s['cells']} cells of {s['cell_mm']} mm"
        return f"ReduceReport({r['map_dir']}: {what}; {len(self.tables)} tables, {pictures} pictures in {r['total_s']:.2f} s)"


def _shard(shard: Shard) -> Tuple[int, int]:
    """``"i/n"``, ``(i, n)`` or None (the whole sweep, 0/1) as (i, n)."""
    if shard is None:
        return 0, 1
    if isinstance(shard, str):
        parts = shard.split("/")
        try:
            i, n = (int(p) for p in parts)
        except ValueError:
            raise BadInputError(f"shard {shard!r}: write it \"i/n\" (shard i of n, 0 ≤ i < n), e.g. \"0/4\"") from None
        return i, n
    try:
        i, n = shard
        return int(i), int(n)
    except (TypeError, ValueError):
        raise BadInputError(f"shard {shard!r}: give \"i/n\" or a pair (i, n) (shard i of n, 0 ≤ i < n)") from None


def sweep(
    spec: Optional[PathLike],
    out: PathLike,
    shard: Shard = None,
    *,
    threads: Optional[int] = None,
    allow_large: bool = False,
    progress: bool = False,
) -> SweepReport:
    """Runs a sweep spec (TOML; the built-in thesis spec when None) into the
    run directory ``out``, as ``cablemap sweep SPEC --out OUT``: the
    library's sweep, solved in parallel in Rust with the GIL released;
    re-running resumes.

    ``shard``: ``"i/n"`` or ``(i, n)`` runs shard i of n (``--shard i
    --shards n``; every shard of a run needs the same n), None the whole
    sweep (environment variables such as ``SLURM_ARRAY_TASK_ID`` are not
    read). ``threads`` as ``--threads`` (one per core when None),
    ``allow_large`` as ``--allow-large``, ``progress`` shows the command's
    progress on stderr.

    Raises :class:`BadInputError` for a spec or request the library refuses
    and :class:`FileFormatError` for files it cannot read, with its messages.
    """
    i, n = _shard(shard)
    spec_path = None if spec is None else os.fspath(spec)
    record, text, note = _native.sweep(spec_path, os.fspath(out), i, n, threads, bool(allow_large), bool(progress))
    return SweepReport(json.loads(record), text, note)


def reduce(
    run: PathLike,
    out: PathLike,
    *,
    partial: bool = False,
    cell_mm: Optional[float] = None,
    a0_bounds: Optional[Sequence[float]] = None,
    a1_bounds: Optional[Sequence[float]] = None,
    designs_per_cell: int = 16,
    memory_samples: Optional[int] = None,
) -> ReduceReport:
    """Reduces the run directory ``run`` (either kind) into the map directory
    ``out``, as ``cablemap reduce RUN --out OUT``: tables, pictures and the
    explorer page; the directory is replaced as a whole.

    The keywords are the command's flags: ``partial`` (map an unfinished
    run's complete chunks), ``cell_mm`` (a cable sweep: its spec's
    ``output.cell_mm`` when None), ``a0_bounds`` (three values) with
    ``a1_bounds`` (two), ``designs_per_cell``, ``memory_samples``.
    """
    settings = {
        "cell_mm": None if cell_mm is None else float(cell_mm),
        "a0_bounds": None if a0_bounds is None else [float(v) for v in a0_bounds],
        "a1_bounds": None if a1_bounds is None else [float(v) for v in a1_bounds],
        "designs_per_cell": int(designs_per_cell),
        "memory_samples": None if memory_samples is None else int(memory_samples),
    }
    record, text = _native.reduce(os.fspath(run), os.fspath(out), bool(partial), json.dumps(settings))
    return ReduceReport(json.loads(record), text)


def _polars() -> Any:
    try:
        import polars
    except ImportError:
        raise ImportError("cablemap.read_run and read_map return polars data frames: pip install polars (and pyarrow for to_pandas)") from None
    return polars


def read_run(run: PathLike, *, partial: bool = False) -> Any:
    """The rows of the run directory ``run`` as one polars DataFrame, in row
    order (routing id, then the ladder), with the columns of docs/schema.md
    (a planar sweep's or a cable sweep's). The chunk files are the ones the
    library checks and lists (manifest, checksums, footers); an unfinished
    run is refused unless ``partial`` (then its complete chunks).
    ``.to_pandas()`` gives pandas.
    """
    pl = _polars()
    files = _native.run_files(os.fspath(run), bool(partial))
    paths = [os.fspath(p) for p in files["files"]]
    if not paths:
        return pl.read_parquet(io.BytesIO(files["empty_parquet"]))
    return pl.read_parquet(paths)


def read_map(path: PathLike) -> Dict[str, Any]:
    """Every table of the map directory ``path`` as polars DataFrames keyed
    by table name: a planar map's ``cells``, ``modes`` and ``designs``; a
    cable sweep's map's ``reach_xy``, ``reach_xz``, ``reach_yz``,
    ``reach_3d`` and, for a planar run, its planar map's (``planar/``)
    ``cells``, ``modes`` and ``designs``. The tables are the library's list
    (the map's summary is checked first). Columns: docs/maps.md,
    docs/schema.md.
    """
    pl = _polars()
    return {name: pl.read_parquet(os.fspath(file)) for name, file in _native.map_tables(os.fspath(path))}


__all__ = ["SweepReport", "ReduceReport", "sweep", "reduce", "read_run", "read_map"]
