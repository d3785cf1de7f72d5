"""A volume from numpy with a transfer function given as a Python list.

    PYTHONPATH=build/python python3 examples/numpy_volume.py [OUT_DIR]
"""
import sys

import numpy as np

import rtfact

out_dir = sys.argv[1] if len(sys.argv) > 1 else "."
# Three Gaussian blobs on a 128^3 grid, indexed [z, y, x] (numpy's C order), as uint16.
z, y, x = np.mgrid[-1:1:128j, -1:1:128j, -1:1:128j]
density = sum(np.exp(-((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / 0.08)
              for cx, cy, cz in [(-0.4, 0, 0), (0.4, 0.2, 0), (0, -0.3, 0.3)])
vol = (density / density.max() * 60000).astype(np.uint16)

scene = rtfact.volume(vol, spacing=(1, 1, 1))  # read in place: no copy of the array
# (x, r, g, b, a): x over the value window (0..1), sRGB colour, opacity per voxel
tf = [(0.0, 0.0, 0.0, 0.0, 0.0), (0.2, 0.1, 0.3, 0.9, 0.0), (0.5, 0.9, 0.6, 0.1, 0.05), (1.0, 1.0, 1.0, 1.0, 0.4)]
img = rtfact.render(scene, size=(512, 512), tf=tf, mode="shaded", spp=2)
rtfact.save_image(f"{out_dir}/blobs_volume.png", img)
print("wrote", f"{out_dir}/blobs_volume.png")
