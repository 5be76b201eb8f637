"""The built-in 3-D robots: the shipped UR5e (six joints, gripper), the Panda and the UR5.

* ``"ur5e"``: ``gdnplan/shipped/robots/ur5e.urdf``, all six arm joints planned, the gripper's
  fingers locked (open by default: ``finger`` m each, at most 0.0425), collision cylinders and
  boxes; ``shipped/robots/ur5e.srdf`` disables base–upper arm (constant, 1.65 cm), wrist 1–
  wrist 3 (never closer than 2.27 cm) and the finger pairs with wrist 1 and wrist 2 (never
  closer than 8 cm in 5000 samples). The forearm against wrist 2 and wrist 3
  (:data:`UR5E_CONTACT_ONLY`) are contact-only pairs: their cylinders stay within 1.45 cm
  (wrist 2) of each other everywhere, so no 2 cm margin fits, yet they do interpenetrate
  (down to −2.0 cm and −1.5 cm): they are checked for d ≥ 0 (:mod:`gdnplan.arm3d.pairs`).
* ``"panda"``: example-robot-data's Franka Panda, seven joints, fingers locked at ``finger`` m
  (at most 0.04), collision meshes as convex hulls, the SRDF's disabled pairs.
* ``"ur5"``: example-robot-data's UR5, six joints, collision meshes as hulls, its SRDF.

example-robot-data is found through its Python package (``pip install example-robot-data``).
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

from ..assets import robot_urdf
from ..errors import InputError, UnknownNameError, did_you_mean
from ..limits import shown
from ..ur5e.kinematics import JOINTS
from .robot3d import Robot3D, robot3d_from_urdf

UR5E_JOINTS = JOINTS  # all six arm joints, as the planar model names them
UR5E_CONTACT_ONLY = (("forearm_link", "wrist_2_link"), ("forearm_link", "wrist_3_link"))
PANDA_JOINTS = tuple(f"panda_joint{i}" for i in range(1, 8))


def _example_robot_data(name: str) -> tuple[Path, Path, Path]:
    """(urdf, srdf, the folder holding the ``example-robot-data`` package) of a robot."""
    try:
        from example_robot_data.robots_loader import ROBOTS
    except ImportError as e:  # pragma: no cover - a dependency of the install
        raise InputError(f"robot: {name!r} needs example-robot-data (pip install it)") from e
    loader = ROBOTS[name]()
    urdf = Path(loader.df_path).resolve()
    return urdf, Path(loader.srdf_path).resolve(), Path(loader.model_path).resolve().parent.parent


def ur5e3d(finger: float = 0.02) -> Robot3D:
    """The shipped UR5e with its gripper, six planning joints; fingers open by ``finger`` m."""
    locked = {"left_finger_joint": finger, "right_finger_joint": finger}
    urdf = robot_urdf("ur5e")
    srdf = urdf.with_suffix(".srdf")
    return robot3d_from_urdf(
        urdf,
        joints=UR5E_JOINTS,
        locked=locked,
        srdf=srdf,
        name="ur5e",
        contact_only=UR5E_CONTACT_ONLY,
    )


def panda3d(finger: float = 0.02) -> Robot3D:
    """example-robot-data's Panda: seven joints, fingers locked at ``finger`` m, its SRDF."""
    urdf, srdf, package = _example_robot_data("panda")
    locked = {"panda_finger_joint1": finger, "panda_finger_joint2": finger}
    return robot3d_from_urdf(
        urdf, [package], joints=PANDA_JOINTS, locked=locked, srdf=srdf, name="panda"
    )


def ur5_3d() -> Robot3D:
    """example-robot-data's UR5: six joints, collision meshes as hulls, its SRDF."""
    urdf, srdf, package = _example_robot_data("ur5")
    return robot3d_from_urdf(urdf, [package], joints=UR5E_JOINTS, srdf=srdf, name="ur5")


FACTORIES = {"ur5e": ur5e3d, "panda": panda3d, "ur5": ur5_3d}


@cache
def _cached(name: str) -> Robot3D:
    return FACTORIES[name]()


def load_robot3d(name: str) -> Robot3D:
    """A built-in 3-D robot by name (``"ur5e"``, ``"panda"``, ``"ur5"``), built once per process.

    The returned robot is shared: treat it as read-only (its Pinocchio data is scratch space).
    """
    if not isinstance(name, str) or name not in FACTORIES:  # a list raised TypeError
        raise UnknownNameError(
            f"robot: unknown 3-D robot {shown(name)}{did_you_mean(name, FACTORIES)}; choose one "
            f"of {list(FACTORIES)}"
        )
    return _cached(name)


def robot3d_names() -> list[str]:
    """Names of the built-in 3-D robots."""
    return list(FACTORIES)
