"""Scene: loading, properties, state checks against `clearway check`, clearance, and bad input."""
import math

import numpy as np
import pytest

import clearway
from conftest import ARM6_WALL, REPO, random_states, write_rows


def tool_verdicts(tool, scene_path, states, tmp_path):
    return tool("check", scene_path, "--states", write_rows(tmp_path / "states.txt", states))


def python_verdicts(scene, states):
    free, pairs = scene.check(states, report=True)
    assert free.dtype == np.bool_ and free.shape == (len(states),)
    return ["free" if f else "collision " + " ".join(p) for f, p in zip(free, pairs)]


def test_properties(arm6):
    assert arm6.name == "arm6_wall"
    assert arm6.dof == 6
    assert arm6.joint_names == ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"]
    assert arm6.limits.shape == (6, 2) and (arm6.limits[:, 0] < arm6.limits[:, 1]).all()
    e = arm6.effects
    assert (e.self, e.environment, e.continuous, e.clearance, e.moving) == (True, True, True, False, False)
    np.testing.assert_array_equal(arm6.start, [0, -0.6, -1.2, -1.34, 0, 0])
    np.testing.assert_array_equal(arm6.goal, [0, 0.6, 1.2, 1.34, 0, 0])
    assert arm6.link_names == ["base_link", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link",
                               "wrist_2_link", "wrist_3_link", "tool0"]
    assert repr(arm6) == "<clearway.Scene arm6_wall: 6 dof, checks self, environment, continuous>"


def test_start_and_goal_as_the_tool_says(arm6, tool):
    free, pairs = arm6.check(np.array([arm6.start, arm6.goal]), report=True)
    expected = [name + ": " + ("free" if f else "collision " + " ".join(p))
                for name, f, p in zip(["start", "goal"], free, pairs)]
    assert tool("check", ARM6_WALL) == expected


def test_check_equals_the_tool_on_arm6(arm6, tool, tmp_path):
    states = random_states(arm6, 2000, seed=1)
    ours = python_verdicts(arm6, states)
    assert ours == tool_verdicts(tool, ARM6_WALL, states, tmp_path)
    # Both verdicts occur, and both kinds of collision, so the comparison says something.
    assert 100 < ours.count("free") < 1900
    assert any("wall" in v or "floor" in v for v in ours)
    assert any(v.split()[-1] in arm6.link_names for v in ours if v != "free")


def test_check_equals_the_tool_on_a_shared_panda_problem(panda_box, tool, tmp_path):
    path, scene = panda_box
    states = random_states(scene, 1000, seed=2)
    ours = python_verdicts(scene, states)
    assert ours == tool_verdicts(tool, path, states, tmp_path)
    assert 50 < ours.count("free") < 950


def test_is_free_and_check_agree(arm6):
    states = random_states(arm6, 300, seed=3)
    free = arm6.check(states)
    assert [arm6.is_free(q) for q in states] == list(free)


def test_batched_verdicts_equal_the_reported_ones(panda_box, arm6):
    # check() without report takes the batch path (kinematics in SIMD lanes); with report, one state at a time.
    for scene in (panda_box[1], arm6):
        states = random_states(scene, 1000, seed=6)
        free, _ = scene.check(states, report=True)
        np.testing.assert_array_equal(scene.check(states), free)
        assert 50 < int(free.sum()) < 950


def test_check_takes_views_copies_and_empty_batches(arm6):
    states = random_states(arm6, 200, seed=4)
    expected = arm6.check(states)
    np.testing.assert_array_equal(arm6.check(np.asfortranarray(states)), expected)
    np.testing.assert_array_equal(arm6.check(np.hstack([states, states])[:, :6]), expected)  # strided rows
    np.testing.assert_array_equal(arm6.check(states.tolist()), expected)
    assert arm6.check(np.zeros((0, 6))).shape == (0,)


def test_invalid_states_raise_naming_row_and_joint(arm6):
    states = random_states(arm6, 10, seed=5)
    states[7, 2] = math.nan
    with pytest.raises(ValueError, match=r"Q\[7\]: state\[2\] \(elbow_joint\) is not finite"):
        arm6.check(states)
    states[7, 2] = 0.0
    states[4, 0] = 100.0
    with pytest.raises(ValueError, match=r"Q\[4\]: state\[0\] \(shoulder_pan_joint\) = 100 is outside \["):
        arm6.check(states)
    with pytest.raises(ValueError, match=r"q\[0\]: state\[5\] \(wrist_3_joint\) is not finite"):
        arm6.is_free([0, 0, 0, 0, 0, math.inf])


def test_wrong_shapes_raise(arm6):
    with pytest.raises(ValueError, match=r"Q must have shape \(N, 6\), got \(3, 5\)"):
        arm6.check(np.zeros((3, 5)))
    with pytest.raises(ValueError, match=r"Q must have shape \(N, 6\), got \(6,\)"):
        arm6.check(np.zeros(6))
    with pytest.raises(ValueError, match=r"q must have shape \(6,\)"):
        arm6.is_free(np.zeros(7))


def test_bad_scene_files_raise_load_error_with_file_and_key(tmp_path):
    missing = tmp_path / "missing.yaml"
    with pytest.raises(clearway.LoadError) as e:
        clearway.Scene.load(str(missing))
    assert e.value.file == str(missing) and str(e.value).startswith(str(missing))

    bad = tmp_path / "bad.yaml"
    text = ARM6_WALL.read_text().replace("../arm6/", str(REPO / "robots" / "arm6") + "/")
    bad.write_text(text.replace("checks:", "chekcs:"))
    with pytest.raises(clearway.LoadError) as e:
        clearway.Scene.load(str(bad))
    assert e.value.file == str(bad)
    assert "chekcs" in e.value.element + e.value.reason
    assert isinstance(e.value, RuntimeError)
    with pytest.raises(ValueError, match="unknown geometry 'mess'"):
        clearway.Scene.load(str(ARM6_WALL), geometry="mess")


FLYER_OVER_PLATE = """format: 1
name: flyer_over_plate
robot:
  urdf: {urdf}
  group: [fly]
  bounds: {{fly/x: [-2, 2], fly/y: [-2, 2], fly/z: [-2, 2]}}
environment:
  obstacles:
    - name: plate
      box: {{size: [2, 2, 0.002]}}
      pose: {{position: [0, 0, 0]}}
checks: [{checks}]
"""


def flyer_scene(tmp_path, checks):
    path = tmp_path / "flyer.yaml"
    path.write_text(FLYER_OVER_PLATE.format(urdf=REPO / "robots" / "flyer" / "flyer.urdf", checks=checks))
    return clearway.Scene.load(str(path))


def test_clearance_of_a_flyer_over_a_plate(tmp_path):
    scene = flyer_scene(tmp_path, "environment, clearance")
    # The flyer's 0.04 m thick plate hangs level at height z over a plate whose top is at z = 0.001.
    heights = np.array([0.5, 0.2, 0.05, 0.0215])
    states = np.array([[0.1, -0.2, z, 0, 0, 0, 1] for z in heights])
    np.testing.assert_allclose(scene.clearance(states), heights - 0.02 - 0.001, rtol=1e-6, atol=1e-9)
    assert scene.check(states).all()
    # Sunk 5 mm into the plate: minus the penetration depth, and a collision.
    sunk = np.array([[0, 0, 0.016, 0, 0, 0, 1]])
    np.testing.assert_allclose(scene.clearance(sunk), [-0.005], rtol=1e-6)
    assert not scene.check(sunk)[0]
    # The same distance as the narrow phase finds between the two boxes.
    d = clearway.distance(clearway.Box([0.15, 0.15, 0.02]), ([0.1, -0.2, 0.2], [0, 0, 0, 1]),
                          clearway.Box([1, 1, 0.001]), None)
    assert scene.clearance(states[1:2])[0] == pytest.approx(d.distance, rel=1e-6)


def test_clearance_needs_the_scene_to_declare_it(arm6, tmp_path):
    with pytest.raises(ValueError, match="does not declare clearance"):
        arm6.clearance(arm6.start[None, :])
    scene = flyer_scene(tmp_path, "environment, clearance")
    with pytest.raises(ValueError, match=r"Q\[1\]: state\[2\] \(fly/z\) is not finite"):
        scene.clearance([[0, 0, 1, 0, 0, 0, 1], [0, 0, math.nan, 0, 0, 0, 1]])


def test_reports_depend_on_the_call_alone(arm6):
    # A check tries the pair that collided last first; each call starts afresh, so what was asked before
    # does not change which pair is named.
    states = random_states(arm6, 500, seed=6)
    first = arm6.check(states, report=True)
    arm6.check(random_states(arm6, 500, seed=7), report=True)
    again = arm6.check(states, report=True)
    np.testing.assert_array_equal(first[0], again[0])
    assert first[1] == again[1]


def test_load_warnings_name_file_and_element(tmp_path):
    # An allowed pair naming a link the URDF lacks is skipped with a warning, as MoveIt does.
    path = tmp_path / "arm6_srdf_extra.yaml"
    srdf = tmp_path / "extra.srdf"
    srdf.write_text((REPO / "robots" / "arm6" / "arm6.srdf").read_text().replace(
        "</robot>", '<disable_collisions link1="base_link" link2="no_such_link" reason="Never"/></robot>'))
    text = ARM6_WALL.read_text().replace("../arm6/arm6.urdf", str(REPO / "robots" / "arm6" / "arm6.urdf"))
    path.write_text(text.replace("../arm6/arm6.srdf", str(srdf)))
    scene = clearway.Scene.load(str(path))
    base = clearway.Scene.load(str(ARM6_WALL)).warnings  # arm6's own (a COLLADA mesh)
    assert scene.warnings[:-1] == base
    assert scene.warnings[-1].startswith(str(srdf) + ": ") and "no_such_link" in scene.warnings[-1]
