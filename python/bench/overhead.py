"""Python vs CLI overhead for the same work: load a scene folder and render it at the same
settings, N times each, alternating. The CLI's time is the whole process (start, load,
render, write the EXR); Python's is Scene.load + Scene.render in a running interpreter
(no file). Also compares each render's own wall time (the CLI's "in X s" line against
RenderResult.stats["seconds"]), which isolates the render call.

    python python/bench/overhead.py [--scene DIR] [--samples 64] [--resolution 128x128] [--repeat 5]
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import blendsynth

REPO = Path(__file__).resolve().parents[2]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default=str(REPO / "fixtures/render/scenes/diffuse_point"))
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--resolution", default="128x128")
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--cli", default=os.environ.get("BLENDSYNTH_CLI") or shutil.which("blendsynth")
                    or str(REPO / "target/release/blendsynth"))
    a = ap.parse_args()
    w, h = (int(x) for x in a.resolution.lower().split("x"))
    extra = [] if a.threads is None else ["--threads", str(a.threads)]
    cli_wall, cli_render, py_wall, py_call, py_render = [], [], [], [], []
    cli_trace, py_trace = [], []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "o.exr")
        for _ in range(a.repeat):
            t0 = time.perf_counter()
            r = subprocess.run([a.cli, "render", a.scene, "--samples", str(a.samples), "--resolution",
                                a.resolution, "--denoise", "off", *extra, "-o", out],
                               capture_output=True, text=True, check=True)
            cli_wall.append(time.perf_counter() - t0)
            m = re.search(r" in ([0-9.]+) s \(([0-9.]+) s setup\)", r.stdout)
            cli_render.append(float(m.group(1)))
            cli_trace.append(float(m.group(1)) - float(m.group(2)))
            t0 = time.perf_counter()
            s = blendsynth.Scene.load(a.scene)
            t1 = time.perf_counter()
            res = s.render(samples=a.samples, resolution=(w, h), denoise=False, passes=["image"],
                           threads=a.threads)
            t2 = time.perf_counter()
            py_wall.append(t2 - t0)
            py_call.append(t2 - t1)
            py_render.append(res.stats["seconds"])
            py_trace.append(res.stats["seconds"] - res.stats["setup_seconds"])
    med = statistics.median
    print(f"scene {a.scene}, {a.resolution}, {a.samples} samples, {a.repeat} runs each (median):")
    print(f"  CLI process (load+render+write EXR): {med(cli_wall):.3f} s   render {med(cli_render):.3f} s")
    print(f"  Python load+render (arrays):         {med(py_wall):.3f} s   render {med(py_render):.3f} s")
    print(f"  overhead, whole job:  {100 * (med(py_wall) / med(cli_wall) - 1):+.2f} %")
    print(f"  Python render() call, arrays returned: {med(py_call):.3f} s")
    print(f"  overhead, render() call vs the CLI's render: {100 * (med(py_call) / med(cli_render) - 1):+.2f} %")
    print(f"  overhead, render inside both:          {100 * (med(py_render) / med(cli_render) - 1):+.2f} %")
    # Setup includes tables a process computes once: Python's later renders reuse them.
    print(f"  path tracing alone (render minus setup): CLI {med(cli_trace):.3f} s, Python {med(py_trace):.3f} s"
          f" ({100 * (med(py_trace) / med(cli_trace) - 1):+.2f} %)")
    # What the binding adds around the same render (thread, polling, arrays): immune to
    # the machine's load, which moves the comparisons above by several percent.
    extra = [c - r for c, r in zip(py_call, py_render)]
    print(f"  binding's own cost per render() call: {1000 * med(extra):.1f} ms"
          f" ({100 * med([e / r for e, r in zip(extra, py_render)]):.2f} % of the render)")


if __name__ == "__main__":
    main()
