"""Scenes built and changed in code: camera, lights with handles, materials, background,
render settings, fog and ambient occlusion, plugin objects by name (custom ones too)."""

import numpy as np
import pytest

import luxon
from conftest import plugin_dir_with


def ball_scene(context=None):
    s = luxon.Scene(context)
    s.set_camera(position=(0, 1, -5), look_at=(0, 0.5, 0), fov=40)
    s.set_background(0.2, 0.3, 0.5)
    lamp = s.add_light("point", position=(-4, 6, -5))
    s.set_material("red", color=(0.8, 0.1, 0.1), specular=0.5)
    s.add_object("sphere", center=(0, 0.8, 0), radius=0.8, material="red")
    s.add_object("plane", "(point: (0, 0, 0), normal: (0, 1, 0))")
    return s, lamp


def test_a_scene_built_in_code_renders():
    s, _ = ball_scene()
    img = s.render(64, 48)
    r, g, b = img[24, 32, :3].astype(int)  # the red ball
    assert r > 100 and r > 2 * g and r > 2 * b
    assert tuple(img[0, 0, :3]) == tuple(
        np.round(255 * (1.055 * np.array([0.2, 0.3, 0.5]) ** (1 / 2.4) - 0.055)).astype(np.uint8)
    )


def test_keywords_and_ron_text_are_the_same_scene():
    a, _ = ball_scene()
    b = luxon.Scene()
    b.set_camera("(position: (0, 1, -5), look_at: (0, 0.5, 0), fov: 40)")
    b.set_background((0.2, 0.3, 0.5))
    b.add_light("Point(position: (-4, 6, -5))")
    b.set_material("red", "(color: (0.8, 0.1, 0.1), specular: 0.5)")
    b.add_object("sphere", {"center": (0, 0.8, 0), "radius": 0.8}, material="red")
    b.add_object("plane", point=np.array([0.0, 0, 0]), normal=(0, 1, 0))
    assert np.array_equal(a.render(48, 32), b.render(48, 32))


def test_to_ron_writes_a_scene_the_loader_renders_the_same(tmp_path):
    s, _ = ball_scene()
    path = tmp_path / "dump.ron"
    path.write_text(s.to_ron())
    assert np.array_equal(s.render(40, 30), luxon.load(path).render(40, 30))


def test_changes_between_renders_touch_only_what_they_need():
    s, lamp = ball_scene()
    assert s.commit()["rebuilt"] == 1
    first = s.render(48, 32)
    s.set_camera(position=(2, 1.5, -4), look_at=(0, 0.5, 0))
    lamp.set("point", position=(4, 6, -5), intensity=0.7)
    fill = s.add_light("directional", direction=(0, -1, 1), intensity=0.3)
    s.set_material("red", color=(0.1, 0.3, 0.9))
    report = s.commit()
    assert report["rebuilt"] == 0 and report["shading"] is True
    assert not np.array_equal(first, s.render(48, 32))
    assert s.lights == [lamp, fill]
    ball = s.objects[0]
    ball.remove()
    assert s.commit()["rebuilt"] == 1 and len(s.objects) == 1


def test_removed_handles_are_refused():
    s, lamp = ball_scene()
    lamp.remove()
    with pytest.raises(luxon.UsageError, match="^light 0 was removed from this scene$"):
        lamp.remove()
    other, _ = ball_scene()
    with pytest.raises(luxon.UsageError, match="another scene"):
        s._set_light_ron(other.lights[0].id, "Point(position: (0, 0, 0))")


def test_fog_and_ambient_occlusion_come_and_go():
    s, _ = ball_scene()
    clear = s.render(40, 30)
    s.set_fog(mode=luxon.Variant("Exp", density=0.2), color=(0.5, 0.5, 0.5))
    foggy = s.render(40, 30)
    assert not np.array_equal(clear, foggy)
    s.set_fog(None)
    assert np.array_equal(clear, s.render(40, 30))
    s.set_ambient_occlusion(samples=4, distance=2.0)
    assert not np.array_equal(clear, s.render(40, 30))
    s.set_ambient_occlusion(None)
    assert np.array_equal(clear, s.render(40, 30))


def test_render_settings_replace_the_scenes():
    s, _ = ball_scene()
    s.set_render(samples=1, max_depth=2)
    assert s._samples() == 1
    s.set_render("(samples: 3)")
    assert s._samples() == 3


def test_a_custom_primitive_written_in_rust_works_unchanged():
    # examples/torus: the SDK's example of a primitive plugin of one's own.
    ctx = luxon.Context(threads=2, plugin_path=[plugin_dir_with("libluxon_torus.so")])
    assert ("primitive", "torus") in [(k, n) for k, n, _ in ctx.plugins()]
    s = luxon.Scene(ctx)
    s.set_camera(position=(0, 3, -4), look_at=(0, 0, 0))
    s.add_light("point", position=(-3, 5, -4))
    s.set_material("gold", color=(0.9, 0.7, 0.2))
    s.add_object("torus", center=(0, 0, 0), major=1.0, minor=0.35, material="gold")
    img = s.render(48, 36)
    r, g, b = img[18, 14, :3].astype(int)  # the ring's left side
    assert r > b + 40
    assert (img[18, 24, :3] == 0).all()  # the hole in its middle: the black background


def test_contexts_say_what_they_found():
    ctx = luxon.default_context()
    names = {n for _, n, _ in ctx.plugins()}
    assert {"sphere", "spheres", "cylinder", "plane", "checker", "png", "exr"} <= names
    assert ctx.threads >= 1 and luxon.Context(threads=3).threads == 3
    assert "plugins" in repr(ctx)


def test_ron_of_python_values():
    assert luxon.to_ron({"a": (1, 2.5), "b": [True, None], "c": 'x"y'}) == (
        '(a: (1, 2.5), b: [true, None], c: "x\\"y")'
    )
    assert luxon.to_ron(np.array([[1, 2], [3, 4]], np.float32)) == "[(1.0, 2.0), (3.0, 4.0)]"
    assert luxon.to_ron(luxon.Variant("Off")) == "Off"
    with pytest.raises(ValueError, match="finite"):
        luxon.to_ron(float("nan"))
    with pytest.raises(TypeError, match="cannot be written as RON"):
        luxon.to_ron(object())
