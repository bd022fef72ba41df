"""The narrow phase: analytic answers, the two pose forms, equality with `clearway query`, bad input."""
import json
import math

import numpy as np
import pytest

import clearway as cw

I = ([0, 0, 0], [0, 0, 0, 1])  # the identity as (position, quaternion)


def at(x, y=0.0, z=0.0):
    return ([x, y, z], [0, 0, 0, 1])


def test_sphere_sphere_distance_and_points():
    d = cw.distance(cw.Sphere(0.5), I, cw.Sphere(0.25), at(2))
    assert d.distance == pytest.approx(1.25, abs=1e-12) and d.lower_bound <= d.distance
    np.testing.assert_allclose(d.point_a, [0.5, 0, 0], atol=1e-12)
    np.testing.assert_allclose(d.point_b, [1.75, 0, 0], atol=1e-12)
    np.testing.assert_allclose(d.normal, [1, 0, 0], atol=1e-12)
    assert d.status in ("converged", "repeated_support", "no_progress") and not d.may_collide()


def test_box_point_and_capsule_capsule():
    d = cw.distance(cw.Box([0.5, 0.5, 0.5]), I, cw.Point(), at(1.5, 0.2, -0.1))
    assert d.distance == pytest.approx(1.0, rel=1e-6)
    # Parallel capsules along z, 1 m apart: the distance between the axes minus both radii.
    d = cw.distance(cw.Capsule(0.1, 0.3), I, cw.Capsule(0.2, 0.5), at(1.0, 0, 0.4))
    assert d.distance == pytest.approx(0.7, rel=1e-6)


def test_intersect_and_penetration_of_overlapping_spheres():
    assert cw.intersect(cw.Sphere(1), I, cw.Sphere(1), at(1.5)).intersecting
    assert not cw.intersect(cw.Sphere(1), I, cw.Sphere(1), at(2.5))
    p = cw.penetration(cw.Sphere(1), I, cw.Sphere(1), at(1.5))
    assert p.depth == pytest.approx(0.5, rel=1e-9) and p.signed_distance == pytest.approx(-0.5, rel=1e-9)
    np.testing.assert_allclose(p.normal, [1, 0, 0], atol=1e-12)
    # Deep box overlap (EPA): a unit cube 0.3 into another along y.
    p = cw.penetration(cw.Box([0.5] * 3), I, cw.Box([0.5] * 3), at(0, 0.7, 0.05))
    assert p.depth == pytest.approx(0.3, rel=1e-6)
    np.testing.assert_allclose(p.normal, [0, 1, 0], atol=1e-6)


def test_raycast_and_shapecast():
    r = cw.raycast(cw.Sphere(1), at(5), [0, 0, 0], [1, 0, 0], 10)
    assert r.hit and r.t == pytest.approx(4, rel=1e-6)
    np.testing.assert_allclose(r.normal, [-1, 0, 0], atol=1e-6)
    assert not cw.raycast(cw.Sphere(1), at(5), [0, 0, 0], [1, 0, 0], 3.9).hit
    s = cw.shapecast(cw.Sphere(0.5), I, [2, 0, 0], cw.Box([0.5, 1, 1]), at(3), 5)
    assert s.hit and s.t == pytest.approx(1.0, rel=1e-6)
    np.testing.assert_allclose(s.point, [2.5, 0, 0], atol=1e-6)


def test_cone_cylinder_and_hull():
    # A cone's apex is at +half_length: 0.5 below a plate at z = 1.
    d = cw.distance(cw.Cone(0.3, 0.5), I, cw.Box([1, 1, 0.01]), at(0, 0, 1.01))
    assert d.distance == pytest.approx(0.5, rel=1e-6)
    d = cw.distance(cw.Cylinder(0.3, 0.5), I, cw.Sphere(0.1), at(1.0, 0, 0.2))
    assert d.distance == pytest.approx(0.6, rel=1e-6)
    cube = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    hull = cw.ConvexHull(np.vstack([cube, [[0, 0, 0], [0.5, 0.2, 0.1]]]))  # interior points are dropped
    assert hull.type == "convex" and sorted(map(tuple, hull.vertices)) == sorted(map(tuple, cube))
    d = cw.distance(hull, I, cw.Box([1, 1, 1]), at(3))
    assert d.distance == pytest.approx(1, rel=1e-6)


def rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def test_quaternion_and_matrix_poses_agree():
    R = rotation([1, 2, 3], 0.7)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, [0.3, 1.2, -0.4]
    w = math.cos(0.35)
    q = list(np.array([1, 2, 3]) / math.sqrt(14) * math.sin(0.35)) + [w]
    a = cw.distance(cw.Box([0.2, 0.3, 0.1]), I, cw.Capsule(0.05, 0.3), T)
    b = cw.distance(cw.Box([0.2, 0.3, 0.1]), I, cw.Capsule(0.05, 0.3), (T[:3, 3], q))
    assert a.distance == pytest.approx(b.distance, rel=1e-12)
    c = cw.distance(cw.Box([0.2, 0.3, 0.1]), None, cw.Capsule(0.05, 0.3), (T[:3, 3], 3 * np.array(q)))  # any length
    assert c.distance == b.distance


SHAPES = ["box", "sphere", "capsule", "cylinder", "cone", "convex"]


def make_shape(rng):
    """A random shape as a query file writes it, and as the module builds it."""
    kind = SHAPES[rng.integers(len(SHAPES))]
    r, h = float(rng.uniform(0.05, 0.5)), float(rng.uniform(0.05, 0.5))
    if kind == "box":
        half = [float(x) for x in rng.uniform(0.05, 0.5, 3)]
        return {"type": "box", "half_extents": half}, cw.Box(half)
    if kind == "sphere":
        return {"type": "sphere", "radius": r}, cw.Sphere(r)
    if kind == "convex":
        points = rng.normal(size=(12, 3)) * 0.3
        return {"type": "convex", "vertices": points.tolist()}, cw.ConvexHull(points)
    make = {"capsule": cw.Capsule, "cylinder": cw.Cylinder, "cone": cw.Cone}[kind]
    return {"type": kind, "radius": r, "half_length": h}, make(r, h)


def make_pose(rng, matrix):
    t = [float(x) for x in rng.uniform(-0.8, 0.8, 3)]
    q = [float(x) for x in rng.normal(size=4)]
    if not matrix:
        return {"position": t, "orientation": q}, (t, q)
    R = rotation(rng.normal(size=3), float(rng.uniform(0, math.pi)))
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return {"R": R.tolist(), "t": t}, T


def test_every_query_equals_the_tool(tool, tmp_path):
    rng = np.random.default_rng(21)
    cases, ours = [], []
    for i in range(300):
        query = ["distance", "intersect", "penetration", "raycast", "shapecast"][i % 5]
        (ja, a), (jpa, pa) = make_shape(rng), make_pose(rng, matrix=i % 2 == 0)
        case = {"id": i, "query": query, "a": {"shape": ja, "pose": jpa}}
        if query == "raycast":
            origin, direction = [float(x) for x in rng.uniform(-2, 2, 3)], [float(x) for x in rng.normal(size=3)]
            case["ray"] = {"origin": origin, "direction": direction, "max_t": 3.0}
            ours.append(cw.raycast(a, pa, origin, direction, 3.0))
        else:
            (jb, b), (jpb, pb) = make_shape(rng), make_pose(rng, matrix=i % 3 == 0)
            case["b"] = {"shape": jb, "pose": jpb}
            if query == "shapecast":
                v = [float(x) for x in rng.normal(size=3)]
                case["cast"] = {"velocity_a": v, "max_t": 2.0}
                ours.append(cw.shapecast(a, pa, v, b, pb, 2.0))
            else:
                ours.append(getattr(cw, query)(a, pa, b, pb))
        cases.append(case)
    path = tmp_path / "cases.jsonl"
    path.write_text("".join(json.dumps(c) + "\n" for c in cases))
    theirs = [json.loads(line) for line in tool("query", path)]
    fields = {"distance": ["distance", "point_a", "point_b", "normal"], "intersect": ["intersect"],
              "penetration": ["depth", "signed_distance", "normal", "point_a", "point_b"],
              "raycast": ["hit", "t", "normal", "point"], "shapecast": ["hit", "t", "normal", "point"]}
    hits = 0
    for case, mine, t in zip(cases, ours, theirs):
        assert t["id"] == case["id"] and t["status"] == mine.status and t["iterations"] == mine.iterations
        for f in fields[case["query"]]:
            value = getattr(mine, "intersecting" if f == "intersect" else f)
            expected = t[f]
            assert (list(value) if isinstance(value, np.ndarray) else value) == expected, (case["id"], f)
        hits += bool(t.get("intersect") or t.get("hit") or t.get("depth", 0) > 0)
    assert 20 < hits < 280  # both answers occur


def test_bad_shapes_and_poses_raise_with_the_library_message():
    with pytest.raises(ValueError, match="sphere: radius must be finite and > 0"):
        cw.Sphere(-1)
    with pytest.raises(ValueError, match="box: half extent must be finite and >= 0"):
        cw.Box([1, -1, 1])
    with pytest.raises(ValueError, match=r"half_extents\[1\] is not finite"):
        cw.Box([1, math.nan, 1])
    with pytest.raises(ValueError, match=r"points must have shape \(N, 3\)"):
        cw.ConvexHull(np.zeros((4, 2)))
    with pytest.raises(ValueError, match=r"points\[2\] is not finite"):
        cw.ConvexHull([[0, 0, 0], [1, 0, 0], [0, math.inf, 0]])
    with pytest.raises(ValueError, match="convex hull"):
        cw.ConvexHull(np.zeros((0, 3)))
    s = cw.Sphere(1)
    with pytest.raises(ValueError, match=r"pose_b position\[0\] is not finite"):
        cw.distance(s, None, s, ([math.nan, 0, 0], [0, 0, 0, 1]))
    with pytest.raises(ValueError, match="pose_a quaternion must not be zero"):
        cw.intersect(s, ([0, 0, 0], [0, 0, 0, 0]), s, None)
    bad = np.eye(4)
    bad[0, 0] = 2
    with pytest.raises(ValueError, match="pose_a is not a rotation"):
        cw.penetration(s, bad, s, None)
    with pytest.raises(ValueError, match=r"pose_b must be None, \(position, quaternion x y z w\) or a 4x4 matrix"):
        cw.distance(s, None, s, np.eye(3))
    with pytest.raises(ValueError, match="max_t must be finite and >= 0"):
        cw.raycast(s, None, [0, 0, 0], [1, 0, 0], -1)
    with pytest.raises(ValueError, match=r"direction\[2\] is not finite"):
        cw.raycast(s, None, [0, 0, 0], [1, 0, math.nan], 1)
    with pytest.raises(ValueError, match="tolerance must be finite and > 0"):
        cw.distance(s, None, s, at(3), tolerance=0)
    with pytest.raises(TypeError, match="tolerance must be a number or None"):
        cw.distance(s, None, s, at(3), tolerance="tight")


def test_shapes_keep_their_parameters():
    assert cw.Box([0.1, 0.2, 0.3]).half_extents.tolist() == [0.1, 0.2, 0.3]
    assert cw.Sphere(0.4).radius == 0.4 and cw.Sphere(0.4).bounding_radius == pytest.approx(0.4)
    for make in (cw.Capsule, cw.Cylinder, cw.Cone):
        s = make(0.2, 0.5)
        assert (s.radius, s.half_length, s.type) == (0.2, 0.5, make.__name__.lower())
    assert cw.Capsule(0.2, 0.5).bounding_radius == pytest.approx(0.7)
    assert isinstance(cw.Segment([0, 0, 0], [1, 0, 0]), cw.Shape) and cw.Triangle([0, 0, 0], [1, 0, 0], [0, 1, 0]).type == "triangle"
