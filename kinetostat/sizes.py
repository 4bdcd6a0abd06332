"""The linkage's length scales, m, that the accuracy measure and the condition numbers are taken
against: per link the largest distance between two of its joint points, the linkage's
(`kinematic_size`) and each Assur group's (`group_scales`). Only the points of the pairs (the
joints) count; a point that carries a load, a centre of mass, or no pair at all plays no part in a
group's geometry. Each is computed once per mechanism (kept in `mech._derived`).

May use: planar (model and structure for type hints only).
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from .planar import diameter

if TYPE_CHECKING:
    from .model import Mechanism

__all__ = ["kinematic_size", "group_scales"]


def _joint_extents(mech: "Mechanism") -> list[float]:
    """Per link: the largest distance between two of its joint points (points of its pairs), m."""
    if "joint_extents" not in mech._derived:
        joints: list[set[str]] = [set() for _ in mech.links]
        for p in mech.pairs:
            if p.kind == "R":
                joints[p.links[0]].add(p.point)
                joints[p.links[1]].add(p.point)
            else:
                joints[p.links[0]].add(p.guide)
                joints[p.links[1]].add(p.point)
        mech._derived["joint_extents"] = [diameter(pts[a] for a in names)
                                          for pts, names in zip(mech.points_z, joints)]
    return mech._derived["joint_extents"]


def kinematic_size(mech: "Mechanism") -> float:
    """The linkage's length scale for the accuracy measure: the largest distance between two
    joint points of one moving link, m (mech.size if no link has two)."""
    return max(_joint_extents(mech)[1:], default=0.0) or mech.size


def group_scales(mech: "Mechanism") -> list[float]:
    """Per Assur group, its length scale for the condition number, m: the largest distance
    between two joint points of one of its links or of the moving links it is attached to."""
    if "group_scales" not in mech._derived:
        ext = _joint_extents(mech)
        mech._derived["group_scales"] = [max((ext[k] for k in (*g.links, *g.known) if k), default=0.0)
                                         or kinematic_size(mech) for g in mech.structure.groups]
    return mech._derived["group_scales"]
