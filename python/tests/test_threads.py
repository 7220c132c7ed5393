"""Renders from Python threads: the GIL is released, two threads at once give the same
images as one, a render is stopped from another thread (CancelToken) or by Ctrl-C, and
progress reaches a callback."""

from __future__ import annotations

import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import blendsynth
from conftest import SCENE

SMALL = dict(samples=8, seed=5, resolution=(40, 40), denoise=False, passes=["image", "instance_id"])


def test_two_threads_give_the_same_images():
    alone = blendsynth.Scene.load(SCENE).render(**SMALL)
    scene = blendsynth.Scene.load(SCENE)
    results = [None, None]
    errors = []

    def work(k: int) -> None:
        try:
            results[k] = scene.render(threads=1, **SMALL)
        except BaseException as e:  # pragma: no cover - reported below
            errors.append(e)

    ts = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert not errors, errors
    for r in results:
        assert np.array_equal(r.image.view(np.uint32), alone.image.view(np.uint32))
        assert np.array_equal(r.instance_id, alone.instance_id)


def test_gil_is_released_while_rendering():
    ticks = []
    stop = threading.Event()

    def ticker() -> None:
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.005)

    t = threading.Thread(target=ticker)
    t.start()
    try:
        t0 = time.perf_counter()
        blendsynth.Scene.load(SCENE).render(samples=64, resolution=(64, 64), denoise=False, passes=["image"])
        t1 = time.perf_counter()
    finally:
        stop.set()
        t.join()
    during = [x for x in ticks if t0 < x < t1]
    # A thread holding the GIL for the whole render would leave no ticks in between.
    assert len(during) >= 3, (len(during), t1 - t0)


def test_cancel_from_another_thread():
    scene = blendsynth.Scene.load(SCENE)
    token = blendsynth.CancelToken()
    seen = []

    def progress(done: int, total: int) -> None:
        seen.append((done, total))
        if done > 0:
            token.cancel()

    t0 = time.perf_counter()
    full = None
    with pytest.raises(blendsynth.Cancelled):
        # Big enough to take minutes if not stopped.
        full = scene.render(samples=4096, resolution=(128, 128), denoise=False, passes=["image"],
                            cancel=token, progress=progress, threads=2)
    assert full is None
    assert time.perf_counter() - t0 < 60
    assert token.cancelled and seen and seen[-1][1] == 128 * 128 * 4096

    # Cancelled by a plain thread, not from the callback.
    token.reset()
    threading.Timer(0.3, token.cancel).start()
    with pytest.raises(blendsynth.Cancelled):
        scene.render(samples=4096, resolution=(128, 128), denoise=False, passes=["image"], cancel=token)
    # The scene is usable afterwards, and an uncancelled token changes nothing.
    token.reset()
    a = scene.render(cancel=token, **SMALL)
    b = scene.render(**SMALL)
    assert np.array_equal(a.image.view(np.uint32), b.image.view(np.uint32))


def test_progress_callback_and_its_exceptions():
    scene = blendsynth.Scene.load(SCENE)
    seen = []
    scene.render(samples=256, resolution=(64, 64), denoise=False, passes=["image"],
                 progress=lambda d, t: seen.append((d, t)))
    assert seen and seen[-1] == (64 * 64 * 256, 64 * 64 * 256)
    assert all(a[0] <= b[0] for a, b in zip(seen, seen[1:]))

    class Stop(Exception):
        pass

    def boom(done: int, total: int) -> None:
        raise Stop()

    with pytest.raises(Stop):
        scene.render(samples=4096, resolution=(128, 128), denoise=False, passes=["image"], progress=boom)


CTRL_C = f"""
import sys, time, blendsynth
s = blendsynth.Scene.load({str(SCENE)!r})
print("ready", flush=True)
t0 = time.perf_counter()
try:
    s.render(samples=100000, resolution=(128, 128), denoise=False, passes=["image"])
except KeyboardInterrupt:
    print("interrupted after %.1f s" % (time.perf_counter() - t0), flush=True)
    sys.exit(0)
sys.exit(3)
"""


def test_ctrl_c_stops_a_render():
    p = subprocess.Popen([sys.executable, "-c", CTRL_C], stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout.readline().strip() == "ready"
        time.sleep(1.0)
        t0 = time.perf_counter()
        p.send_signal(signal.SIGINT)
        out, _ = p.communicate(timeout=60)
        stopped = time.perf_counter() - t0
    finally:
        if p.poll() is None:
            p.kill()
            p.wait()
    assert p.returncode == 0, out
    assert "interrupted after" in out
    assert stopped < 20, stopped
