# Type hints of the `luxon` package (the compiled part, luxon._luxon, has none of its own).
from os import PathLike
from typing import Any, Callable, Literal, Sequence, TypedDict, Union, overload

import numpy as np
import numpy.typing as npt

_Path = Union[str, PathLike[str]]
_Vec3 = Union[Sequence[float], npt.NDArray[np.floating[Any]]]
# Arrays read in place: (n, 3) float32/float64 rows, (n,) radii, (m, 3) integer indices.
_Rows = npt.NDArray[np.floating[Any]]
_Radii = Union[float, npt.NDArray[np.floating[Any]]]
_Indices = npt.NDArray[np.integer[Any]]

__all__ = [
    "CancelledError",
    "ArrayObject",
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

class LuxonError(Exception): ...

class SceneError(LuxonError):
    file: str | None
    line: int | None
    column: int | None

class PluginError(LuxonError): ...
class CancelledError(LuxonError): ...
class UsageError(LuxonError, ValueError): ...

class FileError(LuxonError, OSError):
    file: str | None
    line: int | None
    column: int | None

class OutOfMemoryError(LuxonError, MemoryError): ...

class Ron:
    text: str
    def __init__(self, text: str) -> None: ...

class Variant:
    name: str
    fields: dict[str, Any]
    def __init__(self, name: str, **fields: Any) -> None: ...

def to_ron(value: Any) -> str: ...

class Image(np.ndarray):
    def _repr_png_(self) -> bytes | None: ...
    def save(self, path: _Path, context: Context | None = None) -> None: ...

class Context:
    def __new__(
        cls, threads: int = 0, plugin_path: _Path | Sequence[_Path] = ()
    ) -> Context: ...
    @property
    def threads(self) -> int: ...
    def plugins(self) -> list[tuple[str, str, str]]: ...
    def searched(self) -> list[str]: ...
    def problems(self) -> list[tuple[str, str]]: ...

def default_context() -> Context: ...

class Light:
    scene: Scene
    def set(self, kind: str, /, **params: Any) -> None: ...
    def remove(self) -> None: ...

class Object:
    scene: Scene
    def remove(self) -> None: ...

class ArrayObject(Object):
    kind: Literal["spheres", "cylinders", "mesh"]
    arrays: dict[str, Any]
    options: dict[str, Any]
    def update(self, *, copy: bool | None = None, **arrays: Any) -> None: ...
    def modified(self) -> None: ...

class Volume(Object):
    values: npt.NDArray[Any]
    options: dict[str, Any]
    def update(self, values: npt.NDArray[Any] | None = None, **options: Any) -> None: ...
    def modified(self) -> None: ...

class CommitReport(TypedDict):
    rebuilt: int
    refitted: int
    degraded: int
    volumes_read: int
    shading: bool
    bvh_seconds: float
    commit_seconds: float

class Scene:
    def __new__(cls, context: Context | None = None) -> Scene: ...
    @property
    def context(self) -> Context: ...
    def set_camera(self, ron: str | None = None, /, **fields: Any) -> None: ...
    def set_render(self, ron: str | None = None, /, **fields: Any) -> None: ...
    @overload
    def set_background(self, r: _Vec3) -> None: ...
    @overload
    def set_background(self, r: float, g: float, b: float) -> None: ...
    def set_origin(self, world: _Vec3 | None = None) -> None: ...
    def set_fog(self, ron: str | None = ..., /, **fields: Any) -> None: ...
    def set_ambient_occlusion(self, ron: str | None = ..., /, **fields: Any) -> None: ...
    def add_light(self, kind: str, /, **params: Any) -> Light: ...
    @property
    def lights(self) -> list[Light]: ...
    def set_material(self, name: str, ron: str | None = None, /, **fields: Any) -> str: ...
    def has_material(self, name: str) -> bool: ...
    def set_texture(
        self, name: str, plugin: str, params: str | dict[str, Any] | None = None, /, **fields: Any
    ) -> str:
        """Defines or replaces the texture ``name`` made by the texture plugin ``plugin``
        (``checker``, ``image``, or your own, e.g. examples/stripes) from its parameters (RON
        text, a dict or keyword arguments); materials wear it by name. Bad parameters raise
        ``SceneError`` at once (``<texture>:line:col: ...``). Returns ``name``."""
    def set_clip_group(
        self, name: str, planes: str | Sequence[tuple[_Vec3, _Vec3] | dict[str, _Vec3]]
    ) -> str:
        """Defines or replaces the clip group ``name``: ``(point, normal)`` planes (or RON
        text); what lies on the side a normal points to is cut from the objects and volumes
        that name the group. Returns ``name``."""
    def add_volume(
        self,
        plugin: str,
        params: str | dict[str, Any] | None = None,
        /,
        *,
        name: str | None = None,
        render: str | dict[str, Any] | None = None,
        **fields: Any,
    ) -> Object:
        """Adds a volume read by the reader plugin ``plugin`` (``raw``, ``vdb``) from its
        parameters, drawn as ``render`` says (None: data only). Returns its handle."""
    def add_object(
        self,
        plugin: str,
        params: str | dict[str, Any] | None = None,
        /,
        *,
        material: str | None = None,
        clip: str | None = None,
        **fields: Any,
    ) -> Object: ...
    @property
    def objects(self) -> list[Object]: ...
    def spheres(
        self,
        centers: _Rows,
        radii: _Radii,
        *,
        colors: _Rows | None = None,
        material: str | None = None,
        copy: bool = False,
    ) -> ArrayObject: ...
    def cylinders(
        self,
        a: _Rows,
        b: _Rows,
        radii: _Radii,
        *,
        caps: bool = True,
        material: str | None = None,
        copy: bool = False,
    ) -> ArrayObject: ...
    def mesh(
        self,
        vertices: _Rows,
        indices: _Indices | None = None,
        *,
        normals: _Rows | None = None,
        colors: _Rows | None = None,
        uvs: npt.NDArray[np.float32] | None = None,
        material: str | None = None,
        copy: bool = False,
    ) -> ArrayObject: ...
    def volume(
        self,
        values: npt.NDArray[Any],
        spacing: _Vec3 = (1.0, 1.0, 1.0),
        origin: _Vec3 = (0.0, 0.0, 0.0),
        *,
        order: Literal["zyx", "xyz"] = "zyx",
        normalize: bool = True,
        name: str | None = None,
        render: str | dict[str, Any] | None = None,
        copy: bool = False,
        **render_fields: Any,
    ) -> Volume: ...
    def commit(self) -> CommitReport: ...
    @overload
    def render(
        self,
        width: int,
        height: int,
        *,
        samples: int | None = None,
        threads: int | None = None,
        dtype: Literal["uint8"] = "uint8",
        progress: Callable[[int, int], object] | None = None,
    ) -> Image: ...
    @overload
    def render(
        self,
        width: int,
        height: int,
        *,
        samples: int | None = None,
        threads: int | None = None,
        dtype: Literal["float32"],
        progress: Callable[[int, int], object] | None = None,
    ) -> Image: ...
    def save(self, path: _Path, image: npt.NDArray[Any] | None = None) -> None: ...
    def to_ron(self) -> str: ...

def load(path: _Path, context: Context | None = None) -> Scene: ...
def write_image(path: _Path, image: npt.NDArray[Any], context: Context | None = None) -> None: ...
