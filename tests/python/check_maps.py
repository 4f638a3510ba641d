"""Reads a map directory (`cablemap reduce` output, docs/maps.md) with pandas
(pyarrow engine) and polars and checks tables, dtypes and counts.

Usage: check_maps.py MAP_DIR [RUN_DIR]
With RUN_DIR (the sweep the map came from) the cell counts and percentiles are
recomputed independently with pandas/numpy from the shards and compared.
Prints one line per check and a final "python: N passed, M failed"; exits 1 on
any failure.
"""

import json
import sys
from pathlib import Path

import pandas as pd
import polars as pl
from harness import finish, run_check

d = Path(sys.argv[1])
summary = json.loads((d / "summary.json").read_text())
K = range(min(summary["order"], 2) + 1)


def cells_pandas():
    c = pd.read_parquet(d / "cells.parquet")
    assert str(c["ix"].dtype) == "int32" and str(c["iy"].dtype) == "int32", c.dtypes
    assert str(c["count"].dtype) == "int64"
    for k in K:
        for s in ["p10", "p90", "gap", "min", "max"]:
            assert str(c[f"a{k}_{s}"].dtype) == "float64", (k, s)
        assert ((c[f"a{k}_p90"] - c[f"a{k}_p10"] - c[f"a{k}_gap"]).abs() < 1e-12).all()
        assert (c[f"a{k}_min"] <= c[f"a{k}_p10"]).all() and (c[f"a{k}_p90"] <= c[f"a{k}_max"]).all()
    modes = [f"mode_{m}" for m in range(12)]
    assert all(str(c[m].dtype) == "int64" for m in modes)
    assert (c[modes].sum(axis=1) == c["count"]).all()
    assert int(c["count"].sum()) == summary["rows_converged"]
    assert len(c) == summary["cells"]
    # The map's coefficients are in the thesis's basis (per unit rest length) by default.
    assert summary["length_basis"] == "rest", summary["length_basis"]


def cells_polars():
    c = pl.read_parquet(d / "cells.parquet")
    assert c.schema["ix"] == pl.Int32 and c.schema["count"] == pl.Int64
    assert c.schema["a0_p10"] == pl.Float64
    assert c["count"].sum() == summary["rows_converged"]
    assert c.null_count().sum_horizontal()[0] == 0


def modes_both():
    m = pd.read_parquet(d / "modes.parquet")
    assert len(m) == 12 and list(m["mode"]) == list(range(12))
    assert str(m["count"].dtype) == "int64" and str(m["rep_tension_n"].dtype) == "float64"
    assert int(m["count"].sum()) == summary["rows_converged"]
    p = pl.read_parquet(d / "modes.parquet")
    assert p.schema["mode"] == pl.Int32 and p.schema["rep_y0_mm"] == pl.Float64


def designs_both():
    g = pd.read_parquet(d / "designs.parquet")
    assert str(g["mirrored"].dtype) == "bool" and str(g["routing_id"].dtype) == "int64"
    x0, y0, cell = summary["x_min_mm"], summary["y_min_mm"], summary["cell_mm"]
    assert ((g["tip_x_mm"] - x0) // cell == g["ix"]).all()
    assert ((g["tip_y_mm"] - y0) // cell == g["iy"]).all()
    p = pl.read_parquet(d / "designs.parquet")
    assert p.schema["mirrored"] == pl.Boolean and p.height == len(g)


def percentiles_match_a_pandas_reference():
    import numpy as np

    run = Path(sys.argv[2])
    rows = pd.read_parquet(run / "shards")
    ok = rows[rows["status"] == "ok"].copy()
    if summary["mirrored"]:
        mirror = ok[~(ok[[f"y{i}_mm" for i in range(5)]] == 0).all(axis=1)].copy()
        mirror["tip_y_mm"] = -mirror["tip_y_mm"]
        for k in K:
            mirror[f"a{k}"] = -mirror[f"a{k}"]
        ok = pd.concat([ok, mirror])
    x0, y0, cell = summary["x_min_mm"], summary["y_min_mm"], summary["cell_mm"]
    ok["ix"] = np.floor((ok["tip_x_mm"] - x0) / cell).astype("int32")
    ok["iy"] = np.floor((ok["tip_y_mm"] - y0) / cell).astype("int32")
    ref = ok.groupby(["ix", "iy"]).agg(
        count=("a0", "size"),
        **{f"a{k}_p10": (f"a{k}", lambda v: np.percentile(v, 10)) for k in K},
        **{f"a{k}_p90": (f"a{k}", lambda v: np.percentile(v, 90)) for k in K},
    )
    cells = pd.read_parquet(d / "cells.parquet").set_index(["ix", "iy"]).sort_index()
    ref = ref.sort_index()
    assert list(ref.index) == list(cells.index), "same non-empty cells"
    assert (ref["count"].to_numpy() == cells["count"].to_numpy()).all()
    for k in K:
        for q in ["p10", "p90"]:
            diff = np.abs(ref[f"a{k}_{q}"].to_numpy() - cells[f"a{k}_{q}"].to_numpy()).max()
            assert diff < 1e-12, (k, q, diff)


checks = [cells_pandas, cells_polars, modes_both, designs_both]
if len(sys.argv) > 2:
    checks.append(percentiles_match_a_pandas_reference)
for fn in checks:
    run_check(fn.__name__, fn)
sys.exit(finish())
