"""Robots: loading, names and limits, forward kinematics, and load errors with file, element and reason."""
import math

import numpy as np
import pytest

import clearway
from conftest import REPO, shared


@pytest.fixture(scope="module")
def panda():
    return clearway.load_robot(str(shared("robots/panda/panda.urdf")), str(shared("robots/panda/panda.srdf")))


def test_names_limits_and_srdf(panda):
    assert panda.name == "panda"
    assert panda.link_names[0] == "panda_link0" and "panda_hand" in panda.link_names
    assert len(panda.link_names) == 12 and len(panda.joint_names) == 11
    # panda_finger_joint2 mimics panda_finger_joint1: it owns no entry of q.
    assert panda.variable_names == [f"panda_joint{i}" for i in range(1, 8)] + ["panda_finger_joint1"]
    assert panda.dof == 8 and panda.limits.shape == (8, 2)
    assert panda.limits[3, 0] == pytest.approx(-3.1416) and panda.limits[7, 1] == pytest.approx(0.04)
    pairs = panda.disabled_pairs
    assert ("panda_link0", "panda_link1", "Adjacent") in pairs and len(pairs) > 10
    assert clearway.load_robot(str(shared("robots/panda/panda.urdf"))).disabled_pairs == []


def test_link_poses_turn_with_the_first_joint(panda):
    # panda_joint1 turns about the world z axis through the origin: every link beyond it turns with it.
    q = np.array([0.3, -0.5, 0.2, -2.0, 0.4, 1.5, 0.7, 0.02])
    poses = panda.link_poses(q)
    assert poses.shape == (12, 4, 4)
    np.testing.assert_array_equal(poses[0], np.eye(4))
    turned = q.copy()
    turned[0] += 0.9
    c, s = math.cos(0.9), math.sin(0.9)
    Rz = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    np.testing.assert_allclose(panda.link_poses(turned)[1:], Rz @ poses[1:], atol=1e-12)
    for T in poses:
        np.testing.assert_allclose(T[:3, :3] @ T[:3, :3].T, np.eye(3), atol=1e-12)
    # panda_link1 sits 0.333 m up the z axis.
    np.testing.assert_allclose(poses[1][:3, 3], [0, 0, 0.333], atol=1e-12)


def test_link_poses_of_a_batch_are_the_poses_of_each(panda):
    rng = np.random.default_rng(31)
    Q = rng.uniform(panda.limits[:, 0], panda.limits[:, 1], size=(5, 8))
    batch = panda.link_poses(Q)
    assert batch.shape == (5, 12, 4, 4)
    for q, poses in zip(Q, batch):
        np.testing.assert_array_equal(panda.link_poses(q), poses)


def test_bad_joint_vectors_raise(panda):
    q = np.zeros(8)
    q[3] = -1.0
    q[5] = math.nan
    with pytest.raises(ValueError, match=r"q: variable 5 'panda_joint6' is nan"):
        panda.link_poses(q)
    q[5] = 0.0
    q[1] = 5.0
    with pytest.raises(ValueError, match=r"q: .*panda_joint2"):
        panda.link_poses(q)
    with pytest.raises(ValueError, match=r"q must have shape \(8,\)"):
        panda.link_poses(np.zeros(7))


def test_load_errors_name_file_element_and_reason(tmp_path):
    missing = tmp_path / "nothing.urdf"
    with pytest.raises(clearway.LoadError) as e:
        clearway.load_robot(str(missing))
    assert e.value.file == str(missing) and str(missing) in str(e.value)

    urdf = (REPO / "robots" / "arm6" / "arm6.urdf").read_text()
    bad = tmp_path / "arm6_bad.urdf"
    bad.write_text(urdf.replace('<joint name="elbow_joint" type="revolute">', '<joint name="elbow_joint" type="wobbly">', 1))
    assert bad.read_text() != urdf
    with pytest.raises(clearway.LoadError) as e:
        clearway.load_robot(str(bad))
    assert e.value.file == str(bad) and "elbow_joint" in e.value.element and "wobbly" in e.value.reason
    assert str(e.value) == f"{e.value.file}: {e.value.element}: {e.value.reason}"


def test_load_warnings_name_file_and_element(tmp_path):
    urdf = tmp_path / "two_links.urdf"
    urdf.write_text("""<?xml version="1.0"?>
<robot name="two">
  <link name="base"><collision><geometry><box size="1 1 1"/></geometry></collision></link>
  <link name="arm"><visual><geometry><box size="1 1 1"/></geometry></visual></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
""")
    robot = clearway.load_robot(str(urdf))
    assert robot.dof == 1 and robot.link_names == ["base", "arm"] and robot.joint_names == ["j"]
    np.testing.assert_array_equal(robot.limits, [[-1, 1]])
    assert len(robot.warnings) == 1 and robot.warnings[0].startswith(str(urdf) + ": ") and "arm" in robot.warnings[0]
