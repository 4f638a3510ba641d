"""cablemap.design, feasible, calibrate, diagnose and predict against the binary.

Each report's to_dict() must equal the command's --json object for the same
input (wall times aside); bad input must raise the package's exception with
the library's message (the one the command prints). The binary is
$CABLEMAP_BIN (scripts/test.sh sets it), else target/release/cablemap.
"""

import json
import os
import subprocess
from pathlib import Path

import pytest

import cablemap

REPO = Path(__file__).resolve().parents[2]
BIN = os.environ.get("CABLEMAP_BIN", str(REPO / "target" / "release" / "cablemap"))
SOROMOX = REPO / "tests" / "data" / "soromox"
DESIGN = REPO / "tests" / "data" / "design"
TABLE_5_1_I = "x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015"

# Wall times: the one thing two runs of the same request do not share.
TIMINGS = {"seconds", "elapsed_s"}


def command(*args, cwd=None):
    """`cablemap ARGS --json`'s object."""
    out = subprocess.run([BIN, *map(str, args), "--json"], capture_output=True, text=True, cwd=cwd)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def command_error(*args):
    """The error the command prints for ARGS (it must fail)."""
    out = subprocess.run([BIN, *map(str, args)], capture_output=True, text=True)
    assert out.returncode != 0, out.stdout
    return out.stderr


def without_timings(value):
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items() if k not in TIMINGS}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


def without_races(design):
    """A design without how far each start ran: a start stops once another
    has fitted exactly, so its evaluations and cost depend on the threads'
    timing; the seeds and the design do not."""
    design = dict(design)
    design["starts"] = [{k: v for k, v in s.items() if k in ("seed", "seed_cost", "source")} for s in design["starts"]]
    return design


def assert_same_report(report, want):
    got = report.to_dict()
    if "starts" in want:
        got, want = without_races(got), without_races(want)
    assert without_timings(got) == without_timings(want)
    # The timings are there, as the command's.
    assert sorted(got) == sorted(want)


# ---------------------------------------------------------------- design


def test_table_5_1_design_equals_the_command_with_its_pictures(tmp_path):
    ours = cablemap.design(TABLE_5_1_I, out=tmp_path / "py")
    want = command("design", "--target", TABLE_5_1_I, "--out", tmp_path / "cli")
    assert_same_report(ours, want)
    assert ours.met and ours.unmet == [] and ours.tension_n == want["tension_n"] and ours.routing_mm == want["routing_mm"]
    # The same target as a dict; the files of --out, shown in notebooks.
    names = sorted(Path(p).name for p in ours.pictures)
    assert names == ["mould.svg", "shape.png"]
    page = ours._repr_html_()
    assert "data:image/png;base64," in page and "<svg" in page and "met" in repr(ours)
    assert (tmp_path / "py" / "design.json").exists()


def test_design_target_as_a_dict_with_rod_fields_and_weights_equals_the_flags():
    ours = cablemap.design({"x": 48, "y": 8, "a0": -0.02, "a1": -0.05}, weights={"a0": 200}, ei_n_mm2=90.0, gravity=False, starts=2)
    want = command("design", "--target", "x=48,y=8,a0=-0.02,a1=-0.05", "--weights", "a0=200", "--ei-n-mm2", "90", "--no-gravity", "--starts", "2")
    assert_same_report(ours, want)


def test_several_cable_design_equals_the_command():
    targets, actuator = DESIGN / "two-targets.toml", DESIGN / "two-free-cables.toml"
    ours = cablemap.design(targets=targets, actuator=actuator, starts=2)
    want = command("design", "--targets", targets, "--actuator", actuator, "--starts", "2")
    assert_same_report(ours, want)
    assert len(ours.cables) == 2 and [t["name"] for t in ours.targets] == [t["name"] for t in want["targets"]]
    assert "cable 1" in repr(ours)


def test_design_refuses_bad_input_with_the_library_message():
    with pytest.raises(cablemap.BadInputError) as e:
        cablemap.design("x=50,q=3")
    assert str(e.value) in command_error("design", "--target", "x=50,q=3")
    with pytest.raises(cablemap.BadInputError, match="target= .* or targets="):
        cablemap.design()
    with pytest.raises(cablemap.BadInputError, match="tension_max_n does not apply"):
        cablemap.design(targets=DESIGN / "two-targets.toml", tension_max_n=2.0)
    with pytest.raises(cablemap.BadInputError, match="unknown actuator field"):
        cablemap.design(TABLE_5_1_I, stiffness=3)


# ---------------------------------------------------------------- feasible


@pytest.fixture(scope="module")
def quick_map(tmp_path_factory):
    """The map of jobs/quick.toml (610 solves), made by the binary."""
    root = tmp_path_factory.mktemp("quick")
    subprocess.run([BIN, "sweep", REPO / "jobs" / "quick.toml", "--out", root / "run", "--quiet"], check=True, capture_output=True)
    subprocess.run([BIN, "reduce", root / "run", "--out", root / "map"], check=True, capture_output=True)
    return root / "map"


def test_feasible_on_a_small_map_equals_the_command(quick_map):
    ours = cablemap.feasible({"x": 50, "y": 5, "a0": -0.025, "a1": -0.06}, map=quick_map, nearest=3)
    want = command("feasible", "--map", quick_map, "--target", "x=50,y=5,a0=-0.025,a1=-0.06", "--nearest", "3")
    assert_same_report(ours, want)
    assert ours.verdict == want["verdict"] and repr(ours).splitlines()[1].strip() == f"verdict: {want['verdict']}"
    assert "verdict" in ours.text


def test_feasible_refuses_a_missing_map_as_a_file_error(tmp_path):
    missing = tmp_path / "no-map"
    with pytest.raises(cablemap.FileFormatError) as e:
        cablemap.feasible("x=50", map=missing)
    assert str(e.value) in command_error("feasible", "--map", missing, "--target", "x=50")
    with pytest.raises(cablemap.BadInputError, match="map=MAP_DIR"):
        cablemap.feasible("x=50")


# ---------------------------------------------------------------- calibrate, diagnose


@pytest.fixture(scope="module")
def synth(tmp_path_factory):
    """Measurements with hidden friction (`cablemap synth`), 3 routings."""
    root = tmp_path_factory.mktemp("synth")
    path = root / "measurements.csv"
    subprocess.run(
        [BIN, "synth", "--out", path, "--effect", "friction", "--magnitude", "0.08", "--routings",
         "arc:2,2,2,2,2;s_curve:3,1,-1,-3,-2;tip_bend:0,0,1,3,4"],
        check=True, capture_output=True,
    )
    return path


def test_calibrate_on_synth_data_equals_the_command(synth):
    ours = cablemap.calibrate(synth, effects=["friction"], fix={"GA": 1.70866})
    want = command("calibrate", synth, "--effect", "friction", "--fix", "GA=1.70866")
    assert_same_report(ours, want)
    assert "iterations" in repr(ours)


def test_diagnose_on_synth_data_equals_the_command_with_its_plots(synth, tmp_path):
    out = tmp_path / "diagnosis"
    want = command("diagnose", synth, "--out", out)
    ours = cablemap.diagnose(synth, out=out)
    assert_same_report(ours, want)
    assert ours.verdict == want["verdict"] and f"verdict: {want['verdict']}" in repr(ours)
    assert sorted(Path(p).name for p in ours.pictures) == ["loops.png", "residuals.png", "shapes.png"]
    assert ours._repr_html_().count("data:image/png;base64,") == 3
    # Without the report: no pictures, as --no-report.
    bare = cablemap.diagnose(synth, report=False, max_effects=1)
    assert bare.pictures == [] and bare.report is None
    assert without_timings(bare.to_dict()) == without_timings(command("diagnose", synth, "--no-report", "--max-effects", "1"))


def test_fits_refuse_bad_input_with_the_library_message(synth, tmp_path):
    with pytest.raises(cablemap.BadInputError) as e:
        cablemap.calibrate(synth, effects=["magic"])
    assert "unknown effect" in str(e.value)
    with pytest.raises(cablemap.BadInputError, match="unknown parameter 'XY'"):
        cablemap.calibrate(synth, fix={"XY": 1.0})
    with pytest.raises(cablemap.BadInputError, match="unknown rod field"):
        cablemap.calibrate(synth, stiffness=1.0)
    missing = tmp_path / "missing.csv"
    with pytest.raises(cablemap.FileFormatError) as e:
        cablemap.calibrate(missing)
    assert str(e.value) in command_error("calibrate", missing)
    with pytest.raises(cablemap.BadInputError) as e:
        cablemap.diagnose(synth, report=False, noise_mm=-1.0)
    assert str(e.value) in command_error("diagnose", synth, "--no-report", "--noise-mm", "-1")


# ---------------------------------------------------------------- captures (3-D)


def test_predict_on_soromox_equals_the_command():
    args = dict(captures=SOROMOX / "captures.csv", actuator=SOROMOX / "actuator.toml", markers=SOROMOX / "markers.csv")
    ours = cablemap.predict(**args)
    want = command("predict", args["captures"], "--actuator", args["actuator"], "--markers", args["markers"])
    assert_same_report(ours, want)
    assert ours.rms_mm == want["rms_mm"] and "marker RMS" in repr(ours)


def test_calibrate_captures_on_soromox_equals_the_command(tmp_path):
    captures, actuator, markers = SOROMOX / "captures.csv", SOROMOX / "actuator.toml", SOROMOX / "markers.csv"
    ours = cablemap.calibrate(captures, actuator=actuator, markers=markers, max_iterations=1, out=tmp_path / "py")
    want = command("calibrate", captures, "--actuator", actuator, "--markers", markers, "--max-iterations", "1", "--out", tmp_path / "cli")
    assert_same_report(ours, want)
    assert (tmp_path / "py" / "calibrated.toml").exists()
    with pytest.raises(cablemap.BadInputError, match="come from FILE.toml's"):
        cablemap.calibrate(captures, actuator=actuator, markers=markers, ei_n_mm2=1.0)


def test_predict_refuses_a_missing_actuator_as_a_file_error(tmp_path):
    missing = tmp_path / "none.toml"
    with pytest.raises(cablemap.FileFormatError) as e:
        cablemap.predict(SOROMOX / "captures.csv", missing)
    assert str(e.value) in command_error("predict", SOROMOX / "captures.csv", "--actuator", missing)
