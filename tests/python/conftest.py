"""Shared helpers of the Python module's tests: paths from ctest's environment, the CLI
runner, a binary PLY writer and the image-regression metric of tests/common/image_compare.h."""
import os
import pathlib
import subprocess

import numpy as np
import pytest

import rtfact

SOURCE_DIR = pathlib.Path(os.environ.get("RTFACT_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
DATASETS = SOURCE_DIR / "datasets"


@pytest.fixture
def cli():
    """Runs `rtfact ARGS... --quiet` and fails with its stderr when it exits non-zero."""
    exe = os.environ.get("RTFACT_CLI")
    if not exe or not os.path.exists(exe):
        pytest.fail("RTFACT_CLI does not name the rtfact binary (run through ctest)")

    def run(*args):
        r = subprocess.run([exe, *map(str, args), "--quiet"], capture_output=True, text=True)
        assert r.returncode == 0, f"rtfact {' '.join(map(str, args))}: {r.stderr}"
        return r

    return run


def write_ply(path, xyz, colors=None):
    """A binary little-endian PLY of float32 positions and optional uint8 colours."""
    n = len(xyz)
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {n}",
              "property float x", "property float y", "property float z"]
    fields = [("x", "<f4"), ("y", "<f4"), ("z", "<f4")]
    if colors is not None:
        header += ["property uchar red", "property uchar green", "property uchar blue"]
        fields += [("r", "u1"), ("g", "u1"), ("b", "u1")]
    header.append("end_header")
    rec = np.zeros(n, dtype=fields)
    rec["x"], rec["y"], rec["z"] = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    if colors is not None:
        rec["r"], rec["g"], rec["b"] = colors[:, 0], colors[:, 1], colors[:, 2]
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode())
        f.write(rec.tobytes())


def image_diff(a, b, tol=8):
    """tests/common/image_compare.h's metric: (fraction of pixels with a channel differing by
    more than tol/255 in 8-bit sRGB, PSNR in dB)."""
    x = rtfact.to_srgb8(a).astype(np.int32)
    y = rtfact.to_srgb8(b).astype(np.int32)
    assert x.shape == y.shape
    d = np.abs(x - y)
    worst = d.max(axis=2)
    mse = float((d.astype(np.float64) ** 2).mean())
    psnr = 99.0 if mse == 0 else 10 * np.log10(255.0 ** 2 / mse)
    return float((worst > tol).mean()), psnr


def assert_images_match(a, b, name, tmp_path=None, tol=8, max_different=0.005, min_psnr=35.0):
    """The image-regression tolerance of the C++ tests (ImageTolerance's defaults)."""
    frac, psnr = image_diff(a, b, tol)
    if frac > max_different or psnr < min_psnr:
        out = pathlib.Path(os.environ.get("RTFACT_TEST_OUT", tmp_path or "."))
        out.mkdir(parents=True, exist_ok=True)
        rtfact.save_image(str(out / f"{name}_actual.png"), a)
        rtfact.save_image(str(out / f"{name}_expected.png"), b)
    assert frac <= max_different and psnr >= min_psnr, f"{name}: {frac:.4f} of pixels differ, PSNR {psnr:.1f} dB"


def coverage(img):
    """Fraction of pixels the scene covers (alpha > 0): guards against comparing two blanks."""
    return float((np.asarray(img)[..., 3] > 0.01).mean())
