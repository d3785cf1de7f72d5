"""numpy in == file in: a scene made from arrays renders the image the CLI renders from
the same data written to a file (same default camera, image-regression tolerance)."""
import numpy as np
import pytest

import rtfact
from conftest import assert_images_match, coverage, write_ply

SIZE = (160, 120)


def cloud(n=20000, seed=3):
    """Points on a wavy sphere with colours from position (a closed surface with structure)."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    r = 1.0 + 0.15 * np.sin(5 * d[:, 0]) * np.cos(4 * d[:, 1])
    xyz = (d * r[:, None]).astype(np.float32)
    colors = ((d * 0.5 + 0.5) * 255).astype(np.uint8)
    return xyz, colors


@pytest.mark.parametrize("integrator", ["eyelight", "direct"])
def test_numpy_points_equal_cli_ply(tmp_path, cli, integrator):
    xyz, colors = cloud()
    ply = tmp_path / "cloud.ply"
    write_ply(ply, xyz, colors)
    out = tmp_path / "cli.exr"
    cli("points", ply, "-o", out, "--size", f"{SIZE[0]}x{SIZE[1]}", "--integrator", integrator)
    expected = rtfact.read_image(str(out))
    img = rtfact.render(rtfact.points(xyz, colors=colors), size=SIZE, integrator=integrator)
    assert img.shape == (SIZE[1], SIZE[0], 4) and img.dtype == np.float32
    assert coverage(img) > 0.05
    assert_images_match(img, expected, f"points_{integrator}", tmp_path)


def test_float64_and_strided_points_equal_float32(tmp_path):
    xyz, colors = cloud(5000)
    a = rtfact.render(rtfact.points(xyz, colors=colors), size=SIZE)
    b = rtfact.render(rtfact.points(xyz.astype(np.float64), colors=colors / 255.0), size=SIZE)
    wide = np.zeros((len(xyz), 6), dtype=np.float32)
    wide[:, ::2] = xyz
    c = rtfact.render(rtfact.points(wide[:, ::2], colors=colors), size=SIZE)  # strided view, no copy made by us
    assert coverage(a) > 0.05
    assert np.array_equal(a, b)
    assert np.array_equal(a, c)


def blob_volume(dtype, nx=40, ny=36, nz=30):
    """A smooth blob with an off-centre hole, indexed [z, y, x], in the range of `dtype`."""
    z, y, x = np.meshgrid(np.linspace(-1, 1, nz), np.linspace(-1, 1, ny), np.linspace(-1, 1, nx), indexing="ij")
    v = np.exp(-3 * (x ** 2 + 1.5 * y ** 2 + 2 * z ** 2)) - 0.6 * np.exp(-20 * ((x - 0.3) ** 2 + y ** 2 + z ** 2))
    v = np.clip(v, 0, None)
    if dtype == np.float32:
        return (v * 100).astype(np.float32)
    if dtype == np.int16:
        return (v * 3000 - 1000).astype(np.int16)
    return (v * np.iinfo(dtype).max).astype(dtype)


TYPES = {np.uint8: "u8", np.uint16: "u16", np.int16: "i16", np.float32: "f32"}


@pytest.mark.parametrize("dtype", list(TYPES))
def test_volume_c_and_fortran_order_equal_cli_raw(tmp_path, cli, dtype):
    vol = blob_volume(dtype)  # [z, y, x], C order: the raw file's layout (x fastest)
    nz, ny, nx = vol.shape
    raw = tmp_path / "blob.raw"
    vol.tofile(raw)
    out = tmp_path / "cli.exr"
    cli("volume", raw, "--dims", f"{nx},{ny},{nz}", "--type", TYPES[dtype], "--spacing", "1,1.5,2", "-o", out,
        "--size", f"{SIZE[0]}x{SIZE[1]}", "--tf", "viridis")
    expected = rtfact.read_image(str(out))
    c_order = rtfact.render(rtfact.volume(vol, spacing=(1, 1.5, 2)), size=SIZE, tf="viridis")
    fortran = np.asfortranarray(vol.transpose())  # [x, y, z], the same bytes in Fortran order
    assert fortran.flags.f_contiguous and fortran.shape == (nx, ny, nz)
    f_order = rtfact.render(rtfact.volume(fortran, spacing=(1, 1.5, 2), order="xyz"), size=SIZE, tf="viridis")
    assert coverage(expected) > 0.05
    assert_images_match(c_order, expected, f"volume_c_{TYPES[dtype]}", tmp_path)
    assert_images_match(f_order, expected, f"volume_f_{TYPES[dtype]}", tmp_path)
    # The same voxels in the same bricks: the images are identical, not just close.
    assert np.array_equal(c_order, f_order)


def test_volume_info_matches_file(tmp_path):
    vol = blob_volume(np.uint16)
    s = rtfact.volume(vol, spacing=(1, 1.5, 2), origin=(5, 0, 0))
    i = s.info()
    assert i["kind"] == "volume"
    assert i["dims"] == (40, 36, 30)
    assert i["voxels"] == vol.size
    assert i["range"] == (float(vol.min()), float(vol.max()))
    assert s.bounds == ((5.0, 0.0, 0.0), (44.0, 52.5, 58.0))


def test_numpy_mesh_equals_cli_ply(tmp_path, cli):
    # A closed, lumpy octahedron-sphere: vertices and faces written as an ASCII PLY.
    t = np.linspace(0, np.pi, 24)
    p = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    T, P = np.meshgrid(t, p, indexing="ij")
    r = 1 + 0.1 * np.cos(6 * P) * np.sin(T)
    v = np.stack([r * np.sin(T) * np.cos(P), r * np.cos(T), r * np.sin(T) * np.sin(P)], -1).reshape(-1, 3)
    faces = []
    for i in range(len(t) - 1):
        for j in range(len(p)):
            a, b = i * len(p) + j, i * len(p) + (j + 1) % len(p)
            c, d = a + len(p), b + len(p)
            faces += [(a, c, b), (b, c, d)]
    faces = np.array(faces, dtype=np.int64)
    ply = tmp_path / "mesh.ply"
    with open(ply, "w") as f:
        f.write(f"ply\nformat ascii 1.0\nelement vertex {len(v)}\nproperty float x\nproperty float y\n"
                f"property float z\nelement face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
        for x in v.astype(np.float32):
            f.write(f"{x[0]!r} {x[1]!r} {x[2]!r}\n")
        for fc in faces:
            f.write(f"3 {fc[0]} {fc[1]} {fc[2]}\n")
    out = tmp_path / "cli.exr"
    cli("mesh", ply, "-o", out, "--size", f"{SIZE[0]}x{SIZE[1]}")
    expected = rtfact.read_image(str(out))
    img = rtfact.render(rtfact.mesh(v.astype(np.float32), faces), size=SIZE)
    assert coverage(img) > 0.05
    assert_images_match(img, expected, "mesh", tmp_path)


def test_volume_no_adaptive_steps_equals_cli(tmp_path, cli):
    """no_adaptive_steps=True is the CLI's --no-adaptive-steps: the plain march."""
    # The blob inside a homogeneous box: the scene takes long steps only where at least 30%
    # of the shown sub-bricks allow them (the box's inside does; the blob alone falls short).
    vol = blob_volume(np.uint8) // 2
    vol[3:27, 3:33, 3:37] = np.maximum(vol[3:27, 3:33, 3:37], 60)
    nz, ny, nx = vol.shape
    raw = tmp_path / "blob.raw"
    vol.tofile(raw)
    out = tmp_path / "plain.exr"
    cli("volume", raw, "--dims", f"{nx},{ny},{nz}", "--type", "u8", "-o", out, "--size", f"{SIZE[0]}x{SIZE[1]}",
        "--tf", "viridis", "--no-adaptive-steps")
    expected = rtfact.read_image(str(out))
    scene = rtfact.volume(vol)
    plain = rtfact.render(scene, size=SIZE, tf="viridis", no_adaptive_steps=True)
    adaptive = rtfact.render(scene, size=SIZE, tf="viridis")
    assert coverage(expected) > 0.05
    assert_images_match(plain, expected, "volume_plain_march", tmp_path)
    assert not np.array_equal(plain, adaptive), "the switch changed nothing: longer steps were expected"


def test_volume_preintegrated_equals_cli(tmp_path, cli):
    """preintegrated=True is the CLI's --preintegrated, and it changes the picture."""
    vol = blob_volume(np.uint8)
    nz, ny, nx = vol.shape
    raw = tmp_path / "blob.raw"
    vol.tofile(raw)
    out = tmp_path / "pre.exr"
    cli("volume", raw, "--dims", f"{nx},{ny},{nz}", "--type", "u8", "-o", out, "--size", f"{SIZE[0]}x{SIZE[1]}",
        "--tf", "viridis", "--step", "2", "--preintegrated")
    expected = rtfact.read_image(str(out))
    scene = rtfact.volume(vol)
    pre = rtfact.render(scene, size=SIZE, tf="viridis", step=2, preintegrated=True)
    plain = rtfact.render(scene, size=SIZE, tf="viridis", step=2)
    assert coverage(expected) > 0.05
    assert_images_match(pre, expected, "volume_preintegrated", tmp_path)
    assert not np.array_equal(pre, plain), "the switch changed nothing"
