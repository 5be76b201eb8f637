"""GraphDistNet vs coal on the 7-DoF arm among 20 random squares (environment (d)).

python examples/02_planar7_distance.py
"""

import numpy as np

import gdnplan as gp

scene = gp.make_scene("d", seed=3)
q = scene.robot.sample(500, seed=0)  # (500, 7) rad
d, g = gp.signed_distance_and_grad(scene, q)  # coal: (500,) m, (500, 7) m/rad
model = gp.load_model("weights/d.safetensors")
d_hat, g_hat = model.distance_and_grad(scene, q)
cos = np.sum(g * g_hat, 1) / (np.linalg.norm(g, axis=1) * np.linalg.norm(g_hat, axis=1) + 1e-12)
print(f"MAE {np.mean(np.abs(d_hat - d)):.4f} m, mean cosine distance {np.mean(1 - cos):.3f}")
print(f"collisions: coal {np.mean(d <= 0):.1%}, GraphDistNet {np.mean(d_hat <= 0):.1%}")
