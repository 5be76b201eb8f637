"""Write planar2.urdf and planar7.urdf: chains of box links rotating about z.

Run from the repository root: ``python robots/make_planar_urdf.py``.
"""

from pathlib import Path

WIDTH = 0.06  # m, link width in the plane
PI = 3.141592653589793
HEIGHT = 1.0  # m, out-of-plane thickness (irrelevant to the 2-D polygons)


def planar_urdf(name: str, lengths: list[float]) -> str:
    parts = [f'<?xml version="1.0"?>\n<robot name="{name}">', '  <link name="base"/>']
    parent, offset = "base", 0.0
    for i, length in enumerate(lengths, start=1):
        parts += [
            f'  <joint name="joint{i}" type="revolute">',
            f'    <parent link="{parent}"/><child link="link{i}"/>',
            f'    <origin xyz="{offset} 0 0"/><axis xyz="0 0 1"/>',
            f'    <limit lower="{-PI}" upper="{PI}" effort="10" velocity="2"/>',
            "  </joint>",
            f'  <link name="link{i}">',
            "    <collision>",
            f'      <origin xyz="{length / 2} 0 0"/>',
            f'      <geometry><box size="{length} {WIDTH} {HEIGHT}"/></geometry>',
            "    </collision>",
            "  </link>",
        ]
        parent, offset = f"link{i}", length
    parts += [
        '  <joint name="tip_joint" type="fixed">',
        f'    <parent link="{parent}"/><child link="tip"/><origin xyz="{offset} 0 0"/>',
        '  </joint>\n  <link name="tip"/>\n</robot>\n',
    ]
    return "\n".join(parts)


if __name__ == "__main__":
    here = Path(__file__).parent
    (here / "planar2.urdf").write_text(planar_urdf("planar2", [0.6, 0.6]))
    (here / "planar7.urdf").write_text(planar_urdf("planar7", [0.3] * 7))
