"""Rendering from Python against the command line: the same scene, size and samples, each
run as a process of its own (load, build, render, write a PNG), alternating, N times each.
Prints both medians and their ratio (Python / CLI); the target is <= 1.05.

    python core/python/bench.py [--scene scenes/spheres.ron] [--res 1280x960] [--samples 16]
                                [--runs 5] [--luxon target/release/luxon]

Both also report the render alone (`luxon render --stats`'s `render` line, and
`scene.render` timed in-process): the interpreter's start, numpy's import and the PNG written
after the render (the command line overlaps it with rendering) are outside it. Run it on a quiet machine: both sides use every CPU.
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]

CHILD = """
import sys, time, luxon
scene, w, h, samples, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
s = luxon.load(scene)
s.commit()  # the build, which `render` in --stats excludes too
t0 = time.perf_counter()
img = s.render(w, h, samples=samples)
print(time.perf_counter() - t0)
s.save(out, img)
"""


def timed(cmd):
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode != 0:
        sys.exit(f"{' '.join(map(str, cmd))} failed:\n{r.stderr}")
    return wall, r.stdout + r.stderr


def render_seconds(stats):
    """The `render` line of `luxon render --stats`."""
    for line in stats.splitlines():
        words = line.split()
        if len(words) == 3 and words[0] == "render" and words[2] == "s":
            return float(words[1])
    sys.exit("no render time in the output of luxon render --stats")


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("--scene", default=str(REPO / "scenes" / "spheres.ron"))
    a.add_argument("--res", default="1280x960")
    a.add_argument("--samples", type=int, default=16)
    a.add_argument("--runs", type=int, default=5)
    a.add_argument("--luxon", default=str(REPO / "target" / "release" / "luxon"))
    o = a.parse_args()
    w, h = (int(x) for x in o.res.split("x"))
    with tempfile.TemporaryDirectory() as tmp:
        cli_png, py_png = os.path.join(tmp, "cli.png"), os.path.join(tmp, "py.png")
        cli_cmd = [o.luxon, "render", o.scene, "--res", o.res, "--samples", str(o.samples), "--stats", "-o", cli_png]
        py_cmd = [sys.executable, "-c", CHILD, o.scene, str(w), str(h), str(o.samples), py_png]
        timed(cli_cmd), timed(py_cmd)  # warm the page cache and the plugins' files
        cli, cli_render, py, py_render = [], [], [], []
        for _ in range(o.runs):
            wall, out = timed(cli_cmd)
            cli.append(wall)
            cli_render.append(render_seconds(out))
            wall, out = timed(py_cmd)
            py.append(wall)
            py_render.append(float(out.strip().splitlines()[-1]))
        same = Path(cli_png).read_bytes() == Path(py_png).read_bytes()
    mc, mp = statistics.median(cli), statistics.median(py)
    print(f"scene {o.scene} at {o.res}, {o.samples} samples, {o.runs} runs each (alternating)")
    print(f"luxon render (process):   median {mc:.3f} s  {sorted(round(x, 3) for x in cli)}")
    print(f"python (process):         median {mp:.3f} s  {sorted(round(x, 3) for x in py)}")
    rc, rp = statistics.median(cli_render), statistics.median(py_render)
    print(f"render alone: luxon --stats median {rc:.3f} s, python scene.render median {rp:.3f} s")
    print(f"ratio python / cli: render {rp / rc:.3f}, whole process {mp / mc:.3f} (target <= 1.05)")
    print(f"same PNG bytes: {same}")


if __name__ == "__main__":
    main()
