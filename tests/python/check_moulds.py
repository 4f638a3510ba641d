"""Reads the moulds of `cablemap mould` (docs/moulds.md) with trimesh and
checks each STL loads closed and consistently wound with the volume
cablemap reports in mould.json: the two-part moulds (mould1.stl,
mould2.stl) or the printed body with lumens and its cores (body.stl,
core.stl).

Usage: check_moulds.py MOULD_DIR [MOULD_DIR ...]
Prints one line per check and a final "python: N passed, M failed"; exits 1 on
any failure.
"""

import json
import sys
from pathlib import Path

import numpy as np
import trimesh
from harness import finish, run_check



def check_file(d, name, parts):
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


def check_cavities(summary):
    for n in (1, 2):
        cavity, body = summary[f"mould{n}_cavity_mm3"], summary[f"mould{n}_body_mm3"]
        assert abs(cavity - body) < 0.005 * body, (n, cavity, body)
    r, length, clamp = summary["radius_mm"], summary["length_mm"], summary["params"]["clamp_mm"]
    assert abs(summary["mould2_body_mm3"] - np.pi * r * r * (length + clamp)) < 1e-6 * summary["mould2_body_mm3"]


def pieces_of(mesh):
    """Connected pieces (faces sharing a vertex), by union-find (trimesh's
    split needs a graph engine the suite does not install)."""
    parent = list(range(len(mesh.vertices)))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b, c in mesh.faces:
        ra = find(a)
        for v in (b, c):
            rv = find(v)
            if rv != ra:
                parent[rv] = ra
    return len({find(v) for v in np.unique(mesh.faces)})


def check_lumen_file(d, entry, expected, pieces):
    name = entry["file"]
    mesh = trimesh.load(d / name, file_type="stl")
    assert isinstance(mesh, trimesh.Trimesh), type(mesh)
    assert mesh.is_watertight, f"{name}: not watertight"
    assert mesh.is_winding_consistent, f"{name}: inconsistent winding"
    assert len(mesh.faces) == entry["triangles"]
    assert abs(mesh.volume - entry["volume_mm3"]) < 1e-4 * entry["volume_mm3"], (mesh.volume, entry)
    assert abs(mesh.volume - expected) < 0.01 * expected, (name, mesh.volume, expected)
    assert pieces_of(mesh) == pieces, (name, pieces_of(mesh), pieces)
    header = (d / name).read_bytes()[:80].decode("ascii")
    assert header.startswith(f"cablemap {name[:-4]}, units mm"), header


def check_lumen_body(d, summary):
    """The body has one hole through it per lumen: genus = lumens (Euler)."""
    mesh = trimesh.load(d / "body.stl", file_type="stl")
    genus = (2 - mesh.euler_number) // 2
    assert genus == len(summary["channels"]), (genus, len(summary["channels"]))


for d in map(Path, sys.argv[1:]):
    summary = json.loads((d / "mould.json").read_text())
    if summary["style"] == "lumens":
        body, core = summary["files"]
        run_check(f"{d.name}/body.stl loads closed with the expected volume (trimesh)", check_lumen_file, d, body, summary["body_expected_mm3"], 1)
        run_check(f"{d.name}/core.stl loads closed, one core per cable (trimesh)", check_lumen_file, d, core, summary["core_expected_mm3"], len(summary["channels"]))
        run_check(f"{d.name}/body.stl has a hole per lumen", check_lumen_body, d, summary)
    else:
        for entry in summary["files"]:
            name = entry["file"]
            run_check(f"{d.name}/{name} loads closed with the reported volume (trimesh)", check_file, d, name, entry["parts"])
        run_check(f"{d.name}: cavity volumes match the body", check_cavities, summary)
sys.exit(finish())
