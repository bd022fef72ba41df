"""clearway.plan: certified paths (checked again here with check_motions), the path `clearway plan` prints
for the same seed, bad arguments as ValueError, an edited scene planned around, and the GIL released."""
import math
import threading
import time

import numpy as np
import pytest

import clearway
from conftest import ARM6_WALL, REPO, shared


def assert_certified(scene, result, start=None, goal=None):
    assert result.solved, result
    assert result.status == "solved" and result.message == ""
    path = result.path
    assert path.dtype == np.float64 and path.ndim == 2 and path.shape[1] == scene.dof and len(path) >= 2
    np.testing.assert_array_equal(path[0], scene.start if start is None else start)
    np.testing.assert_array_equal(path[-1], scene.goal if goal is None else goal)
    free, _ = scene.check_motions(path[:-1], path[1:], mode="certified")
    assert free.all(), f"segments {np.flatnonzero(~free)} are not certified free"
    assert result.solve_time > 0 and result.state_checks > 0 and result.motion_checks > 0 and result.length > 0


def test_plans_a_certified_path_on_the_bundled_scene(arm6):
    r = clearway.plan(arm6, seed=3, time=30)
    assert_certified(arm6, r)
    assert len(r.path) >= 3, "the wall blocks the straight line"
    assert r.planner == "RRTConnect" and r.seed == 3 and r.ompl_status == "Exact solution"
    assert r.simplify_time > 0 and r.simplify_motion_checks > 0
    assert r.state_check_time > 0 and r.motion_check_time > 0
    assert r.uncertified_segments == []
    assert repr(r).startswith(f"<PlanResult solved: {len(r.path)} states, length ")
    raw = clearway.plan(arm6, seed=3, time=30, simplify=False)
    assert_certified(arm6, raw)
    assert raw.simplify_time == 0 and raw.simplify_motion_checks == 0


def test_the_same_seed_plans_the_tools_path(arm6, tool):
    lines = tool("plan", ARM6_WALL, "--seed", 8, "--time", 30)
    assert lines[0] == f"path {len(lines) - 1}"
    printed = np.array([[float(x) for x in line.split()] for line in lines[1:]])
    r = clearway.plan(arm6, seed=8, time=30)
    np.testing.assert_array_equal(r.path, printed)  # 17 digits: the same doubles
    # Again after an unseeded query and another seed: OMPL's seeds come from one process-wide generator.
    clearway.plan(arm6, time=30)
    other = clearway.plan(arm6, seed=9, time=30)
    assert not np.array_equal(other.path, r.path), "seeds 8 and 9 planned the same path: is the seed used?"
    np.testing.assert_array_equal(clearway.plan(arm6, seed=8, time=30).path, printed)
    # numpy integers are seeds too.
    np.testing.assert_array_equal(clearway.plan(arm6, seed=np.uint64(8), time=30).path, printed)


@pytest.mark.parametrize("rel", ["scenes/bookshelf_small_panda/bookshelf_small_panda_0001.yaml",
                                 "scenes/box_ur5/box_ur5_0001.yaml"])
def test_plans_certified_paths_on_shared_families(rel):
    scene = clearway.Scene.load(str(shared(rel)))
    first = clearway.plan(scene, seed=1, time=60)
    assert_certified(scene, first)
    # Every plan (and check_motions' certified checks) uses the one checker the scene keeps: a new one per
    # call cost a UR5 a third of a second.
    np.testing.assert_array_equal(clearway.plan(scene, seed=1, time=60).path, first.path)
    assert scene.motion_checkers_kept == 1


def test_plans_between_given_states(arm6):
    start, goal = np.array(arm6.goal), np.array(arm6.start)  # the other way round
    r = clearway.plan(arm6, seed=2, time=30, start=start, goal=goal)
    assert_certified(arm6, r, start, goal)


def test_an_edited_scene_is_planned_around(arm6):
    first = clearway.plan(arm6, seed=7, time=30)
    assert_certified(arm6, first)
    # A ball where the wrist is halfway along the first path's middle segment.
    i = (len(first.path) - 1) // 2
    mid = 0.5 * (first.path[i] + first.path[i + 1])
    robot = clearway.load_robot(str(REPO / "robots/arm6/arm6.urdf"), str(REPO / "robots/arm6/arm6.srdf"))
    wrist = robot.link_poses(mid)[robot.link_names.index("wrist_2_link")][:3, 3]
    edited = arm6.with_obstacle("ball", clearway.Sphere(0.06), pose=(wrist, [0, 0, 0, 1]))
    assert not edited.is_free(mid)
    free, _ = edited.check_motions(first.path[:-1], first.path[1:])
    assert not free.all(), "the ball does not block the first path"
    second = clearway.plan(edited, seed=7, time=30)
    assert_certified(edited, second)
    assert arm6.is_free(mid), "the edit changed the scene it was made from"


def test_colliding_ends_are_results_not_errors(arm6):
    r = clearway.plan(arm6, start=[0, 1.7, 0.5, 0, 0, 0])  # into the floor
    assert not r.solved and r.status == "start colliding"
    assert "start is in collision" in r.message and "floor" in r.message
    assert r.path.shape == (0, 6)
    assert "start colliding" in repr(r)
    assert clearway.plan(arm6, goal=[0, 1.7, 0.5, 0, 0, 0]).status == "goal colliding"


def test_bad_arguments_raise_value_error(arm6):
    with pytest.raises(ValueError, match="unknown planner 'Teleport'"):
        clearway.plan(arm6, planner="Teleport")
    for t in (0, -1, math.nan, math.inf, 1e6 * (1 + 1e-15)):
        with pytest.raises(ValueError, match="time: needs a number > 0 and <= 1e6"):
            clearway.plan(arm6, time=t)
    for seed in (-1, 2**64):
        with pytest.raises(ValueError, match="seed must be a whole number from 0 to 2\\^64 - 1"):
            clearway.plan(arm6, seed=seed)
    with pytest.raises(TypeError, match="seed must be a whole number or None"):
        clearway.plan(arm6, seed=1.5)
    with pytest.raises(ValueError, match="start"):
        clearway.plan(arm6, start=[0, 0, 0])
    with pytest.raises(ValueError, match="start: "):
        clearway.plan(arm6, start=[0, 0, 0, 0, 0, 99])
    with pytest.raises(ValueError, match="goal: "):
        clearway.plan(arm6, goal=[0, 0, 0, 0, math.nan, 0])
    assert "RRTConnect" in clearway.planners and "PRM" in clearway.planners


def test_planning_releases_the_gil(arm6):
    # RRT* plans for its whole time limit; meanwhile this thread must keep running Python.
    done = threading.Event()
    thread = threading.Thread(target=lambda: (clearway.plan(arm6, planner="RRTstar", time=1.0, seed=1), done.set()))
    thread.start()
    time.sleep(0.1)
    counted, t0 = 0, time.monotonic()
    while time.monotonic() - t0 < 0.3:
        counted += 1
    overlapped = not done.is_set()
    thread.join()
    assert overlapped, "the plan ended before the count: nothing was measured"
    assert counted > 10000, f"only {counted} loops in 0.3 s beside the planner: the GIL was held"
