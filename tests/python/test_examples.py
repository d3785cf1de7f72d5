"""The three scripts in examples/ run and write a non-empty image."""
import os
import subprocess
import sys

import numpy as np
import pytest

import rtfact
from conftest import SOURCE_DIR


@pytest.mark.parametrize("script, image", [("numpy_points.py", "torus_points.png"),
                                           ("numpy_volume.py", "blobs_volume.png"),
                                           ("file_render.py", "bunny.png")])
def test_example(tmp_path, script, image):
    args = [sys.executable, str(SOURCE_DIR / "examples" / script)]
    if script == "file_render.py":
        args.append(str(SOURCE_DIR / "datasets" / "meshes" / "bunny.ply"))
    r = subprocess.run(args + [str(tmp_path)], capture_output=True, text=True, env=dict(os.environ))
    assert r.returncode == 0, r.stderr
    assert "wrote" in r.stdout and r.stderr == ""
    img = rtfact.read_image(str(tmp_path / image))
    assert img.shape[0] >= 480
    srgb = rtfact.to_srgb8(img).astype(int)
    # Not a flat background: the subject shows.
    assert srgb.std() > 10 and np.unique(srgb.reshape(-1, 3), axis=0).shape[0] > 50
