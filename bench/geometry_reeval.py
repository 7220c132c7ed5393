"""Geometry re-evaluation after a parameter change, Blender against blendsynth, in one run
(issue 28: "no slower than Blender's").

    .venv/bin/python bench/geometry_reeval.py [--blend FILE] [--object NAME] [--path P]
        [--values 0.1,0.3,...] [--blendsynth BIN] [--work DIR] [--json FILE]

Defaults: the published colon (../shared/published/colon_nodes.blend, read in place), its
Geometry Nodes object `Colon` at the file's frame, and the study's geometry parameter
`node_groups["Colon Geo Node"].nodes["Value.001"].outputs[0].default_value` set to each of
five values.

Blender (bpy 4.5.4, a process of its own, scripts never auto-run): the file is opened,
the viewport settings set to the render values Cycles evaluates with (the exporter's
RenderSettings: modifiers shown in renders, render levels and resolutions), and evaluated
once; then per value the property is set through RNA (which tags what depends
on it) and the time is taken for the depsgraph update that re-evaluates the object, plus
copying out its evaluated mesh (`to_mesh`; its Geometry Nodes instances are made by the
update, not realised: blendsynth's figure includes realising them, so it is the stricter
one). The vertex column counts both with the instances' vertices.
blendsynth: the file is converted once into the work folder; per value `blendsynth mesh
--set PATH=VALUE` evaluates the object from scratch and prints its own evaluation time
(Geometry Nodes evaluation and realisation; scene loading and the file write excluded).
The table gives each value's times and the medians, and blendsynth's peak memory for the
whole `mesh` process (GNU time); the JSON has the same.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
DEFAULT_PATH = 'node_groups["Colon Geo Node"].nodes["Value.001"].outputs[0].default_value'

BLENDER_SIDE = r'''
import bpy, json, sys, time
blend, obj_name, path, values = sys.argv[-4], sys.argv[-3], sys.argv[-2], json.loads(sys.argv[-1])
bpy.ops.wm.open_mainfile(filepath=blend, load_ui=False, use_scripts=False)
sys.path.insert(0, sys.argv[-5])
from export_scene import RenderSettings  # the render-time settings Cycles evaluates with
RenderSettings().__enter__()
owner_path, _, prop = path.rpartition(".")
owner = bpy.data.path_resolve(owner_path)
obj = bpy.data.objects[obj_name]
dg = bpy.context.evaluated_depsgraph_get()
dg.update()


def mesh_vertices(dg):
    # to_mesh(): the evaluated mesh component (the instances stay instances).
    ev = obj.evaluated_get(dg)
    n = len(ev.to_mesh().vertices)
    ev.to_mesh_clear()
    return n


def instance_vertices(dg):
    # Untimed: the vertices of the object's instances, for the count blendsynth realises.
    n = 0
    for inst in dg.object_instances:
        if inst.is_instance and inst.parent is not None and inst.parent.original == obj:
            me = inst.object.to_mesh()
            n += len(me.vertices) if me is not None else 0
            inst.object.to_mesh_clear()
    return n


first = mesh_vertices(dg) + instance_vertices(dg)
out = []
for v in values:
    setattr(owner, prop, v)
    t0 = time.perf_counter()
    dg = bpy.context.evaluated_depsgraph_get()
    dg.update()
    n = mesh_vertices(dg)
    seconds = time.perf_counter() - t0
    out.append({"value": v, "seconds": seconds, "vertices": n + instance_vertices(dg)})
print("RESULT " + json.dumps({"first_vertices": first, "runs": out}))
'''


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--blend", default=os.path.join(REPO, "..", "shared", "published", "colon_nodes.blend"))
    ap.add_argument("--object", default="Colon")
    ap.add_argument("--path", default=DEFAULT_PATH)
    ap.add_argument("--values", default="0.1,0.3,0.5,0.7,0.9")
    ap.add_argument("--blendsynth", default=os.path.join(REPO, "target", "release", "blendsynth"))
    ap.add_argument("--work", default=os.path.join(tempfile.gettempdir(), "blendsynth-geometry-reeval"))
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    if not os.path.isfile(a.blend):
        sys.exit(f"{a.blend}: not found")
    values = [float(v) for v in a.values.split(",")]
    os.makedirs(a.work, exist_ok=True)
    py = sys.executable

    script = os.path.join(a.work, "blender_side.py")
    with open(script, "w") as f:
        f.write(BLENDER_SIDE)
    r = subprocess.run([py, script, os.path.join(REPO, "blender_export"), a.blend, a.object, a.path,
                        json.dumps(values)],
                       capture_output=True, text=True, check=True)
    line = next(l for l in r.stdout.splitlines() if l.startswith("RESULT "))
    blender = json.loads(line[len("RESULT "):])

    export = os.path.join(a.work, "export")
    env = dict(os.environ, BLENDSYNTH_BPY_PYTHON=py)
    subprocess.run([a.blendsynth, "convert", a.blend, "-o", export], check=True, env=env,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    ours = []
    # GNU time's %M: the whole `mesh` process's peak resident set, in kB.
    timer = ["/usr/bin/time", "-f", "PEAK_KB %M"] if os.path.exists("/usr/bin/time") else []
    for v in values:
        r = subprocess.run(timer + [a.blendsynth, "mesh", export, "--object", a.object, "--set", f"{a.path}={v}",
                                    "-o", os.path.join(a.work, "mesh.glb")], capture_output=True, text=True, check=True)
        m = re.search(r"(\d+) vertices.*evaluated in ([0-9.]+) s", r.stdout)
        peak = re.search(r"PEAK_KB (\d+)", r.stderr)
        ours.append({"value": v, "seconds": float(m.group(2)), "vertices": int(m.group(1)),
                     "peak_mb": int(peak.group(1)) / 1024 if peak else None})

    print(f"{a.object} in {os.path.basename(a.blend)}, {a.path}")
    print("| value | Blender s | blendsynth s | vertices Blender / blendsynth | blendsynth peak MB |")
    print("|---|---|---|---|---|")
    for b, o in zip(blender["runs"], ours):
        peak = f"{o['peak_mb']:.0f}" if o["peak_mb"] else "-"
        print(f"| {b['value']} | {b['seconds']:.3f} | {o['seconds']:.3f} | {b['vertices']} / {o['vertices']} | {peak} |")
    mb = statistics.median(x["seconds"] for x in blender["runs"])
    mo = statistics.median(x["seconds"] for x in ours)
    print(f"| median | {mb:.3f} | {mo:.3f} | ratio blendsynth / Blender {mo / mb:.2f} | |")
    result = {"blend": a.blend, "object": a.object, "path": a.path, "blender": blender["runs"],
              "blendsynth": ours, "median_blender": mb, "median_blendsynth": mo, "ratio": mo / mb}
    with open(a.json or os.path.join(a.work, "geometry_reeval.json"), "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
