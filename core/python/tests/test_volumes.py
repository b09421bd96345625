"""Volumes from 3-D numpy arrays: a Gaussian renders bit for bit as the same voxels written to
a raw file and read by the `raw` volume plugin, in either axis order and through strided
views; dtype and shape errors; writes in place read again after modified()."""

import importlib.util

import numpy as np
import pytest

import luxon
from conftest import REPO

LOOK = (
    "(transfer: (points: [(x: 0.0, color: (0.1, 0.2, 0.8), opacity: 0), "
    "(x: 0.3, color: (0.9, 0.6, 0.2), opacity: 8), (x: 1.0, color: (1.0, 1.0, 0.9), opacity: 40)], "
    "range: (0, 1)), shading: (ambient: 0.3, diffuse: 0.8, specular: 0.2, shininess: 20))"
)
N = (20, 24, 28)  # x, y, z voxels
SPACING = (0.1, 0.08, 0.07)
ORIGIN = (-1.0, -0.9, -0.95)
CAMERA = "(position: (2.2, -3.0, 1.6), look_at: (0, 0, 0), up: (0, 0, 1), fov: 40)"


def gaussian():
    """values[z, y, x]: an anisotropic Gaussian blob, off centre (so axis mix-ups show)."""
    nx, ny, nz = N
    z, y, x = np.meshgrid(
        np.arange(nz) - 0.4 * nz, np.arange(ny) - 0.5 * ny, np.arange(nx) - 0.6 * nx, indexing="ij"
    )
    g = np.exp(-(x**2 / 30.0 + y**2 / 60.0 + z**2 / 90.0))
    return g.astype(np.float32)


def scene():
    s = luxon.Scene()
    s.set_camera(CAMERA)
    s.set_background(0.02, 0.02, 0.05)
    s.add_light("Point(position: (3, -5, 4))")
    return s


def raw_scene(tmp_path, g):
    path = tmp_path / "g.raw"
    g.tofile(path)
    text = f"""Scene(
        camera: {CAMERA},
        background: (0.02, 0.02, 0.05),
        lights: [Point(position: (3, -5, 4))],
        volumes: [(
            plugin: "raw", name: "g",
            params: (file: "{path}", dims: {N}, format: "f32", spacing: {SPACING}, origin: {ORIGIN}),
            render: {LOOK},
        )],
    )"""
    (tmp_path / "g.ron").write_text(text)
    return luxon.load(tmp_path / "g.ron")


def test_a_numpy_volume_renders_as_the_raw_file(tmp_path):
    g = gaussian()
    want = raw_scene(tmp_path, g).render(64, 48)
    assert len(np.unique(want[..., 0])) > 10, "the volume is seen"

    s = scene()
    v = s.volume(g, SPACING, ORIGIN, name="g", render=LOOK)
    assert np.array_equal(s.render(64, 48), want)

    # values[x, y, z] (a transposed view, read through its strides) and a Fortran copy.
    for values in (g.T, np.asfortranarray(g.T)):
        t = scene()
        t.volume(values, SPACING, ORIGIN, order="xyz", name="g", render=LOOK)
        assert np.array_equal(t.render(64, 48), want)

    # A slice of a larger array, read in place.
    big = np.zeros((N[2] + 4, N[1] + 2, N[0] + 6), np.float32)
    big[2:-2, 1:-1, 3:-3] = g
    t = scene()
    t.volume(big[2:-2, 1:-1, 3:-3], SPACING, ORIGIN, name="g", render=LOOK)
    assert np.array_equal(t.render(64, 48), want)

    # Written in place, then modified(): read again.
    g *= 0.5
    v.modified()
    half = s.render(64, 48)
    assert not np.array_equal(half, want)
    assert np.array_equal(half, raw_scene(tmp_path, g).render(64, 48))


def test_volume_errors():
    s = scene()
    with pytest.raises(TypeError, match=r"^volume: values: an array of dtype int64; expected float32"):
        s.volume(np.zeros((4, 4, 4), np.int64))
    with pytest.raises(ValueError, match=r"^volume: values: an array of shape \(4, 4\); expected three"):
        s.volume(np.zeros((4, 4), np.float32))
    with pytest.raises(ValueError, match="order"):
        s.volume(np.zeros((4, 4, 4), np.float32), order="yxz")
    with pytest.raises(luxon.SceneError, match="<volume_render>"):
        s.volume(np.zeros((4, 4, 4), np.float32), render="(transfer: (pionts: []))")
    v = s.volume(np.zeros((4, 4, 4), np.int64), copy=True)
    assert v.values.dtype == np.float32
    assert s.commit()["volumes_read"] == 1
    v.update(render="(transfer: (preset: \"ct-bone\"))", spacing=(0.5, 0.5, 0.5))
    report = s.commit()
    assert report["volumes_read"] == 1 and report["rebuilt"] == 0
    v.remove()
    assert s.objects == []


def test_the_mri_example_renders_as_the_scene_file(tmp_path):
    # The example reads ../shared/volumes with numpy; scenes/mri-head.ron the same file
    # through the raw plugin, drawn alike.
    path = REPO / "examples" / "python" / "mri.py"
    spec = importlib.util.spec_from_file_location("mri", path)
    m = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(m)
    if not m.DATA.is_file():
        pytest.skip(f"{m.DATA} not found (the shared volumes beside the checkout)")
    out = tmp_path / "mri.png"
    s = m.main(["--size", "48x48", "--out", str(out)])
    assert out.stat().st_size > 500
    want = luxon.load(REPO / "scenes" / "mri-head.ron").render(48, 48)
    assert np.array_equal(s.render(48, 48), want)
    assert len(np.unique(want[..., 0])) > 10
