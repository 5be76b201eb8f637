"""The UR5e fetch: reach into the storage, grasp the stick, bring it out (GraphDistNet).

python examples/03_ur5e_fetch.py
"""

from gdnplan.fetch import run_fetch

for stage in run_fetch(seed=0, collision="graphdistnet"):
    print(
        f"{stage.name:>10} ({stage.scene.robot.info['gripper']} gripper): "
        f"certified {stage.success}, clearance {stage.min_distance:+.4f} m, "
        f"{stage.solve_time:.1f} s"
    )
