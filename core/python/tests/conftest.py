"""Shared helpers of the Python tests: the checkout's paths, the command line, PNG decoding."""

import subprocess
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[3]
SCENES = REPO / "scenes"
GOLDEN = Path(__file__).resolve().parent / "golden"


def cli():
    """The checkout's ``luxon`` command (the newest of target/release and target/debug):
    the tests compare the module with it. ``cargo build`` (or the Rust tests) makes it."""
    found = [REPO / "target" / p / "luxon" for p in ("release", "debug")]
    found = [p for p in found if p.is_file()]
    if not found:
        pytest.fail("no luxon command in target/release or target/debug: run `cargo build` first")
    return max(found, key=lambda p: p.stat().st_mtime)


def run_cli(*args, cwd=None):
    return subprocess.run([str(cli()), *map(str, args)], capture_output=True, text=True, cwd=cwd)


def read_png(path):
    """An 8-bit RGBA PNG as an (h, w, 4) uint8 array."""
    from PIL import Image as PILImage

    with PILImage.open(path) as im:
        return np.asarray(im.convert("RGBA"))


def plugin_dir_with(lib):
    """The checkout's target directory that holds the plugin library ``lib`` (the example
    plugins are built by ``cargo build`` and by the Rust tests)."""
    for p in ("release", "debug"):
        d = REPO / "target" / p
        if (d / lib).is_file():
            return d
    pytest.fail(f"{lib} not in target/release or target/debug: run `cargo build` first")


def slow_scene(luxon):
    """The shipped spheres scene: at 1200x900 with 64 samples on one thread it takes many
    seconds, enough to interrupt, cancel or watch."""
    return luxon.load(SCENES / "spheres.ron")
