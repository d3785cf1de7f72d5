"""Bad arrays, settings and files raise clear exceptions (never a crash): ValueError with
the CLI-style one-line message naming the argument, TypeError for unknown setting names,
rtfact.Error (an OSError) for files."""
import numpy as np
import pytest

import rtfact
from conftest import DATASETS

XYZ = np.random.default_rng(1).random((500, 3), dtype=np.float32)


@pytest.mark.parametrize("arr, message", [
    (np.zeros((5, 3), dtype=np.int32), "xyz: dtype int32 is not float32 or float64"),
    (np.zeros((5, 2), dtype=np.float32), "xyz: expected an N x 3 array, got shape (5, 2)"),
    (np.zeros((5,), dtype=np.float32), "xyz: expected an N x 3 array, got shape (5,)"),
    (np.zeros((0, 3), dtype=np.float32), "xyz: empty array"),
    (np.array([[0, 0, 0], [1, np.nan, 0]], dtype=np.float32), "points: non-finite coordinate at point 1"),
    (np.array([[0, 0, 0], [1, np.inf, 0]], dtype=np.float64), "points: non-finite coordinate at point 1"),
    ("not numbers", "xyz:"),
])
def test_bad_point_arrays(arr, message):
    with pytest.raises(ValueError) as e:
        rtfact.points(arr)
    assert message in str(e.value)


def test_bad_optional_point_arrays():
    with pytest.raises(ValueError, match="colors: has 4 rows for 500 points"):
        rtfact.points(XYZ, colors=np.zeros((4, 3), np.uint8))
    with pytest.raises(ValueError, match="colors: dtype int64"):
        rtfact.points(XYZ, colors=np.zeros((500, 3), np.int64))
    with pytest.raises(ValueError, match="radius: must be positive"):
        rtfact.points(XYZ, radius=-1.0)
    with pytest.raises(ValueError, match="radius at point 0 is not a positive"):
        rtfact.points(XYZ, radius=np.zeros(500, np.float32))
    with pytest.raises(ValueError, match="non-finite normal at point 3"):
        n = np.ones((500, 3), np.float32)
        n[3, 1] = np.nan
        rtfact.points(XYZ, normals=n)


def test_bad_volume_arrays():
    with pytest.raises(ValueError, match="volume: expected a 3D array, got shape \\(4, 4\\)"):
        rtfact.volume(np.zeros((4, 4), np.uint8))
    with pytest.raises(ValueError, match="volume: dtype complex64 is not a real number type"):
        rtfact.volume(np.zeros((4, 4, 4), np.complex64))
    with pytest.raises(ValueError, match="needs at least 2 voxels along every axis"):
        rtfact.volume(np.zeros((1, 4, 4), np.uint8))
    with pytest.raises(ValueError, match="needs at least 2 voxels"):
        rtfact.volume(np.zeros((0, 4, 4), np.float32))
    v = np.zeros((4, 5, 6), np.float32)
    v[1, 2, 3] = np.nan
    with pytest.raises(ValueError, match=r"volume: non-finite value at voxel \(x=3, y=2, z=1\)"):
        rtfact.volume(v)
    with pytest.raises(ValueError, match="order: expected 'zyx'"):
        rtfact.volume(np.zeros((4, 4, 4), np.uint8), order="yxz")
    with pytest.raises(ValueError, match="spacing must be positive"):
        rtfact.volume(np.zeros((4, 4, 4), np.uint8), spacing=(1, 0, 1))


def test_bad_mesh_arrays():
    v = np.zeros((3, 3), np.float32)
    with pytest.raises(ValueError, match="faces: index 3 in face 0 is outside the 3 vertices"):
        rtfact.mesh(v, np.array([[0, 1, 3]]))
    with pytest.raises(ValueError, match="faces: index -1"):
        rtfact.mesh(v, np.array([[0, 1, -1]]))
    with pytest.raises(ValueError, match="faces: dtype float32 is not an integer type"):
        rtfact.mesh(v, np.zeros((1, 3), np.float32))


@pytest.fixture(scope="module")
def cloud():
    return rtfact.points(XYZ)


@pytest.mark.parametrize("settings, error, message", [
    ({"integrator": "foo"}, ValueError, "integrator: 'foo' is not one of eyelight, direct, ao"),
    ({"radius_factor": float("nan")}, ValueError, "radius_factor: expected a finite number, got nan"),
    ({"lod_quality": 100}, ValueError, "lod_quality: must be in [0.0, 64.0], got 100"),
    ({"accel": "octree"}, ValueError, "accel: 'octree' is not one of kd, wide"),
    ({"size": (0, 10)}, ValueError, "size: must be in [1, 16384], got 0"),
    ({"size": "10by10"}, ValueError, "size: expected WxH"),
    ({"spp": 0}, ValueError, "spp: must be in [1,"),
    ({"packet": 5}, ValueError, "packet: must be one of"),
    ({"eye": (1, 2)}, ValueError, "eye: expected 3 numbers"),
    ({"fov": float("inf")}, ValueError, "fov: expected a finite number"),
    ({"mode": "dvr"}, TypeError, "unknown setting 'mode' for a points scene"),
    ({"colour": "rgb"}, TypeError, "unknown setting 'colour'"),
    ({"progress": "yes"}, ValueError, "progress: expected True or False"),
])
def test_bad_settings(cloud, settings, error, message):
    with pytest.raises(error) as e:
        rtfact.render(cloud, size=(8, 8), **settings) if "size" not in settings else rtfact.render(cloud, **settings)
    assert message in str(e.value)


def test_bad_volume_settings():
    vol = rtfact.volume(np.arange(4 * 5 * 6, dtype=np.uint8).reshape(4, 5, 6))
    for settings, message in [({"tf": "nope"}, "tf: 'nope' is neither a preset"),
                              ({"tf": [(0.5, 1, 1, 1)]}, "tf: row 0: expected (x, r, g, b, a)"),
                              ({"tf": [(0.5, 1, 1, 1, 1), (0.2, 1, 1, 1, 1)]}, "tf:"),
                              ({"clip": "w:0:1"}, "clip: expected axis:lo:hi"),
                              ({"clip": {"z": (0.6, 0.5)}}, "clip: expected axis:lo:hi"),
                              ({"step": 0}, "step: must be in [0.01, 64.0]"),
                              ({"mode": "xray"}, "mode: 'xray' is not one of dvr, shaded, mip, iso")]:
        with pytest.raises(ValueError) as e:
            rtfact.render(vol, size=(8, 8), **settings)
        assert message in str(e.value), str(e.value)


def test_camera_errors(cloud):
    with pytest.raises(ValueError, match="eye: coincides with at"):
        rtfact.Camera((1, 1, 1), (1, 1, 1))
    with pytest.raises(ValueError, match="up: is parallel"):
        rtfact.Camera((0, 0, 5), (0, 0, 0), up=(0, 0, 1))
    with pytest.raises(TypeError, match="either camera= or eye/at/up/fov"):
        rtfact.render(cloud, rtfact.Camera((0, 0, 5), (0, 0, 0)), eye=(1, 1, 1))


def test_file_errors(tmp_path):
    missing = tmp_path / "missing.ply"
    with pytest.raises(rtfact.Error) as e:
        rtfact.load(missing)
    assert isinstance(e.value, OSError)
    assert str(missing) in str(e.value)
    junk = tmp_path / "junk.ply"
    junk.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty float x\nend_header\n")
    with pytest.raises(OSError) as e:
        rtfact.load(junk)
    assert str(e.value).startswith(str(junk) + ":") and "\n" not in str(e.value)
    with pytest.raises(rtfact.Error, match="missing.json"):
        rtfact.transfer_function(str(tmp_path / "missing.json"))
    with pytest.raises(rtfact.Error, match="unsupported image format"):
        rtfact.save_image(str(tmp_path / "x.bmpx"), np.zeros((4, 4, 4), np.float32))
    with pytest.raises(ValueError, match="image: expected an"):
        rtfact.save_image(str(tmp_path / "x.png"), np.zeros((4, 4), np.float32))
    with pytest.raises(ValueError, match="dims: expected"):
        rtfact.load(DATASETS / "volumes" / "tooth_103x94x161_uint8.raw", dims=(1, 2))
    with pytest.raises(TypeError, match="unknown load option 'dim'"):
        rtfact.load(DATASETS / "volumes" / "tooth_103x94x161_uint8.raw", dim=(1, 2, 3))
