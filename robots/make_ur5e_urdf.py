"""Write ur5e.urdf (UR5e from its DH parameters + a 2F-85-like gripper), see gdnplan.ur5e.

Run from the repository root: ``python robots/make_ur5e_urdf.py``.
"""

from pathlib import Path

from gdnplan.ur5e import ur5e_urdf

if __name__ == "__main__":
    (Path(__file__).parent / "ur5e.urdf").write_text(ur5e_urdf())
