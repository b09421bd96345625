"""Renders release the GIL, report progress, stop on Ctrl-C and when the callback raises."""

import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import luxon
from conftest import SCENES

# Long enough on one thread (several seconds on a fast machine) to be interrupted mid-way.
SLOW = dict(width=1200, height=900, samples=64, threads=1)


def test_other_python_threads_run_while_rendering():
    scene = luxon.load(SCENES / "spheres.ron")
    scene.commit()
    count = 0
    stop = threading.Event()

    def counter():
        nonlocal count
        while not stop.is_set():
            count += 1

    t = threading.Thread(target=counter)
    t.start()
    try:
        t0 = time.perf_counter()
        # Sized to last well over 0.2 s on a fast machine (320 × 240 took 0.18 s on one).
        scene.render(640, 480, samples=16, threads=1)
        seconds = time.perf_counter() - t0
        seen = count
    finally:
        stop.set()
        t.join()
    # A thread that held the GIL would keep the counter at ~0 (it gets the GIL only at the
    # render's ~100 ms ticks). Pure-Python counting reaches millions per second.
    assert seconds > 0.2
    assert seen > 100_000 * seconds, (seen, seconds)


def test_progress_is_reported_and_ends_at_the_total():
    scene = luxon.load(SCENES / "spheres.ron")
    seen = []
    scene.render(320, 240, samples=16, threads=1, progress=lambda d, t: seen.append((d, t)))
    assert seen[-1] == (320 * 240, 320 * 240)
    assert all(t == 320 * 240 for _, t in seen)
    assert [d for d, _ in seen] == sorted(d for d, _ in seen)


class Stop(Exception):
    pass


def test_a_callback_that_raises_cancels_the_render():
    scene = luxon.load(SCENES / "spheres.ron")
    calls = 0

    def progress(done, total):
        nonlocal calls
        calls += 1
        if calls == 2:
            raise Stop(done)

    t0 = time.perf_counter()
    with pytest.raises(Stop):
        scene.render(**SLOW, progress=progress)
    assert time.perf_counter() - t0 < 5
    # The scene is still usable and the next render complete.
    assert np.array_equal(scene.render(32, 24), luxon.load(SCENES / "spheres.ron").render(32, 24))


# The child restores Python's own Ctrl-C handler: a process started from a background job of a
# non-interactive shell (`bash -c 'pytest ... &'`) inherits SIGINT ignored, and Python then
# installs no handler, so the SIGINT would (rightly) do nothing.
CHILD = r"""
import signal, sys, time, luxon
signal.signal(signal.SIGINT, signal.default_int_handler)
scene = luxon.load(sys.argv[1])
scene.commit()
print("rendering", flush=True)
t0 = time.perf_counter()
try:
    scene.render(1200, 900, samples=64, threads=1)
    print("finished", flush=True)
except KeyboardInterrupt:
    print("interrupted %.3f" % (time.perf_counter() - t0), flush=True)
    img = scene.render(16, 12)
    print("again", img.shape, flush=True)
"""


def test_ctrl_c_interrupts_a_render():
    p = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(SCENES / "spheres.ron")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert p.stdout.readline().strip() == "rendering"
        time.sleep(0.5)
        sent = time.perf_counter()
        os.kill(p.pid, signal.SIGINT)
        out, err = p.communicate(timeout=30)
        waited = time.perf_counter() - sent
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == 0, err
    lines = out.splitlines()
    assert lines[0].startswith("interrupted "), out
    assert lines[1] == "again (12, 16, 4)"
    # Stopped within about a tick and a tile, not at the end of a render of many seconds.
    assert waited < 3, waited
