import numpy as np
from PIL import Image

import gdnplan as gp
from gdnplan.viz import animate_paths, interpolate_path


def test_interpolate_path_keeps_waypoints():
    path = np.array([[0.0, 0.0], [1.0, 2.0], [3.0, 2.0]])
    dense = interpolate_path(path, 4)
    assert dense.shape == (9, 2)
    np.testing.assert_allclose(dense[::4], path)
    np.testing.assert_allclose(dense[1], [0.25, 0.5])


def test_animation_has_one_frame_per_interpolated_configuration(tmp_path):
    scene = gp.make_scene("a")
    stages = [
        (scene, np.linspace([0.0, 0.0], [1.0, 0.5], 3)),
        (scene, np.array([[1.0, 0.5], [2.0, 0.5]])),
    ]
    out = tmp_path / "plan.gif"
    animate_paths(stages, out, per_segment=2)
    assert Image.open(out).n_frames == 5 + 3
    assert not list(tmp_path.glob(".*tmp*"))
