"""Scene edits from Python: obstacles added, moved and removed, points inserted, bodies attached and
detached; each edit is a new Scene and leaves the old one as it was."""
import numpy as np
import pytest

import clearway


def test_an_added_obstacle_collides_and_the_old_scene_is_unchanged(arm6):
    start = np.array(arm6.start)
    assert arm6.is_free(start)
    assert set(arm6.obstacle_names) == {"floor", "wall", "ceiling", "post"}
    # A box round the arm's base.
    boxed = arm6.with_obstacle("crate", clearway.Box([0.3, 0.3, 0.3]), pose=([0, 0, 0.2], [0, 0, 0, 1]))
    assert not boxed.is_free(start)
    assert arm6.is_free(start)
    assert "crate" in boxed.obstacle_names and "crate" not in arm6.obstacle_names
    free, pairs = boxed.check(start[None, :], report=True)
    assert not free[0] and "crate" in pairs[0]
    moved = boxed.with_obstacle_moved("crate", ([5, 5, 5], [0, 0, 0, 1]))
    assert moved.is_free(start)
    assert boxed.without_obstacle("crate").is_free(start)
    # Edits keep the scene's states and checks.
    assert moved.dof == arm6.dof and moved.effects.environment


def test_points_become_voxels(arm6):
    start = np.array(arm6.start)
    grid = np.stack(np.meshgrid(np.arange(-1, 1, 0.05), np.arange(-1, 1, 0.05), np.arange(0, 1, 0.05)), -1).reshape(-1, 3)
    assert not arm6.with_points(grid, resolution=0.05).is_free(start)
    assert arm6.with_points(grid + 10.0, resolution=0.05).is_free(start)


def test_an_attached_body_moves_with_its_link_and_detaches(arm6):
    start = np.array(arm6.start)
    held = arm6.with_attached("ball", link="tool0", shape=clearway.Sphere(0.5), touch_links=["wrist_3_link"])
    assert "ball" in held.link_names and "ball" not in arm6.link_names
    free, pairs = held.check(start[None, :], report=True)
    assert not free[0] and "ball" in pairs[0]
    assert held.without_attached("ball").is_free(start)
    assert held.without_attached("ball").link_names == arm6.link_names


def test_bad_edits_raise(arm6):
    with pytest.raises(ValueError, match="already exists"):
        arm6.with_obstacle("wall", clearway.Sphere(0.1))
    with pytest.raises(ValueError, match="no obstacle is named"):
        arm6.without_obstacle("door")
    with pytest.raises(ValueError, match="not finite"):
        arm6.with_obstacle_moved("wall", ([np.nan, 0, 0], [0, 0, 0, 1]))
    with pytest.raises(ValueError):
        arm6.with_points(np.array([[0, 0, 0]]))  # no map: a resolution is needed
    with pytest.raises(ValueError, match="shape"):
        arm6.with_points(np.zeros((3, 2)), resolution=0.1)
    with pytest.raises(ValueError, match="no link 'claw'"):
        arm6.with_attached("ball", link="claw", shape=clearway.Sphere(0.1))
    with pytest.raises(ValueError, match="no attached body"):
        arm6.without_attached("forearm_link")
