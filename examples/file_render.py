"""Any file the CLI reads: what it holds, then a render from a chosen camera.

    PYTHONPATH=build/python python3 examples/file_render.py [FILE] [OUT_DIR]
"""
import pathlib
import sys

import rtfact

path = sys.argv[1] if len(sys.argv) > 1 else str(pathlib.Path(__file__).parents[1] / "datasets/meshes/bunny.ply")
out_dir = sys.argv[2] if len(sys.argv) > 2 else "."
scene = rtfact.load(path)
for key, value in scene.info().items():
    print(f"{key}: {value}")
cam = scene.fit_camera(fov=35, size=(640, 480))
img = rtfact.render(scene, cam, size=(640, 480), spp=4)
out = f"{out_dir}/{pathlib.Path(path).stem}.png"
rtfact.save_image(out, img)
print("wrote", out)
