"""A molecule from an array of atoms, ball-and-stick: spheres for the atoms, cylinders for
the bonds, both read in place from numpy arrays (no copy).

The molecule is generated: three alpha helices of a protein-like chain (backbone N, CA, C, O
and a CB per residue) built from ideal bond lengths, angles and the helix's torsions, packed
side by side as in a helix bundle. Any array of atoms works the same way: from a PDB file with
MDAnalysis or ASE, say, ``positions`` (n, 3) and ``elements`` (n,) are all it needs.

    python examples/python/molecule.py --size 800x450 --out molecule.png
"""

import argparse

import numpy as np

import luxon

# Ball radii (Å) and colours (linear RGB) by element, as molecular viewers colour them.
ATOMS = {
    "C": (0.36, (0.32, 0.33, 0.36)),
    "N": (0.34, (0.10, 0.22, 0.85)),
    "O": (0.33, (0.85, 0.08, 0.06)),
}
BOND_RADIUS = 0.14


def place(a, b, c, length, angle, torsion):
    """The atom bonded to ``c`` at ``length`` Å, with angle b-c-d ``angle`` and torsion
    a-b-c-d ``torsion`` (degrees): how chains are built from internal coordinates."""
    angle, torsion = np.radians(angle), np.radians(torsion)
    bc = (c - b) / np.linalg.norm(c - b)
    n = np.cross(b - a, bc)
    n /= np.linalg.norm(n)
    m = np.cross(n, bc)
    d = np.array(
        [-length * np.cos(angle), length * np.sin(angle) * np.cos(torsion), length * np.sin(angle) * np.sin(torsion)]
    )
    return c + d[0] * bc + d[1] * m + d[2] * n


def helix(residues):
    """One alpha helix: (elements, positions (n, 3), bonds (m, 2)) of a backbone with CBs."""
    phi, psi, omega = -57.0, -47.0, 180.0
    n = np.array([0.0, 0.0, 0.0])
    ca = np.array([1.458, 0.0, 0.0])
    c = ca + 1.525 * np.array([-np.cos(np.radians(111.2)), np.sin(np.radians(111.2)), 0.0])
    elements, positions, bonds = [], [], []

    def add(element, p, bonded_to=None):
        elements.append(element)
        positions.append(p)
        if bonded_to is not None:
            bonds.append((bonded_to, len(positions) - 1))
        return len(positions) - 1

    prev_c = None
    for _ in range(residues):
        i_n = add("N", n, prev_c)
        i_ca = add("C", ca, i_n)
        i_c = add("C", c, i_ca)
        add("O", place(n, ca, c, 1.231, 120.5, psi + 180.0), i_c)
        add("C", place(c, n, ca, 1.53, 110.5, -122.5), i_ca)  # CB
        next_n = place(n, ca, c, 1.329, 116.2, psi)
        next_ca = place(ca, c, next_n, 1.458, 121.7, omega)
        next_c = place(c, next_n, next_ca, 1.525, 111.2, phi)
        n, ca, c, prev_c = next_n, next_ca, next_c, i_c
    return elements, np.array(positions), bonds


def helix_bundle(residues=16, helices=3, spread=5.2):
    """``helices`` copies of a helix around a common axis (x), ``spread`` Å from it, each
    turned to face it, alternately one way and the other."""
    elements, p, bonds = helix(residues)
    # The helix's own axis: the least-squares line through its atoms.
    centre = p.mean(axis=0)
    _, _, vt = np.linalg.svd(p - centre)
    axis = vt[0]
    # A frame whose z is the helix axis.
    x = np.cross(axis, [0.0, 0.0, 1.0] if abs(axis[2]) < 0.9 else [1.0, 0.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(axis, x)
    local = (p - centre) @ np.stack([x, y, axis], axis=1)
    all_el, all_p, all_b = [], [], []
    for k in range(helices):
        t = 2 * np.pi * k / helices
        flip = 1.0 if k % 2 == 0 else -1.0
        rot = np.array([[np.cos(t), -np.sin(t), 0.0], [np.sin(t), np.cos(t), 0.0], [0.0, 0.0, 1.0]])
        q = local * np.array([1.0, flip, flip])
        q = q @ rot.T + spread * np.array([np.cos(t), np.sin(t), 0.0])
        base = len(all_el)
        all_el += elements
        all_p.append(q[:, [2, 0, 1]])  # the bundle's axis along x
        all_b += [(i + base, j + base) for i, j in bonds]
    return np.array(all_el), np.concatenate(all_p), np.array(all_b)


def build(scene, elements, positions, bonds, copy=False):
    """Adds the molecule: one spheres object and one cylinders object (half bonds, coloured
    as their atom) per element, read from arrays. Returns the objects by element."""
    objects = {}
    for el, (radius, color) in ATOMS.items():
        scene.set_material(el, color=color, specular=0.45, shininess=40, ambient=0.25)
    mid = 0.5 * (positions[bonds[:, 0]] + positions[bonds[:, 1]])
    for el in ATOMS:
        atoms = np.ascontiguousarray(positions[elements == el])
        if len(atoms) == 0:
            continue
        # Half bonds from this element's atoms to the bonds' middles.
        ends = [positions[bonds[:, s]][elements[bonds[:, s]] == el] for s in (0, 1)]
        mids = [mid[elements[bonds[:, s]] == el] for s in (0, 1)]
        a = np.concatenate(ends)
        b = np.concatenate(mids)
        balls = scene.spheres(atoms, ATOMS[el][0], material=el, copy=copy)
        sticks = scene.cylinders(a, b, BOND_RADIUS, material=el, caps=False, copy=copy)
        objects[el] = (balls, sticks)
    return objects


def setup(scene, positions):
    """Camera, lights and background framing ``positions``."""
    centre = positions.mean(axis=0)
    size = np.ptp(positions, axis=0).max()
    eye = centre + size * np.array([0.25, -1.0, 0.38])
    scene.set_camera(position=tuple(eye), look_at=tuple(centre), up=(0, 0, 1), fov=40)
    scene.set_background(0.93, 0.94, 0.96)
    scene.add_light("point", position=tuple(centre + size * np.array([-0.8, -1.5, 2.0])), intensity=0.8)
    scene.add_light("directional", direction=(-0.5, 1.0, -0.6), intensity=0.35)
    scene.set_render(samples=4, max_depth=4)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", default="800x450", help="WIDTHxHEIGHT")
    ap.add_argument("--samples", type=int, default=4)
    ap.add_argument("--out", default="molecule.png")
    args = ap.parse_args(argv)
    w, h = (int(v) for v in args.size.split("x"))

    elements, positions, bonds = helix_bundle()
    scene = luxon.Scene()
    setup(scene, positions)
    build(scene, elements, positions, bonds)
    scene.render(w, h, samples=args.samples)
    scene.save(args.out)
    print(f"{len(positions)} atoms, {len(bonds)} bonds -> {args.out}")
    return scene


if __name__ == "__main__":
    main()
