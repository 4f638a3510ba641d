"""Reads the moulds of `cablemap mould` (docs/moulds.md) with trimesh and
checks each STL loads closed and consistently wound with the volume
cablemap reports in mould.json.

Usage: check_moulds.py MOULD_DIR
Prints one line per check and a final "python: N passed, M failed"; exits 1 on
any failure.
"""

import json
import sys
from pathlib import Path

import numpy as np
import trimesh
from harness import finish, run_check

d = Path(sys.argv[1])
summary = json.loads((d / "mould.json").read_text())


def check_file(name, parts):
    mesh = trimesh.load(d / name, file_type="stl")
    assert isinstance(mesh, trimesh.Trimesh), type(mesh)
    assert mesh.is_watertight, f"{name}: not watertight"
    assert mesh.is_winding_consistent, f"{name}: inconsistent winding"
    listed = sum(p["volume_mm3"] for p in parts)
    assert mesh.volume > 0
    assert abs(mesh.volume - listed) < 1e-4 * listed, (mesh.volume, listed)
    # Both parts stand on the bed, side by side.
    assert abs(mesh.bounds[0][2]) < 1e-4, mesh.bounds
    assert len(mesh.faces) == sum(p["triangles"] for p in parts)
    header = (d / name).read_bytes()[:80].decode("ascii")
    assert header.startswith(f"cablemap {name[:-4]}, units mm"), header


def check_cavities():
    for n in (1, 2):
        cavity, body = summary[f"mould{n}_cavity_mm3"], summary[f"mould{n}_body_mm3"]
        assert abs(cavity - body) < 0.005 * body, (n, cavity, body)
    r, length, clamp = summary["radius_mm"], summary["length_mm"], summary["params"]["clamp_mm"]
    assert abs(summary["mould2_body_mm3"] - np.pi * r * r * (length + clamp)) < 1e-6 * summary["mould2_body_mm3"]


for entry in summary["files"]:
    name = entry["file"]
    run_check(f"{name} loads closed with the reported volume (trimesh)", check_file, name, entry["parts"])
run_check("cavity volumes match the body", check_cavities)
sys.exit(finish())
