#!/usr/bin/env python3
"""Writes the collision meshes of robots/arm6 (a 6-joint test arm) in every format the loader reads.

Each link mesh is a closed box or prism with known extents, so that tests can check what the loader made
of it (unit, up axis, scale, node transform, triangulation):

  base.stl        ASCII STL, metres            cylinder r 0.08, z in [0, 0.10]
  shoulder.stl    binary STL, metres           cylinder r 0.06, z in [0, 0.15]
  upper_arm.obj   OBJ with quad faces, metres  box x, y in [-0.04, 0.04], z in [0, 0.40]
  forearm.dae     COLLADA, centimetres, Y_UP   box x, y in [-0.03, 0.03], z in [0, 0.35] in metres, <up_axis>
                                               ignored as ROS does (honoured: y in [-0.35, 0], z in [-0.03, 0.03])
  wrist1_mm.stl   ASCII STL, millimetres       cylinder r 35, z in [0, 100] (the URDF scales it by 0.001)
  wrist2.dae      COLLADA, metres, Z_UP        box x, y in [-0.03, 0.03], z in [0, 0.06], under a node
                                               translated by (0, 0, 0.02): z in [0.02, 0.08] once loaded

Run from anywhere: python3 robots/gen/gen_arm6_meshes.py (writes robots/arm6/meshes/). Output is
deterministic; the generated files are committed next to this script's output folder.
"""
import math
import os
import struct

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "arm6", "meshes")


def box(lo, hi):
    """Corners and outward quads (counter-clockwise seen from outside) of an axis-aligned box."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    quads = [(0, 3, 2, 1), (4, 5, 6, 7),  # bottom (−z), top (+z)
             (0, 1, 5, 4), (2, 3, 7, 6),  # −y, +y
             (1, 2, 6, 5), (3, 0, 4, 7)]  # +x, −x
    return v, quads


def quads_to_triangles(quads):
    return [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]


def prism(radius, z0, z1, sides=24):
    """A closed regular prism around z approximating a cylinder: vertices and outward triangles."""
    v = []
    for z in (z0, z1):
        for k in range(sides):
            a = 2.0 * math.pi * k / sides
            v.append((radius * math.cos(a), radius * math.sin(a), z))
    bottom_centre, top_centre = len(v), len(v) + 1
    v += [(0.0, 0.0, z0), (0.0, 0.0, z1)]
    t = []
    for k in range(sides):
        n = (k + 1) % sides
        t += [(k, n, sides + n), (k, sides + n, sides + k)]  # side wall
        t.append((bottom_centre, n, k))                      # bottom cap, facing −z
        t.append((top_centre, sides + k, sides + n))         # top cap, facing +z
    return v, t


def normal(v, tri):
    a, b, c = (v[i] for i in tri)
    u = [b[i] - a[i] for i in range(3)]
    w = [c[i] - a[i] for i in range(3)]
    n = (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])
    length = math.sqrt(sum(x * x for x in n))
    return tuple(x / length for x in n)


def fmt(x):
    return "%.9g" % (x + 0.0)  # + 0.0 turns −0 into 0


def write_ascii_stl(name, v, tris):
    with open(os.path.join(OUT, name), "w", newline="\n") as f:
        f.write("solid %s\n" % name)
        for t in tris:
            f.write("  facet normal %s\n    outer loop\n" % " ".join(fmt(x) for x in normal(v, t)))
            for i in t:
                f.write("      vertex %s\n" % " ".join(fmt(x) for x in v[i]))
            f.write("    endloop\n  endfacet\n")
        f.write("endsolid %s\n" % name)


def write_binary_stl(name, v, tris):
    with open(os.path.join(OUT, name), "wb") as f:
        f.write(b"clearway arm6 binary STL".ljust(80, b" "))  # must not start with "solid"
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            f.write(struct.pack("<3f", *normal(v, t)))
            for i in t:
                f.write(struct.pack("<3f", *v[i]))
            f.write(struct.pack("<H", 0))


def write_obj(name, v, faces):
    with open(os.path.join(OUT, name), "w", newline="\n") as f:
        f.write("# clearway arm6: %s\no %s\n" % (name, os.path.splitext(name)[0]))
        for p in v:
            f.write("v %s\n" % " ".join(fmt(x) for x in p))
        for face in faces:
            f.write("f %s\n" % " ".join(str(i + 1) for i in face))


def write_dae(name, v, tris, meter, unit_name, up_axis, translate=(0.0, 0.0, 0.0)):
    positions = " ".join(fmt(x) for p in v for x in p)
    indices = " ".join(str(i) for t in tris for i in t)
    with open(os.path.join(OUT, name), "w", newline="\n") as f:
        f.write("""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset>
    <contributor><authoring_tool>clearway robots/gen/gen_arm6_meshes.py</authoring_tool></contributor>
    <unit name="%(unit_name)s" meter="%(meter)s"/>
    <up_axis>%(up_axis)s</up_axis>
  </asset>
  <library_geometries>
    <geometry id="shape" name="shape">
      <mesh>
        <source id="shape-positions">
          <float_array id="shape-positions-array" count="%(count)d">%(positions)s</float_array>
          <technique_common>
            <accessor source="#shape-positions-array" count="%(vertices)d" stride="3">
              <param name="X" type="float"/>
              <param name="Y" type="float"/>
              <param name="Z" type="float"/>
            </accessor>
          </technique_common>
        </source>
        <vertices id="shape-vertices">
          <input semantic="POSITION" source="#shape-positions"/>
        </vertices>
        <triangles count="%(triangles)d">
          <input semantic="VERTEX" source="#shape-vertices" offset="0"/>
          <p>%(indices)s</p>
        </triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="scene" name="scene">
      <node id="part" name="part">
        <translate>%(translate)s</translate>
        <instance_geometry url="#shape"/>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene>
    <instance_visual_scene url="#scene"/>
  </scene>
</COLLADA>
""" % dict(unit_name=unit_name, meter=fmt(meter), up_axis=up_axis, count=3 * len(v), positions=positions,
           vertices=len(v), triangles=len(tris), indices=indices,
           translate=" ".join(fmt(x) for x in translate)))


def main():
    os.makedirs(OUT, exist_ok=True)

    v, t = prism(0.08, 0.0, 0.10)
    write_ascii_stl("base.stl", v, t)

    v, t = prism(0.06, 0.0, 0.15)
    write_binary_stl("shoulder.stl", v, t)

    v, q = box((-0.04, -0.04, 0.0), (0.04, 0.04, 0.40))
    write_obj("upper_arm.obj", v, q)

    # Forearm in centimetres, in a file that declares Y_UP (as exporters often do) while its coordinates
    # are the link's, z up: ROS (RViz, MoveIt) ignores <up_axis>, and so does the loader by default.
    # Honouring the up axis would lay it along -y.
    v, q = box((-0.03, -0.03, 0.0), (0.03, 0.03, 0.35))
    cm = [(100.0 * x, 100.0 * y, 100.0 * z) for x, y, z in v]
    write_dae("forearm.dae", cm, quads_to_triangles(q), 0.01, "centimeter", "Y_UP")

    v, t = prism(35.0, 0.0, 100.0)
    write_ascii_stl("wrist1_mm.stl", v, t)

    v, q = box((-0.03, -0.03, 0.0), (0.03, 0.03, 0.06))
    write_dae("wrist2.dae", v, quads_to_triangles(q), 1.0, "meter", "Z_UP", translate=(0.0, 0.0, 0.02))


if __name__ == "__main__":
    main()
