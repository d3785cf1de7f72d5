"""The GIL is released while rendering (a Python thread keeps running), and repeated
renders do not leak."""
import threading
import time

import numpy as np

import rtfact


def render_beside_a_ticking_thread(scene, spp):
    """Renders on a worker thread while this one ticks every 2 ms; returns (t0, t1, ticks)."""
    done = threading.Event()
    span = {}

    def work():
        t0 = time.monotonic()
        rtfact.render(scene, size=(320, 320), spp=spp, threads=1, step=0.25)
        span["t"] = (t0, time.monotonic())
        done.set()

    ticks = []
    t = threading.Thread(target=work)
    t.start()
    while not done.is_set():
        ticks.append(time.monotonic())
        time.sleep(0.002)
    t.join()
    return span["t"][0], span["t"][1], ticks


def test_python_thread_runs_during_render():
    z, y, x = np.mgrid[-1:1:96j, -1:1:96j, -1:1:96j]
    vol = (np.exp(-2 * (x ** 2 + y ** 2 + z ** 2)) * 60000).astype(np.uint16)
    scene = rtfact.volume(vol)
    # The render must last long enough to tell a held GIL from a released one; how long a
    # given spp takes depends on the CPU and the kernel, so double spp until it does.
    spp = 12
    while True:
        t0, t1, ticks = render_beside_a_ticking_thread(scene, spp)
        duration = t1 - t0
        if duration > 0.3 or spp >= 12 * 64:
            break
        spp *= 2
    assert duration > 0.2, f"render too short ({duration:.3f} s at spp {spp}) to tell"
    inside = [s for s in ticks if t0 <= s <= t1]
    gaps = np.diff([t0] + inside + [t1])
    # With the GIL held by the render, this thread would stop for the whole render.
    assert len(inside) >= 10 and gaps.max() < 0.5 * duration, (len(inside), gaps.max(), duration)


def rss_kib():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise RuntimeError("no VmRSS")


def test_200_renders_do_not_grow_memory():
    rng = np.random.default_rng(5)
    xyz = rng.random((3000, 3), dtype=np.float32)
    normals = np.tile(np.array([[0, 0, 1]], np.float32), (3000, 1))  # given: no normal estimation per scene
    size = (128, 128)  # 256 KiB per image: 200 leaked images would be 50 MiB
    volume = rtfact.volume(rng.integers(0, 4000, (24, 24, 24), dtype=np.uint16))

    def once(i):
        s = rtfact.points(xyz, normals=normals, radius=0.01)  # a new scene each time: arrays in, build, render
        img = rtfact.render(s, size=size)
        assert img.shape == (128, 128, 4)
        rtfact.render(volume, size=size, tf="viridis")

    for i in range(20):  # warm-up: allocator pools, TBB threads, lazily built tables
        once(i)
    before = rss_kib()
    for i in range(200):
        once(i)
    grown = rss_kib() - before
    # Bound: 16 MiB (a leak of the images or the scenes would add >= 50 MiB).
    assert grown < 16 * 1024, f"RSS grew by {grown} KiB over 200 renders"
