"""Segments: check_motions against `clearway motion` in every mode, the certified check's guarantees, and
bad input."""
import math

import numpy as np
import pytest

import clearway
from conftest import ARM6_WALL, REPO, random_states, write_rows


def segments(scene, n, seed):
    """n segments from random states to states at most 1.5 rad away per joint, within the limits."""
    q0 = random_states(scene, n, seed)
    step = np.random.default_rng(seed + 100).uniform(-1.5, 1.5, size=q0.shape)
    q1 = np.clip(q0 + step, scene.limits[:, 0], scene.limits[:, 1])
    return q0, q1


def free_starts(scene, n, seed):
    q0, q1 = segments(scene, 4 * n, seed)
    keep = scene.check(q0) & scene.check(q1)
    return q0[keep][:n], q1[keep][:n]


def as_tool_prints(free, last_valid, pairs):
    return ["free" if f else f"collision {lv:.9g} " + " ".join(p) for f, lv, p in zip(free, last_valid, pairs)]


@pytest.mark.parametrize("mode", ["certified", "cast", "sampled:0.02"])
def test_check_motions_equals_the_tool_on_arm6(arm6, tool, tmp_path, mode):
    q0, q1 = free_starts(arm6, 150, seed=11)
    free, last_valid, pairs = arm6.check_motions(q0, q1, mode=mode, report=True)
    assert free.dtype == np.bool_ and last_valid.dtype == np.float64
    motions = write_rows(tmp_path / "motions.txt", np.hstack([q0, q1]))
    assert as_tool_prints(free, last_valid, pairs) == tool("motion", ARM6_WALL, "--motions", motions, "--motion", mode)
    assert 10 < free.sum() < 140  # both verdicts occur
    assert (last_valid[free] == 1).all() and (last_valid[~free] < 1).all() and (last_valid >= 0).all()


def test_check_motions_equals_the_tool_on_a_shared_panda_problem(panda_box, tool, tmp_path):
    path, scene = panda_box
    q0, q1 = free_starts(scene, 60, seed=12)
    free, last_valid, pairs = scene.check_motions(q0, q1, report=True)
    motions = write_rows(tmp_path / "motions.txt", np.hstack([q0, q1]))
    assert as_tool_prints(free, last_valid, pairs) == tool("motion", path, "--motions", motions)
    assert 0 < free.sum() < 60


def test_certified_misses_nothing_dense_sampling_finds(arm6):
    q0, q1 = free_starts(arm6, 150, seed=13)
    certified, _ = arm6.check_motions(q0, q1)
    dense, _ = arm6.check_motions(q0, q1, mode="sampled:0.002")
    assert not (certified & ~dense).any()
    assert (~dense).sum() > 10


def test_a_larger_contact_distance_only_removes_free_verdicts(arm6):
    q0, q1 = free_starts(arm6, 150, seed=14)
    fine, _ = arm6.check_motions(q0, q1, contact_distance=1e-4)
    coarse, _ = arm6.check_motions(q0, q1, contact_distance=0.05)
    assert not (coarse & ~fine).any()
    assert coarse.sum() < fine.sum()


def test_the_last_valid_state_is_free(arm6):
    q0, q1 = free_starts(arm6, 100, seed=15)
    free, last_valid = arm6.check_motions(q0, q1)
    hit = ~free
    states = q0[hit] + last_valid[hit, None] * (q1[hit] - q0[hit])
    assert hit.sum() > 10 and arm6.check(states).all()


def test_a_motion_of_length_zero_from_a_free_state_is_free(arm6):
    q0, _ = free_starts(arm6, 20, seed=16)
    free, last_valid = arm6.check_motions(q0, q0)
    assert free.all() and (last_valid == 1).all()


def test_bad_motions_raise(arm6):
    q0, q1 = segments(arm6, 5, seed=17)
    q1[3, 4] = math.nan
    with pytest.raises(ValueError, match=r"Q1\[3\]: state\[4\] \(wrist_2_joint\) is not finite"):
        arm6.check_motions(q0, q1)
    with pytest.raises(ValueError, match="as many rows"):
        arm6.check_motions(q0, q0[:4])
    with pytest.raises(ValueError, match=r"unknown mode 'exact'"):
        arm6.check_motions(q0, q0, mode="exact")
    with pytest.raises(ValueError, match=r"sampled:RES needs a resolution > 0"):
        arm6.check_motions(q0, q0, mode="sampled:-1")
    for bad in (-1.0, 0.0, math.nan, math.inf):
        with pytest.raises(ValueError, match="contact_distance must be finite and > 0"):
            arm6.check_motions(q0, q0, contact_distance=bad)


RISING_PLATE = """format: 1
name: rising_plate
robot:
  urdf: {urdf}
  group: [fly]
  bounds: {{fly/x: [-2, 2], fly/y: [-2, 2], fly/z: [-2, 2]}}
environment:
  obstacles:
    - name: plate
      box: {{size: [2, 2, 0.002]}}
      pose: {{position: [0, 0, 0]}}
      velocity: [0, 0, 1]
checks: [environment, continuous, clearance, moving]
"""


@pytest.fixture
def rising_plate(tmp_path):
    """The flyer (a 0.04 m thick plate) above a plate that rises at 1 m/s from z = 0."""
    path = tmp_path / "rising.yaml"
    path.write_text(RISING_PLATE.format(urdf=REPO / "robots" / "flyer" / "flyer.urdf"))
    return path, clearway.Scene.load(str(path))


def test_states_see_moving_obstacles_at_their_times(rising_plate):
    _, scene = rising_plate
    level = [0, 0, 0.5, 0, 0, 0, 1]  # the flyer's underside at z = 0.48; the plate's top at 0.001 + t
    times = np.array([0, 0.4, 0.47, 0.49, 0.7])  # at 0.7 the plate cuts the rod standing on the flyer
    np.testing.assert_array_equal(scene.check(np.tile(level, (5, 1)), times=times), [True, True, True, False, False])
    assert scene.is_free(level) and not scene.is_free(level, t=0.6)
    np.testing.assert_allclose(scene.clearance(np.tile(level, (2, 1)), times=[0.2, 0.3]), [0.279, 0.179], rtol=1e-6)
    with pytest.raises(ValueError, match=r"times\[1\] is not finite"):
        scene.check(np.tile(level, (2, 1)), times=[0, math.nan])
    with pytest.raises(ValueError, match=r"times must have shape \(2,\)"):
        scene.check(np.tile(level, (2, 1)), times=[0, 1, 2])


def test_timed_motions_equal_the_tools_timed_lines(rising_plate, tool, tmp_path):
    path, scene = rising_plate
    rng = np.random.default_rng(18)
    n = 60
    q0 = np.tile([0, 0, 0.5, 0, 0, 0, 1.0], (n, 1))
    q1 = q0.copy()
    q0[:, 2] = rng.uniform(0.3, 1.0, n)
    q1[:, 2] = rng.uniform(0.3, 1.5, n)
    times = np.sort(rng.uniform(0, 0.8, (n, 2)), axis=1)
    free, last_valid, pairs = scene.check_motions(q0, q1, times=times, report=True)
    lines = write_rows(tmp_path / "timed.txt", np.hstack([times[:, :1], q0, times[:, 1:], q1]))
    assert as_tool_prints(free, last_valid, pairs) == tool("motion", path, "--motions", lines)
    assert 5 < free.sum() < n - 5
    # Standing still at z = 0.5 from t = 0 to 1, the plate arrives at t = 0.479: the last valid fraction is just before.
    still = np.array([[0, 0, 0.5, 0, 0, 0, 1.0]])
    free, last_valid = scene.check_motions(still, still, times=[[0, 1]])
    assert not free[0] and 0.47 < last_valid[0] <= 0.479
    assert scene.check_motions(still, still)[0][0]  # without times, at t = 0 throughout


def test_checkers_of_many_contact_distances_are_not_all_kept(arm6):
    # A checker per distinct contact distance was kept for the scene's life: a sweep of 20,000 distances
    # held 788 MB. Only the most recently used 8 are kept; the verdicts are those of a fresh checker.
    q0, q1 = free_starts(arm6, 2, seed=17)
    expected, _ = arm6.check_motions(q0, q1, contact_distance=1e-3)
    for k in range(12):
        arm6.check_motions(q0, q1, contact_distance=2e-3 + k * 1e-7)
    assert arm6.motion_checkers_kept == 8
    again, _ = arm6.check_motions(q0, q1, contact_distance=1e-3)
    assert (again == expected).all()
