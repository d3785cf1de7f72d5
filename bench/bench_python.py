"""rtfact-bench python: the Python module against the CLI for the same renders, and the
zero-copy check of array inputs.

1. Overhead: the same file loaded, built, rendered and written as PNG, by `rtfact` and by
   rtfact.load/render/save_image in one Python process (wall time; interpreter start-up
   and `import rtfact` excluded). The CLI's side is its wall time minus its process
   start-up (dynamic loading of ~300 shared libraries, seconds on a loaded machine),
   measured as the wall time of `rtfact --help` run just before each render. Medians of
   --repeat interleaved runs. Target: Python <= 1.05 x the CLI. For reference, the CLI's
   own --stats (load_ms + prepare_ms + build_ms + render_ms, plus the same PNG write)
   is printed too: it leaves out the framebuffer, the resolve and the default-TF choice,
   so it undercounts the CLI.
2. Arrays: a float32 N x 3 cloud through rtfact.points against the CLI on the same points
   as a PLY (the CLI reads the file, Python copies the array once).
3. Zero-copy: peak RSS growth (VmHWM after /proc/self/clear_refs) while making a scene
   from a uint16 volume and from float32 points, each in a fresh child process with
   glibc's mmap threshold fixed (so large blocks are mapped and unmapped, not recycled),
   against the input's size and what the engine keeps (bricks; the cloud).
"""
import ctypes
import json
import argparse
import os
import pathlib
import platform
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import rtfact

ROOT = pathlib.Path(__file__).resolve().parents[1]


def cpu_name():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def status_kib(key):
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1])
    return 0


def peak_growth_mib(make):
    """Peak RSS growth while `make()` runs (MiB), and its result."""
    with open("/proc/self/clear_refs", "w") as f:  # "5": reset the peak RSS (VmHWM)
        f.write("5")
    before = status_kib("VmRSS")
    result = make()
    return (status_kib("VmHWM") - before) / 1024.0, result


def cli_startup(cli, repeat):
    """Median wall time of `rtfact --help`: exec, dynamic loading, static initialisers."""
    times = []
    for _ in range(repeat + 1):
        t0 = time.perf_counter()
        subprocess.run([cli, "--help"], capture_output=True, check=True)
        times.append(time.perf_counter() - t0)
    return statistics.median(times[1:])


def cli_run(cli, args):
    t0 = time.perf_counter()
    subprocess.run([cli, "--help"], capture_output=True, check=True)
    startup = time.perf_counter() - t0
    t0 = time.perf_counter()
    r = subprocess.run([cli, *args, "--quiet", "--stats"], capture_output=True, text=True)
    wall = time.perf_counter() - t0 - startup
    if r.returncode != 0:
        sys.exit(f"rtfact-bench python: the CLI failed: {r.stderr.strip()}")
    stats = dict(line.split("=", 1) for line in r.stdout.splitlines() if "=" in line)
    engine_ms = sum(float(stats.get(k, 0)) for k in ("load_ms", "prepare_ms", "build_ms", "render_ms"))
    return wall, float(stats.get("render_ms", "nan")), engine_ms


def compare(name, cli_fn, py_fn, repeat, startup):
    cli_fn(), py_fn()  # warm-up: page cache, lazily built tables
    cli, py = [], []
    for _ in range(repeat):  # interleaved, so that load changes on a shared machine hit both
        cli.append(cli_fn())
        py.append(py_fn())
    cw, cr = statistics.median(c[0] for c in cli), statistics.median(c[1] for c in cli)
    pw, pr = statistics.median(p[0] for p in py), statistics.median(p[1] for p in py)
    ce = statistics.median(c[2] + p[2] for c, p in zip(cli, py))  # CLI steps + the same PNG write
    print(f"{name}: cli_ms={cw * 1e3:.1f} python_ms={pw * 1e3:.1f} ratio={pw / cw:.3f} "
          f"(cli --stats steps + png {ce:.1f} ms; engine render_ms: cli {cr:.1f} python {pr:.1f})", flush=True)
    return pw / cw


def zero_copy_child(what, n):
    """In a fresh process: peak RSS growth while making one scene from an array."""
    libc = ctypes.CDLL("libc.so.6")
    libc.mallopt(-3, 1 << 20)  # M_MMAP_THRESHOLD = 1 MiB, fixed: big blocks are mmapped, freed ones unmapped
    rng = np.random.default_rng(1)
    if what == "volume":
        arr = rng.integers(1, 60000, (n, n, n), dtype=np.uint16)  # no all-zero bricks
        make = lambda: rtfact.volume(arr)  # noqa: E731
    else:
        d = rng.normal(size=(n, 3))
        arr = (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)
        make = lambda: rtfact.points(arr)  # noqa: E731
    rtfact.volume(np.ones((4, 4, 4), np.uint8)) if what == "volume" else rtfact.points(arr[:10])  # warm-up
    grown, scene = peak_growth_mib(make)
    kept = scene.info().get("memory_mb", 0.0)
    print(json.dumps({"input_mib": arr.nbytes / 2 ** 20, "grown_mib": grown, "kept_mib": kept}))


def zero_copy(what, n):
    r = subprocess.run([sys.executable, __file__, "--zero-copy-child", what, str(n)], capture_output=True, text=True,
                       check=True)
    return json.loads(r.stdout)


def main():
    ap = argparse.ArgumentParser(prog="rtfact-bench python", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=os.environ.get("RTFACT_CLI", "rtfact"))
    ap.add_argument("--size", default="1024x1024")
    ap.add_argument("--spp", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--points", type=int, default=1_000_000, help="points of the array benchmark")
    ap.add_argument("--voxels", type=int, default=256, help="edge of the uint16 volume of the zero-copy check")
    ap.add_argument("files", nargs="*", help="files to render (default: the bundled mesh, cloud and volume)")
    ap.add_argument("--zero-copy-child", nargs=2, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.zero_copy_child:
        return zero_copy_child(a.zero_copy_child[0], int(a.zero_copy_child[1]))
    w, h = map(int, a.size.split("x"))
    files = a.files or [str(ROOT / "datasets/meshes/bunny.ply"), str(ROOT / "datasets/points/bunny_bun000.ply"),
                        str(ROOT / "datasets/volumes/tooth_103x94x161_uint8.mhd")]
    print(f"cpu={cpu_name()} threads={os.cpu_count()} python={platform.python_version()} numpy={np.__version__}")
    startup = cli_startup(a.cli, a.repeat)
    print(f"cli_startup_ms={startup * 1e3:.1f} (rtfact --help, median; subtracted run by run)")
    ratios = []
    with tempfile.TemporaryDirectory() as tmp:
        for f in files:
            kind = rtfact.load(f).kind
            cli_out, py_out = f"{tmp}/cli.png", f"{tmp}/py.png"

            def cli_fn():
                return cli_run(a.cli, [kind, f, "-o", cli_out, "--size", a.size, "--spp", str(a.spp)])

            def py_fn():
                t0 = time.perf_counter()
                img, st = rtfact.render(rtfact.load(f), size=(w, h), spp=a.spp, stats=True)
                t1 = time.perf_counter()
                rtfact.save_image(py_out, img)
                t2 = time.perf_counter()
                return t2 - t0, float(st["render_ms"]), (t2 - t1) * 1e3

            ratios.append(compare(f"file {pathlib.Path(f).name} ({kind})", cli_fn, py_fn, a.repeat, startup))

        rng = np.random.default_rng(1)
        d = rng.normal(size=(a.points, 3))
        xyz = (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)
        ply = f"{tmp}/sphere.ply"
        radius = 2.0 / np.sqrt(a.points)  # about the spacing of N points on the unit sphere
        # Unit-sphere points with their normals (= positions) and one radius, so that neither
        # side spends the time on normal or spacing estimation.
        rec = np.zeros(a.points, dtype=[(c, "<f4") for c in ("x", "y", "z", "nx", "ny", "nz")])
        rec["x"], rec["y"], rec["z"] = xyz.T
        rec["nx"], rec["ny"], rec["nz"] = xyz.T
        with open(ply, "wb") as fh:
            props = "".join(f"property float {c}\n" for c in ("x", "y", "z", "nx", "ny", "nz"))
            fh.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {a.points}\n{props}end_header\n".encode())
            fh.write(rec.tobytes())

        def cli_arr():
            return cli_run(a.cli, ["points", ply, "-o", f"{tmp}/c.png", "--size", a.size, "--spp", str(a.spp),
                                   "--radius", str(radius)])

        def py_arr():
            t0 = time.perf_counter()
            img, st = rtfact.render(rtfact.points(xyz, normals=xyz), size=(w, h), spp=a.spp, radius=radius, stats=True)
            t1 = time.perf_counter()
            rtfact.save_image(f"{tmp}/p.png", img)
            t2 = time.perf_counter()
            return t2 - t0, float(st["render_ms"]), (t2 - t1) * 1e3

        ratios.append(compare(f"array {a.points} float32 points vs PLY", cli_arr, py_arr, a.repeat, startup))

    v = zero_copy("volume", a.voxels)
    extra = v["grown_mib"] - v["kept_mib"]
    print(f"zero-copy volume uint16 {a.voxels}^3: input_mib={v['input_mib']:.1f} peak_growth_mib={v['grown_mib']:.1f} "
          f"bricks_mib={v['kept_mib']:.1f} extra_mib={extra:.1f} "
          f"-> {'no copy' if extra < 0.25 * v['input_mib'] else 'A COPY'} of the input")
    p = zero_copy("points", a.points)
    print(f"points float32 {a.points}: input_mib={p['input_mib']:.1f} peak_growth_mib={p['grown_mib']:.1f} "
          f"-> {p['grown_mib'] / p['input_mib']:.2f} x the input (the engine's cloud: one copy of the positions)")
    print(f"python_over_cli_max_ratio={max(ratios):.3f} target<=1.05 {'ok' if max(ratios) <= 1.05 else 'EXCEEDED'}")


if __name__ == "__main__":
    main()
