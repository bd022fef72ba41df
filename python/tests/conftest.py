"""Shared fixtures of the Python tests: the repository's and the shared development data's robots and
scenes, and the built `clearway` tool whose answers the module must equal.

The shared data (../shared next to the repository, or $CLEARWAY_SHARED) is found as the C++ tests find it
(tests/shared_data.h): a test whose data is missing is skipped, or fails when CI=true. So is a test that
needs the tool ($CLEARWAY_TOOL, set by CTest) when it was not built.
"""
import os
import pathlib
import subprocess

import numpy as np
import pytest

import clearway

REPO = pathlib.Path(__file__).resolve().parents[2]


def _missing(what):
    if os.environ.get("CI") == "true":
        pytest.fail(what + ": required because CI=true")
    pytest.skip(what)


def shared_dir():
    env = os.environ.get("CLEARWAY_SHARED")
    if env:
        return pathlib.Path(env)
    return pathlib.Path(os.environ.get("CLEARWAY_SHARED_DIR", REPO.parent / "shared"))


def shared(rel):
    """shared_dir()/rel, skipping (or failing under CI=true) the test when it is missing."""
    path = shared_dir() / rel
    if not path.exists():
        _missing(f"shared data not found: {path} (the development data next to the repository, "
                 "or $CLEARWAY_SHARED; see DATA.md)")
    return path


@pytest.fixture(scope="session")
def tool():
    """A function running `clearway ARGS...` and returning its stdout lines (it must exit 0)."""
    path = os.environ.get("CLEARWAY_TOOL", "")
    if not path or not os.access(path, os.X_OK):
        _missing(f"the clearway tool was not found (CLEARWAY_TOOL={path!r}; build with CLEARWAY_BUILD_TOOLS=ON)")

    def run(*args, input=None):
        done = subprocess.run([path, *map(str, args)], input=input, capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, f"clearway {' '.join(map(str, args))}: exit {done.returncode}\n{done.stderr}"
        return done.stdout.splitlines()

    return run


ARM6_WALL = REPO / "robots" / "scenes" / "arm6_wall.yaml"


@pytest.fixture(scope="session")
def arm6():
    return clearway.Scene.load(str(ARM6_WALL))


@pytest.fixture(scope="session")
def panda_box():
    """A shared MotionBenchMaker problem: the Panda among boxes and cylinders (path, scene)."""
    path = shared("scenes/box_panda/box_panda_0001.yaml")
    return path, clearway.Scene.load(str(path))


def random_states(scene, n, seed):
    """n states uniform within the scene's limits (every scene used here has finite limits)."""
    limits = scene.limits
    assert np.isfinite(limits).all()
    rng = np.random.default_rng(seed)
    return rng.uniform(limits[:, 0], limits[:, 1], size=(n, scene.dof))


def write_rows(path, rows):
    """One row per line, each number written so that it reads back to the same double."""
    with open(path, "w") as f:
        for row in rows:
            f.write(" ".join(repr(float(x)) for x in row) + "\n")
    return path
