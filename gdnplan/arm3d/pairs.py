"""Self-collision pairs of a 3-D robot: which link pairs are checked, and why the others are not.

A pair of links (each carrying collision shapes) is checked unless

* ``"same body"``: both move with the same planning joint (they are rigidly attached, e.g. a
  wrist, its flange and a locked gripper): their distance never changes;
* ``"adjacent"``: the URDF joins the two links by one planning joint (and fixed joints only).
  Adjacent links meet at their joint, and their shapes (mesh hulls especially) touch or overlap
  there at every configuration, so a check would report a collision that planning cannot
  remove. A locked joint on the way keeps a pair checked: with a UR5e's wrist joints locked the
  gripper shares the forearm's body, yet it can fold into the upper arm;
* the SRDF, when one is given, disables it (``<disable_collisions link1= link2= reason=/>``:
  MoveIt's "Adjacent", "Never", "Default", "Always"); the reason is kept.

Without an SRDF only the first two rules apply. The shipped UR5e has one
(``shipped/robots/ur5e.srdf``): without it, pairs such as the forearm against the wrist-2
housing stay within 1.5 cm of each other at every configuration and would pin the overall
minimum distance to that gap. Every shape of one link is paired with every shape of the other.
"""

from __future__ import annotations

import itertools
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import InputError, UnknownNameError


def srdf_disabled_pairs(srdf: str | Path, model: pin.Model) -> dict[frozenset[str], str]:
    """The SRDF's disabled link pairs → reason ("" when none is given).

    UnknownNameError for a missing file; InputError for a file that is not XML or names a link
    that is not in the robot (an SRDF of another robot).
    """
    path = Path(srdf)
    if not path.is_file():
        raise UnknownNameError(f"srdf: file {path} does not exist (or is not a file)")
    try:
        root = ET.fromstring(path.read_bytes())
    except ET.ParseError as e:
        raise InputError(f"srdf: {path} is not a readable XML file ({e})") from e
    out: dict[frozenset[str], str] = {}
    for item in root.iter("disable_collisions"):
        a, b = item.get("link1"), item.get("link2")
        for link in (a, b):
            if link is None or not model.existFrame(link):
                raise InputError(
                    f"srdf: {path.name} disables a pair with link {link!r}, which the URDF does "
                    "not have; give the SRDF of this robot"
                )
        out[frozenset((a, b))] = item.get("reason", "")
    return out


def self_collision_pairs(
    full: pin.Model, reduced: pin.Model, shapes: Sequence, srdf: str | Path | None
) -> tuple[np.ndarray, dict[frozenset[str], str]]:
    """Shape index pairs (P, 2) to check, and every unchecked link pair → its reason.

    ``shapes`` carry ``link`` (URDF link name) and ``body`` (reduced joint index).
    """
    disabled_srdf = srdf_disabled_pairs(srdf, full) if srdf is not None else {}
    body: dict[str, int] = {}
    for s in shapes:
        body[s.link] = s.body
    links = list(body)
    disabled: dict[frozenset[str], str] = {}
    for a, b in itertools.combinations(links, 2):
        ba, bb = body[a], body[b]
        key = frozenset((a, b))
        if ba == bb:
            disabled[key] = "same body"
        elif _adjacent(full, reduced, a, b, ba, bb):
            disabled[key] = "adjacent"
        elif key in disabled_srdf:
            disabled[key] = f"srdf: {disabled_srdf[key] or 'disabled'}"
    pairs = [
        (i, j)
        for i, j in itertools.combinations(range(len(shapes)), 2)
        if shapes[i].link != shapes[j].link
        and frozenset((shapes[i].link, shapes[j].link)) not in disabled
    ]
    return np.array(pairs, dtype=int).reshape(-1, 2), disabled


def _adjacent(full: pin.Model, reduced: pin.Model, a: str, b: str, ba: int, bb: int) -> bool:
    """Links a, b (on reduced bodies ba ≠ bb) are joined by one joint of the full model: the
    planning joint between their bodies, with no locked joint on the way."""
    if not (reduced.parents[ba] == bb or reduced.parents[bb] == ba):
        return False
    if not (full.existFrame(a) and full.existFrame(b)):
        return True  # not URDF links (a held object): the bodies decide
    ja, jb = (full.frames[full.getFrameId(link)].parentJoint for link in (a, b))
    return full.parents[ja] == jb or full.parents[jb] == ja


def checked_link_pairs(robot) -> set[frozenset[str]]:
    """The link pairs a robot checks for self-collision (from its shape pairs)."""
    return {frozenset((robot.shapes[i].link, robot.shapes[j].link)) for i, j in robot.self_pairs}
