import matplotlib
import pytest

matplotlib.use("Agg")


class Recorder:
    """A meshcat window that keeps the packed commands instead of sending them."""

    def __init__(self):
        self.commands = []

    def send(self, command):
        import umsgpack

        data = command.lower()
        umsgpack.packb(data)  # what the zmq window sends: must serialise
        self.commands.append(data)


@pytest.fixture
def meshcat_window() -> Recorder:
    """A fake meshcat window: ``meshcat.Visualizer(window=...)`` records instead of sending."""
    return Recorder()


@pytest.fixture(scope="module")
def panda_scene():
    """example-robot-data's Panda among 20 random boxes (seed 1)."""
    from gdnplan.arm3d import load_robot3d, random_boxes

    return random_boxes(load_robot3d("panda"), 20, seed=1)


@pytest.fixture(scope="module")
def ur5e_scene():
    """The 3-D UR5e among 20 random boxes (seed 1)."""
    from gdnplan.arm3d import load_robot3d, random_boxes

    return random_boxes(load_robot3d("ur5e"), 20, seed=1)
