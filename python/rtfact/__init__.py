"""RTfact from Python: CPU ray tracing of point clouds, meshes and volumes.

Numpy arrays in, numpy images out, no window, X server or GPU::

    import numpy as np, rtfact
    scene = rtfact.points(np.random.rand(100000, 3).astype(np.float32))
    img = rtfact.render(scene, size=(512, 512))      # (512, 512, 4) float32 linear RGBA
    rtfact.save_image("cloud.png", img)

Settings are the CLI's option names with underscores (``rtfact points --radius-factor 2``
is ``radius_factor=2``). Errors: ValueError for bad arrays and settings, TypeError for
unknown setting names, rtfact.Error (an OSError) for files. See docs/python.md.
"""
import numpy as _np

from . import _rtfact
from ._rtfact import (Camera, Error, Scene, TransferFunction, info, load, mesh, points, presets, read_image,
                      save_image, spheres, to_srgb8, transfer_function, volume)

__all__ = ["Camera", "Error", "Image", "Scene", "TransferFunction", "info", "load", "mesh", "points", "presets",
           "read_image", "render", "save_image", "spheres", "to_srgb8", "transfer_function", "volume"]


class Image(_np.ndarray):
    """An (h, w, 4) float32 linear RGBA image: a numpy array that shows itself in Jupyter."""

    def _repr_png_(self):
        a = _np.asarray(self)
        if a.ndim != 3 or a.shape[2] not in (3, 4):
            return None
        return _rtfact._png_bytes(a)


def render(scene, camera=None, **settings):
    """Renders `scene` and returns an Image ((h, w, 4) float32 linear RGBA, row 0 at the top).

    camera: an rtfact.Camera, or None for the scene's default view (eye/at/up/fov=
    override it as the CLI's --eye/--at/--up/--fov do). Common settings: size=(w, h)
    (default 1024 x 1024), spp=1, threads=0 (all cores), packet, progress=False,
    stats=False (True: returns (image, stats dict) with render_ms etc.). Per kind, the
    options of its CLI subcommand: points (integrator, color, lod, lod_quality, normals,
    radius, radius_factor, leaf_size, ao_samples), mesh (integrator, light, material, bvh,
    ao_samples, max_depth, secondary), volume (tf, mode, iso, step, window, level, clip,
    no_skip, no_adaptive_steps, preintegrated). The GIL is released while rendering.
    """
    out = _rtfact.render(scene, camera, **settings)
    if isinstance(out, tuple):
        return out[0].view(Image), out[1]
    return out.view(Image)


def _scene_png(scene):
    return _rtfact._png_bytes(_rtfact.render(scene, size=(384, 384)))


Scene._repr_png_ = _scene_png
