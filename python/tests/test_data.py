"""cablemap.sweep, reduce, read_run and read_map against pyarrow's read of
the same files and against the cablemap binary's messages.

The binary is $CABLEMAP_BIN (scripts/test.sh sets it), else
target/release/cablemap of the repository.
"""

import os
import subprocess
from pathlib import Path

import polars as pl
import pyarrow.parquet as pq
import pytest

import cablemap

REPO = Path(__file__).resolve().parents[2]
BIN = os.environ.get("CABLEMAP_BIN", str(REPO / "target" / "release" / "cablemap"))
QUICK = REPO / "jobs" / "quick.toml"
PAIR = REPO / "jobs" / "antagonistic-pair.toml"

# A planar sweep with the centreline stored (list columns): 2 levels, mirror
# pairs dropped (16 routings), 3 tensions, 4 routings per chunk.
CENTRELINE_SPEC = """
[grid]
levels = 2
extent_r = 0.5
[tension]
min_n = 0.5
max_n = 1.5
count = 3
[solver]
steps_per_span = 4
[output]
order = 2
centreline = true
chunk_routings = 4
"""


def arrow_frame(path):
    """pyarrow's read of a file or a folder of Parquet files, as polars."""
    return pl.from_arrow(pq.read_table(path))


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """jobs/quick.toml swept into a run and reduced into a map."""
    root = tmp_path_factory.mktemp("quick")
    swept = cablemap.sweep(QUICK, root / "run", threads=2)
    reduced = cablemap.reduce(root / "run", root / "map")
    return root, swept, reduced


def test_sweep_reports_what_it_wrote(quick):
    root, swept, _ = quick
    assert isinstance(swept, cablemap.SweepReport)
    assert swept.rows_written == 610 and swept.complete and swept.wall_s > 0
    assert swept.summary["rows_skipped"] == 0 and swept.run["rows_total"] == 610
    assert Path(swept.run_dir) == root / "run"
    assert "610 rows" in repr(swept) and "complete" in repr(swept)
    assert swept.text.startswith("shard 0/1: 610 rows solved and written")
    # Sweeping again resumes: nothing left to do.
    again = cablemap.sweep(QUICK, root / "run")
    assert again.rows_written == 0 and again.summary["rows_skipped"] == 610


def test_read_run_equals_pyarrow(quick):
    root, _, _ = quick
    frame = cablemap.read_run(root / "run")
    assert frame.height == 610
    assert frame.equals(arrow_frame(root / "run" / "shards"))
    # Types of docs/schema.md ("What the readers give").
    assert frame.schema["routing_id"] == pl.Int64 and frame.schema["iterations"] == pl.Int32
    assert frame.schema["status"] == pl.String and frame.schema["a3"] == pl.Float64
    assert frame["routing_id"].is_sorted()
    pandas = frame.to_pandas()
    assert str(pandas["routing_id"].dtype) == "int64" and str(pandas["iterations"].dtype) == "int32"


def test_read_run_with_centrelines_equals_pyarrow(tmp_path):
    spec = tmp_path / "centreline.toml"
    spec.write_text(CENTRELINE_SPEC)
    report = cablemap.sweep(spec, tmp_path / "run")
    assert report.rows_written == 16 * 3 and report.summary["chunks_written"] == 4
    frame = cablemap.read_run(tmp_path / "run")
    assert frame.schema["centreline_x_mm"] == pl.List(pl.Float64)
    assert frame.equals(arrow_frame(tmp_path / "run" / "shards"))


def test_reduce_then_read_map_equals_pyarrow(quick):
    root, _, reduced = quick
    assert isinstance(reduced, cablemap.ReduceReport)
    # The mirror images restored: 610 rows and their mirrors, the straight routing's 5 once.
    assert reduced.summary["mirrored"] and reduced.rows == 2 * 610 - 5
    assert reduced.total_s > 0 and Path(reduced.map_dir) == root / "map"
    assert set(reduced.tables) == {"cells", "modes", "designs"}
    assert "map of 1215 rows" in repr(reduced) and reduced.text.startswith(f"map {root / 'map'}")
    tables = cablemap.read_map(root / "map")
    assert set(tables) == {"cells", "modes", "designs"}
    for name, frame in tables.items():
        assert frame.height > 0, name
        assert frame.equals(arrow_frame(root / "map" / f"{name}.parquet")), name
    assert tables["cells"]["count"].sum() == reduced.summary["rows_converged"]


def test_cable_sweep_map_reads_reach_and_planar_tables(tmp_path):
    swept = cablemap.sweep(PAIR, tmp_path / "run")
    assert swept.complete and swept.rows_written == swept.run["rows_total"]
    run = cablemap.read_run(tmp_path / "run")
    assert run.height == swept.rows_written and "tension2_n" in run.columns
    assert run.equals(arrow_frame(tmp_path / "run" / "shards"))
    reduced = cablemap.reduce(tmp_path / "run", tmp_path / "map")
    assert "cable map" in repr(reduced)
    tables = cablemap.read_map(tmp_path / "map")
    assert set(tables) == {"reach_xy", "reach_xz", "reach_yz", "reach_3d", "cells", "modes", "designs"}
    for name, frame in tables.items():
        folder = tmp_path / "map" / ("planar" if name in ("cells", "modes", "designs") else "")
        assert frame.equals(arrow_frame(folder / f"{name}.parquet")), name
    assert tables["reach_3d"]["count"].sum() == reduced.summary["ok"]


def test_sharded_sweep_equals_the_whole_run(quick, tmp_path):
    root, _, _ = quick
    out = tmp_path / "sharded"
    first = cablemap.sweep(QUICK, out, "0/3")
    assert not first.complete and 0 < first.rows_written < 610
    # An unfinished run is read only when asked to be.
    with pytest.raises(cablemap.BadInputError, match="incomplete"):
        cablemap.read_run(out)
    assert cablemap.read_run(out, partial=True).height == first.rows_written
    written = [first.rows_written]
    for shard in [(1, 3), "2/3"]:
        written.append(cablemap.sweep(QUICK, out, shard).rows_written)
    assert sum(written) == 610
    assert cablemap.read_run(out).equals(cablemap.read_run(root / "run"))


def test_bad_spec_raises_the_library_message(tmp_path):
    spec = tmp_path / "bad.toml"
    spec.write_text("[grid]\nlevels = 3\n[tensions]\nmin_n = 1.0\n")
    with pytest.raises(cablemap.BadInputError) as caught:
        cablemap.sweep(spec, tmp_path / "run")
    message = str(caught.value)
    assert "unknown field `tensions`" in message
    cli = subprocess.run([BIN, "sweep", str(spec), "--out", str(tmp_path / "cli-run"), "--quiet"], capture_output=True, text=True)
    assert cli.returncode != 0 and message in cli.stderr
    assert not (tmp_path / "run").exists()


def test_bad_shard_and_missing_files_are_refused(quick, tmp_path):
    root, _, _ = quick
    with pytest.raises(cablemap.BadInputError, match="shard"):
        cablemap.sweep(QUICK, tmp_path / "run", "3/3")
    with pytest.raises(cablemap.BadInputError, match="i/n"):
        cablemap.sweep(QUICK, tmp_path / "run", "first")
    with pytest.raises(cablemap.FileFormatError, match="reading spec"):
        cablemap.sweep(tmp_path / "missing.toml", tmp_path / "run")
    # A map given as a run, and a run given as a map: the library says which to give.
    with pytest.raises(cablemap.FileFormatError, match="is a map"):
        cablemap.read_run(root / "map")
    with pytest.raises(cablemap.FileFormatError, match="reduce it first"):
        cablemap.read_map(root / "run")
