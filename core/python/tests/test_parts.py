"""Textures, clip groups and plugin volumes defined from Python, starting from an empty
scene; and the memory budget refusing what arrays would make too big."""

import numpy as np
import pytest

import luxon
from conftest import plugin_dir_with

A = (0.9, 0.8, 0.1)
B = (0.1, 0.1, 0.4)


def srgb8(rgb):
    c = np.array(rgb)
    return np.round(255 * np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055))


def stripes_context():
    # examples/stripes: a texture plugin written in Rust, built by `cargo build`.
    return luxon.Context(threads=2, plugin_path=[plugin_dir_with("libluxon_stripes.so")])


def wall_scene(context, width):
    """An empty scene given a camera facing a wall in stripes across x, lit by ambient light
    only (each pixel is a stripe's colour)."""
    s = luxon.Scene(context)
    s.set_camera(position=(0, 0, 5), look_at=(0, 0, 0), fov=40)
    s.add_light("point", position=(2, 3, 6))
    s.set_texture("bands", "stripes", a=A, b=B, width=width, axis=(1, 0, 0), filter=False)
    s.set_material("wall", texture="bands", ambient=1, diffuse=0, specular=0)
    s.add_object("plane", point=(0, 0, 0), normal=(0, 0, 1), material="wall")
    return s


def runs(row):
    """The runs of equal pixels along a row of RGBA pixels."""
    changes = np.any(row[1:] != row[:-1], axis=1)
    return 1 + int(changes.sum())


def test_a_texture_plugin_from_python_paints_stripes():
    s = wall_scene(stripes_context(), 0.4)
    img = s.render(64, 48)
    # Stripes across x: every column is one colour, the colours are the plugin's two, and
    # they alternate along a row, a stripe every few pixels.
    assert (img == img[:1]).all()
    row = img[24, :, :3].astype(int)
    colours = {tuple(c) for c in row}
    assert colours == {tuple(srgb8(A).astype(int)), tuple(srgb8(B).astype(int))}
    coarse = runs(img[24])
    assert coarse >= 8
    starts = [0] + [x for x in range(1, 64) if (row[x] != row[x - 1]).any()]
    inner = np.diff(starts)[1:]  # whole stripes (the first may be cut by the edge)
    assert inner.max() - inner.min() <= 1, "stripes of one width"

    # A replaced texture shows at the next render: half the width, twice the stripes.
    s.set_texture("bands", "stripes", f"(a: {A}, b: {B}, width: 0.2, filter: false)")
    assert s.commit()["rebuilt"] == 1
    fine = s.render(64, 48)
    assert runs(fine[24]) >= 2 * coarse - 2


def test_texture_errors_point_into_the_parameters():
    s = luxon.Scene(stripes_context())
    with pytest.raises(luxon.SceneError, match=r"^<texture>:1:\d+: .*widht") as e:
        s.set_texture("t", "stripes", widht=0.1)
    assert e.value.file == "<texture>" and e.value.line == 1
    with pytest.raises(luxon.SceneError, match="width"):
        s.set_texture("t", "stripes", dict(width=-1.0))
    with pytest.raises(luxon.LuxonError, match="no-such-texture"):
        s.set_texture("t", "no-such-texture")
    with pytest.raises(luxon.SceneError, match="no texture named `t`"):
        s.set_material("m", texture="t")


def test_a_clip_group_cuts_a_ball_in_half():
    s = luxon.Scene()
    s.set_camera(position=(0, 0, 5), look_at=(0, 0, 0), fov=40)
    s.add_light("point", position=(2, 3, 6))
    s.set_material("red", color=(0.8, 0.1, 0.1))
    assert s.set_clip_group("half", [((0, 0, 0), (1, 0, 0))]) == "half"
    s.add_object("sphere", center=(0, 0, 0), radius=1.2, material="red", clip="half")
    img = s.render(64, 48)
    # +x (the right of the picture) is cut away: background there, the ball on the left.
    assert (img[24, 40, :3] == 0).all()
    assert img[24, 24, 0] > 100
    s.set_clip_group("half", "[(point: (0, 0, 0), normal: (-1, 0, 0))]")
    img = s.render(64, 48)
    assert (img[24, 24, :3] == 0).all() and img[24, 40, 0] > 100
    with pytest.raises(luxon.SceneError, match=r"^<clip_planes>:1:\d+: .*zero length"):
        s.set_clip_group("bad", [((0, 0, 0), (0, 0, 0))])


def blob(n=16):
    i = np.arange(n) - (n - 1) / 2
    z, y, x = np.meshgrid(i, i, i, indexing="ij")
    return np.exp(-(x * x + y * y + z * z) / 20).astype(np.float32)


def test_a_volume_read_by_its_plugin_renders_as_the_same_array(tmp_path):
    values = blob()
    path = tmp_path / "blob.raw"
    values.tofile(path)
    look = dict(transfer=dict(preset="hot"), step=0.05)
    grid = dict(origin=(-1, -1, -1), spacing=(0.125, 0.125, 0.125))

    def scene():
        s = luxon.Scene()
        s.set_camera(position=(2, 1.5, 4), look_at=(0, 0, 0), fov=40)
        return s

    s = scene()
    empty = s.render(48, 32)
    v = s.add_volume("raw", file=str(path), dims=(16, 16, 16), format="f32", name="blob",
                     render=look, **grid)
    got = s.render(48, 32)
    assert not np.array_equal(got, empty)
    same = scene()
    same.volume(values, grid["spacing"], grid["origin"], name="blob", render=look)
    assert np.array_equal(same.render(48, 32), got)

    with pytest.raises(luxon.LuxonError, match="no-such-reader"):
        s.add_volume("no-such-reader", "()")
    v.remove()
    assert np.array_equal(s.render(48, 32), empty)


def test_a_small_memory_budget_refuses_big_arrays_with_a_message():
    s = luxon.Scene()
    s.set_camera(position=(0, 0, 30), look_at=(0, 0, 0))
    s.set_render(memory="1 MiB")
    centers = np.zeros((100_000, 3))
    centers[:, 0] = np.arange(100_000) * 1e-3
    big = s.spheres(centers, 0.01)
    with pytest.raises(luxon.LuxonError, match=r"BVH of object 0 \(spheres\).*memory budget"):
        s.commit()
    big.remove()
    s.volume(np.random.default_rng(1).random((96, 96, 96), dtype=np.float32))
    with pytest.raises(luxon.LuxonError, match=r"^volume `object \d+` .*memory budget of 1 MiB"):
        s.commit()
