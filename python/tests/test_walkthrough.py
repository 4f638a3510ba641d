"""docs/python.md's walkthrough runs: its ```python blocks, in order, in one
namespace, in a fresh directory with a copy of jobs/ (the specs it sweeps),
so that the documentation cannot rot.

The walkthrough calls the `cablemap` command (for `cablemap synth`): the
binary's directory ($CABLEMAP_BIN's, else target/release) is put first on
PATH.
"""

import os
import re
import shutil
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
BIN = os.environ.get("CABLEMAP_BIN", str(REPO / "target" / "release" / "cablemap"))
DOC = REPO / "docs" / "python.md"


def python_blocks(text):
    """The ```python blocks of a Markdown text, in order."""
    return re.findall(r"^```python\n(.*?)^```$", text, flags=re.S | re.M)


def test_the_walkthrough_has_its_steps():
    code = "\n".join(python_blocks(DOC.read_text(encoding="utf-8")))
    for step in ("cablemap.simulate(", "cablemap.solve_batch(", "pl.DataFrame(", "cablemap.design(", "cablemap.diagnose(", "savefig("):
        assert step in code, f"docs/python.md's walkthrough lost its step {step}"


def test_the_walkthrough_runs(tmp_path, monkeypatch):
    shutil.copytree(REPO / "jobs", tmp_path / "jobs")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("PATH", str(Path(BIN).resolve().parent) + os.pathsep + os.environ.get("PATH", ""))
    blocks = python_blocks(DOC.read_text(encoding="utf-8"))
    assert blocks, "docs/python.md has no ```python blocks"
    namespace = {"__name__": "walkthrough"}
    for i, block in enumerate(blocks, 1):
        exec(compile(block, f"docs/python.md (python block {i})", "exec"), namespace)
    # What the steps wrote.
    assert set(namespace["tables"]) == {"cells", "modes", "designs"}
    assert namespace["reach"].height > 0
    assert (tmp_path / "target-I" / "shape.png").exists()
    assert (tmp_path / "diagnosis" / "report.md").exists()
    assert (tmp_path / "loops.png").stat().st_size > 1000
