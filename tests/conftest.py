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
