"""Luxon, a parallel ray tracer, from Python.

Load a scene file of any format Luxon reads, or build one in code, and render it to a numpy
array::

    import luxon
    scene = luxon.load("scenes/spheres.ron")
    image = scene.render(640, 480, samples=4)       # (480, 640, 4) uint8, sRGB
    scene.save("spheres.png", image)                # through the writer plugins

    s = luxon.Scene()
    s.set_camera(position=(0, 1, -5), look_at=(0, 0.5, 0))
    s.add_light("point", position=(-4, 6, -5))
    s.set_material("red", color=(0.8, 0.1, 0.1), specular=0.5)
    s.add_object("sphere", center=(0, 0.8, 0), radius=0.8, material="red")
    img = s.render(320, 240)                        # displays itself in Jupyter

    atoms = s.spheres(centers, 0.3)                 # (n, 3) numpy array, read in place
    centers += velocities * dt                      # a step of the simulation, in place
    atoms.modified()                                # the next render refits

Errors are exceptions (:class:`LuxonError` and its subclasses) with the command line's
messages (``file:line:col: ...``). See ``help(luxon.Scene)``.
"""

import os

import numpy as np

from . import _luxon
from ._errors import (
    CancelledError,
    FileError,
    LuxonError,
    OutOfMemoryError,
    PluginError,
    SceneError,
    UsageError,
)
from ._image import Image
from ._ron import Ron, Variant, to_ron
from ._scene import ArrayObject, Context, Light, Object, Scene, Volume, default_context

__all__ = [
    "ArrayObject",
    "CancelledError",
    "Context",
    "FileError",
    "Image",
    "Light",
    "LuxonError",
    "Object",
    "OutOfMemoryError",
    "PluginError",
    "Ron",
    "Scene",
    "SceneError",
    "UsageError",
    "Variant",
    "Volume",
    "default_context",
    "load",
    "to_ron",
    "write_image",
]


def load(path, context=None):
    """Loads a scene file of any format Luxon reads (RON ``.ron``, NFF, OBJ, Tachyon, SPD,
    OpenVDB... as ``luxon render`` does) into a :class:`Scene`. Raises :class:`SceneError`
    with the command line's ``file:line:col`` message if it cannot."""
    return Scene(context, os.fspath(path))


def write_image(path, image, context=None):
    """Writes an ``(h, w, 4)`` image (uint8 sRGB or float32 linear RGBA) to ``path`` with the
    writer plugin the extension names (``.png``, ``.exr``, ``.ppm``...). The file appears
    whole or not at all."""
    if context is None:
        context = default_context()
    _luxon.write_image(context, os.fspath(path), np.ascontiguousarray(image).view(np.ndarray))
