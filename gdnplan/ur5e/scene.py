"""The registered ``fetch`` scene: a fetch layout with free grasp, lift, home and out poses.

The configurations are exact IK solutions (:func:`gdnplan.ur5e.analytic_ik`) of the layout's
tcp targets, kept when coal's signed distance clears ``MIN_CLEARANCE``.
"""

from __future__ import annotations

import numpy as np

from ..distance import signed_distance
from ..errors import InfeasibleProblemError, UnknownNameError
from ..limits import check_int
from ..robot import load_robot
from ..scene import Scene, register_scene
from .gripper import GRIPPER_STATES
from .ik import analytic_ik
from .layout import CANONICAL_FETCH, FetchLayout, random_fetch_layout

MAX_FETCH_TRIES = 1000  # fetch_scene: random layouts drawn at most
MIN_CLEARANCE = 0.015  # m: q_grasp, q_home and q_out keep at least this signed distance


def _fetch_scenes(layout: FetchLayout) -> dict[str, Scene]:
    """The layout's scene for each gripper state (the held stick is no obstacle)."""
    fixed = (layout.table(), layout.storage())
    held = load_robot(
        "ur5e",
        gripper="holding",
        stick_length=layout.stick_length,
        stick_width=layout.stick_width,
    )
    return {
        "open": Scene(load_robot("ur5e", gripper="open"), (*fixed, layout.stick()), "fetch"),
        "closed": Scene(load_robot("ur5e", gripper="closed"), (*fixed, layout.stick()), "fetch"),
        "holding": Scene(held, fixed, "fetch"),
    }


def _best(scene: Scene, candidates: list[np.ndarray], near: np.ndarray | None) -> np.ndarray | None:
    """The candidate with clearance ≥ MIN_CLEARANCE, closest to ``near`` (else most clear)."""
    if not candidates:
        return None
    q = np.array(candidates)
    ok = signed_distance(scene, q) >= MIN_CLEARANCE
    if not ok.any():
        return None
    q = q[ok]
    if near is None:
        return q[np.argmax(signed_distance(scene, q))]
    return q[np.argmin(np.abs(q - near).sum(1))]


def fetch_configurations(layout: FetchLayout) -> dict[str, np.ndarray] | None:
    """Free configurations of a layout (coal clearance ≥ MIN_CLEARANCE), or None.

    ``q_grasp``: gripper open and horizontal through the entrance, fingers around the stick's
    near end (the stick an obstacle). ``q_pregrasp``: the same gripper attitude drawn back out of
    the entrance (a waypoint for planners). ``q_lift``: the same grasp raised by LIFT, stick held.
    ``q_home`` (gripper open, above and in front of the box) and ``q_out`` (stick held, entirely
    outside the box) are the free IK solutions nearest to q_grasp. The fetch sequence is
    home → pregrasp → grasp (open), close, lift → out (holding).
    """
    scenes = _fetch_scenes(layout)
    robot = scenes["open"].robot
    q_grasp = _best(scenes["open"], analytic_ik(robot, layout.grasp_target()), None)
    if q_grasp is None:
        return None
    configs = {"q_grasp": q_grasp}
    for key, target, state in (
        ("q_pregrasp", layout.pregrasp_target(), "open"),
        ("q_lift", layout.lift_target(), "holding"),
        ("q_home", layout.home_target(), "open"),
        ("q_out", layout.out_target(), "holding"),
    ):
        configs[key] = _best(scenes[state], analytic_ik(robot, target), q_grasp)
        if configs[key] is None:
            return None
    return configs


@register_scene("fetch")
def fetch_scene(seed: int = 0, gripper: str = "open", max_tries: int = 100) -> Scene:
    """UR5e with its gripper, a table, a storage box with a small entrance and a stick inside.

    seed = 0 is the canonical layout (:data:`CANONICAL_FETCH`); other seeds draw random
    layouts (:func:`random_fetch_layout`), redrawn until :func:`fetch_configurations` finds
    free grasp, home and out configurations (at most ``max_tries`` ≤ 1 000 draws). ``gripper``
    selects the robot: ``open``/``closed`` with the stick an obstacle, or ``holding`` it (the
    stick is then part of the robot and no obstacle).

    ``info``: ``layout`` (FetchLayout), ``storage`` and ``stick`` and ``table`` polygons,
    ``entrance`` (u, v_low, v_high), ``stick_center``, ``stick_length``, ``stick_width``,
    ``grasp_tcp`` (u, v, φ), ``q_grasp``, ``q_pregrasp``, ``q_lift``, ``q_home``, ``q_out`` (3,) and
    ``gripper``.
    """
    if gripper not in GRIPPER_STATES:
        raise UnknownNameError(
            f"gripper: unknown state {gripper!r}; choose one of {list(GRIPPER_STATES)}"
        )
    check_int(max_tries, "max_tries", 1, MAX_FETCH_TRIES)
    rng = np.random.default_rng(seed)
    for _ in range(max_tries):
        layout = CANONICAL_FETCH if seed == 0 else random_fetch_layout(rng)
        configs = fetch_configurations(layout)
        if configs is not None:
            break
        if seed == 0:
            raise InfeasibleProblemError("fetch: the canonical layout has no free grasp")
    else:
        raise InfeasibleProblemError(
            f"fetch: seed {seed}: no layout with a free grasp in max_tries={max_tries} draws"
        )
    scene = _fetch_scenes(layout)[gripper]
    info = {
        "layout": layout,
        "gripper": gripper,
        "table": layout.table(),
        "storage": layout.storage(),
        "stick": layout.stick(),
        "entrance": (layout.front, *layout.entrance),
        "stick_center": layout.stick_center,
        "stick_length": layout.stick_length,
        "stick_width": layout.stick_width,
        "grasp_tcp": layout.grasp_target(),
        **configs,
    }
    return Scene(scene.robot, scene.obstacles, name="fetch", seed=seed, info=info)
