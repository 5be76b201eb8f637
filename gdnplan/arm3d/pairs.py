"""Self-collision pairs of a 3-D robot: which link pairs are checked, how, and why.

Every pair of links (each carrying collision shapes) falls in one of three kinds.

**Unchecked** (``robot.disabled`` keeps the reason), never evaluated:

* ``"same body"``: both move with the same planning joint (they are rigidly attached, e.g. a
  wrist, its flange and a locked gripper): their distance never changes;
* ``"adjacent"``: the URDF joins the two links by one planning joint (and fixed joints only).
  Adjacent links meet at their joint, and their shapes (mesh hulls especially) touch or overlap
  there at every configuration, so a check would report a collision that planning cannot
  remove. A locked joint on the way keeps a pair checked: with a UR5e's wrist joints locked the
  gripper shares the forearm's body, yet it can fold into the upper arm. So a link that folds
  back into its parent *away* from their joint is not seen either: the shipped UR5e's forearm
  end enters its upper arm (up to 5 cm) for |elbow| > 2.9 rad, where its wrist links, which
  are checked, already hit the upper arm (docs/decisions.md, the third certificate
  adversary); for a robot of your own, limit such a joint where the fold begins;
* the SRDF, when one is given, disables it (``<disable_collisions link1= link2= reason=/>``:
  MoveIt's "Adjacent", "Never", "Default", "Always"); the reason is kept. An SRDF pair must
  truly never come close: gdnplan does not look at it again.

**Contact-only** (``robot.contact_only``): checked for contact only, signed distance d ≥ 0
whatever the clearance margin. These are pairs that can collide but whose geometry keeps them
closer than any useful margin at every configuration: the shipped UR5e's forearm against the
wrist-2 housing (d ≤ 1.45 cm everywhere, down to −2.0 cm) and against wrist 3 (down to
−1.5 cm). Disabling them would be unsound (the cylinders do interpenetrate); giving them the
margin (default 2 cm) would make every configuration infeasible. Users declare their own with
``robot3d_from_urdf(..., contact_only=[(link1, link2), ...])``.

**Ordinary**: every other pair, which must keep the clearance margin like an obstacle pair.

The pair table (:mod:`gdnplan.arm3d.narrow3d`) compares d_k + o_k with the margin M, with the
offset o_k = M on contact-only pairs and 0 elsewhere, so min_k (d_k + o_k) ≥ M ⟺ obstacle and
ordinary pairs ≥ M and contact-only pairs ≥ 0. A certificate (:mod:`gdnplan.arm3d.ccd3d`)
proves exactly that on the whole continuous path. :func:`gdnplan.arm3d.signed_distance3d`
returns true signed distances (no offsets) over all checked pairs, contact-only ones included.

Without an SRDF only the first two rules disable pairs. The shipped UR5e has one
(``shipped/robots/ur5e.srdf``) and declares its contact-only pairs in
:mod:`gdnplan.arm3d.builtin`. Every shape of one link is paired with every shape of the other.
"""

from __future__ import annotations

import itertools
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..errors import InputError, UnknownNameError
from ..files import read_input


def srdf_disabled_pairs(srdf: str | Path, model: pin.Model) -> dict[frozenset[str], str]:
    """The SRDF's disabled link pairs → reason ("" when none is given).

    UnknownNameError for a missing file; InputError for a file that is not XML or names a link
    that is not in the robot (an SRDF of another robot).
    """
    path = Path(srdf)
    if not path.is_file():
        raise UnknownNameError(f"srdf: file {path} does not exist (or is not a file)")
    try:
        root = ET.fromstring(read_input(path, "srdf"))
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
    full: pin.Model,
    reduced: pin.Model,
    shapes: Sequence,
    srdf: str | Path | None,
    contact_only: Sequence[tuple[str, str]] = (),
) -> tuple[np.ndarray, dict[frozenset[str], str], frozenset[frozenset[str]]]:
    """Shape index pairs (P, 2) to check, every unchecked link pair → its reason, and the
    checked link pairs that are contact-only (:func:`check_contact_only`).

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
    contact = check_contact_only(contact_only, tuple(body), disabled)
    return np.array(pairs, dtype=int).reshape(-1, 2), disabled, contact


def check_contact_only(
    contact_only, links: Sequence[str], disabled: dict[frozenset[str], str]
) -> frozenset[frozenset[str]]:
    """The declared contact-only link pairs as a set of frozensets.

    InputError for anything but a sequence of (link, link) name pairs, a link without
    collision shapes (or not in the robot), a link paired with itself, or a pair that is not
    checked at all (same body, adjacent, disabled by the SRDF: the reason is named).
    """
    if isinstance(contact_only, (str, bytes)) or not isinstance(contact_only, (list, tuple)):
        raise InputError(
            f"contact_only: expected a list of (link, link) pairs, got {contact_only!r}"
        )
    out: set[frozenset[str]] = set()
    for k, item in enumerate(contact_only):
        where = f"contact_only[{k}]"
        if not (isinstance(item, (list, tuple)) and len(item) == 2):
            raise InputError(f"{where}: expected a pair of link names, got {item!r}")
        for link in item:
            if not isinstance(link, str) or link not in links:
                raise InputError(
                    f"{where}: {link!r} is not a link with collision shapes; choose from "
                    f"{list(links)}"
                )
        key = frozenset(item)
        if len(key) != 2:
            raise InputError(f"{where}: a link cannot be paired with itself ({item[0]!r})")
        if key in disabled:
            raise InputError(
                f"{where}: {item[0]!r}–{item[1]!r} is not checked at all ({disabled[key]}); "
                "only a checked pair can be contact-only (remove it from the SRDF first)"
            )
        out.add(key)
    return frozenset(out)


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
    """The link pairs a robot checks for self-collision (from its shape pairs), contact-only
    pairs included."""
    return {frozenset((robot.shapes[i].link, robot.shapes[j].link)) for i, j in robot.self_pairs}


def contact_only_mask(shapes: Sequence, self_pairs: np.ndarray, contact_only) -> np.ndarray:
    """(P,) bool: the shape pairs ``self_pairs`` (P, 2) whose link pair is contact-only.

    InputError when a contact-only link pair has no shape pair among ``self_pairs``.
    """
    keys = [frozenset((shapes[i].link, shapes[j].link)) for i, j in self_pairs]
    mask = np.array([k in contact_only for k in keys], dtype=bool)
    missing = set(contact_only) - set(keys)
    if missing:
        names = sorted("–".join(sorted(p)) for p in missing)
        raise InputError(f"contact_only: {names} are not checked self-collision pairs")
    return mask
