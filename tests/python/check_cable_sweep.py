"""Reads a cable sweep (`cablemap map CABLE_SPEC --out DIR`: the run in
DIR/run, its chunk files in DIR/run/shards, the maps in DIR/map) with pyarrow,
pandas and polars and checks the documented columns and dtypes
(docs/schema.md, "Cable sweeps"): one row per routing and tension
combination, one tension column per cable, the 3-D tip, failed solves as
nulls, and reach maps whose counts add up to the solved rows.

Usage: check_cable_sweep.py DIR [DIR ...]
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

POSE = ["tip_x_mm", "tip_y_mm", "tip_z_mm", "tip_tangent_x", "tip_tangent_y", "tip_tangent_z",
        "tip_body_y_x", "tip_body_y_y", "tip_body_y_z", "tip_angle_rad", "length_mm"]


def spec_counts(out):
    return json.loads((out / "map" / "summary.json").read_text())


def manifest(out):
    return json.loads((out / "run" / "manifest.json").read_text())


def check_rows_pyarrow(run):
    # The chunk folder is one Parquet dataset.
    t = pq.read_table(run / "run" / "shards")
    s = spec_counts(run)
    assert t.num_rows == s["rows"] == manifest(run)["total_rows"], (t.num_rows, s["rows"])
    assert manifest(run)["format"] == "cablemap-cables/1"
    names = t.schema.names
    cables = sum(1 for n in names if n.startswith("tension") and n.endswith("_n"))
    assert cables >= 1
    for c in range(1, cables + 1):
        assert t.schema.field(f"tension{c}_n").type == pa.float64()
        for axis in "yz":
            for j in range(5):
                assert t.schema.field(f"cable{c}_{axis}{j}_mm").type == pa.float64()
    assert t.schema.field("routing_id").type == pa.int64()
    assert t.schema.field("status").type in (pa.string(), pa.large_string())
    assert t.schema.field("iterations").type == pa.int32()
    for n in POSE + ["a0", "a_bend_y0", "a_twist0"]:
        assert t.schema.field(n).type == pa.float64(), n


def check_rows_pandas(run):
    df = pd.read_parquet(run / "run" / "shards")
    ok = df["status"] == "ok"
    assert ok.sum() == spec_counts(run)["ok"]
    assert df.loc[ok, POSE].notna().all().all()
    assert df.loc[~ok, POSE].isna().all().all()
    # Unit tangents and body axes.
    t = df.loc[ok, ["tip_tangent_x", "tip_tangent_y", "tip_tangent_z"]].pow(2).sum(axis=1)
    assert (t.sub(1.0).abs() < 1e-9).all()
    # Rows of a routing are contiguous, tension combinations in grid order.
    assert df["routing_id"].is_monotonic_increasing
    # Every (routing, tensions) once.
    tens = [c for c in df.columns if c.startswith("tension")]
    assert not df.duplicated(["routing_id"] + tens).any()


def check_maps_polars(run):
    ok = spec_counts(run)["ok"]
    for name, axes in [("reach_xy", "xy"), ("reach_xz", "xz"), ("reach_yz", "yz"), ("reach_3d", "xyz")]:
        m = pl.read_parquet(run / "map" / f"{name}.parquet")
        assert m["count"].sum() == ok, (name, m["count"].sum(), ok)
        for a in axes:
            assert m[f"i{a}"].dtype == pl.Int32 and m[f"{a}_mm"].dtype == pl.Float64
        assert m["count"].dtype == pl.Int64 and (m["count"] > 0).all()


def main(runs):
    for run in map(Path, runs):
        run_check(f"cable rows (pyarrow) [{run.name}]", check_rows_pyarrow, run)
        run_check(f"cable rows (pandas) [{run.name}]", check_rows_pandas, run)
        run_check(f"reach maps (polars) [{run.name}]", check_maps_polars, run)
    return finish()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
