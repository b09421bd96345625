"""Spheres, cylinders and meshes from numpy arrays: read in place (no copy of a 1 M-sphere
array), refused with TypeError/ValueError when they cannot be, refitted after writes in
place, replaced, kept alive by the scene; a molecule from arrays renders as the same molecule
written as a RON scene file."""

import gc
import importlib.util
import tracemalloc

import numpy as np
import pytest

import luxon
from conftest import REPO


def base_scene():
    s = luxon.Scene()
    s.set_camera(position=(7, 5, 9), look_at=(0, 0, 0), up=(0, 1, 0))
    s.add_light("point", position=(10, 12, 6))
    s.set_background(0.1, 0.15, 0.3)
    s.set_material("clay", color=(0.8, 0.4, 0.2), specular=0.4)
    return s


def cloud(n, seed=1):
    rng = np.random.default_rng(seed)
    centers = rng.uniform(-2, 2, size=(n, 3))
    radii = rng.uniform(0.04, 0.1, size=n)
    return centers, radii


def test_a_million_spheres_are_read_in_place():
    n = 1_000_000
    centers, radii = cloud(n)  # 24 MB + 8 MB
    s = base_scene()
    s.set_camera(position=(0, 0, 7), look_at=(0, 0, 0))
    tracemalloc.start()
    try:
        obj = s.spheres(centers, radii, material="clay")
        report = s.commit()
        img = s.render(32, 24, samples=1)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert report["rebuilt"] >= 1
    assert peak < 1_000_000, f"the Python side allocated {peak} bytes"
    assert obj.arrays["centers"] is centers and obj.arrays["radii"] is radii
    assert len(np.unique(img[..., 0])) > 4, "the spheres are seen"

    # copy=True: Luxon reads a copy, which the Python side does allocate.
    tracemalloc.start()
    try:
        copied = s.spheres(centers, radii, copy=True)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak >= centers.nbytes + radii.nbytes
    assert copied.arrays["centers"] is not centers
    assert np.array_equal(copied.arrays["centers"], centers)


def test_wrong_dtypes_raise_type_error():
    s = base_scene()
    c = np.zeros((4, 3))
    with pytest.raises(TypeError) as e:
        s.spheres(c.astype(np.int64), 0.1)
    assert str(e.value) == (
        "spheres: centers: an array of dtype int64; expected float32 or float64. Pass "
        "copy=True to have Luxon convert it, or centers.astype(np.float64)"
    )
    with pytest.raises(TypeError, match=r"^spheres: radii: an array of dtype float16;"):
        s.spheres(c, np.ones(4, np.float16))
    with pytest.raises(TypeError, match="in this machine's byte order"):
        s.spheres(c.astype(c.dtype.newbyteorder()), 0.1)
    with pytest.raises(TypeError) as e:
        s.spheres([[0, 0, 0]], 0.1)
    assert str(e.value) == (
        "spheres: centers: expected a numpy array of float32 or float64, not list; pass "
        "copy=True to read other sequences (Luxon keeps a copy), or np.asarray(centers, "
        "dtype=np.float64)"
    )
    with pytest.raises(TypeError, match=r"^mesh: indices: an array of dtype float64; expected uint32"):
        s.mesh(np.zeros((3, 3)), np.zeros((1, 3)))
    with pytest.raises(TypeError, match=r"^mesh: uvs: .* expected float32"):
        s.mesh(np.zeros((3, 3)), uvs=np.zeros((3, 2)))
    # copy=True converts all of these.
    s.spheres([[0, 0, 0]], 0.1, copy=True)
    s.spheres(c.astype(np.int64), np.ones(4, np.float16), copy=True)
    s.mesh(np.zeros((3, 3)), np.zeros((1, 3)), uvs=np.zeros((3, 2)), copy=True)
    assert len(s.objects) == 3


def test_wrong_shapes_and_sizes_raise_value_error():
    s = base_scene()
    with pytest.raises(ValueError) as e:
        s.spheres(np.zeros((10, 2)), 0.1)
    assert str(e.value) == "spheres: centers: an array of shape (10, 2); expected (n, 3)"
    with pytest.raises(ValueError, match=r"^spheres: radii: an array of shape \(10, 1\); expected \(n,\)$"):
        s.spheres(np.zeros((10, 3)), np.ones((10, 1)))
    with pytest.raises(ValueError) as e:
        s.spheres(np.zeros((10, 3)), np.ones(9))
    assert str(e.value) == "spheres: radii: 9 rows for 10 centers; give one per center"
    with pytest.raises(ValueError, match=r"^cylinders: b: 4 rows for 5 bases \(a\)"):
        s.cylinders(np.zeros((5, 3)), np.ones((4, 3)), 0.1)
    with pytest.raises(ValueError, match=r"^mesh: colors: 2 rows for 3 vertices"):
        s.mesh(np.zeros((3, 3)), colors=np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"^mesh: 4 vertices without indices"):
        s.mesh(np.zeros((4, 3)))
    with pytest.raises(ValueError, match="negative vertex indices"):
        s.mesh(np.zeros((3, 3)), np.array([[0, -1, 2]]))
    # Transposed or reversed views cannot be read in place; row slices can.
    wide = np.zeros((10, 4))
    with pytest.raises(ValueError) as e:
        s.spheres(np.zeros((3, 10)).T, 0.1)
    assert "np.ascontiguousarray(centers)" in str(e.value) and "copy=True" in str(e.value)
    with pytest.raises(ValueError, match="cannot be read in place"):
        s.spheres(np.zeros((10, 3))[::-1], 0.1)
    s.spheres(wide[:, :3], 0.1)
    s.spheres(np.zeros((3, 10)).T, 0.1, copy=True)
    assert len(s.objects) == 2
    # Values are checked by the commit, naming the object and the element.
    bad = np.zeros((3, 3))
    bad[1, 0] = np.nan
    s.spheres(bad, 0.1)
    with pytest.raises(luxon.UsageError, match=r"sphere 1 has a non-finite value"):
        s.commit()


def test_moved_spheres_refit_and_render_as_a_fresh_scene():
    centers, radii = cloud(2000, seed=7)
    s = base_scene()
    obj = s.spheres(centers, radii, material="clay")
    first = s.render(64, 48)
    centers += np.array([0.05, -0.1, 0.02])  # in place
    centers[::7] *= 1.1
    obj.modified()
    report = s.commit()
    assert report["refitted"] == 1 and report["rebuilt"] == 0
    moved = s.render(64, 48)
    assert not np.array_equal(first, moved)
    fresh = base_scene()
    fresh.spheres(centers.copy(), radii.copy(), material="clay")
    assert np.array_equal(moved, fresh.render(64, 48))
    # Without modified(), a write is not read (the geometry is the last commit's).
    assert s.commit()["refitted"] == 0


def test_replacing_arrays():
    centers, radii = cloud(500, seed=3)
    s = base_scene()
    obj = s.spheres(centers, radii, material="clay")
    s.render(48, 32)
    fewer = centers[:200].copy()
    obj.update(centers=fewer, radii=0.08)
    assert obj.arrays["centers"] is fewer
    assert s.commit()["rebuilt"] >= 1
    img = s.render(48, 32)
    fresh = base_scene()
    fresh.spheres(fewer, 0.08, material="clay")
    assert np.array_equal(img, fresh.render(48, 32))
    with pytest.raises(ValueError, match="200 centers"):
        obj.update(radii=np.ones(10))
    with pytest.raises(TypeError, match="unknown array 'vertices'"):
        obj.update(vertices=fewer)
    obj.remove()
    with pytest.raises(luxon.UsageError, match="was removed"):
        obj.modified()
    assert s.objects == []


def test_arrays_dropped_by_python_live_in_the_scene():
    s = base_scene()
    centers, radii = cloud(3000, seed=5)
    want = centers.copy(), radii.copy()
    s.spheres(centers, radii, material="clay")
    s.mesh(np.array([[-3.0, -1, -3], [3, -1, -3], [0, -1, 3]], np.float32), np.array([[0, 1, 2]], np.uint32))
    s.cylinders(np.array([[0.0, 0, 0]]), np.array([[0.0, 2, 0]]), np.array([0.1]))
    del centers, radii
    gc.collect()
    np.ones((3000, 3)) * 7  # reuse of freed memory would show
    img = s.render(48, 32)
    ref = base_scene()
    ref.spheres(*want, material="clay")
    ref.mesh(np.array([[-3.0, -1, -3], [3, -1, -3], [0, -1, 3]]), np.array([[0, 1, 2]]), copy=True)
    ref.cylinders(np.array([[0.0, 0, 0]]), np.array([[0.0, 2, 0]]), 0.1)
    assert np.array_equal(img, ref.render(48, 32))
    del s
    gc.collect()


def test_a_mesh_from_arrays_renders_as_the_mesh_plugin():
    k = 12
    u, v = np.meshgrid(np.linspace(-2, 2, k), np.linspace(-2, 2, k))
    verts = np.stack([u.ravel(), 0.3 * np.sin(2 * u.ravel()) * np.cos(v.ravel()), v.ravel()], axis=1)
    colors = np.stack([(u.ravel() + 2) / 4, np.full(k * k, 0.5), (v.ravel() + 2) / 4], axis=1)
    quads = [(i * k + j, i * k + j + 1, (i + 1) * k + j + 1, (i + 1) * k + j) for i in range(k - 1) for j in range(k - 1)]
    tris = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))], np.int64)
    s = base_scene()
    s.mesh(verts, tris, colors=colors, material="clay")
    img = s.render(48, 32)

    r = base_scene()
    r.add_object(
        "mesh",
        luxon.Ron(
            "(positions: ["
            + ", ".join(f"({x!r}, {y!r}, {z!r})" for x, y, z in verts.tolist())
            + "], indices: ["
            + ", ".join(f"({a}, {b}, {c})" for a, b, c in tris.tolist())
            + "], colors: ["
            + ", ".join(f"({x!r}, {y!r}, {z!r})" for x, y, z in colors.tolist())
            + "])"
        ).text,
        material="clay",
    )
    assert np.array_equal(img, r.render(48, 32))


def load_example(name):
    path = REPO / "examples" / "python" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def molecule_ron(m, elements, positions, bonds):
    """The molecule as a RON scene: the spheres plugin per element, a cylinder per half bond."""
    mats = ", ".join(
        f'"{el}": (color: ({c[0]!r}, {c[1]!r}, {c[2]!r}), specular: 0.45, shininess: 40, ambient: 0.25)'
        for el, (_, c) in m.ATOMS.items()
    )
    objects = []
    mid = 0.5 * (positions[bonds[:, 0]] + positions[bonds[:, 1]])
    vec = lambda p: f"({p[0]!r}, {p[1]!r}, {p[2]!r})"
    for el, (radius, _) in m.ATOMS.items():
        atoms = positions[elements == el].tolist()
        objects.append(
            f'(plugin: "spheres", params: (centers: [{", ".join(map(vec, atoms))}], radius: {radius!r}), material: "{el}")'
        )
        for s in (0, 1):
            sel = elements[bonds[:, s]] == el
            for a, b in zip(positions[bonds[:, s]][sel].tolist(), mid[sel].tolist()):
                objects.append(
                    f'(plugin: "cylinder", params: (base: {vec(a)}, apex: {vec(b)}, radius: {m.BOND_RADIUS!r}, caps: false), material: "{el}")'
                )
    return f"Scene(camera: (position: (0, 0, 10), look_at: (0, 0, 0)), materials: {{{mats}}}, objects: [{', '.join(objects)}])"


def test_an_array_molecule_renders_as_the_same_molecule_in_ron(tmp_path):
    m = load_example("molecule")
    elements, positions, bonds = m.helix_bundle(residues=6, helices=2)
    s = luxon.Scene()
    m.setup(s, positions)
    m.build(s, elements, positions, bonds)
    img = s.render(64, 40, samples=1)

    path = tmp_path / "molecule.ron"
    path.write_text(molecule_ron(m, elements, positions, bonds))
    r = luxon.load(path)
    m.setup(r, positions)
    assert np.array_equal(img, r.render(64, 40, samples=1))
    assert len(np.unique(img.reshape(-1, 4), axis=0)) > 20, "the molecule is seen"


def test_the_molecule_example_runs(tmp_path):
    m = load_example("molecule")
    out = tmp_path / "m.png"
    scene = m.main(["--size", "80x45", "--samples", "1", "--out", str(out)])
    assert out.stat().st_size > 1000
    assert len(scene.objects) == 6


def test_numpy_scalars_are_written_as_ron_numbers():
    assert luxon.to_ron((np.float64(0.5), np.float32(2.0), np.int64(3))) == "(0.5, 2.0, 3)"


def test_array_objects_beside_plugin_objects_and_lights_change():
    s = base_scene()
    s.add_object("plane", point=(0, -2.5, 0), normal=(0, 1, 0))
    centers, radii = cloud(300, seed=9)
    s.spheres(centers, radii, material="clay")
    first = s.render(48, 32)
    lamp = s.lights[0]
    lamp.set("point", position=(-10, 12, 6))
    s.set_material("clay", color=(0.2, 0.5, 0.9))
    s.set_camera(position=(6, 6, 9), look_at=(0, 0, 0), up=(0, 1, 0))
    report = s.commit()
    assert report["rebuilt"] == 0 and report["refitted"] == 0
    assert not np.array_equal(first, s.render(48, 32))


def test_array_objects_wear_a_custom_texture_plugin():
    # examples/stripes: the SDK's example texture plugin, from its scene file; array spheres
    # in its material render as the same spheres given to the spheres plugin.
    from conftest import plugin_dir_with

    ctx = luxon.Context(threads=2, plugin_path=[plugin_dir_with("libluxon_stripes.so")])
    centers = np.array([[-1.2, 0.5, 2.0], [1.3, 0.6, 2.5], [0.2, 1.9, 3.5]])
    radii = np.array([0.45, 0.55, 0.4])
    a = luxon.load(REPO / "examples" / "stripes" / "scene.ron", context=ctx)
    a.spheres(centers, radii, material="zebra")
    b = luxon.load(REPO / "examples" / "stripes" / "scene.ron", context=ctx)
    b.add_object("spheres", centers=centers, radii=radii.tolist(), material="zebra")
    img = a.render(64, 48)
    assert np.array_equal(img, b.render(64, 48))
    a.set_material("zebra", texture="filtered", specular=0.5)
    assert not np.array_equal(img, a.render(64, 48))
