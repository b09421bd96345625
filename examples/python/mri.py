"""An MRI head from a 3-D numpy array: the Chapel Hill MRI scan (../shared/volumes, beside
the checkout) read with numpy, handed to the scene as an array (no file reader, no copy
before the commit), drawn as scenes/mri-head.ron draws the same data through the `raw`
plugin: the scalp faint, the brain dense, gradient shaded.

Any 3-D array works the same way: from nibabel (``nib.load(path).get_fdata()``, indexed
``[x, y, z]``: pass ``order="xyz"``) or pydicom slices stacked with numpy.

    python examples/python/mri.py --size 512x512 --out mri.png
"""

import argparse
import gzip
from pathlib import Path

import numpy as np

import luxon

DATA = Path(__file__).resolve().parents[2] / ".." / "shared" / "volumes" / "mri-head-256x256x109-u8.raw.gz"

# Brain (darker in this T1 scan) dense, the bright scalp faint; as scenes/mri-head.ron.
TRANSFER = dict(
    points=[
        dict(x=0.0, color=(0, 0, 0), opacity=0),
        dict(x=0.1, color=(0.9, 0.75, 0.65), opacity=0),
        dict(x=0.16, color=(0.95, 0.85, 0.75), opacity=14),
        dict(x=0.3, color=(1.0, 0.95, 0.9), opacity=30),
        dict(x=0.36, color=(0.95, 0.6, 0.5), opacity=2),
        dict(x=1.0, color=(0.95, 0.6, 0.5), opacity=2),
    ],
    range=(0, 1),
)


def read_head(path=DATA):
    """The scan as values[z, y, x] uint8: 109 sagittal slices of 256 x 256."""
    with gzip.open(path) as f:
        return np.frombuffer(f.read(), np.uint8).reshape(109, 256, 256)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", default="256x256", help="WIDTHxHEIGHT")
    ap.add_argument("--data", default=str(DATA))
    ap.add_argument("--out", default="mri.png")
    args = ap.parse_args(argv)
    w, h = (int(v) for v in args.size.split("x"))

    head = read_head(args.data)
    s = luxon.Scene()
    s.set_camera(position=(-2.2, -0.6, 2.6), look_at=(0, 0, 0), up=(0, -1, 0), fov=34)
    s.add_light("point", position=(5, -4, 3), intensity=1.0)
    s.add_light("directional", direction=(1, 0.5, -1), intensity=0.3)
    s.volume(
        head,
        spacing=(0.0078125, 0.0078125, 0.0073394),
        origin=(-0.99609375, -0.99609375, -0.39633),
        name="head",
        transfer=TRANSFER,
        step=0.0078,
        shading=dict(ambient=0.3, diffuse=0.8, specular=0.25, shininess=20),
    )
    s.render(w, h)
    s.save(args.out)
    print(f"{head.shape[::-1]} voxels -> {args.out}")
    return s


if __name__ == "__main__":
    main()
