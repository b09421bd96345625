"""``luxon.Scene``, ``luxon.Context`` and the handles of a scene's lights and objects."""

import os
import threading

import numpy as np

from . import _luxon
from ._image import Image
from ._ron import text as _text, to_ron

_PLUGINS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "plugins")


class Context(_luxon.Context):
    """The plugins Luxon found and the thread pool its loads, builds and renders run on.

    ``Context(threads=0, plugin_path=())``: ``threads`` is the pool's size (0: every CPU this
    process may use); plugins are searched in ``plugin_path``, then ``$LUXON_PLUGIN_PATH``,
    then the plugins installed with this package. Most programs never make one: scenes made
    without a context share :func:`luxon.default_context`.

    ``plugins()`` lists what was found as ``(kind, name, library)``, ``searched()`` the places
    looked in, ``problems()`` the files that could not be used and why.
    """

    def __new__(cls, threads=0, plugin_path=()):
        if isinstance(plugin_path, (str, os.PathLike)):
            plugin_path = [plugin_path]
        path = [os.fspath(p) for p in plugin_path]
        env = os.environ.get("LUXON_PLUGIN_PATH", "")
        path += [p for p in env.split(os.pathsep) if p]
        if os.path.isdir(_PLUGINS):
            path.append(_PLUGINS)
        return super().__new__(cls, threads, path)

    def __repr__(self):
        return f"<luxon.Context: {self.threads} threads, {len(self.plugins())} plugins>"


_default = None
_default_lock = threading.Lock()


def default_context():
    """The context of scenes made without one (made at first use: every CPU, the default
    plugin path)."""
    global _default
    with _default_lock:
        if _default is None:
            _default = Context()
        return _default


class Light:
    """A light of a scene (from :meth:`Scene.add_light` or :attr:`Scene.lights`)."""

    __slots__ = ("scene", "id")

    def __init__(self, scene, id):
        self.scene = scene
        self.id = id

    def set(self, kind, /, **params):
        """Replaces the light, as :meth:`Scene.add_light` describes one."""
        self.scene._set_light_ron(self.id, _light_text(kind, params))

    def remove(self):
        """Removes the light from its scene; the handle is refused from then on."""
        self.scene._remove_light(self.id)

    def __eq__(self, other):
        return isinstance(other, Light) and self.id == other.id

    def __hash__(self):
        return hash(self.id)

    def __repr__(self):
        return f"<luxon.Light {self.id!r}>"


class Object:
    """An object of a scene (from :meth:`Scene.add_object` or :attr:`Scene.objects`)."""

    __slots__ = ("scene", "id")

    def __init__(self, scene, id):
        self.scene = scene
        self.id = id

    def remove(self):
        """Removes the object; the next render builds the scene again."""
        self.scene._remove_object(self.id)

    def __eq__(self, other):
        return isinstance(other, Object) and self.id == other.id

    def __hash__(self):
        return hash(self.id)

    def __repr__(self):
        return f"<luxon.Object {self.id!r}>"


class ArrayObject(Object):
    """Spheres, cylinders or a mesh read from numpy arrays (from :meth:`Scene.spheres`,
    :meth:`Scene.cylinders` or :meth:`Scene.mesh`).

    Zero-copy arrays are read where they are at every commit and render, so a simulation can
    write them in place between renders and call :meth:`modified`; :meth:`update` gives the
    object other arrays. Never write an array while a render that reads it runs (in another
    Python thread, say).
    """

    __slots__ = ("kind", "arrays", "options")

    def __init__(self, scene, id, kind, arrays, options):
        super().__init__(scene, id)
        self.kind = kind
        #: The arrays the object reads now (after ``copy=True``, Luxon's copies), by name.
        self.arrays = arrays
        self.options = options

    def update(self, *, copy=None, **arrays):
        """Replaces some of the object's arrays, keeping the others: ``update(centers=new)``,
        ``update(radii=0.2)``. ``copy`` defaults to the object's. The object's BVH is built
        again at the next commit (its size may change)."""
        unknown = set(arrays) - set(_ARRAY_ARGS[self.kind])
        if unknown:
            raise TypeError(
                f"{self.kind}.update: unknown array {sorted(unknown)[0]!r}; "
                f"expected {', '.join(_ARRAY_ARGS[self.kind])}"
            )
        if copy is None:
            copy = self.options["copy"]
        merged = {**self.arrays, **arrays}
        self.arrays = _make_object(self.scene, self.kind, merged, {**self.options, "copy": copy}, self.id)

    def modified(self):
        """Tells Luxon the object's arrays were written in place: the next commit (or render)
        reads them again and refits the object's BVH (or builds it again when a refit would
        make it slow, or a mesh's indices changed)."""
        self.scene._modified(self.id)

    def __repr__(self):
        first = self.arrays[_ARRAY_ARGS[self.kind][0]]
        return f"<luxon.ArrayObject {self.kind} {self.id!r}: {len(first)} rows>"


# The array arguments of each kind, first the one that counts the rows.
_ARRAY_ARGS = {
    "spheres": ("centers", "radii", "colors"),
    "cylinders": ("a", "b", "radii"),
    "mesh": ("vertices", "indices", "normals", "colors", "uvs"),
}


def _copied(a, name):
    """``copy=True``: a packed copy of ``a`` of a dtype Luxon reads (float arrays keep float32,
    everything else real becomes float64; indices uint32 or uint64)."""
    if a is None:
        return None
    if name == "radii" and np.ndim(a) == 0:
        return float(a)
    a = np.asarray(a)
    if name == "indices":
        if a.size and a.min() < 0:
            raise ValueError("mesh: indices: negative vertex indices")
        dtype = np.uint32 if a.size == 0 or a.max() < 2**32 else np.uint64
    elif name == "uvs":
        dtype = np.float32
    else:
        dtype = np.float32 if a.dtype == np.float32 else np.float64
    return np.array(a, dtype=dtype, order="C", copy=True)


def _make_object(scene, kind, arrays, options, id=None):
    """Adds (or with ``id`` replaces) an array object; returns the arrays it reads."""
    if options["copy"]:
        arrays = {k: _copied(v, k) for k, v in arrays.items()}
    idx = arrays.get("indices")
    if isinstance(idx, np.ndarray) and idx.dtype.kind == "i" and idx.size and idx.min() < 0:
        raise ValueError("mesh: indices: negative vertex indices")
    material = options.get("material")
    if kind == "spheres":
        made = scene._spheres(arrays["centers"], arrays["radii"], arrays["colors"], material, id)
    elif kind == "cylinders":
        made = scene._cylinders(
            arrays["a"], arrays["b"], arrays["radii"], options["caps"], material, id
        )
    else:
        made = scene._mesh(
            arrays["vertices"],
            arrays["indices"],
            arrays["normals"],
            arrays["colors"],
            arrays["uvs"],
            material,
            id,
        )
    if id is None:
        return ArrayObject(scene, made, kind, arrays, options)
    return arrays


class Volume(Object):
    """A volume from a numpy array (from :meth:`Scene.volume`)."""

    __slots__ = ("values", "options")

    def __init__(self, scene, id, values, options):
        super().__init__(scene, id)
        self.values = values
        self.options = options

    def update(self, values=None, **options):
        """Replaces the voxels and/or options (``spacing``, ``origin``, ``order``,
        ``normalize``, ``render``) of the volume; read at the next commit."""
        if "render" in options:
            r = options.pop("render")
            options["look"] = r if isinstance(r, str) else _text(None, r or {}, "volume render")
        opts = {**self.options, **options}
        if values is None:
            values = self.values
        _make_volume(self.scene, values, opts, self.id)
        self.values, self.options = values, opts

    def modified(self):
        """Tells Luxon the voxels were written in place: the next commit reads them again."""
        self.scene._modified(self.id)

    def __repr__(self):
        return f"<luxon.Volume {self.id!r}: {np.shape(self.values)}>"


def _make_volume(scene, values, o, id=None):
    return scene._volume(
        values,
        o["order"],
        [float(c) for c in o["origin"]],
        [float(c) for c in o["spacing"]],
        bool(o["normalize"]),
        o["name"],
        o["look"],
        id,
    )


def _light_text(kind, params):
    if not isinstance(kind, str):
        raise TypeError(f"light kind: expected a str, not {type(kind).__name__}")
    if not params and "(" in kind:
        return kind
    fields = ", ".join(f"{k}: {to_ron(v)}" for k, v in params.items())
    return f"{kind[:1].upper()}{kind[1:]}({fields})"


_UNSET = object()


class Scene(_luxon.Scene):
    """A scene kept between renders: loaded from a file (:func:`luxon.load`) or built in code,
    changed in place, and rendered to numpy arrays.

    ``Scene(context=None)`` is an empty scene: no camera until :meth:`set_camera`, no lights
    or objects, the default material, a black background, the default render settings.

    Every setter takes either RON text, exactly as in a scene file, or keyword arguments that
    are written as RON for you (tuples are vectors, lists are lists, dicts are structs;
    :class:`luxon.Variant` and :class:`luxon.Ron` cover enums and raw text)::

        s = luxon.Scene()
        s.set_camera(position=(0, 1, -5), look_at=(0, 0.5, 0), fov=40)
        s.set_camera("(position: (0, 1, -5), look_at: (0, 0.5, 0), fov: 40)")  # the same

    Errors in that text raise :class:`luxon.SceneError` pointing into it
    (``<camera>:1:2: unknown field ...``). A render commits the scene first: changing the
    camera, lights, materials, background, fog or render settings costs microseconds, adding
    or removing objects builds the scene again once (see :meth:`commit`).
    """

    def __new__(cls, context=None, _path=None):
        if context is None:
            context = default_context()
        return super().__new__(cls, context, _path)

    # --- camera and settings ------------------------------------------------------------

    def set_camera(self, ron=None, /, **fields):
        """The camera: ``position``, ``look_at``, and optionally ``up``, ``fov`` (degrees),
        ``projection``... as the scene files' ``camera:`` field."""
        self._set_camera_ron(_text(ron, fields, "camera"))

    def set_render(self, ron=None, /, **fields):
        """The render settings (``samples``, ``max_depth``, ``transparency``...), as the scene
        files' ``render:`` field. They replace the scene's: a field not given takes its
        default. The image size is the render's, and ``outputs`` are ignored (use
        :meth:`save`)."""
        self._set_render_ron(_text(ron, fields, "render settings"))

    def set_background(self, r, g=None, b=None):
        """The colour of rays that hit nothing: ``set_background(0.1, 0.2, 0.4)`` or
        ``set_background((0.1, 0.2, 0.4))`` (linear RGB)."""
        rgb = tuple(r) if g is None and b is None else (r, g, b)
        self._set_background([float(c) for c in rgb])

    def set_origin(self, world=None):
        """Render space's origin in world coordinates (None: the camera's position at the
        first build). See the Rust API's ``Scene::set_origin``."""
        self._set_origin(None if world is None else [float(c) for c in world])

    def set_fog(self, ron=_UNSET, /, **fields):
        """Fog, as the scene files' ``fog:`` field: ``set_fog(mode=luxon.Variant("Exp",
        density=0.05), color=(0.2, 0.3, 0.6))``; ``set_fog(None)`` clears it."""
        if ron is None and not fields:
            return self._set_fog_ron(None)
        self._set_fog_ron(_text(None if ron is _UNSET else ron, fields, "fog"))

    def set_ambient_occlusion(self, ron=_UNSET, /, **fields):
        """Ambient occlusion, as the scene files' ``ambient_occlusion:`` field
        (``samples``, ``distance``, ``intensity``...); ``set_ambient_occlusion(None)`` turns it
        off."""
        if ron is None and not fields:
            return self._set_ambient_occlusion_ron(None)
        self._set_ambient_occlusion_ron(
            _text(None if ron is _UNSET else ron, fields, "ambient occlusion")
        )

    # --- lights, materials, objects -----------------------------------------------------

    def add_light(self, kind, /, **params):
        """Adds a light and returns its handle: ``add_light("point", position=(4, -4, 6),
        intensity=0.8)``, or the RON text ``add_light("Point(position: (4, -4, 6))")``.
        Kinds are the scene files' (``Point``, ``Directional``, ``Spot``...)."""
        return Light(self, self._add_light_ron(_light_text(kind, params)))

    @property
    def lights(self):
        """The scene's lights, in order (a loaded scene's in file order)."""
        return [Light(self, i) for i in self._lights()]

    def set_material(self, name, ron=None, /, **fields):
        """Defines or replaces the material ``name`` (``color``, ``diffuse``, ``specular``,
        ``transmit``, ``texture``...): ``set_material("red", color=(0.8, 0.1, 0.1))``.
        Returns ``name``, to pass as an object's ``material``."""
        self._set_material_ron(name, _text(ron, fields, f"material {name!r}"))
        return name

    def set_texture(self, name, plugin, params=None, /, **fields):
        """Defines or replaces the texture ``name`` made by the texture plugin ``plugin``
        (``checker``, ``image``, or one of your own such as examples/stripes) from its
        parameters as RON text, a dict or keyword arguments: ``set_texture("bands",
        "stripes", width=0.1, axis=(1, 0, 0))``. Materials wear it by name
        (``set_material("wall", texture="bands")``). The plugin reads the parameters at once:
        a bad one raises :class:`luxon.SceneError` pointing into them (``<texture>:1:9:
        ...``). The next render builds the scene again. Returns ``name``."""
        if isinstance(params, dict):
            if fields:
                raise TypeError("set_texture: give params or keyword arguments, not both")
            params, fields = None, params
        self._set_texture(name, plugin, _text(params, fields, f"texture {name!r}"))
        return name

    def set_clip_group(self, name, planes):
        """Defines or replaces the clip group ``name``: objects (``add_object(...,
        clip=name)``) and volumes (``render`` with ``clip=name``) in it lose what lies on the
        side a plane's normal points to. ``planes``: a list of ``(point, normal)`` pairs or
        ``dict(point=..., normal=...)``, or the RON text of a scene file's group:
        ``set_clip_group("half", [((0, 0, 0), (1, 0, 0))])``. Returns ``name``."""
        if not isinstance(planes, str):
            rows = []
            for p in planes:
                if not isinstance(p, dict):
                    point, normal = p
                    p = dict(point=tuple(point), normal=tuple(normal))
                rows.append(p)
            planes = to_ron(rows)
        self._set_clip_group_ron(name, planes)
        return name

    def add_volume(self, plugin, params=None, /, *, name=None, render=None, **fields):
        """Adds a volume read by the volume reader plugin ``plugin`` (``raw``, ``vdb``),
        from its parameters as RON text, a dict or keyword arguments, as a scene file's
        ``volumes`` give them: ``add_volume("raw", file="head.raw", dims=(256, 256, 109),
        name="head", render=dict(transfer=dict(preset="grayscale")))``. ``render``: how it is
        drawn (RON text or a dict; None: data only, not drawn). The plugin reads the file at
        the next render or commit. Returns the volume's :class:`Object` handle (for
        :meth:`Object.remove`). For a volume in a numpy array, see :meth:`volume`."""
        if isinstance(params, dict):
            if fields:
                raise TypeError("add_volume: give params or keyword arguments, not both")
            params, fields = None, params
        look = render
        if isinstance(render, dict):
            look = _text(None, render, "volume render")
        return Object(
            self, self._add_plugin_volume(plugin, _text(params, fields, plugin), name, look)
        )

    def has_material(self, name):
        """Whether the scene has a material called ``name`` (``default`` always)."""
        return self._has_material(name)

    def add_object(self, plugin, params=None, /, *, material=None, clip=None, **fields):
        """Adds an object made by the primitive plugin ``plugin`` (``sphere``, ``spheres``,
        ``cylinder``, ``plane``, ``mesh``... or any plugin of your own), from its parameters
        as RON text (``params``, what follows ``params:`` in a scene file), a dict, or keyword
        arguments: ``add_object("sphere", center=(0, 0.8, 0), radius=0.8,
        material="red")``. The plugin reads them at the next render or commit, and its errors
        point into them (``<object 0>:1:9: ...``). Returns the object's handle."""
        if isinstance(params, dict):
            if fields:
                raise TypeError("add_object: give params or keyword arguments, not both")
            params, fields = None, params
        return Object(self, self._add_plugin_object(plugin, _text(params, fields, plugin), material, clip))

    @property
    def objects(self):
        """The scene's objects made by plugins or from arrays, in order (imported geometry
        has no handle)."""
        return [Object(self, i) for i in self._objects()]

    # --- objects read from numpy arrays -------------------------------------------------
    #
    # Zero-copy: a numpy array of a dtype Luxon reads, rows side by side (C order, or a row
    # slice such as atoms[:, :3]), is read in place; the scene keeps a reference to it.

    def spheres(self, centers, radii, *, colors=None, material=None, copy=False):
        """Adds spheres read from numpy arrays and returns their :class:`ArrayObject`.

        ``centers``: ``(n, 3)`` float32 or float64 (world coordinates). ``radii``: one number
        for all, or ``(n,)`` float32/float64. ``colors``: optional ``(n, 3)`` linear RGB
        replacing the material's colour per sphere. ``material``: a name from
        :meth:`set_material` (default: ``"default"``).

        With ``copy=False`` (the default) the arrays are read in place, never copied: write
        them between renders and call :meth:`ArrayObject.modified`. An array Luxon cannot
        read in place raises ``TypeError`` (its dtype) or ``ValueError`` (its shape, its
        layout or its length); ``copy=True`` converts and copies anything array-like instead
        (the originals may then change freely)."""
        return _make_object(
            self,
            "spheres",
            {"centers": centers, "radii": radii, "colors": colors},
            {"material": material, "copy": copy},
        )

    def cylinders(self, a, b, radii, *, caps=True, material=None, copy=False):
        """Adds cylinders from ``a[i]`` to ``b[i]`` (both ``(n, 3)`` float32/float64) of
        ``radii`` (a number or ``(n,)``), closed by discs unless ``caps=False``, and returns
        their :class:`ArrayObject`. Arrays as in :meth:`spheres` (zero-copy unless
        ``copy=True``)."""
        return _make_object(
            self,
            "cylinders",
            {"a": a, "b": b, "radii": radii},
            {"material": material, "copy": copy, "caps": caps},
        )

    def mesh(
        self, vertices, indices=None, *, normals=None, colors=None, uvs=None, material=None,
        copy=False,
    ):
        """Adds a triangle mesh and returns its :class:`ArrayObject`.

        ``vertices``: ``(n, 3)`` float32/float64. ``indices``: ``(m, 3)`` uint32, int32,
        uint64 or int64 vertex numbers per triangle (``None``: every three vertices make
        one). Optional per-vertex ``normals`` and ``colors`` (linear RGB) ``(n, 3)``
        float32/float64, ``uvs`` ``(n, 2)`` float32. Arrays as in :meth:`spheres`
        (zero-copy unless ``copy=True``). After writing the vertices in place call
        :meth:`ArrayObject.modified` (a refit); new indices build the BVH again."""
        return _make_object(
            self,
            "mesh",
            {
                "vertices": vertices,
                "indices": indices,
                "normals": normals,
                "colors": colors,
                "uvs": uvs,
            },
            {"material": material, "copy": copy},
        )

    # --- volumes from 3-D arrays --------------------------------------------------------

    def volume(
        self, values, spacing=(1.0, 1.0, 1.0), origin=(0.0, 0.0, 0.0), *, order="zyx",
        normalize=True, name=None, render=None, copy=False, **render_fields,
    ):
        """Adds a volume from a 3-D numpy array and returns its :class:`Volume`.

        ``values``: float32, float64, uint8 or uint16, indexed ``values[z, y, x]``
        (``order="zyx"``, a C array of slices as a raw file holds them) or ``values[x, y, z]``
        (``order="xyz"``, as nibabel gives them); any strides (slices, transposes) are read as
        they are. Voxel ``(i, j, k)`` lies at ``origin + (i, j, k) * spacing`` (world units).
        Integer voxels are divided by 255 or 65535 unless ``normalize=False``.

        ``render``: how it is drawn, the RON text or dict a scene file's volume has after
        ``render:`` (``transfer``, ``step``, ``shading``...), or keyword arguments:
        ``volume(mri, spacing, transfer=dict(preset="viridis"), step=0.01)``; by default the
        ``grayscale`` preset.

        The array is referenced, not copied, but read only at commits: Luxon copies it into
        its bricks at the next commit, and again at the first commit after
        :meth:`Volume.modified`; between commits it may be written freely. ``copy=True``
        converts any array-like first (to float32 unless it is one of the types above)."""
        if copy:
            a = np.asarray(values)
            if a.dtype not in (np.float32, np.float64, np.uint8, np.uint16):
                a = a.astype(np.float32)
            values = np.array(a, order="C", copy=True)
        if isinstance(render, dict):
            render_fields = {**render, **render_fields}
            render = None
        if render is None and not render_fields:
            render = '(transfer: (preset: "grayscale"))'
        look = _text(render, render_fields, "volume render")
        options = dict(spacing=spacing, origin=origin, order=order, normalize=normalize, name=name, look=look)
        return Volume(self, _make_volume(self, values, options), values, options)

    # --- building, rendering, saving ----------------------------------------------------

    def commit(self):
        """Brings the built scene up to date now (a render does it anyway) and says what it
        did: ``{"rebuilt": 0 or 1, "shading": bool, "bvh_seconds": ..., "commit_seconds":
        ...}``. Useful to build outside a timed render, or to see a plugin's error early."""
        return self._commit()

    def render(self, width, height, *, samples=None, threads=None, dtype="uint8", progress=None):
        """Renders the scene at ``width`` x ``height`` and returns an :class:`luxon.Image`, a
        numpy array of shape ``(height, width, 4)``: ``dtype="uint8"`` (sRGB, the bytes a PNG
        holds) or ``"float32"`` (linear RGBA, as an EXR holds).

        ``samples``: samples per pixel for this render (default: the scene's setting).
        ``threads``: render threads (default: the context's pool; 0: every CPU).
        ``progress``: called as ``progress(done_pixels, total_pixels)`` on this thread about
        ten times a second and once at the end; if it raises, the render is cancelled and the
        exception propagates.

        The GIL is released while rendering (other Python threads run), and Ctrl-C
        (``KeyboardInterrupt``) stops the render within a tile per thread; the scene stays
        usable. Same pixels, bit for bit, as ``luxon render`` at that size and for any thread
        count.
        """
        image = self._render(width, height, samples, threads, dtype, progress).view(Image)
        self._last = image
        return image

    def save(self, path, image=None):
        """Writes ``image`` (default: the last render) to ``path`` with the writer plugin the
        extension names (``.png``, ``.exr``, ``.ppm``...)."""
        if image is None:
            image = getattr(self, "_last", None)
            if image is None:
                raise ValueError("save: nothing rendered yet; give the image or call render first")
        from . import write_image

        write_image(path, image, context=self.context)

    def to_ron(self):
        """The scene as a RON scene file (what ``luxon convert`` writes): for a bug report, or
        to render it with the command line."""
        return self._to_ron()

    def __repr__(self):
        return (
            f"<luxon.Scene: {len(self._lights())} lights, {len(self._objects())} objects>"
        )
