"""The examples under examples/python run and say what the module says."""
import os
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

import clearway
from conftest import REPO, shared, _missing

EXAMPLES = REPO / "examples" / "python"


def run(script, *args):
    done = subprocess.run([sys.executable, str(EXAMPLES / script), *map(str, args)], capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_random_states_counts_each_pair(tmp_path):
    path = shared("scenes/box_panda/box_panda_0001.yaml")
    out = run("random_states.py", path, "--count", 3000, "--seed", 9, "--plot", tmp_path / "pairs.png")
    scene = clearway.Scene.load(str(path))
    states = np.random.default_rng(9).uniform(scene.limits[:, 0], scene.limits[:, 1], size=(3000, scene.dof))
    free, pairs = scene.check(states, report=True)
    colliding = float(re.search(r"([0-9.]+) colliding", out).group(1))
    assert colliding == pytest.approx(1 - free.mean(), abs=1e-4)
    rows = re.findall(r"^\s+([0-9.]+)\s+(\S+) / (\S+)$", out, re.M)
    assert sum(float(f) for f, _, _ in rows) == pytest.approx(colliding, abs=1e-3 + 1e-4 * len(rows))
    for f, a, b in rows:
        assert float(f) == pytest.approx(pairs.count((a, b)) / 3000, abs=1e-4)
    try:
        import matplotlib  # noqa: F401
        assert (tmp_path / "pairs.png").stat().st_size > 1000
    except ImportError:
        assert "matplotlib is not installed" in out


def test_audit_srdf_writes_the_audits_srdf(tmp_path):
    urdf, srdf = REPO / "robots" / "arm6" / "arm6.urdf", REPO / "robots" / "arm6" / "arm6.srdf"
    out = run("audit_srdf.py", urdf, "--srdf", srdf, "--samples", 500, "--seed", 2, "--out", tmp_path / "out.srdf")
    assert (tmp_path / "out.srdf").read_text() == clearway.audit(str(urdf), srdf=str(srdf), samples=500, seed=2).to_srdf()
    assert "arm6: 21 pairs: " in out and "differs: " in out


def test_batch_overhead_agrees_with_the_cpp_loop():
    timer = os.environ.get("CLEARWAY_BATCH_TIMER", "")
    if not os.access(timer, os.X_OK):
        _missing(f"clearway_batch_timer not found (CLEARWAY_BATCH_TIMER={timer!r})")
    out = run("batch_overhead.py", shared("scenes/box_panda/box_panda_0001.yaml"), "--count", 500, "--rounds", 1,
              "--timer", timer)
    assert re.search(r"overhead: +-?[0-9.]+ ns per state", out)
