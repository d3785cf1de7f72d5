"""A point cloud from numpy: a noisy torus coloured by height, rendered with direct light.

    PYTHONPATH=build/python python3 examples/numpy_points.py [OUT_DIR]
"""
import sys

import numpy as np

import rtfact

out_dir = sys.argv[1] if len(sys.argv) > 1 else "."
rng = np.random.default_rng(0)
u, v = rng.uniform(0, 2 * np.pi, (2, 200_000))
R, r = 1.0, 0.35
xyz = np.stack([(R + r * np.cos(v)) * np.cos(u), r * np.sin(v), (R + r * np.cos(v)) * np.sin(u)], axis=1)
xyz = (xyz + rng.normal(scale=0.003, size=xyz.shape)).astype(np.float32)  # float32 N x 3
t = (xyz[:, 1] - xyz[:, 1].min()) / np.ptp(xyz[:, 1])
colors = np.stack([t, 0.4 + 0.3 * t, 1 - t], axis=1)  # floats in 0..1

scene = rtfact.points(xyz, colors=colors)
print(scene.info())
img = rtfact.render(scene, size=(640, 480), integrator="direct", spp=4)
rtfact.save_image(f"{out_dir}/torus_points.png", img)
print("wrote", f"{out_dir}/torus_points.png")
