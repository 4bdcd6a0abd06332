"""A model for engine users: MJCF (MuJoCo) and URDF documents built from the harness's scene.

Both come from `build_scene` (scene.py): the links as rigid bodies with their mass, centre of
mass and I_S, the spanning tree of the pairs rooted at the frame (revolute joints about z,
prismatic joints along the guide), gravity along -y, SI units. Neither carries the applied loads
(gas force, resistance, springs), the drive or friction: those are the analysis's business.

- `to_mjcf(mech)`: the scene's MJCF exactly as the MuJoCo routes build it (`engine_mujoco.mjcf`:
  one body `link<k>` per moving link, joints `pair<i>`, the loop-closing pairs as equality
  constraints `cut<i>`: connect for a revolute pair, weld to a massless slotted helper body
  `slot<i>` for a prismatic one), with the simulation route's placeholder mass and inertia
  (SIM_FLOOR of the model's scales) on massless bodies, and a keyframe `phi0`: the assembled
  state at phi = 0 moving at the drive's speed (qpos = 0 is not assembled where a tree joint is
  prismatic).
- `to_urdf(mech)`: the spanning tree only. URDF describes trees and cannot express a closed
  loop: each cut pair is written as an XML comment `<!-- loop closure ... -->` naming the two
  links, the points (in the links' URDF frames) and the condition, for the user to add as a
  constraint in their engine. Link k's URDF frame is its model frame moved to the anchor of the
  joint that carries it (URDF puts a joint's axis through the child frame's origin); revolute
  pairs are `continuous` joints (a crank turns without limit), prismatic pairs `prismatic`
  joints whose `limit` is the travel range and peak sliding speed of the analysed cycle
  (effort 0: a passive pair). Inertias are those of a lamina in the plane: izz = I_S,
  ixx = iyy = I_S / 2. Massless links have no `<inertial>`.

May use: kinetostat, .scene, .engine_mujoco (its MJCF writer; MuJoCo itself is not imported).
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from kinetostat import Mechanism
from kinetostat._text import one_line, xml_clean_tree, xml_safe
from kinetostat.planar import rotate

from .engine_mujoco import SIM_FLOOR, mjcf, slot_motion
from .scene import Scene, build_scene

__all__ = ["to_mjcf", "to_urdf"]


def _scene(mech: Mechanism) -> Scene:
    """The scene over one cycle (steps = 360): row 0 is phi = 0, the rows give the travel ranges."""
    return build_scene(mech, steps=360)


def _f(x: float) -> str:
    return repr(float(x))


def _v(*xs: float) -> str:
    return " ".join(_f(x) for x in xs)


def _comment(text: str) -> str:
    """Text safe inside an XML comment: one line, no '--', no character XML cannot hold."""
    text = xml_safe(one_line(text))
    while "--" in text:
        text = text.replace("--", "- -")
    return text


def _about(mech: Mechanism) -> str:
    return (f"kinetostat model {mech.name!r}" + (f" ({Path(mech.path).name})" if mech.path else "")
            + f"; SI units; gravity {mech.g:g} m/s^2 along -y; driven link: crank link1, "
              f"{mech.drive.omega:g} rad/s {'ccw' if mech.drive.sense > 0 else 'cw'}")


# ----------------------------------------------------------------------------- MJCF

def to_mjcf(mech: Mechanism) -> str:
    """The model as an MJCF document for MuJoCo (see the module docstring)."""
    scene = _scene(mech)
    xml = mjcf(scene, floor=SIM_FLOOR)
    state = {f"pair{j.pair.index}": (scene.q[0, n], scene.qd[0, n]) for n, j in enumerate(scene.joints)}
    state.update({f"slot{i}": (s[0], v[0]) for i, (s, v, _) in slot_motion(scene).items()})
    # MuJoCo orders the joints as they appear in the document (bodies depth first)
    names = [j.get("name") for j in ET.fromstring(xml).iter("joint")]
    qpos, qvel = zip(*(state[n] for n in names))
    head, _, _ = xml.rpartition("</mujoco>")
    note = _comment(f"{_about(mech)}. Loads, drive and friction are not exported. Massless links carry "
                    f"placeholder masses ({SIM_FLOOR:g} of the scales). Keyframe phi0: the assembled state "
                    f"at phi = 0 deg at the drive's speed.")
    first, _, rest = head.partition("\n")
    return (f"{first}\n  <!-- {note} -->\n{rest}"
            f'  <keyframe>\n    <key name="phi0" qpos="{_v(*qpos)}" qvel="{_v(*qvel)}"/>\n  </keyframe>\n'
            "</mujoco>\n")


# ----------------------------------------------------------------------------- URDF

def to_urdf(mech: Mechanism) -> str:
    """The model's spanning tree as a URDF document; the loop-closing pairs as comments
    (URDF cannot express closed loops; see the module docstring)."""
    scene = _scene(mech)
    off = {0: np.zeros(2)} | {j.child: np.asarray(j.anchor_child, float) for j in scene.joints}
    name = lambda k: f"link{k}"
    robot = ET.Element("robot", name=mech.name)
    robot.append(ET.Comment(_comment(
        f" {_about(mech)}. The spanning tree of the pairs; URDF cannot express closed loops, so the "
        f"loop-closing pairs follow as 'loop closure' comments. Link k's frame is its model frame moved "
        f"to the anchor of the joint that carries it. Loads, drive and friction are not exported. ")))
    assembled = ", ".join(f"pair{j.pair.index} = {_f(scene.q[0, n])} {'rad' if j.kind == 'R' else 'm'}"
                          for n, j in enumerate(scene.joints))
    robot.append(ET.Comment(_comment(f" assembled at phi = 0 deg: {assembled} ")))
    ET.SubElement(robot, "link", name=name(0)).append(ET.Comment(" the frame (link 0) "))
    for n, (j, b) in enumerate(zip(scene.joints, scene.bodies)):
        link = ET.SubElement(robot, "link", name=name(b.link))
        link.append(ET.Comment(_comment(f" {mech.links[b.link].name} ")))
        if b.mass > 0 or b.I_S > 0:
            inertial = ET.SubElement(link, "inertial")
            ET.SubElement(inertial, "origin", xyz=_v(*(b.com - off[b.link]), 0.0), rpy="0 0 0")
            ET.SubElement(inertial, "mass", value=_f(b.mass))
            half = _f(b.I_S / 2)
            ET.SubElement(inertial, "inertia", ixx=half, ixy="0", ixz="0", iyy=half, iyz="0", izz=_f(b.I_S))
        joint = ET.SubElement(robot, "joint", name=f"pair{j.pair.index}",
                              type="continuous" if j.kind == "R" else "prismatic")
        joint.append(ET.Comment(f" {j.pair.label}{' (the crank)' if n == scene.crank_joint else ''} "))
        ET.SubElement(joint, "parent", link=name(j.parent))
        ET.SubElement(joint, "child", link=name(j.child))
        ET.SubElement(joint, "origin", xyz=_v(*(j.anchor_parent - off[j.parent]), 0.0), rpy=_v(0.0, 0.0, j.rel_angle))
        if j.kind == "R":
            ET.SubElement(joint, "axis", xyz="0 0 1")
        else:
            axis = rotate(j.axis, np.float64(-j.rel_angle))       # the slide axis in the joint frame
            ET.SubElement(joint, "axis", xyz=_v(axis[0], axis[1], 0.0))
            ET.SubElement(joint, "limit", lower=_f(scene.q[:, n].min()), upper=_f(scene.q[:, n].max()),
                          effort="0", velocity=_f(np.nanmax(np.abs(scene.qd[:, n]))))
    for p in scene.cuts:
        robot.append(ET.Comment(_comment(" " + _loop_closure(mech, p, off) + " ")))
    xml_clean_tree(robot)              # names of the model may hold anything (U+0001, U+FFFE)
    ET.indent(robot)
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"


def _loop_closure(mech: Mechanism, pair, off: dict) -> str:
    """The condition of a cut pair, in the links' URDF frames."""
    at = lambda k, point: f"point {point} of link{k} (xyz {_v(*(np.asarray(mech.links[k].points[point]) - off[k]), 0.0)})"
    a, b = pair.links
    if pair.kind == "R":
        return (f"loop closure: revolute pair {pair.label} (about z): {at(b, pair.point)} coincides with "
                f"{at(a, pair.point)}")
    return (f"loop closure: prismatic pair {pair.label}: {at(b, pair.point)} stays on the line through "
            f"{at(a, pair.guide)} along direction {_v(*pair.direction, 0.0)} of link{a}, and link{b} keeps "
            f"the angle {_f(pair.alpha)} rad to link{a}")
