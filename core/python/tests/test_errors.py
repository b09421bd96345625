"""Errors as Python exceptions with the command line's messages; no panic reaches Python."""

import pydoc
from pathlib import Path

import pytest

import luxon
from conftest import run_cli

BAD = """Scene(
    camera: (position: (0, 0, -5), look_at: (0, 0, 0)),
    lights: [Point(positon: (0, 4, -4))],
    objects: [],
)
"""


def cli_message(*args, cwd=None):
    r = run_cli(*args, cwd=cwd)
    assert r.returncode != 0
    line = r.stderr.strip().splitlines()[-1]
    assert line.startswith("luxon: error: "), r.stderr
    return line[len("luxon: error: "):]


def test_a_bad_scene_file_raises_the_command_lines_message(tmp_path):
    (tmp_path / "bad.ron").write_text(BAD)
    with pytest.raises(luxon.SceneError) as e:
        luxon.load(tmp_path / "bad.ron")
    assert (e.value.line, e.value.column) == (3, 20)
    assert Path(e.value.file) == tmp_path / "bad.ron"
    assert "unknown field `positon`" in str(e.value)
    assert str(e.value) == cli_message("render", tmp_path / "bad.ron", "-o", tmp_path / "x.png")


def test_a_missing_file_says_so(tmp_path):
    with pytest.raises(luxon.SceneError) as e:
        luxon.load(tmp_path / "nope.ron")
    assert e.value.line is None and e.value.file == str(tmp_path / "nope.ron")
    assert str(e.value) == cli_message("render", tmp_path / "nope.ron")
    with pytest.raises(luxon.SceneError, match="unsupported scene file extension `.txt`"):
        luxon.load(tmp_path / "scene.txt")


def test_text_given_to_a_method_is_pointed_into():
    s = luxon.Scene()
    with pytest.raises(luxon.SceneError) as e:
        s.set_camera(positon=(0, 0, 5), look_at=(0, 0, 0))
    assert (e.value.file, e.value.line, e.value.column) == ("<camera>", 1, 2)
    assert str(e.value).startswith("<camera>:1:2: unknown field `positon`")
    with pytest.raises(luxon.SceneError, match=r"^<light>:1:7: unknown field `positon`"):
        s.add_light("Point(positon: (0, 0, 5))")


def test_plugin_errors_point_into_the_objects_parameters():
    s = luxon.Scene()
    s.set_camera(position=(0, 0, -5), look_at=(0, 0, 0))
    s.add_object("sphere", center=(0, 0, 0), radius=-1)
    with pytest.raises(luxon.SceneError) as e:
        s.commit()
    assert e.value.file == "<object 0>" and e.value.line == 1
    with pytest.raises(luxon.UsageError, match="spherez"):
        s.add_object("spherez", center=(0, 0, 0))
    with pytest.raises(ValueError, match="no material named `gold`"):
        s.add_object("sphere", center=(0, 0, 0), radius=1, material="gold")


def test_a_scene_without_a_camera_is_refused():
    with pytest.raises(luxon.LuxonError, match="camera"):
        luxon.Scene().render(8, 8)


def test_bad_values_are_refused_before_luxon_sees_them():
    s = luxon.Scene()
    with pytest.raises(luxon.UsageError, match="background"):
        s.set_background(-1, 0, 0)
    with pytest.raises(TypeError, match="not both"):
        s.set_camera("(position: (0, 0, 5), look_at: (0, 0, 0))", fov=30)
    with pytest.raises(TypeError, match="must be a str"):
        s.set_render(42)


def test_every_exception_is_a_luxon_error():
    for name in ("SceneError", "PluginError", "CancelledError", "UsageError", "FileError",
                 "OutOfMemoryError"):
        assert issubclass(getattr(luxon, name), luxon.LuxonError)
    assert issubclass(luxon.UsageError, ValueError)
    assert issubclass(luxon.FileError, OSError)


def test_help_documents_the_scene():
    text = pydoc.render_doc(luxon.Scene, renderer=pydoc.plaintext)
    for word in ("render(self, width, height", "add_light", "set_camera", "add_object",
                 "KeyboardInterrupt", "SceneError", "save", "spheres(self, centers, radii",
                 "cylinders(self, a, b, radii", "mesh(self, vertices, indices", "copy=True",
                 "modified", "volume(self, values, spacing"):
        assert word in text, word
    stub = (Path(luxon.__file__).parent / "__init__.pyi").read_text()
    for name in luxon.__all__:
        assert name in stub, name
