#!/usr/bin/env python3
"""Writes robots/dual_arm/dual_arm.urdf: a mobile two-armed robot built only from URDF primitives, for the
many-pair case (a robot of a few dozen small links, every pair of them checked).

  base      box on four fixed wheel cylinders; a prismatic lift carries a mast and a torso that turns
            about z; a head (pan) with a camera box on a fixed neck
  each arm  shoulder ball, upper-arm capsule, roll cylinder, elbow ball, forearm capsule, two wrist
            joints (cylinder, ball), a palm box and two fingers of two phalanges (box, capsule)

34 links with geometry and 27 joint variables; without an SRDF, every pair but the 33 adjacent ones is
checked (528 pairs). The joint limits keep about half of the uniformly random states free.

Run from anywhere: python3 robots/gen/gen_dual_arm.py (writes robots/dual_arm/dual_arm.urdf). Output is
deterministic; the generated file is committed.
"""
import os

links, joints = [], []


def origin(xyz="0 0 0", rpy="0 0 0"):
    return f'<origin xyz="{xyz}" rpy="{rpy}"/>'


def box(size, xyz="0 0 0", rpy="0 0 0"):
    return origin(xyz, rpy) + f'<geometry><box size="{size}"/></geometry>'


def cylinder(r, length, xyz="0 0 0", rpy="0 0 0"):
    return origin(xyz, rpy) + f'<geometry><cylinder radius="{r}" length="{length}"/></geometry>'


def sphere(r, xyz="0 0 0"):
    return origin(xyz) + f'<geometry><sphere radius="{r}"/></geometry>'


def capsule(r, length, xyz="0 0 0", rpy="0 0 0"):
    return origin(xyz, rpy) + f'<geometry><capsule radius="{r}" length="{length}"/></geometry>'


def link(name, geometry):
    links.append(f'  <link name="{name}"><collision>{geometry}</collision></link>')


def joint(name, kind, parent, child, xyz="0 0 0", rpy="0 0 0", axis="0 0 1", lower=-2.8, upper=2.8):
    limit = f'<limit lower="{lower}" upper="{upper}" effort="10" velocity="1"/>' if kind != "fixed" else ""
    axis_tag = f'<axis xyz="{axis}"/>' if kind != "fixed" else ""
    joints.append(f'  <joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
                  f'{origin(xyz, rpy)}{axis_tag}{limit}</joint>')


link("base", box("0.6 0.5 0.2", "0 0 0.15"))
for i, (x, y) in enumerate([(0.25, 0.25), (0.25, -0.25), (-0.25, 0.25), (-0.25, -0.25)]):
    link(f"wheel{i}", cylinder(0.08, 0.05, rpy="1.5707963267948966 0 0"))
    joint(f"wheel{i}_mount", "fixed", "base", f"wheel{i}", xyz=f"{x} {y} 0.08")
link("mast", box("0.15 0.15 0.6", "0 0 0.3"))
joint("lift", "prismatic", "base", "mast", xyz="0 0 0.25", lower=0, upper=0.3)
link("torso", box("0.25 0.4 0.3", "0 0 0.15"))
joint("torso_yaw", "revolute", "mast", "torso", xyz="0 0 0.6", lower=-1.5, upper=1.5)
link("neck", cylinder(0.04, 0.1, "0 0 0.05"))
joint("neck_mount", "fixed", "torso", "neck", xyz="0 0 0.3")
link("head", sphere(0.1))
joint("head_pan", "revolute", "neck", "head", xyz="0 0 0.15", lower=-1.5, upper=1.5)
link("camera", box("0.05 0.15 0.05"))
joint("camera_mount", "fixed", "head", "camera", xyz="0.1 0 0")
for side, sy in (("l", 1), ("r", -1)):
    p = side + "_"
    link(p + "shoulder", sphere(0.07))
    joint(p + "shoulder_pitch", "revolute", "torso", p + "shoulder", xyz=f"0 {0.26 * sy} 0.25", axis="0 1 0",
          lower=-2.0, upper=1.0)
    link(p + "upper_arm", capsule(0.05, 0.25, "0.15 0 0", "0 1.5707963267948966 0"))
    joint(p + "shoulder_yaw", "revolute", p + "shoulder", p + "upper_arm", lower=-0.3 if sy > 0 else -1.5,
          upper=1.5 if sy > 0 else 0.3)
    link(p + "upper_roll", cylinder(0.055, 0.08, rpy="0 1.5707963267948966 0"))
    joint(p + "upper_arm_roll", "revolute", p + "upper_arm", p + "upper_roll", xyz="0.3 0 0", axis="1 0 0")
    link(p + "elbow", sphere(0.055))
    joint(p + "elbow_pitch", "revolute", p + "upper_roll", p + "elbow", xyz="0.1 0 0", axis="0 1 0",
          lower=-2.2, upper=0.2)
    link(p + "forearm", capsule(0.04, 0.14, "0.14 0 0", "0 1.5707963267948966 0"))
    joint(p + "forearm_roll", "revolute", p + "elbow", p + "forearm", axis="1 0 0")
    link(p + "wrist", cylinder(0.04, 0.06, rpy="1.5707963267948966 0 0"))
    joint(p + "wrist_pitch", "revolute", p + "forearm", p + "wrist", xyz="0.27 0 0", axis="0 1 0",
          lower=-1.5, upper=1.5)
    link(p + "wrist2", sphere(0.04))
    joint(p + "wrist_yaw", "revolute", p + "wrist", p + "wrist2", xyz="0.04 0 0", lower=-1.5, upper=1.5)
    link(p + "palm", box("0.06 0.1 0.04", "0.03 0 0"))
    joint(p + "wrist_roll", "revolute", p + "wrist2", p + "palm", xyz="0.03 0 0", axis="1 0 0")
    for f, fy in (("a", 0.035), ("b", -0.035)):
        link(p + "finger_" + f, box("0.06 0.015 0.02", "0.03 0 0"))
        joint(p + "finger_" + f, "revolute", p + "palm", p + "finger_" + f, xyz=f"0.06 {fy} 0",
              lower=-0.5, upper=0.5)
        link(p + "tip_" + f, capsule(0.008, 0.03, "0.02 0 0", "0 1.5707963267948966 0"))
        joint(p + "tip_" + f, "revolute", p + "finger_" + f, p + "tip_" + f, xyz="0.06 0 0",
              lower=-0.5, upper=0.5)

here = os.path.dirname(os.path.abspath(__file__))
out = os.path.join(here, "..", "dual_arm", "dual_arm.urdf")
os.makedirs(os.path.dirname(out), exist_ok=True)
with open(out, "w") as f:
    f.write('<?xml version="1.0"?>\n<!-- Generated by robots/gen/gen_dual_arm.py: do not edit. -->\n')
    f.write('<robot name="dual_arm">\n' + "\n".join(links + joints) + "\n</robot>\n")
