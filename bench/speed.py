"""blendsynth against Cycles on the same CPU, in one run: speed, memory, error and scaling.

    .venv/bin/python bench/speed.py [--quick] [--scenes a,b,...] [--size N] [--json FILE]
                                    [--work DIR] [--ref-factor K] [--no-scaling]

For each scene, with Cycles (bpy 4.5.4, CPU, adaptive sampling and denoising off) and
with `target/release/blendsynth render` (same size, samples, no denoising, adaptive off):

- wall: the whole process's wall time (Python start, bpy import and .blend load for
  Cycles; start, scene load, BVH build and EXR write for blendsynth), all cores;
- peak memory: the process's maximum resident set (GNU time's %M, /usr/bin/time);
- samples/s: pixels x samples over the wall time (Msamples/s);
- RMSE (linear RGB) against a high-sample Cycles reference (K x the scene's samples, another
  seed; cached in the work folder, so a second run skips it);
- time-to-equal-error ratio: blendsynth is rendered at 1/4, 1/2, 1 and 2 times the
  samples (quick: 1/2, 1, 2); a fit of RMSE^2 = b^2 + v / spp (bias and variance) and of
  wall = t0 + c * spp gives the time blendsynth needs to reach the RMSE Cycles reaches at
  the scene's samples, over Cycles' time. `inf` when blendsynth's bias b alone is above
  Cycles' error (no sample count reaches it);
- speed-up 1 -> all cores of both, from the same render with one thread.

Prints a table and writes JSON (--json, default WORK/speed.json). Scenes are authored
or exported into --work (default /tmp/blendsynth-bench; nothing goes into the repository):
the published colon is read from ../shared/published/colon_nodes.blend and exported with
`blendsynth convert`; the built-in colon is authored with
assets/doi-23843904/make_scenes.py; the rest with bench/scenes.py.

Needs a release build (`cargo build --release`) and a Python with bpy 4.5.4 (run it with
that Python: `.venv/bin/python`). On a shared or loaded machine the figures are
indicative only: the script records the load average before and after.
"""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
PUBLISHED = os.path.abspath(os.path.join(REPO, "..", "shared", "published", "colon_nodes.blend"))
BIN = os.path.join(REPO, "target", "release", "blendsynth")
PY = sys.executable

# name: (source, frame or None, samples)
SCENES = {
    "published_f11595": ("published", 11595, 16),
    "published_f50": ("published", 50, 16),
    "builtin_colon": ("builtin:colonoscopy", None, 64),
    "builtin_laparoscopy": ("builtin:laparoscopy", None, 64),
    "endo_colon": ("own:endo_colon", None, 64),
    "shading_light": ("own:shading_light", None, 64),
    "texture_heavy": ("own:texture_heavy", None, 32),
}
QUICK = ["shading_light", "endo_colon"]


TIME = "/usr/bin/time"


def run(cmd, log=None):
    """Runs cmd to completion; returns (wall seconds, peak RSS MB, stdout).

    The peak comes from GNU time (`%M`, the child's own maximum RSS): wait4 on a child
    forked from this process would report this process's RSS (bpy is loaded here) as a
    floor, since Linux carries the high-water mark across exec."""
    t = time.perf_counter()
    peak_file = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"blendsynth-bench-{os.getpid()}.rss")
    full = [TIME, "-f", "%M", "-o", peak_file] + cmd if os.path.exists(TIME) else cmd
    p = subprocess.Popen(full, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    out = p.stdout.read()
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t
    p.returncode = os.waitstatus_to_exitcode(status)
    peak = ru.ru_maxrss / 1024.0
    if full is not cmd and p.returncode == 0:
        with open(peak_file) as f:
            peak = int(f.read().split()[-1]) / 1024.0
        os.remove(peak_file)
    if log:
        with open(log, "a") as f:
            f.write(f"$ {' '.join(cmd)}\n{out}\n")
    if p.returncode != 0:
        sys.exit(f"failed ({p.returncode}): {' '.join(cmd)}\n{out[-3000:]}")
    return wall, peak, out


_bpy = None


def load_exr(path):
    global _bpy
    if _bpy is None:
        import bpy

        _bpy = bpy
    im = _bpy.data.images.load(os.path.abspath(path))
    w, h = im.size
    a = np.array(im.pixels[:], dtype=np.float64).reshape(h, w, 4)[:, :, :3]
    _bpy.data.images.remove(im)
    return a


def rmse(a, b):
    return float(np.sqrt(((a - b) ** 2).mean()))


def prepare(name, work, log):
    """(blend for Cycles, export folder for blendsynth, frame or None)."""
    source, frame, _ = SCENES[name]
    if source == "published":
        if not os.path.exists(PUBLISHED):
            sys.exit(f"{PUBLISHED} is missing (the published colon scene)")
        blend, export = PUBLISHED, os.path.join(work, "published", "export")
    elif source.startswith("builtin:"):
        d = os.path.join(work, "builtin")
        blend = os.path.join(d, source.split(":")[1] + ".blend")
        if not os.path.exists(blend):
            os.makedirs(d, exist_ok=True)
            run([PY, os.path.join(REPO, "assets", "doi-23843904", "make_scenes.py"), d], log)
        export = os.path.join(d, source.split(":")[1])
    else:
        d = os.path.join(work, name)
        blend, export = os.path.join(d, name + ".blend"), os.path.join(d, "export")
        if not os.path.exists(blend):
            run([PY, os.path.join(HERE, "scenes.py"), source.split(":")[1], blend], log)
    if not os.path.exists(os.path.join(export, "scene.json")):
        run([BIN, "convert", blend, "-o", export, "--no-evaluated", "--blender", PY], log)
    return blend, export, frame


def cycles(blend, frame, size, spp, seed, threads, out, log):
    wall, mem, text = run([PY, os.path.join(HERE, "cycles_render.py"), blend, "-" if frame is None else str(frame), str(size), str(spp), str(seed), str(threads), out], log)
    render = next((float(l.split()[1]) for l in text.splitlines() if l.startswith("render_seconds")), None)
    return {"wall": wall, "peak_mb": mem, "render_seconds": render}


def ours(export, frame, size, spp, threads, out, log):
    cmd = [BIN, "render", export, "--samples", str(spp), "--threshold", "0", "--resolution", f"{size}x{size}", "--denoise", "off", "-o", out]
    if frame is not None:
        cmd += ["--frame", str(frame)]
    if threads:
        cmd += ["--threads", str(threads)]
    wall, mem, _ = run(cmd, log)
    return {"wall": wall, "peak_mb": mem}


def equal_error_time(points, target):
    """Fits RMSE^2 = b2 + v / spp and wall = t0 + c * spp over points [(spp, wall, rmse)];
    returns (blendsynth's wall time at RMSE `target` or inf, the fit)."""
    spp = np.array([p[0] for p in points], dtype=float)
    wall = np.array([p[1] for p in points], dtype=float)
    err2 = np.array([p[2] ** 2 for p in points], dtype=float)
    (b2, v), *_ = np.linalg.lstsq(np.stack([np.ones_like(spp), 1.0 / spp], 1), err2, rcond=None)
    (t0, c), *_ = np.linalg.lstsq(np.stack([np.ones_like(spp), spp], 1), wall, rcond=None)
    b2, v = max(b2, 0.0), max(v, 1e-30)
    fit = {"bias_rmse": float(np.sqrt(b2)), "variance_per_spp": float(v), "t0": float(t0), "seconds_per_spp": float(c)}
    if target ** 2 <= b2:
        return float("inf"), fit
    need = v / (target ** 2 - b2)
    fit["spp_needed"] = float(need)
    return float(t0 + c * need), fit


def bench(name, a, log):
    work = a.work
    _, _, spp = SCENES[name]
    if a.quick:
        spp = max(4, spp // 4)
    size = a.size
    blend, export, frame = prepare(name, work, log)
    d = os.path.join(work, "runs", f"{name}_{size}_{spp}")
    os.makedirs(d, exist_ok=True)
    ref_spp = spp * a.ref_factor
    ref = os.path.join(work, "refs", f"{name}_{size}_{ref_spp}.exr")
    if not os.path.exists(ref):
        os.makedirs(os.path.dirname(ref), exist_ok=True)
        print(f"  {name}: Cycles reference at {ref_spp} spp (cached in {ref})", flush=True)
        cycles(blend, frame, size, ref_spp, 7919, 0, ref, log)
    R = load_exr(ref)
    row = {"scene": name, "size": size, "samples": spp, "frame": frame, "reference_spp": ref_spp}
    c = cycles(blend, frame, size, spp, 0, 0, os.path.join(d, "cycles.exr"), log)
    c["rmse"] = rmse(load_exr(os.path.join(d, "cycles.exr")), R)
    factors = [0.5, 1, 2] if a.quick else [0.25, 0.5, 1, 2]
    points = []
    for f in factors:
        n = max(1, int(round(spp * f)))
        out = os.path.join(d, f"ours_{n}.exr")
        r = ours(export, frame, size, n, 0, out, log)
        r["rmse"] = rmse(load_exr(out), R)
        points.append((n, r["wall"], r["rmse"]))
        if n == spp:
            o = r
    pixels = size * size
    for r in (c, o):
        r["msamples_per_s"] = pixels * spp / r["wall"] / 1e6
    t_eq, fit = equal_error_time(points, c["rmse"])
    row.update(cycles=c, blendsynth=o, points=[{"spp": p[0], "wall": p[1], "rmse": p[2]} for p in points], fit=fit)
    row["blendsynth_seconds_to_cycles_error"] = t_eq
    row["time_to_equal_error_ratio"] = t_eq / c["wall"]
    if not a.no_scaling:
        c1 = cycles(blend, frame, size, spp, 0, 1, os.path.join(d, "cycles_1t.exr"), log)
        o1 = ours(export, frame, size, spp, 1, os.path.join(d, "ours_1t.exr"), log)
        row["cycles"]["speedup_1_to_all"] = c1["wall"] / c["wall"]
        row["blendsynth"]["speedup_1_to_all"] = o1["wall"] / o["wall"]
        row["cycles"]["wall_1_thread"], row["blendsynth"]["wall_1_thread"] = c1["wall"], o1["wall"]
    return row


def fmt(v, spec):
    return "-" if v is None else ("inf" if v == float("inf") else format(v, spec))


def table(rows):
    head = "| scene | spp | wall bs / Cycles (s) | peak MB bs / Cycles | Msamples/s bs / Cycles | RMSE bs / Cycles | time-to-equal-error ratio | speed-up 1->all bs / Cycles |"
    lines = [head, "|" + "---|" * 8]
    for r in rows:
        o, c = r["blendsynth"], r["cycles"]
        lines.append(
            f"| {r['scene']} | {r['samples']} | {o['wall']:.2f} / {c['wall']:.2f} | {o['peak_mb']:.0f} / {c['peak_mb']:.0f} "
            f"| {o['msamples_per_s']:.3f} / {c['msamples_per_s']:.3f} | {o['rmse']:.5f} / {c['rmse']:.5f} "
            f"| {fmt(r['time_to_equal_error_ratio'], '.2f')} | {fmt(o.get('speedup_1_to_all'), '.2f')} / {fmt(c.get('speedup_1_to_all'), '.2f')} |"
        )
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help=f"64x64, a quarter of the samples, scenes {','.join(QUICK)}")
    ap.add_argument("--scenes", help=f"comma-separated, of: {','.join(SCENES)}")
    ap.add_argument("--size", type=int, help="square image size (default 256; quick 64)")
    ap.add_argument("--ref-factor", type=int, help="reference samples over the scene's (default 16; quick 8)")
    ap.add_argument("--work", default="/tmp/blendsynth-bench")
    ap.add_argument("--json", help="default WORK/speed.json")
    ap.add_argument("--no-scaling", action="store_true", help="skip the one-thread renders")
    a = ap.parse_args()
    a.size = a.size or (64 if a.quick else 256)
    a.ref_factor = a.ref_factor or (8 if a.quick else 16)
    names = a.scenes.split(",") if a.scenes else (QUICK if a.quick else list(SCENES))
    for n in names:
        if n not in SCENES:
            sys.exit(f"unknown scene {n!r}; known: {', '.join(SCENES)}")
    if not os.path.exists(BIN):
        sys.exit(f"{BIN} is missing: run `cargo build --release` first")
    os.makedirs(a.work, exist_ok=True)
    log = os.path.join(a.work, "commands.log")
    load_before = os.getloadavg()
    rows = []
    path = a.json or os.path.join(a.work, "speed.json")
    for n in names:
        print(f"{n} ...", flush=True)
        rows.append(bench(n, a, log))
        print(table(rows[-1:]).splitlines()[-1], flush=True)
        # Written after every scene, so an interrupted run keeps the scenes it finished.
        result = {
            "cores": os.cpu_count(),
            "load_average_before": load_before,
            "load_average_after": os.getloadavg(),
            "quick": a.quick,
            "rows": rows,
        }
        with open(path, "w") as f:
            json.dump(result, f, indent=1)
    print()
    print(table(rows))
    print(f"\n{os.cpu_count()} cores, load average {load_before[0]:.2f} before, {result['load_average_after'][0]:.2f} after "
          f"(a loaded machine makes every figure indicative only). JSON: {path}; commands: {log}")


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)
