"""Segments: check_motions against `clearway motion` in every mode, the certified check's guarantees, and
bad input."""
import math

import numpy as np
import pytest

from conftest import ARM6_WALL, random_states, write_rows


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
    assert as_tool_prints(free, last_valid, pairs) == tool("motion", ARM6_WALL, "--motions", motions, "--mode", mode)
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
