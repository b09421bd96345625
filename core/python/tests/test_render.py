"""Scenes from files rendered to numpy: the golden picture, both pixel formats, every scene
format, images written through the writer plugins and shown by Jupyter."""

import io

import numpy as np
import pytest

import luxon
from conftest import GOLDEN, SCENES, read_png, run_cli


def spheres_64x48(**kw):
    return luxon.load(SCENES / "spheres.ron").render(64, 48, **kw)


def test_spheres_equal_the_golden_picture():
    img = spheres_64x48()
    assert isinstance(img, luxon.Image) and isinstance(img, np.ndarray)
    assert img.shape == (48, 64, 4) and img.dtype == np.uint8
    # Not black, not flat: a sky, a floor and three spheres.
    assert img[..., :3].mean() > 60 and img[..., :3].std() > 20
    assert (img[..., 3] == 255).all()
    # Made by `luxon render scenes/spheres.ron --res 64x48 -o spheres-64x48.png`.
    assert np.array_equal(img, read_png(GOLDEN / "spheres-64x48.png"))


def test_the_module_renders_what_the_command_line_renders(tmp_path):
    out = tmp_path / "cli.png"
    r = run_cli("render", SCENES / "molecule.ron", "--res", "40x30", "-o", out)
    assert r.returncode == 0, r.stderr
    img = luxon.load(SCENES / "molecule.ron").render(40, 30)
    assert np.array_equal(img, read_png(out))


def test_float32_is_linear_and_encodes_to_the_uint8_render():
    scene = luxon.load(SCENES / "spheres.ron")
    lin = scene.render(64, 48, dtype="float32")
    srgb = scene.render(64, 48)
    assert lin.dtype == np.float32 and lin.shape == (48, 64, 4)
    # The PNG writer's curve.
    x = np.clip(lin[..., :3], 0, 1)
    curve = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    diff = np.abs(np.round(curve * 255).astype(int) - srgb[..., :3].astype(int))
    assert diff.max() <= 1 and (diff == 0).mean() > 0.99


def test_thread_counts_give_the_same_pixels():
    scene = luxon.load(SCENES / "spheres.ron")
    one = scene.render(48, 32, threads=1)
    two = scene.render(48, 32, threads=2)
    assert np.array_equal(one, two)


def test_samples_hold_for_one_render_only():
    scene = luxon.load(SCENES / "spheres.ron")
    assert scene._samples() == 4
    one = scene.render(32, 24, samples=1)
    assert scene._samples() == 4
    assert not np.array_equal(one, scene.render(32, 24))
    assert np.array_equal(one, scene.render(32, 24, samples=1))


def test_bad_render_arguments():
    scene = luxon.load(SCENES / "spheres.ron")
    with pytest.raises(ValueError, match="dtype \"float64\""):
        scene.render(8, 8, dtype="float64")
    with pytest.raises(ValueError, match="width and height must be at least 1"):
        scene.render(0, 8)
    with pytest.raises(OverflowError):
        scene.render(-1, 8)


NFF = (
    "v\nfrom 0 -6 2\nat 0 0 0.5\nup 0 0 1\nangle 40\nhither 0.1\nresolution 64 48\n"
    "b 0.2 0.3 0.6\nl 4 -4 6\nf 0.9 0.2 0.2 0.6 0.4 30 0 0\ns 0 0 1 1\n"
)
TACHYON = (
    "BEGIN_SCENE RESOLUTION 24 16\n"
    "CAMERA ZOOM 1 ASPECTRATIO 1 ANTIALIASING 0 RAYDEPTH 4 CENTER 0 0 -6 VIEWDIR 0 0 1 "
    "UPDIR 0 1 0 END_CAMERA\n"
    "LIGHT CENTER 4 5 -6 RAD 0 COLOR 1 1 1\n"
    "SPHERE CENTER -1 0 0 RAD 1 TEXTURE AMBIENT 0.1 DIFFUSE 0.8 SPECULAR 0 OPACITY 1 "
    "COLOR 1 0.2 0.2 TEXFUNC 0\n"
    "END_SCENE\n"
)


@pytest.mark.parametrize(
    "name, text",
    [("ball.nff", NFF), ("ball.dat", TACHYON)],
)
def test_every_scene_format_loads_as_the_command_line_reads_it(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    out = tmp_path / "cli.png"
    r = run_cli("render", path, "--res", "32x24", "-o", out)
    assert r.returncode == 0, r.stderr
    img = luxon.load(path).render(32, 24)
    assert np.array_equal(img, read_png(out))
    assert img[..., :3].std() > 5


def test_obj_and_compressed_nff_load(tmp_path):
    import gzip

    (tmp_path / "ball.nff.gz").write_bytes(gzip.compress(NFF.encode()))
    a = luxon.load(tmp_path / "ball.nff.gz").render(32, 24)
    (tmp_path / "ball.nff").write_text(NFF)
    assert np.array_equal(a, luxon.load(tmp_path / "ball.nff").render(32, 24))
    vase = luxon.load(SCENES / "models" / "vase.obj").render(32, 24)
    assert vase[..., :3].std() > 5


def test_save_writes_through_the_writer_plugins(tmp_path):
    scene = luxon.load(SCENES / "spheres.ron")
    img = scene.render(64, 48)
    scene.save(tmp_path / "last.png")  # the last render
    assert np.array_equal(read_png(tmp_path / "last.png"), img)
    lin = scene.render(64, 48, dtype="float32")
    scene.save(tmp_path / "lin.png", lin)
    assert np.array_equal(read_png(tmp_path / "lin.png"), img)
    img.save(tmp_path / "x.ppm")
    assert (tmp_path / "x.ppm").read_bytes().startswith(b"P6\n64 48\n255\n")
    luxon.write_image(tmp_path / "x.exr", lin)
    assert (tmp_path / "x.exr").read_bytes()[:4] == b"\x76\x2f\x31\x01"


def test_save_refuses_what_is_not_an_image(tmp_path):
    with pytest.raises(ValueError, match=r"expected \(height, width, 4\)"):
        luxon.write_image(tmp_path / "x.png", np.zeros((4, 4, 3), np.uint8))
    with pytest.raises(TypeError, match="float64"):
        luxon.write_image(tmp_path / "x.png", np.zeros((4, 4, 4)))
    with pytest.raises(luxon.LuxonError, match="xyz"):
        luxon.write_image(tmp_path / "x.xyz", np.zeros((4, 4, 4), np.uint8))
    with pytest.raises(ValueError, match="nothing rendered yet"):
        luxon.Scene().save(tmp_path / "x.png")


def test_jupyter_shows_the_image_as_png():
    from PIL import Image as PILImage

    img = spheres_64x48()
    png = img._repr_png_()
    assert png.startswith(b"\x89PNG\r\n\x1a\n")
    assert np.array_equal(np.asarray(PILImage.open(io.BytesIO(png)).convert("RGBA")), img)
    lin = luxon.load(SCENES / "spheres.ron").render(64, 48, dtype="float32")
    assert np.array_equal(np.asarray(PILImage.open(io.BytesIO(lin._repr_png_()))), img)
    # A slice that is no longer an RGBA image falls back to numpy's repr.
    assert img[..., :3]._repr_png_() is None
