"""UR5e / UR5 kinematics (gdnplan.ur5e.kinematics, .urdf): the DH product, the URDF, Pinocchio."""

import numpy as np
import pinocchio as pin

from gdnplan import ur5e as U
from gdnplan.assets import ROBOTS_DIR


def full_fk(model: pin.Model, q: np.ndarray, frame: str, base: str) -> np.ndarray:
    """(4, 4) pose of ``frame`` relative to ``base`` from Pinocchio."""
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    return (
        data.oMf[model.getFrameId(base)].inverse() * data.oMf[model.getFrameId(frame)]
    ).homogeneous


def dh_textbook(q: np.ndarray, d, a, alpha) -> np.ndarray:
    """Independent DH product, one joint at a time: Rz(θ) Tz(d) Tx(a) Rx(α)."""

    def rz(t):
        return np.array(
            [
                [np.cos(t), -np.sin(t), 0, 0],
                [np.sin(t), np.cos(t), 0, 0],
                [0, 0, 1, 0],
                [0, 0, 0, 1],
            ]
        )

    def rx(t):
        return np.array(
            [
                [1, 0, 0, 0],
                [0, np.cos(t), -np.sin(t), 0],
                [0, np.sin(t), np.cos(t), 0],
                [0, 0, 0, 1],
            ]
        )

    def tr(x, z):
        out = np.eye(4)
        out[0, 3], out[2, 3] = x, z
        return out

    t = np.eye(4)
    for i in range(6):
        t = t @ rz(q[i]) @ tr(0, d[i]) @ tr(a[i], 0) @ rx(alpha[i])
    return t


PUBLISHED = dict(
    d=(0.1625, 0, 0, 0.1333, 0.0997, 0.0996),
    a=(0, -0.425, -0.3922, 0, 0, 0),
    alpha=(np.pi / 2, 0, 0, np.pi / 2, -np.pi / 2, 0),
)


def test_urdf_file_is_generated():
    assert (ROBOTS_DIR / "ur5e.urdf").read_text() == U.ur5e_urdf()


def test_ur5e_fk_equals_dh():
    model = pin.buildModelFromUrdf(str(ROBOTS_DIR / "ur5e.urdf"))
    rng = np.random.default_rng(0)
    for _ in range(200):
        q = np.concatenate([rng.uniform(-2 * np.pi, 2 * np.pi, 6), [0.0, 0.0]])
        got = full_fk(model, q, "flange", "base")
        want = dh_textbook(q[:6], **PUBLISHED)
        np.testing.assert_allclose(got, want, atol=1e-9)
        np.testing.assert_allclose(U.UR5E_DH.forward(q[:6])[0], want, atol=1e-12)
    # the published zero pose: flange at (a2 + a3, −(d4 + d6), d1 − d5) in the base frame
    np.testing.assert_allclose(
        full_fk(model, np.zeros(8), "flange", "base")[:3, 3], [-0.8172, -0.2329, 0.0628], atol=1e-12
    )


def test_ur5_from_example_robot_data_equals_ur5_dh():
    """The DH code against independent data: example-robot-data's UR5 URDF (base turned by π)."""
    import example_robot_data

    model = example_robot_data.load("ur5").model
    turn = np.diag([-1.0, -1.0, 1.0])
    for q in np.random.default_rng(1).uniform(-np.pi, np.pi, (50, 6)):
        got = full_fk(model, q, "tool0", "base_link")[:3, 3]
        np.testing.assert_allclose(got, turn @ U.UR5_DH.forward(q)[0][:3, 3], atol=1e-9)
