"""cablemap.simulate and cablemap.solve_batch against the cablemap binary.

The binary is $CABLEMAP_BIN (scripts/test.sh sets it), else
target/release/cablemap of the repository.
"""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import cablemap

REPO = Path(__file__).resolve().parents[2]
BIN = os.environ.get("CABLEMAP_BIN", str(REPO / "target" / "release" / "cablemap"))


def run_json(*args):
    """`cablemap simulate ARGS --json`'s object."""
    out = subprocess.run([BIN, "simulate", *args, "--json"], capture_output=True, text=True, check=True)
    return json.loads(out.stdout)


def assert_records_equal(ours, theirs, tol=1e-12):
    assert sorted(ours) == sorted(theirs)
    for key, want in theirs.items():
        got = ours[key]
        if isinstance(want, float):
            assert got == pytest.approx(want, rel=0, abs=tol), key
        elif isinstance(want, list) and want and isinstance(want[0], float):
            np.testing.assert_allclose(got, want, rtol=0, atol=tol, err_msg=key)
        else:
            assert got == want, key


def test_planar_simulate_equals_the_command():
    sim = cablemap.simulate(routing_mm=[1, -2, 3, 0.5, -3], tension_n=1.5)
    want = run_json("--routing", "1,-2,3,0.5,-3", "--tension-n", "1.5")
    assert_records_equal(sim.to_dict(), want)
    assert sim.tip_x_mm == want["tip_x_mm"] and sim.a == want["a"] and sim.status == "ok"
    # The centreline ends at the tip.
    x = sim.centreline[:, sim.centreline_columns.index("x_mm")]
    y = sim.centreline[:, sim.centreline_columns.index("y_mm")]
    assert x[-1] == pytest.approx(sim.tip_x_mm, abs=1e-9) and y[-1] == pytest.approx(sim.tip_y_mm, abs=1e-9)


def test_rod_fields_order_and_basis_equal_the_flags():
    sim = cablemap.simulate(
        routing_mm=[2, 2, 2, 2, 2], tension_n=0.8, ei_n_mm2=90.0, gravity=False, order=5, length_basis="deformed", stiffening_alpha=0.5
    )
    want = run_json(
        "--routing", "2,2,2,2,2", "--tension-n", "0.8", "--ei-n-mm2", "90", "--no-gravity", "--order", "5",
        "--length-basis", "deformed", "--stiffening-alpha", "0.5",
    )
    assert_records_equal(sim.to_dict(), want)


def test_displacement_driven_cable_equals_the_command():
    sim = cablemap.simulate(routing_mm=[1, 1, 1, 1, 1], displacement_mm=2.0, cable_ea_n=500.0)
    want = run_json("--routing", "1,1,1,1,1", "--displacement-mm", "2", "--cable-ea-n", "500")
    assert_records_equal(sim.to_dict(), want)


def test_several_spatial_cables_equal_the_command():
    cables = [
        {"y_mm": [2, 3, 1, -1, 2], "z_mm": [1, -1, 2, 2, 0], "tension_n": 1.4},
        {"y_mm": [-2, -2, -2, -2, -2], "tension_n": 0.5},
    ]
    sim = cablemap.simulate(cables=cables)
    want = run_json("--cable", "y=2,3,1,-1,2 z=1,-1,2,2,0 tension=1.4", "--cable", "y=-2,-2,-2,-2,-2 tension=0.5")
    assert_records_equal(sim.to_dict(), want)
    assert sim.centreline.shape[1] == len(sim.centreline_columns)


def test_actuator_file_round_trips_through_toml(tmp_path):
    path = REPO / "tests" / "data" / "spatial" / "antagonistic.toml"
    actuator = cablemap.Actuator.read(path)
    sim = cablemap.simulate(actuator=actuator)
    assert_records_equal(sim.to_dict(), run_json("--actuator", str(path)))
    copy = tmp_path / "copy.toml"
    actuator.write(copy)
    assert cablemap.Actuator.read(copy) == actuator


def test_actuator_from_fields_and_thesis_default():
    thesis = cablemap.Actuator.thesis()
    assert thesis.rod["length_mm"] == 65.0 and thesis.cables == []
    longer = cablemap.Actuator(length_mm=80.0, gj_n_mm2=70.0)
    assert longer.rod["length_mm"] == 80.0 and longer.to_dict()["gj_n_mm2"] == 70.0
    assert "length_mm = 80.0" in longer.to_toml()


def test_invalid_routing_raises_the_library_message():
    out = subprocess.run([BIN, "simulate", "--routing", "1,2,9,0,0", "--tension-n", "1"], capture_output=True, text=True)
    assert out.returncode != 0
    with pytest.raises(cablemap.BadInputError) as e:
        cablemap.simulate(routing_mm=[1, 2, 9, 0, 0], tension_n=1.0)
    message = str(e.value)
    assert message.startswith("routing_mm: ")
    # The library's message, as the command prints it after its flag.
    assert message[len("routing_mm: "):] in out.stderr, (message, out.stderr)
    assert isinstance(e.value, ValueError) and isinstance(e.value, cablemap.CablemapError)


def test_unknown_field_and_missing_file_are_named():
    with pytest.raises(cablemap.BadInputError, match="unknown actuator field \"lenght_mm\".*length_mm"):
        cablemap.simulate(routing_mm=[0, 0, 0, 0, 0], tension_n=1.0, lenght_mm=70)
    with pytest.raises(cablemap.FileFormatError, match="no-such.toml"):
        cablemap.Actuator.read("no-such.toml")


def test_batch_equals_the_same_solves_one_by_one():
    routings = np.array([[1, -2, 3, 0.5, -3], [2, 2, 2, 2, 2], [0, 1, 0, -1, 0], [1, 2, 9, 0, 0]], dtype=float)
    tensions = np.linspace(0.5, 2.0, 4)
    batch = cablemap.solve_batch(routings, tensions, order=4)
    assert batch["tip_x_mm"].shape == (4, 4) and batch["a"].shape == (4, 4, 5)
    assert (batch["status"][3] == "invalid_routing").all() and np.isnan(batch["tip_x_mm"][3]).all()
    assert (batch["status"][:3] == "ok").all()
    for i in range(3):
        for j, t in enumerate(tensions):
            one = cablemap.simulate(routing_mm=routings[i], tension_n=t, order=4)
            # Another ladder to the same tension: equal to the solver's tolerance.
            assert batch["tip_x_mm"][i, j] == pytest.approx(one.tip_x_mm, abs=1e-7)
            assert batch["tip_y_mm"][i, j] == pytest.approx(one.tip_y_mm, abs=1e-7)
            assert batch["tip_angle_rad"][i, j] == pytest.approx(one.tip_angle_rad, abs=1e-8)
            np.testing.assert_allclose(batch["a"][i, j], one.a, rtol=0, atol=1e-8)
    # Threads do not change a result: each routing starts cold.
    single = cablemap.solve_batch(routings, tensions, order=4, threads=1)
    for key in ("tip_x_mm", "tip_y_mm", "a"):
        np.testing.assert_array_equal(single[key], batch[key])


def test_batch_equals_the_sweep_ladder_bitwise():
    """A batch row is the sweep's ladder: solve_batch of one routing equals
    the same solves in a loop of single-routing batches."""
    routing = [[1, -2, 3, 0.5, -3]]
    tensions = [1.0, 1.5, 2.0]
    whole = cablemap.solve_batch(routing, tensions)
    prefix = cablemap.solve_batch(routing, tensions[:2])
    np.testing.assert_array_equal(whole["tip_x_mm"][:, :2], prefix["tip_x_mm"])


def test_batch_refuses_bad_input():
    with pytest.raises(cablemap.BadInputError, match="tensions_n\\[1\\]"):
        cablemap.solve_batch([[0, 0, 0, 0, 0]], [1.0, -1.0])
    with pytest.raises(cablemap.BadInputError, match="\\(n, 5\\)"):
        cablemap.solve_batch(np.zeros((2, 4)), [1.0])
