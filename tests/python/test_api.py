"""The module's API on real files and arrays: load/info, render, Camera and fit_camera,
transfer functions, image helpers, Jupyter display, quiet by default."""
import json

import numpy as np
import pytest

import rtfact
from conftest import DATASETS, coverage

BUNNY_POINTS = DATASETS / "points" / "bunny_bun000.ply"
BUNNY_MESH = DATASETS / "meshes" / "bunny.ply"
TOOTH = DATASETS / "volumes" / "tooth_103x94x161_uint8.mhd"


def test_load_and_info_of_each_kind():
    p = rtfact.load(BUNNY_POINTS)
    assert p.kind == "points" and p.source == str(BUNNY_POINTS)
    i = p.info()
    assert i["kind"] == "points" and isinstance(i["points"], int) and i["points"] > 1000
    assert i["bounds"] == p.bounds and len(i["bounds"]) == 2
    m = rtfact.load(BUNNY_MESH)
    assert m.kind == "mesh" and m.info()["triangles"] > 1000
    merged = rtfact.load([BUNNY_MESH, BUNNY_MESH])  # several mesh files: one scene
    assert merged.info()["triangles"] == 2 * m.info()["triangles"]
    v = rtfact.load(TOOTH)
    vi = v.info()
    assert v.kind == "volume" and vi["dims"] == (103, 94, 161) and vi["voxels"] == 103 * 94 * 161
    lo, hi = vi["range"]
    assert 0 <= lo < hi <= 255
    # rtfact.info(path) is `rtfact info FILE`; rtfact.info(scene) is scene.info()
    fi = rtfact.info(TOOTH)
    assert fi and all(isinstance(k, str) for k in fi)
    assert rtfact.info(v) == vi


def test_render_returns_linear_rgba_image():
    img = rtfact.render(rtfact.load(BUNNY_MESH), size=(96, 64))
    assert isinstance(img, rtfact.Image) and isinstance(img, np.ndarray)
    assert img.shape == (64, 96, 4) and img.dtype == np.float32 and img.flags.c_contiguous
    assert 0.1 < coverage(img) < 0.9
    img2, stats = rtfact.render(rtfact.load(BUNNY_MESH), size=(96, 64), stats=True)
    assert np.array_equal(img, img2)
    assert stats["width"] == 96 and stats["height"] == 64 and stats["render_ms"] >= 0


def test_point_structures_give_the_same_full_detail_image():
    cloud = rtfact.load(BUNNY_POINTS)
    kd = rtfact.render(cloud, size=(64, 48), lod=False)
    wide, stats = rtfact.render(cloud, size=(64, 48), lod=False, accel="wide", stats=True)
    assert 0.05 < coverage(kd) and stats["bytes_per_point"] > 50  # the wide structure was built
    assert np.mean(np.abs(kd - wide) > 1e-3) < 0.002  # the same discs: last-bit differences only


def test_raw_volume_load_options():
    v = rtfact.load(DATASETS / "volumes" / "tooth_103x94x161_uint8.raw", dims=(103, 94, 161), type="u8",
                    spacing=(1, 1, 2))
    assert v.info()["dims"] == (103, 94, 161)
    assert v.bounds[1][2] == pytest.approx(320.0)


def test_camera_and_fit_camera():
    s = rtfact.load(BUNNY_MESH)
    cam = s.fit_camera(size=(80, 60))
    assert isinstance(cam, rtfact.Camera) and cam.fov == 45
    a = rtfact.render(s, size=(80, 60))
    b = rtfact.render(s, cam, size=(80, 60))
    assert np.array_equal(a, b)
    # An explicit camera looking from the other side sees something else.
    c = rtfact.render(s, rtfact.Camera(eye=tuple(2 * np.array(cam.at) - np.array(cam.eye)), at=cam.at), size=(80, 60))
    assert coverage(c) > 0.1 and not np.array_equal(a, c)
    # eye/at/fov keywords as the CLI's --eye/--at/--fov
    d = rtfact.render(s, size=(80, 60), eye=cam.eye, at=cam.at, fov=45)
    assert np.array_equal(a, d)
    assert "rtfact.Camera(eye=" in repr(cam)


def test_transfer_functions_from_presets_json_and_lists(tmp_path):
    vol = rtfact.load(TOOTH)
    size = (64, 64)
    default = rtfact.render(vol, size=size)
    preset = rtfact.render(vol, size=size, tf="grayscale")
    assert not np.array_equal(default, preset)
    json_file = DATASETS / "volumes" / "phantom_translucent_tf.json"
    from_file = rtfact.render(vol, size=size, tf=str(json_file))
    from_dict = rtfact.render(vol, size=size, tf=json.loads(json_file.read_text()))
    assert np.array_equal(from_file, from_dict)
    rows = [(0.0, 0, 0, 0, 0), (0.3, 1, 0.5, 0, 0.0), (1.0, 1, 1, 1, 0.8)]
    from_list = rtfact.render(vol, size=size, tf=rows)
    assert coverage(from_list) > 0.05
    assert not np.array_equal(from_list, default)
    tf = rtfact.transfer_function(rows)
    assert np.array_equal(rtfact.render(vol, size=size, tf=tf), from_list)
    assert "viridis" in rtfact.presets and rtfact.transfer_function("viridis").name == "viridis"
    # ParaView preset form: a list holding one object with RGBPoints
    pv = [{"Name": "pv", "RGBPoints": [0, 0, 0, 1, 1, 1, 0, 0], "Points": [0, 0, 0.5, 0, 1, 0.6, 0.5, 0]}]
    assert coverage(rtfact.render(vol, size=size, tf=pv[0])) > 0.05


def test_image_helpers_round_trip(tmp_path):
    img = rtfact.render(rtfact.spheres(), size=(48, 32))
    srgb = rtfact.to_srgb8(img)
    assert srgb.shape == (32, 48, 3) and srgb.dtype == np.uint8
    png = tmp_path / "s.png"
    rtfact.save_image(str(png), img)
    back = rtfact.read_image(str(png))
    assert back.shape == (32, 48, 4)
    # The PNG holds exactly to_srgb8's values (the same sRGB curve and rounding).
    assert np.abs(rtfact.to_srgb8(back).astype(int) - srgb.astype(int)).max() <= 1
    exr = tmp_path / "s.exr"
    rtfact.save_image(str(exr), img)
    assert np.allclose(rtfact.read_image(str(exr)), img)


def test_jupyter_display():
    img = rtfact.render(rtfact.spheres(), size=(32, 32))
    png = img._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    scene_png = rtfact.spheres()._repr_png_()
    assert scene_png[:8] == b"\x89PNG\r\n\x1a\n" and len(scene_png) > 1000


def test_quiet_unless_progress_asked(capfd):
    s = rtfact.load(BUNNY_POINTS)
    rtfact.render(s, size=(32, 32))
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_volume_array_is_read_once():
    # The scene owns its bricks: changing the array afterwards does not change the scene.
    a = np.zeros((16, 16, 16), np.uint16)
    a[4:12, 4:12, 4:12] = 1000
    s = rtfact.volume(a)
    before = rtfact.render(s, size=(32, 32))
    a[:] = 0
    assert np.array_equal(rtfact.render(s, size=(32, 32)), before)
    assert coverage(before) > 0.05
