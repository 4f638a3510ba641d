"""Reads sweep output with pyarrow, pandas and polars and checks the columns
come back with the documented dtypes (docs/schema.md), every row once, failed
solves as nulls (never NaN) and the run's metadata in each file's footer.

Usage: check_sweep.py RUN_DIR [RUN_DIR ...]   (directories made by `cablemap sweep`)
Prints one line per check and a final "python: N passed, M failed"; exits 1 on
any failure.
"""

import json
import sys
from pathlib import Path

import pandas as pd
import polars as pl
import pyarrow as pa
import pyarrow.parquet as pq
from harness import finish, run_check

POSE = ["tip_x_mm", "tip_y_mm", "tip_angle_rad", "base_angle_rad", "length_mm"]
Y = [f"y{i}_mm" for i in range(5)]

def check(name):
    def wrap(fn):
        def run(*args):
            run_check(f"{name} [{args[0].name}]", fn, *args)

        return run

    return wrap


def manifest(run):
    return json.loads((run / "manifest.json").read_text())


def coefficient_names(m):
    return [f"a{i}" for i in range(m["spec"]["output"]["order"] + 1)]


@check("pyarrow dataset: schema and row count")
def check_pyarrow(run):
    m = manifest(run)
    table = pq.read_table(run / "shards")
    assert table.num_rows == m["total_rows"], (table.num_rows, m["total_rows"])
    s = table.schema
    assert s.field("routing_id").type == pa.int64()
    for c in Y + ["tension_n", "displacement_mm"] + POSE + coefficient_names(m):
        assert s.field(c).type == pa.float64(), (c, s.field(c).type)
    assert s.field("status").type == pa.string()
    assert s.field("iterations").type == pa.int32()
    for c in ["routing_id", "status", "iterations", "tension_n"] + Y:
        assert table.column(c).null_count == 0, c
    if m["spec"]["output"]["centreline"]:
        assert s.field("centreline_x_mm").type == pa.list_(pa.float64())
        assert s.field("centreline_y_mm").type == pa.list_(pa.float64())


@check("pandas: dtypes, unique rows, nulls only for failures")
def check_pandas(run):
    m = manifest(run)
    df = pd.read_parquet(run / "shards", engine="pyarrow")
    assert len(df) == m["total_rows"]
    assert df["routing_id"].dtype == "int64"
    assert df["iterations"].dtype == "int32"
    for c in Y + ["tension_n"] + POSE + coefficient_names(m):
        assert df[c].dtype == "float64", (c, df[c].dtype)
    assert df["status"].map(type).eq(str).all()
    assert not df.duplicated(["routing_id", "tension_n"]).any()
    assert sorted(df["routing_id"].unique()) == list(range(m["routings"]))
    ok = df["status"] == "ok"
    outputs = POSE + coefficient_names(m)
    assert df.loc[ok, outputs].notna().all().all(), "a successful row has a missing output"
    assert df.loc[~ok, outputs].isna().all().all(), "a failed row has an output"
    assert (df.loc[~ok, "iterations"] == 0).all()
    counts = df["status"].value_counts().to_dict()
    files = sorted((run / "shards").glob("chunk-*.parquet"))
    total = {}
    for f in files:
        for k, v in json.loads(pq.read_metadata(f).metadata[b"cablemap.status_counts"]).items():
            total[k] = total.get(k, 0) + v
    assert counts == total, (counts, total)


@check("polars: dtypes, nulls not NaN, footer metadata")
def check_polars(run):
    m = manifest(run)
    df = pl.read_parquet(str(run / "shards" / "*.parquet"))
    assert df.height == m["total_rows"]
    assert df.schema["routing_id"] == pl.Int64
    assert df.schema["iterations"] == pl.Int32
    assert df.schema["status"] == pl.String
    for c in Y + ["tension_n"] + POSE + coefficient_names(m):
        assert df.schema[c] == pl.Float64, (c, df.schema[c])
        assert df[c].is_nan().sum() == 0, f"NaN stored in {c}"
    failures = df.filter(pl.col("status") != "ok").height
    assert df["tip_x_mm"].null_count() == failures
    assert df.select(pl.struct("routing_id", "tension_n").n_unique()).item() == df.height
    if m["spec"]["output"]["centreline"]:
        assert df.schema["centreline_x_mm"] == pl.List(pl.Float64)
        ok = df.filter(pl.col("status") == "ok")
        assert (ok["centreline_x_mm"].list.len() == 49).all()
        assert df.filter(pl.col("status") != "ok")["centreline_x_mm"].null_count() == failures
    first = sorted((run / "shards").glob("chunk-*.parquet"))[0]
    meta = pl.read_parquet_metadata(first)
    assert meta["cablemap.spec_sha256"] == m["spec_sha256"]
    assert json.loads(meta["cablemap.spec"])["tension"] == m["spec"]["tension"]
    # The coefficient basis is recorded in the manifest and every footer.
    assert m["length_basis"] == m["spec"]["output"]["length_basis"] == "rest", m["length_basis"]
    assert meta["cablemap.length_basis"] == m["length_basis"]


def main():
    runs = [Path(a) for a in sys.argv[1:]]
    if not runs:
        print(__doc__)
        return 2
    for run in runs:
        check_pyarrow(run)
        check_pandas(run)
        check_polars(run)
    return finish()


if __name__ == "__main__":
    sys.exit(main())
