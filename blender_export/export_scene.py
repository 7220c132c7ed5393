"""Export a .blend file to blendsynth's scene exchange format (blender_export/FORMAT.md).

Run inside Blender 4.2+:
    blender -b --factory-startup --disable-autoexec --python export_scene.py -- --in F.blend --out DIR
or with the bpy module:
    python export_scene.py --in F.blend --out DIR

Options: --frame N (evaluate at frame N; default the file's current frame),
--frames A..B (evaluate at frame A, and also write the evaluated meshes of objects whose
evaluation is animated at every frame A+1..B), --no-evaluated (skip the evaluated
reference meshes).

The .blend is opened by this script with auto-run scripts disabled: a .blend can carry
Python (registered text blocks, driver expressions) and none of it may run.
Everything is read generically through Blender's RNA, so node types and settings this
script has never heard of still come out.
"""

import argparse
import json
import math
import os
import re
import shutil
import struct
import sys
import time
import traceback

import bpy
import numpy as np

EXPORTER_VERSION = 1
FLT_MAX = 3.4028234663852886e38
MAX_DEPTH = 5            # nesting limit for non-ID structs (FORMAT.md "Generic RNA values")
MAX_ARRAY = 1 << 16      # longer RNA arrays (preview pixels and the like) are not scene data

WARNINGS = []
# Folders the .blend's external files may come from (its own folder, then every
# --allow-path), as real paths; and the files copied into the export.
ALLOWED_ROOTS = []
COPIED = []


def fail(msg):
    # One line, prefixed so callers (src/blender) can pick it out of Blender's chatter.
    msg = " ".join(str(msg).split())  # one line, even for Blender's multi-line errors
    print(f"blendsynth-export: error: {msg}", file=sys.stderr)
    sys.stdout.flush()
    sys.stderr.flush()
    sys.exit(1)


def q(name):
    """A name as a quoted key of a Blender data path: objects["A \\"B\\""]."""
    return '"' + name.replace("\\", "\\\\").replace('"', '\\"') + '"'


def key(idb):
    """An ID's name in the export: its name, or for data linked from a library Blender's
    name_full (`Cube [lib]`, the library ID's name in brackets), since linked data may
    share its name with local data or with data from another library."""
    return idb.name_full


def id_ref(idb):
    return {"id_type": idb.id_type, "name": key(idb)}


# ---------------------------------------------------------------- generic RNA values

# Bookkeeping every ID has (name, users, session_uid, preview pixels, ...): not scene
# data, and session_uid would make exports differ run to run.
ID_BASE = frozenset(p.identifier for p in bpy.types.ID.bl_rna.properties)
# Properties every node has; the ones that matter are exported explicitly per node.
NODE_BASE = frozenset(p.identifier for p in bpy.types.Node.bl_rna.properties)
# Properties whose read crashes Blender: a fluid domain's grids read the simulation's cache
# (SIGSEGV when it is not baked or not found). They are simulation output, not settings.
UNSAFE_RNA = {"FluidDomainSettings": frozenset({
    "density_grid", "velocity_grid", "flame_grid", "color_grid", "heat_grid", "temperature_grid"}),
    # The Menu Switch's `enum_definition` is the node itself (kept for old scripts):
    # walking it writes the node into itself five levels deep.
    "GeometryNodeMenuSwitch": frozenset({"enum_definition"})}


def py_value(v, where, depth):
    """A value read from RNA or an ID property, as JSON-ready data. Floats are left
    as they are; sanitize() makes the whole document finite at the end."""
    if v is None or isinstance(v, (bool, int, float, str)):
        return v
    if isinstance(v, bpy.types.ID):
        return id_ref(v)
    if isinstance(v, bpy.types.bpy_struct):
        return rna_value(v, depth + 1, where) if depth < MAX_DEPTH else None
    if isinstance(v, (set, frozenset)):  # enum flags
        return sorted(v)
    if hasattr(v, "to_dict"):  # IDPropertyGroup
        return {str(k): py_value(x, f"{where}[{k!r}]", depth) for k, x in v.to_dict().items()}
    if hasattr(v, "to_list"):  # IDPropertyArray
        return [py_value(x, where, depth) for x in v.to_list()]
    if isinstance(v, dict):
        return {str(k): py_value(x, f"{where}[{k!r}]", depth) for k, x in v.items()}
    if isinstance(v, (bytes, bytearray)):
        return v.decode("utf-8", "replace")
    try:  # bpy arrays (possibly nested), mathutils Vector/Color/Euler/Quaternion/Matrix rows
        return [py_value(x, where, depth) for x in v]
    except TypeError:
        return str(v)


def rna_value(struct_, depth=0, where="", skip=()):
    """All RNA properties of `struct_` (walked through bl_rna.properties, no hand list):
    ID pointers as {"id_type", "name"}, non-ID structs recursively up to MAX_DEPTH,
    collections as lists. Properties that cannot be read are skipped."""
    out = {}
    is_id = isinstance(struct_, bpy.types.ID)
    try:
        props = list(struct_.bl_rna.properties)
        skip = set(skip) | UNSAFE_RNA.get(struct_.bl_rna.identifier, frozenset())
    except Exception:
        return out
    for prop in props:
        ident = prop.identifier
        if ident == "rna_type" or ident in skip or (is_id and ident in ID_BASE):
            continue
        w = f"{where}.{ident}"
        try:
            value = getattr(struct_, ident)
        except Exception:  # context-dependent or unsupported in this build: leave out
            continue
        try:
            if prop.type == "POINTER":
                if value is None:
                    out[ident] = None
                elif isinstance(value, bpy.types.ID):
                    out[ident] = id_ref(value)
                elif depth < MAX_DEPTH:
                    out[ident] = rna_value(value, depth + 1, w)
            elif prop.type == "COLLECTION":
                if depth < MAX_DEPTH:
                    out[ident] = [id_ref(x) if isinstance(x, bpy.types.ID) else rna_value(x, depth + 1, f"{w}[{i}]")
                                  for i, x in enumerate(value)]
            else:
                if getattr(prop, "is_array", False) and len(value) > MAX_ARRAY:
                    continue
                out[ident] = py_value(value, w, depth)
        except Exception as e:
            WARNINGS.append(f"{w}: not exported ({e})")
    return out


def sanitize(v, path, warnings):
    """Makes every float finite (FORMAT.md): ±inf clamps to ±FLT_MAX, NaN becomes 0 and
    is reported with its JSON path."""
    if isinstance(v, float):
        if math.isfinite(v):
            return v
        if math.isnan(v):
            warnings.append(f"{path}: NaN replaced by 0")
            return 0.0
        return FLT_MAX if v > 0 else -FLT_MAX
    if isinstance(v, dict):
        return {k: sanitize(x, f"{path}.{k}" if path else k, warnings) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [sanitize(x, f"{path}[{i}]", warnings) for i, x in enumerate(v)]
    return v


# ---------------------------------------------------------------- node trees

SOCKET_NO_DEFAULT = {"SHADER", "GEOMETRY", "CUSTOM"}


def socket_entry(s, index, where):
    # A socket of an add-on that is not installed (NodeSocketUndefined) reports type VALUE
    # but holds no value: it is CUSTOM, what Blender calls sockets it has no type for.
    kind = "CUSTOM" if s.bl_idname == "NodeSocketUndefined" else s.type
    d = {"index": index, "identifier": s.identifier, "name": s.name, "type": kind, "bl_idname": s.bl_idname,
         "is_linked": s.is_linked, "hide": s.hide, "enabled": s.enabled, "hide_value": s.hide_value,
         "is_multi_input": s.is_multi_input}
    if kind not in SOCKET_NO_DEFAULT and hasattr(s, "default_value"):
        try:
            d["default_value"] = py_value(s.default_value, f"{where}.default_value", 0)
        except Exception as e:
            WARNINGS.append(f"{where}.default_value: not exported ({e})")
    return d


def ies_content(n, where):
    """The photometric data Cycles loads for an IES Texture node: the Text's content, or
    the file's, read under the same path policy as images; "\n" (which Cycles fails to
    parse, so every lookup is 100) where it finds none."""
    if n.mode == "INTERNAL":
        return (n.ies.as_string() if n.ies is not None else "") or "\n"
    src = bpy.path.abspath(n.filepath, library=n.id_data.library) if n.filepath else ""
    if not (src and os.path.isfile(src)):
        WARNINGS.append(f"{where}: IES file {n.filepath!r} not found (Cycles renders such a texture as 100)")
        return "\n"
    real = os.path.realpath(src)
    if not any(os.path.commonpath([real, root]) == root for root in ALLOWED_ROOTS):
        fail(f"{where}: IES file {n.filepath!r} resolves to {real}, outside the .blend's folder "
             f"{ALLOWED_ROOTS[0]}; if you trust this file, allow its folder with --allow-path "
             f"{os.path.dirname(real)} (or load it into a Text in the .blend)")
    if os.path.getsize(real) > (16 << 20):
        fail(f"{where}: IES file {real} is over 16 MB: not photometric data")
    # Bytes as Latin-1 characters: Cycles parses bytes, and only ASCII digits matter.
    with open(real, "rb") as f:
        return f.read().decode("latin-1")


# Where Point Density grids go (set by main) and how many were written.
POINT_DENSITY = {"out": None, "count": 0}
# The node properties Blender's point density grid depends on.
POINT_DENSITY_PROPS = ("point_source", "object", "particle_system", "resolution", "radius", "space",
                       "particle_color_source", "vertex_color_source", "vertex_attribute_name")
# Largest grid side written (256^3 RGBA floats are 256 MB).
POINT_DENSITY_MAX_RESOLUTION = 256


def point_density_grid(n, where):
    """The voxel grid Cycles renders a Point Density node with: Blender computes it at sync
    (`calc_point_density` on the render depsgraph, Cycles' BlenderPointDensityLoader) over
    the bounds `calc_point_density_minmax` gives; written as RGBA float32, x fastest. The
    properties it depends on are recorded, so blendsynth can refuse an override of them."""
    res = n.resolution
    if res > POINT_DENSITY_MAX_RESOLUTION:
        fail(f"{where}: Point Density resolution {res} is over {POINT_DENSITY_MAX_RESOLUTION}")
    scene = bpy.context.scene
    entry = {"resolution": res, "frame": scene.frame_current + scene.frame_subframe,
             "properties": {k: v for k, v in rna_value(n, 0, where, skip=NODE_BASE).items() if k in POINT_DENSITY_PROPS},
             "object_matrix": [list(r) for r in n.object.matrix_world] if n.object else None}
    with RenderSettings():
        dg = bpy.context.evaluated_depsgraph_get()
        # As Cycles: the bounds from the cache, then the grid (sampling frees the cache).
        n.cache_point_density(depsgraph=dg)
        mn, mx = n.calc_point_density_minmax(depsgraph=dg)
        values = np.array(n.calc_point_density(depsgraph=dg), dtype="<f4")
    if values.size != res ** 3 * 4:
        fail(f"{where}: Blender's point density grid has {values.size} values, not {res}^3 x 4")
    rel = f"point_density/{POINT_DENSITY['count']:04d}.bin"
    POINT_DENSITY["count"] += 1
    os.makedirs(os.path.join(POINT_DENSITY["out"], "point_density"), exist_ok=True)
    with open(os.path.join(POINT_DENSITY["out"], rel), "wb") as f:
        f.write(values.tobytes())
    return entry | {"file": rel, "min": vec(mn), "max": vec(mx)}


def zone_pairing(n):
    """A zone input node (Repeat, For Each Element, Simulation) names its output node:
    the pointer is a node, which the generic walk would write out whole."""
    paired = getattr(n, "paired_output", None)
    return {"paired_output": paired.name} if isinstance(paired, bpy.types.Node) else {}


def node_entry(n, where):
    group = getattr(n, "node_tree", None)
    extra = {"ies": ies_content(n, where)} if n.bl_idname == "ShaderNodeTexIES" else {}
    if n.bl_idname == "ShaderNodeTexPointDensity":
        extra = {"point_density": point_density_grid(n, where)}
    return extra | {
        "name": n.name, "bl_idname": n.bl_idname, "label": n.label, "mute": n.mute,
        "parent": n.parent.name if n.parent else None,
        "location": [n.location[0], n.location[1]], "hide": n.hide,
        "node_tree": key(group) if isinstance(group, bpy.types.NodeTree) else None,
        "properties": rna_value(n, 0, where, skip=NODE_BASE | {"paired_output"}) | zone_pairing(n),
        "inputs": [socket_entry(s, i, f"{where}.inputs[{i}]") for i, s in enumerate(n.inputs)],
        "outputs": [socket_entry(s, i, f"{where}.outputs[{i}]") for i, s in enumerate(n.outputs)],
    }


def link_entry(l, out_index, in_index):
    d = {"from_node": l.from_node.name, "from_socket": l.from_socket.identifier,
         "from_index": out_index[l.from_node.name][l.from_socket.as_pointer()],
         "to_node": l.to_node.name, "to_socket": l.to_socket.identifier,
         "to_index": in_index[l.to_node.name][l.to_socket.as_pointer()],
         "is_muted": l.is_muted, "is_valid": l.is_valid}
    # Extra key (readers ignore unknown keys): the order of links into a multi-input
    # socket (Join Geometry) is this id, not their order in tree.links.
    if hasattr(l, "multi_input_sort_id"):
        d["multi_input_sort_id"] = l.multi_input_sort_id
    return d


def interface_entry(item, where):
    parent = getattr(item, "parent", None)
    d = {"item_type": item.item_type, "name": item.name,
         # Top-level items have the unnamed root panel as parent: report that as null.
         "parent": parent.name if parent is not None and parent.parent is not None else None}
    if item.item_type == "SOCKET":
        d.update({"in_out": item.in_out, "identifier": item.identifier, "socket_type": item.socket_type})
        for k in ("default_value", "min_value", "max_value"):
            if hasattr(item, k):
                try:
                    d[k] = py_value(getattr(item, k), f"{where}.{k}", 0)
                except Exception as e:
                    WARNINGS.append(f"{where}.{k}: not exported ({e})")
    # interface_items of a panel repeats its children, which items_tree lists anyway.
    d["properties"] = rna_value(item, 0, where, skip={"parent", "default_value", "min_value", "max_value", "interface_items"})
    return d


def node_tree_entry(tree, where):
    # Socket positions by pointer: links name sockets by identifier and index.
    out_index = {n.name: {s.as_pointer(): i for i, s in enumerate(n.outputs)} for n in tree.nodes}
    in_index = {n.name: {s.as_pointer(): i for i, s in enumerate(n.inputs)} for n in tree.nodes}
    interface = []
    if getattr(tree, "interface", None) is not None:
        interface = [interface_entry(it, f"{where}.interface.items_tree[{i}]") for i, it in enumerate(tree.interface.items_tree)]
    return {
        "name": key(tree), "bl_idname": tree.bl_idname, "interface": interface,
        "nodes": [node_entry(n, f"{where}.nodes[{q(n.name)}]") for n in tree.nodes],
        "links": [link_entry(l, out_index, in_index) for l in tree.links],
    }


# ---------------------------------------------------------------- meshes (glb)

def safe_name(index, name):
    return f"{index:04d}_{re.sub(r'[^A-Za-z0-9._-]', '_', name)[:80]}.glb"


class Glb:
    """Accumulates accessors in one BIN buffer and writes a glb (no Blender glTF exporter:
    it would split vertices, and the exact Blender topology is the point)."""

    def __init__(self, name):
        self.name, self.chunks, self.offset, self.views, self.accessors = name, [], 0, [], []

    def add(self, array, gltf_type, component, what):
        a = np.ascontiguousarray(array)
        if a.shape[0] == 0:
            return None  # FORMAT.md: accessors with zero elements are omitted
        if a.dtype.kind == "f" and not np.isfinite(a).all():
            if np.isnan(a).any():
                WARNINGS.append(f"{self.name}: {what}: NaN replaced by 0")
            a = np.nan_to_num(a, nan=0.0, posinf=FLT_MAX, neginf=-FLT_MAX)
        data = a.tobytes()
        self.views.append({"buffer": 0, "byteOffset": self.offset, "byteLength": len(data)})
        acc = {"bufferView": len(self.views) - 1, "componentType": component, "count": int(a.shape[0]), "type": gltf_type}
        if gltf_type == "VEC3" and component == 5126:  # glTF requires bounds on POSITION
            acc["min"] = [float(x) for x in a.min(axis=0)]
            acc["max"] = [float(x) for x in a.max(axis=0)]
        self.accessors.append(acc)
        self.chunks.append(data)
        pad = (-len(data)) % 4  # every view starts 4-byte aligned
        self.chunks.append(b"\0" * pad)
        self.offset += len(data) + pad
        return len(self.accessors) - 1

    def write(self, path, extras, primitive):
        binary = b"".join(self.chunks)
        doc = {"asset": {"version": "2.0", "generator": f"blendsynth export_scene.py v{EXPORTER_VERSION}"},
               "extras": {"blendsynth": extras}}
        if binary:
            doc.update({"buffers": [{"byteLength": len(binary)}], "bufferViews": self.views, "accessors": self.accessors})
        if primitive:
            doc["meshes"] = [{"name": self.name, "primitives": [primitive]}]
            doc["nodes"] = [{"mesh": 0, "name": self.name}]
            doc["scenes"] = [{"nodes": [0]}]
            doc["scene"] = 0
        js = json.dumps(doc, allow_nan=False, separators=(",", ":")).encode()
        js += b" " * ((-len(js)) % 4)
        body = struct.pack("<II", len(js), 0x4E4F534A) + js
        if binary:
            body += struct.pack("<II", len(binary), 0x004E4942) + binary
        tmp = path + ".tmp"
        with open(tmp, "wb") as f:
            f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(body)))
            f.write(body)
        os.replace(tmp, path)


def get(coll, attr, n, width, dtype):
    """foreach_get into a numpy array. dtypes match Blender's raw storage (uint32 for
    index fields, int32 for INT attributes) so the fast memcpy path is taken."""
    a = np.empty(n * width, dtype=dtype)
    if n:
        coll.foreach_get(attr, a)
    return a.reshape(n, width) if width > 1 else a


# data_type -> (foreach field, width, numpy dtype, glTF type, glTF component type)
ATTR_LAYOUT = {
    "FLOAT": ("value", 1, np.float32, "SCALAR", 5126),
    "FLOAT2": ("vector", 2, np.float32, "VEC2", 5126),
    "FLOAT_VECTOR": ("vector", 3, np.float32, "VEC3", 5126),
    "FLOAT_COLOR": ("color", 4, np.float32, "VEC4", 5126),
    "BYTE_COLOR": ("color", 4, np.float32, "VEC4", 5126),   # `color` is scene linear
    "QUATERNION": ("value", 4, np.float32, "VEC4", 5126),   # w, x, y, z
    "FLOAT4X4": ("value", 16, np.float32, "MAT4", 5126),    # foreach_get is column-major, as glTF
    "INT": ("value", 1, np.int32, "SCALAR", 5125),
    "INT32_2D": ("value", 2, np.int32, "VEC2", 5125),
    "INT8": ("value", 1, np.int8, "SCALAR", 5120),
    "BOOLEAN": ("value", 1, np.bool_, "SCALAR", 5121),
}

TOPOLOGY_LAYOUT = {  # extras key -> (glTF type, component)
    "vertex_positions": ("VEC3", 5126), "edge_verts": ("VEC2", 5125), "face_offsets": ("SCALAR", 5125),
    "corner_verts": ("SCALAR", 5125), "corner_edges": ("SCALAR", 5125), "corner_normals": ("VEC3", 5126),
    "triangle_corners": ("SCALAR", 5125), "triangle_faces": ("SCALAR", 5125),
}


def mesh_arrays(me, where):
    """Blender's exact mesh as numpy arrays: (counts, arrays, attributes, uv names)."""
    nv, ne, nf, nc = len(me.vertices), len(me.edges), len(me.polygons), len(me.loops)
    me.calc_loop_triangles()
    nt = len(me.loop_triangles)
    arrays = {
        "vertex_positions": get(me.vertices, "co", nv, 3, np.float32),
        "edge_verts": get(me.edges, "vertices", ne, 2, np.uint32),
        "corner_verts": get(me.loops, "vertex_index", nc, 1, np.uint32),
        "corner_edges": get(me.loops, "edge_index", nc, 1, np.uint32),
        "triangle_corners": get(me.loop_triangles, "loops", nt, 3, np.uint32).reshape(-1),
        "triangle_faces": get(me.loop_triangles, "polygon_index", nt, 1, np.uint32),
    }
    if nf:
        starts = get(me.polygons, "loop_start", nf, 1, np.uint32)
        arrays["face_offsets"] = np.append(starts, np.uint32(nc)).astype(np.uint32)
        if hasattr(me, "corner_normals"):  # Blender 4.1+
            arrays["corner_normals"] = get(me.corner_normals, "vector", nc, 3, np.float32)
        else:
            me.calc_normals_split()
            arrays["corner_normals"] = get(me.loops, "normal", nc, 3, np.float32)
    else:
        arrays["face_offsets"] = np.zeros(0, np.uint32)
    attrs = []
    for a in me.attributes:
        if a.name.startswith(".") or a.name == "position":
            continue
        layout = ATTR_LAYOUT.get(a.data_type)
        if layout is None:  # STRING, INT16_2D: not in format version 1
            WARNINGS.append(f'{where}.attributes[{q(a.name)}]: data type {a.data_type} not exported')
            continue
        field, width, dtype, _, _ = layout
        attrs.append((a.name, a.domain, a.data_type, get(a.data, field, len(a.data), width, dtype)))
    return (nv, ne, nf, nc, nt), arrays, attrs, [uv.name for uv in me.uv_layers]


def write_mesh_glb(path, name, counts, arrays, attrs, uv_names):
    nv, ne, nf, nc, nt = counts
    g = Glb(name)
    ex = {"version": 1, "name": name, "vertex_count": nv, "edge_count": ne, "face_count": nf,
          "corner_count": nc, "triangle_count": nt}
    for key, (ty, comp) in TOPOLOGY_LAYOUT.items():
        if key in arrays:
            idx = g.add(arrays[key], ty, comp, key)
            if idx is not None:
                ex[key] = idx
    ex["attributes"] = []
    uv_data = {}
    for aname, domain, dtype, data in attrs:
        _, _, _, ty, comp = ATTR_LAYOUT[dtype]
        idx = g.add(data.astype(np.uint8) if dtype == "BOOLEAN" else data, ty, comp, f"attribute {aname}")
        if idx is not None:
            ex["attributes"].append({"name": aname, "domain": domain, "data_type": dtype, "accessor": idx})
            if domain == "CORNER" and dtype == "FLOAT2":
                uv_data[aname] = data
    primitive = None
    if nt:
        # The viewable primitive: one glTF vertex per face corner, so corner normals and
        # UV seams need no vertex splitting; indices are the loop triangles' corners.
        prim = {"attributes": {"POSITION": g.add(arrays["vertex_positions"][arrays["corner_verts"]], "VEC3", 5126, "POSITION")},
                "indices": ex["triangle_corners"], "mode": 4}
        if "corner_normals" in ex:
            prim["attributes"]["NORMAL"] = ex["corner_normals"]
        for i, uv in enumerate(n for n in uv_names if n in uv_data):
            flipped = uv_data[uv].copy()
            flipped[:, 1] = 1.0 - flipped[:, 1]  # glTF's v runs top-down
            prim["attributes"][f"TEXCOORD_{i}"] = g.add(flipped, "VEC2", 5126, f"TEXCOORD_{i}")
        primitive = prim
    g.write(path, ex, primitive)


def concat_meshes(parts):
    """Joins mesh_arrays() results into one mesh, offsetting indices. Attributes are kept
    where every non-empty part has them with the same domain and type."""
    parts = [p for p in parts if p[0][0] > 0] or parts[:1]
    if len(parts) == 1:
        return parts[0]
    keys = ["vertex_positions", "edge_verts", "corner_verts", "corner_edges", "triangle_corners",
            "triangle_faces", "corner_normals"]
    out = {k: [] for k in keys}
    face_offsets = [np.zeros(1, np.uint32)]
    nv = ne = nc = nf = 0
    for (pv, pe, pf, pc, _), arrays, _, _ in parts:
        out["vertex_positions"].append(arrays["vertex_positions"])
        out["edge_verts"].append(arrays["edge_verts"] + np.uint32(nv))
        out["corner_verts"].append(arrays["corner_verts"] + np.uint32(nv))
        out["corner_edges"].append(arrays["corner_edges"] + np.uint32(ne))
        out["triangle_corners"].append(arrays["triangle_corners"] + np.uint32(nc))
        out["triangle_faces"].append(arrays["triangle_faces"] + np.uint32(nf))
        out["corner_normals"].append(arrays.get("corner_normals", np.zeros((pc, 3), np.float32)))
        if pf:
            face_offsets.append(arrays["face_offsets"][1:] + np.uint32(nc))
        nv, ne, nc, nf = nv + pv, ne + pe, nc + pc, nf + pf
    arrays = {k: np.concatenate(v) for k, v in out.items()}
    arrays["face_offsets"] = np.concatenate(face_offsets) if nf else np.zeros(0, np.uint32)
    if not nf:
        del arrays["corner_normals"]
    common = None
    for _, _, attrs, _ in parts:
        sig = [(a[0], a[1], a[2]) for a in attrs]
        common = sig if common is None else [s for s in common if s in sig]
    attrs = [(n, dom, dt, np.concatenate([d for _, _, pa, _ in parts for (pn, pd, pt, d) in pa if (pn, pd, pt) == (n, dom, dt)]))
             for n, dom, dt in common or []]
    uv_names = [u for u in parts[0][3] if all(u in p[3] for p in parts)]
    return (nv, ne, nf, nc, len(arrays["triangle_faces"])), arrays, attrs, uv_names


def transform_part(part, m):
    """Moves a mesh_arrays() result by the 4x4 matrix m (positions and corner normals)."""
    counts, arrays, attrs, uvs = part
    p = arrays["vertex_positions"].astype(np.float64)
    arrays["vertex_positions"] = (p @ m[:3, :3].T + m[:3, 3]).astype(np.float32)
    if "corner_normals" in arrays:
        n = arrays["corner_normals"].astype(np.float64) @ np.linalg.inv(m[:3, :3])  # inverse transpose
        n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
        arrays["corner_normals"] = n.astype(np.float32)
    return counts, arrays, attrs, uvs


NON_GEOMETRY = {"EMPTY", "LIGHT", "CAMERA", "SPEAKER", "LIGHT_PROBE", "ARMATURE", "LATTICE"}


def empty_part():
    """mesh_arrays() of an empty mesh (an object with no mesh of its own, e.g. an empty
    instancing a collection)."""
    me = bpy.data.meshes.new("blendsynth-empty")
    try:
        return mesh_arrays(me, "empty")
    finally:
        bpy.data.meshes.remove(me)


def with_materials(part, materials, slots):
    """The part with its face material indices moved into the owner's slot list
    `materials` (extended with the part's `slots`), so joined parts keep their materials."""
    counts, arrays, attrs, uvs = part
    nf = counts[2]
    base = len(materials)
    materials.extend(slots or [None])
    idx = next((d for n, dom, dt, d in attrs if n == "material_index" and dom == "FACE" and dt == "INT"), None)
    idx = np.zeros(nf, np.int32) if idx is None else idx.reshape(-1).astype(np.int32)
    idx = np.clip(idx, 0, max(len(slots) - 1, 0)) + base
    attrs = [a for a in attrs if a[0] != "material_index"] + [("material_index", "FACE", "INT", idx.astype(np.int32))]
    return counts, arrays, attrs, uvs


def slot_materials(ob, me):
    """An evaluated object's material per slot, object-linked slots included."""
    if ob is not None and len(ob.material_slots):
        return [key(s.material) if s.material else None for s in ob.material_slots]
    return [key(m) if m else None for m in me.materials]


NESTED_INSTANCER_PREFIX = ".instancer."


class InstancerValues:
    """Instancer attribute values (Attribute node, type Instancer) of the instances an
    object's Geometry Nodes make, as Blender's find_geonode_attribute_rgba reads them: the
    instance-domain attribute of the innermost nesting level that has it, at that level's
    instance index (DepsgraphObjectInstance.persistent_id); else the instancer object's,
    then its data's, custom property or RNA path (find_rna_property_rgba); else zero."""

    def __init__(self, ob, ev, names):
        self.names = names
        self.fallback = {n: rna_rgba(ob, n) or rna_rgba(ob.data, n) or (0.0, 0.0, 0.0, 0.0) for n in names}
        try:
            self.root = ev.evaluated_geometry() if names else None
        except (AttributeError, RuntimeError):
            self.root = None
        self.levels = {}

    def level(self, path):
        """(instance attributes by name, references) of the instances at reference path."""
        if path not in self.levels:
            gs = self.root
            for r in path:
                gs = gs.instance_references()[r] if gs is not None else None
                if not isinstance(gs, bpy.types.GeometrySet):
                    gs = None
                    break
            pc = gs.instances_pointcloud() if gs is not None else None
            attrs, ref = {}, None
            if pc is not None:
                n = len(pc.points)
                for name in self.names + [".reference_index"]:
                    a = pc.attributes.get(name)
                    if a is None or a.domain != "POINT":
                        continue
                    if name == ".reference_index":
                        ref = np.zeros(n, np.int32)
                        a.data.foreach_get("value", ref)
                        continue
                    v = np.zeros(n * 4, np.float32)
                    if a.data_type in ("FLOAT_COLOR", "BYTE_COLOR"):
                        a.data.foreach_get("color", v)
                        v = v.reshape(n, 4)
                    elif a.data_type == "FLOAT_VECTOR":
                        w = np.zeros(n * 3, np.float32)
                        a.data.foreach_get("vector", w)
                        v = np.concatenate([w.reshape(n, 3), np.ones((n, 1), np.float32)], 1)
                    elif a.data_type in ("FLOAT", "INT", "BOOLEAN"):
                        w = np.zeros(n, np.float32 if a.data_type == "FLOAT" else np.int32 if a.data_type == "INT" else bool)
                        a.data.foreach_get("value", w)
                        w = w.astype(np.float32)
                        v = np.stack([w, w, w, np.ones(n, np.float32)], 1)
                    else:
                        continue
                    attrs[name] = v
            self.levels[path] = (attrs, ref)
        return self.levels[path]

    def of(self, persistent_id):
        """name -> RGBA for the instance with this persistent id (Blender orders it
        innermost level first, INT_MAX past the last level)."""
        ids = []
        for idx in persistent_id:
            if idx < 0 or idx == 2147483647:
                break
            ids.append(idx)
        found, path = {}, ()
        for idx in reversed(ids):
            attrs, ref = self.level(path)
            if not attrs and ref is None:
                break
            for name, v in attrs.items():
                if idx < len(v):
                    found[name] = tuple(float(x) for x in v[idx])  # inner levels overwrite outer
            if ref is None or idx >= len(ref):
                break
            path = path + (int(ref[idx]),)
        return {n: found.get(n, self.fallback[n]) for n in self.names}


def with_instancer_values(part, values):
    """The part with one constant point attribute per Instancer name (NESTED_INSTANCER_PREFIX
    + name): instances realised into one mesh keep their own value."""
    counts, arrays, attrs, uvs = part
    nv = counts[0]
    extra = [(NESTED_INSTANCER_PREFIX + n, "POINT", "FLOAT_COLOR", np.tile(np.array(v, np.float32), (nv, 1)))
             for n, v in sorted(values.items())]
    return counts, arrays, attrs + extra, uvs


# Per object: the point clouds its evaluation makes as instances (`evaluated_meshes`):
# (keys, matrix into the object's space, material).
POINT_CLOUDS = {}


def pointcloud_keys(pc):
    """x, y, z, radius per point of a point cloud as Cycles' export_pointcloud reads it:
    the `radius` point attribute, 0.01 where there is none."""
    n = len(pc.points)
    keys = np.zeros((n, 4), np.float64)
    pos = np.zeros(n * 3, np.float32)
    pc.attributes["position"].data.foreach_get("vector", pos)
    keys[:, :3] = pos.reshape(-1, 3)
    radius = pc.attributes.get("radius")
    if radius is not None and radius.domain == "POINT" and radius.data_type == "FLOAT":
        r = np.zeros(n, np.float32)
        radius.data.foreach_get("value", r)
        keys[:, 3] = r
    else:
        keys[:, 3] = 0.01
    return keys


def export_points(objs, out, index, frozen_meshes, depsgraph):
    """Each object's point clouds (a point cloud object's own points, and those its
    Geometry Nodes make as instances) in points/, by object name, in the object's space
    (radii scaled by the cube root of the instance transform's determinant, as Cycles
    scales them): x, y, z, radius per point (float32), then each point's index into the
    entry's `materials` (uint32; each cloud's first material is appended there)."""
    got = {}
    for o in objs:
        clouds = list(POINT_CLOUDS.get(key(o), []))
        if o.type == "POINTCLOUD":
            ev = o.evaluated_get(depsgraph)
            if len(ev.data.points):
                clouds.insert(0, (pointcloud_keys(ev.data), np.identity(4), (slot_materials(ev, ev.data)[:1] or [None])[0]))
        if not clouds:
            continue
        mats = frozen_meshes[key(o)][2]
        keys, slots = [], []
        for k, m, mat in clouds:
            k = k.copy()
            k[:, :3] = k[:, :3] @ m[:3, :3].T + m[:3, 3]
            k[:, 3] *= abs(np.linalg.det(m[:3, :3])) ** (1.0 / 3.0)
            keys.append(k)
            slots.append(np.full(len(k), len(mats), np.uint32))
            mats.append(mat)
        rel = f"points/{safe_name(index[key(o)], key(o))[:-4]}.bin"
        os.makedirs(os.path.join(out, "points"), exist_ok=True)
        with open(os.path.join(out, rel), "wb") as f:
            f.write(np.concatenate(keys).astype("<f4").tobytes())
            f.write(np.concatenate(slots).astype("<u4").tobytes())
        got[key(o)] = {"file": rel, "count": int(sum(len(k) for k in keys))}
    return got


def evaluated_meshes(objs, depsgraph):
    """For each object: its evaluated mesh plus the instances it generates (realised),
    in its local space, and the material slots its faces index. One pass over
    depsgraph.object_instances (instance objects are only valid during their iteration
    step, so each is converted right away)."""
    parts, realized_parts, inverse, mats, uvinfo, inst_values = {}, {}, {}, {}, {}, {}
    lookup = [n for n in ATTRIBUTE_LOOKUP_NAMES]
    for o in objs:
        ev = o.evaluated_get(depsgraph)
        mats[key(o)] = []
        inst_values[key(o)] = InstancerValues(o, ev, lookup) if lookup and any(
            m.type == "NODES" for m in o.modifiers) else None
        try:
            me = ev.to_mesh()
        except RuntimeError:
            me = None
        instancer = o.instance_type != "NONE" or any(m.type == "PARTICLE_SYSTEM" for m in o.modifiers)
        if me is not None and instancer and not o.show_instancer_for_render:
            # Object > Instancing > Show Instancer > Render off: only the instances render.
            ev.to_mesh_clear()
            me = None
        if me is None:
            parts[key(o)] = [empty_part()]
            uvinfo[key(o)] = ([], None, None)
        else:
            try:
                part = mesh_arrays(me, f"evaluated[{q(key(o))}]")
                parts[key(o)] = [with_materials(part, mats[key(o)], slot_materials(ev, me))]
                uvinfo[key(o)] = ([uv.name for uv in me.uv_layers],
                                  next((uv.name for uv in me.uv_layers if uv.active_render), None),
                                  getattr(me.attributes, "default_color_name", None) or None)
            finally:
                ev.to_mesh_clear()
        realized_parts[key(o)] = []
        inverse[key(o)] = np.linalg.inv(np.array(ev.matrix_world, dtype=np.float64))
    for inst in depsgraph.object_instances:
        if not inst.is_instance or inst.parent is None:
            continue
        owner = key(inst.parent.original)
        if owner not in parts:
            continue
        io = inst.object  # the instanced geometry (inst.parent is the instancer)
        if io.type in NON_GEOMETRY:
            continue
        if io.type == "POINTCLOUD":
            # Cycles renders these points as spheres: exported apart (`export_points`).
            if len(io.data.points):
                POINT_CLOUDS.setdefault(owner, []).append(
                    (pointcloud_keys(io.data), inverse[owner] @ np.array(inst.matrix_world, dtype=np.float64),
                     (slot_materials(io, io.data)[:1] or [None])[0]))
            continue
        try:
            ime = io.to_mesh()
        except RuntimeError:
            continue
        if ime is None:
            continue
        try:
            part = mesh_arrays(ime, f"evaluated[{q(owner)}].instance")
            part = with_materials(part, mats[owner], slot_materials(io, ime))
            if inst_values[owner] is not None:
                part = with_instancer_values(part, inst_values[owner].of(list(inst.persistent_id)))
            texspace = (vec(ime.texspace_location), vec(ime.texspace_size)) if io.type == "MESH" else None
        finally:
            io.to_mesh_clear()
        rel = inverse[owner] @ np.array(inst.matrix_world, dtype=np.float64)
        parts[owner].append(transform_part(part, rel))
        realized_parts[owner].append(realized_instance(part[0], rel, inst, io, texspace, particle_state(inst)))
    for name, iv in inst_values.items():
        if iv is not None and realized_parts[name]:
            # The instancer's own geometry reads the object's value (no instance layer).
            parts[name][0] = with_instancer_values(parts[name][0], dict(iv.fallback))
    realized = {name: {"own_counts": list(map(int, p[0][0])), "instances": realized_parts[name]} if realized_parts[name] else None
                for name, p in parts.items()}
    return {name: (concat_meshes(p), realized[name], mats[name], uvinfo[name]) for name, p in parts.items()}


def realized_instance(counts, rel, inst, io, texspace, particle):
    """What Cycles would give an instance realised into its instancer's evaluated mesh,
    which it renders as an object of its own: the part's element counts (parts follow
    each other in every domain), its transform in the instancer's space, its Object
    Info values (DepsgraphObjectInstance.random_id, the instanced object's colour and pass
    index), mesh texture space (Generated) and particle (`particle_state`)."""
    return {"counts": list(map(int, counts)), "matrix": [list(map(float, r)) for r in rel],
            "random_id": int(inst.random_id) & 0xFFFFFFFF, "object": io.original.name,
            "color": vec(io.color), "pass_index": int(io.pass_index),
            "texspace_location": texspace[0] if texspace else None,
            "texspace_size": texspace[1] if texspace else None,
            "particle": particle}


def particle_state(inst):
    """The particle an instance stands for, as Cycles' sync_dupli_particle reads it for
    Particle Info: its index among the system's particles (persistent_id[0]), age
    (frame_current_final - birth time), lifetime, location, size, velocity and angular
    velocity at the frame. None when no particle system made the instance, or for a
    child particle (Cycles then gives the instance its dummy particle)."""
    psys = inst.particle_system
    if psys is None:
        return None
    i = int(inst.persistent_id[0])
    if i < 0 or i >= len(psys.particles):
        return None
    pa = psys.particles[i]
    return {"index": i, "age": bpy.context.scene.frame_current_final - pa.birth_time,
            "lifetime": pa.lifetime, "location": vec(pa.location), "size": pa.size,
            "velocity": vec(pa.velocity), "angular_velocity": vec(pa.angular_velocity)}


def hair_strands(o, depsgraph, path):
    """The strands Cycles renders for an object's hair particle systems (render type Path),
    as Cycles' blender/curves.cpp syncs them: children only when the system has children,
    else the parents; (1 << render_step) + 1 keys each (plus the spiral kink's extra
    steps), from the evaluated path cache (BKE_particle_co_hair) in object space; per key
    the radius of the shape between the root and tip radii by the key's length fraction.
    Writes x, y, z, radius per key (little-endian float32) to `path`; returns the
    systems' entries, or None when the object has no strands."""
    ev = o.evaluated_get(depsgraph)
    inverse = np.linalg.inv(np.array(ev.matrix_world, dtype=np.float64))
    n_slots = max(len(ev.material_slots), 1)
    systems, chunks = [], []
    for _, psys, first, count in rendered_path_systems(ev):
        st = psys.settings
        steps = (1 << st.render_step) + 1
        if st.kink == "SPIRAL":
            steps += st.kink_extra_steps
        root = st.radius_scale * 0.5 * st.root_radius
        tip = st.radius_scale * 0.5 * st.tip_radius
        keys = np.zeros((count, steps, 4), dtype=np.float64)
        for c in range(count):
            prev = (0.0, 0.0, 0.0)
            for s in range(steps):
                co = psys.co_hair(ev, particle_no=first + c, step=s)
                # co_hair leaves a step the cache lacks unset: Cycles keeps the previous key.
                w = tuple(co) if co is not None else prev
                keys[c, s, :3] = w
                prev = w
        pts = keys[:, :, :3] @ inverse[:3, :3].T + inverse[:3, 3]
        keys[:, :, :3] = pts
        seg = np.linalg.norm(np.diff(pts, axis=1), axis=2)
        along = np.concatenate([np.zeros((count, 1)), np.cumsum(seg, axis=1)], axis=1)
        total = along[:, -1:]
        time_ = np.where(total > 0.0, along / np.where(total > 0.0, total, 1.0), 0.0)
        radius = 1.0 - time_
        if st.shape < 0.0:
            radius = radius ** (1.0 + st.shape)
        elif st.shape > 0.0:
            radius = radius ** (1.0 / (1.0 - st.shape))
        radius = radius * (root - tip) + tip
        if st.use_close_tip:
            radius[:, -1] = 0.0
        keys[:, :, 3] = radius
        chunks.append(keys.astype("<f4").reshape(-1))
        systems.append({"name": psys.name, "material_slot": min(max(st.material - 1, 0), n_slots - 1),
                        "curve_count": count, "keys_per_curve": steps, "children": first > 0})
    if not systems:
        return None
    with open(path, "wb") as f:
        f.write(np.concatenate(chunks).tobytes())
    return systems


def rendered_path_systems(ev):
    """(modifier, system, first particle, count) of each hair system Cycles renders as
    strands, in `hair_strands`' order."""
    for m in ev.modifiers:
        if m.type != "PARTICLE_SYSTEM" or not m.show_render:
            continue
        psys = m.particle_system
        st = psys.settings
        if st.type != "HAIR" or st.render_type != "PATH":
            continue
        totpart, totchild = len(psys.particles), len(psys.child_particles)
        first = totpart if (st.child_type != "NONE" and totchild) else 0
        if totpart + totchild - first > 0:
            yield m, psys, first, totpart + totchild - first


def particle_hair_attributes(o, depsgraph):
    """What Cycles' blender/curves.cpp gives particle hair from its emitter, per curve:
    each UV map (ObtainCacheParticleUV: the active render one is the hair's UV) and each
    byte colour corner attribute, sRGB-decoded (ObtainCacheParticleVcol), by name.
    Returns ([(name, domain, data_type, float32 array)], uv name)."""
    ev = o.evaluated_get(depsgraph)
    me = o.data
    uv_names = [uv.name for uv in me.uv_layers]
    vcol_names = [a.name for a in me.attributes if a.data_type == "BYTE_COLOR" and a.domain == "CORNER"]
    uvs = {n: [] for n in uv_names}
    cols = {n: [] for n in vcol_names}
    for m, psys, first, count in rendered_path_systems(ev):
        parts = psys.particles
        for c in range(count):
            pa_no = first + c
            # Cycles passes the parent particle for parents and the first one for children.
            pa = parts[pa_no] if pa_no < len(parts) else parts[0]
            for i, n in enumerate(uv_names):
                uvs[n].append(tuple(psys.uv_on_emitter(m, particle=pa, particle_no=pa_no, uv_no=i)))
            for i, n in enumerate(vcol_names):
                cols[n].append(tuple(psys.mcol_on_emitter(m, particle=pa, particle_no=pa_no, vcol_no=i)) + (1.0,))
    attrs = [(n, "CURVE", "FLOAT2", np.array(v, np.float32).reshape(-1, 2)) for n, v in uvs.items() if v]
    for n, v in cols.items():
        if v:
            a = np.array(v, np.float64).reshape(-1, 4)
            rgb = a[:, :3]
            a[:, :3] = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
            attrs.append((n, "CURVE", "FLOAT_COLOR", a.astype(np.float32)))
    render_uv = next((uv.name for uv in me.uv_layers if uv.active_render), None)
    return attrs, render_uv


CURVES_ATTRIBUTE_WIDTH = {"FLOAT": 1, "INT": 1, "INT8": 1, "BOOLEAN": 1, "FLOAT2": 2, "INT32_2D": 2,
                          "FLOAT_VECTOR": 3, "FLOAT_COLOR": 4, "BYTE_COLOR": 4}


def curves_attributes(o, depsgraph):
    """A Curves object's point and curve attributes as Cycles' attr_create_generic reads
    them (numbers as float32, colours linear), by name, and its UV: the first 2D vector
    curve attribute. Types Cycles cannot read in shaders (quaternions, matrices) are left
    out. Returns ([(name, domain, data_type, float32 array)], uv name)."""
    cv = o.evaluated_get(depsgraph).data
    attrs, uv = [], None
    for a in cv.attributes:
        w = CURVES_ATTRIBUTE_WIDTH.get(a.data_type)
        if a.name.startswith(".") or w is None or a.domain not in ("POINT", "CURVE"):
            continue
        n = len(a.data)
        if a.data_type in ("FLOAT_COLOR", "BYTE_COLOR"):
            field = "color"
        elif a.data_type in ("FLOAT_VECTOR", "FLOAT2", "INT32_2D"):
            field = "vector"
        else:
            field = "value"
        dtype = {"BOOLEAN": bool, "INT": np.int32, "INT8": np.int32, "INT32_2D": np.int32}.get(a.data_type, np.float32)
        raw = np.zeros(n * w, dtype)
        try:
            a.data.foreach_get(field, raw)
        except (AttributeError, RuntimeError, TypeError):
            continue
        v = raw.astype(np.float32).reshape(n, w)
        kind = {1: "FLOAT", 2: "FLOAT2", 3: "FLOAT_VECTOR", 4: "FLOAT_COLOR"}[w]
        if uv is None and kind == "FLOAT2" and a.domain == "CURVE":
            uv = a.name
        attrs.append((a.name, a.domain, kind, v))
    return attrs, uv


def write_hair_attributes(entry, attrs, uv, out):
    """Adds the hair attributes to a hair entry: one float32 file of every attribute in
    order, each count x width values."""
    if not attrs:
        return entry
    rel = entry["file"][:-4] + ".attributes.bin"
    with open(os.path.join(out, rel), "wb") as f:
        for _, _, _, v in attrs:
            f.write(v.astype("<f4").tobytes())
    return dict(entry, attributes_file=rel, uv=uv,
                attributes=[{"name": n, "domain": d, "data_type": t} for n, d, t, _ in attrs])


def export_hair(objs, out, index):
    """Each object's hair strands (`hair_strands`) in hair/, by object name: the file and
    its systems."""
    got = {}
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for o in objs:
        if not any(m.type == "PARTICLE_SYSTEM" for m in o.modifiers):
            continue
        rel = f"hair/{safe_name(index[key(o)], key(o))[:-4]}.bin"
        os.makedirs(os.path.join(out, "hair"), exist_ok=True)
        systems = hair_strands(o, depsgraph, os.path.join(out, rel))
        if systems is not None:
            got[key(o)] = write_hair_attributes({"file": rel, "systems": systems},
                                                *particle_hair_attributes(o, depsgraph), out)
    return got


def curves_keys(o, depsgraph, path):
    """The curves Cycles renders for a Curves object (`type == 'CURVES'`, Blender 3.3+ hair),
    as its blender/curves.cpp (export_hair_curves) syncs them from the evaluated Curves:
    the control points as keys whatever the curve type, the `radius` point attribute
    (0.005 where the Curves have none), every curve with the object's first material
    slot. Writes x, y, z, radius per key (object space, little-endian float32), then
    the point count per curve (little-endian uint32) to `path`; returns the system
    entry, or None when there are no curves."""
    cv = o.evaluated_get(depsgraph).data
    n_points, n_curves = len(cv.points), len(cv.curves)
    if n_curves == 0 or n_points == 0:
        return None
    pos = np.zeros(n_points * 3, np.float32)
    cv.points.foreach_get("position", pos)
    keys = np.zeros((n_points, 4), np.float32)
    keys[:, :3] = pos.reshape(-1, 3)
    radius = cv.attributes.get("radius")
    if radius is not None and radius.domain == "POINT" and radius.data_type == "FLOAT":
        r = np.zeros(n_points, np.float32)
        radius.data.foreach_get("value", r)
        keys[:, 3] = r
    else:
        keys[:, 3] = 0.005
    offsets = np.zeros(n_curves + 1, np.int64)
    cv.curve_offset_data.foreach_get("value", offsets)
    counts = np.diff(offsets).astype("<u4")
    with open(path, "wb") as f:
        f.write(keys.astype("<f4").tobytes())
        f.write(counts.tobytes())
    return {"name": key(o.data), "material_slot": 0, "curve_count": n_curves, "keys_per_curve": 0,
            "key_count": n_points, "children": False}


def export_curves(objs, out, index, frozen_meshes):
    """Each Curves object's curves (`curves_keys`) in hair/, by object name, as a hair
    entry of one system; the object's first material slot is appended to its evaluated
    entry's materials (Cycles gives all its curves shader 0: the first slot)."""
    got = {}
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for o in objs:
        if o.type != "CURVES":
            continue
        rel = f"hair/{safe_name(index[key(o)], key(o))[:-4]}.bin"
        os.makedirs(os.path.join(out, "hair"), exist_ok=True)
        system = curves_keys(o, depsgraph, os.path.join(out, rel))
        if system is None:
            continue
        mats = frozen_meshes[key(o)][2]
        ev = o.evaluated_get(depsgraph)
        first = slot_materials(ev, ev.data)[:1] or [None]
        system["material_slot"] = len(mats)
        mats.extend(first)
        entry = {"file": rel, "systems": [system]}
        entry["normals_file"] = curves_normals(o, depsgraph, out, rel[:-4] + ".normals.bin")
        got[key(o)] = write_hair_attributes(entry, *curves_attributes(o, depsgraph), out)
    return got


def curves_normals(o, depsgraph, out, rel):
    """A Curves object's normals at its control points (`Curves.normals`: the evaluated
    normals of each curve's Normal Mode, Minimum Twist, Z Up or Free, at its points), which
    Cycles' export_hair_curves passes as the curves' normal attribute
    (curves_normals_point_domain_calc) and the Principled Hair BSDF's Huang model turns an
    elliptical fibre about. Writes x, y, z per key (object space, little-endian float32)
    to `rel`; returns `rel`."""
    cv = o.evaluated_get(depsgraph).data
    n = np.zeros(len(cv.points) * 3, np.float32)
    cv.normals.foreach_get("vector", n)
    with open(os.path.join(out, rel), "wb") as f:
        f.write(n.astype("<f4").tobytes())
    return rel


FROZEN_TYPES = {"CURVE", "SURFACE", "FONT", "META", "CURVES", "POINTCLOUD"}
ID_COLLECTIONS = {"OBJECT": "objects", "MESH": "meshes", "CURVE": "curves", "CURVES": "hair_curves",
                  "POINTCLOUD": "pointclouds", "KEY": "shape_keys",
                  "ARMATURE": "armatures", "META": "metaballs", "METABALL": "metaballs", "LATTICE": "lattices",
                  "PARTICLE": "particles", "COLLECTION": "collections", "TEXTURE": "textures",
                  "NODETREE": "node_groups", "IMAGE": "images", "FONT": "fonts"}


class RenderSettings:
    """While active, the viewport settings Blender evaluates with are set to their render
    values: the depsgraph Python gets is the viewport's, and Cycles renders with modifiers
    shown in renders only, Subdivision Surface / Multires render levels, Screw render
    steps, particle render
    amounts and curve / metaball render resolutions. Restored on exit, so the export's
    properties stay the file's. (A Geometry Nodes Is Viewport node still reads true.)"""

    def __enter__(self):
        self.saved = []
        for o in bpy.data.objects:
            for m in o.modifiers:
                self.put(m, "show_viewport", m.show_render)
                if m.type in ("SUBSURF", "MULTIRES"):
                    self.put(m, "levels", m.render_levels)
                if m.type == "SCREW":
                    self.put(m, "steps", m.render_steps)
            for ps in getattr(o, "particle_systems", []):
                st = ps.settings
                self.put(st, "display_percentage", 100)
                self.put(st, "child_percent", st.rendered_child_count)
                self.put(st, "display_step", st.render_step)  # hair paths at Cycles' render steps
        for c in bpy.data.curves:
            if c.render_resolution_u > 0:
                self.put(c, "resolution_u", c.render_resolution_u)
            if c.render_resolution_v > 0:
                self.put(c, "resolution_v", c.render_resolution_v)
        for mb in bpy.data.metaballs:
            if mb.render_resolution > 0:
                self.put(mb, "resolution", mb.render_resolution)
        bpy.context.view_layer.update()
        return self

    def put(self, owner, attr, value):
        try:
            old = getattr(owner, attr)
            if old != value:
                setattr(owner, attr, value)
                self.saved.append((owner, attr, old))
        except (AttributeError, TypeError, ValueError):
            pass  # read-only here (linked data): Blender evaluates it as saved

    def __exit__(self, *exc):
        for owner, attr, old in reversed(self.saved):
            setattr(owner, attr, old)
        bpy.context.view_layer.update()
        return False


def frozen_target(o):
    """Whether blendsynth renders this object from its evaluated mesh (it does not build
    it itself): meshes with modifiers (the export keeps these as reference meshes too),
    shape keys or vertex/face instancing; curves, surfaces, text, metaballs; empties
    instancing a collection."""
    if o.type == "MESH":
        return bool(len(o.modifiers)) or getattr(o.data, "shape_keys", None) is not None \
            or o.instance_type in ("VERTS", "FACES")
    if o.type in FROZEN_TYPES:
        return True
    return o.type == "EMPTY" and o.instance_type == "COLLECTION" and o.instance_collection is not None


def id_path(idb):
    return f"{ID_COLLECTIONS.get(idb.id_type, idb.id_type.lower() + 's')}[{q(key(idb))}]"


def under(path, prefix):
    return path == prefix or (path.startswith(prefix) and path[len(prefix)] in ".[")


TIME_MODIFIERS = {"CLOTH", "SOFT_BODY", "FLUID", "DYNAMIC_PAINT", "OCEAN", "EXPLODE", "PARTICLE_SYSTEM",
                  "PARTICLE_INSTANCE", "WAVE", "BUILD", "MESH_CACHE", "MESH_SEQUENCE_CACHE"}
TIME_NODES = {"GeometryNodeInputSceneTime", "GeometryNodeSimulationInput", "GeometryNodeSimulationOutput"}


def tree_reads_time(tree, seen):
    """Whether a Geometry Nodes tree (groups included) reads the scene time or simulates."""
    if key(tree) in seen:
        return False
    seen.add(key(tree))
    for n in tree.nodes:
        if n.bl_idname in TIME_NODES:
            return True
        if getattr(n, "node_tree", None) is not None and tree_reads_time(n.node_tree, seen):
            return True
    return False


def frozen_inputs(o):
    """What the object's evaluated geometry reads, as data-path prefixes, and which of
    those are animated (F-curves, drivers, NLA): an override under a prefix, or another
    frame with an animated one, would need Blender to evaluate it again. Also what the
    evaluated mesh lacks that Cycles renders (hair)."""
    reads = [(o, f"{id_path(o)}.modifiers")]
    others, unsupported = [], []
    def add(idb):
        if idb is not None and isinstance(idb, bpy.types.ID) and all(r[0] != idb or r[1] != id_path(idb) for r in reads):
            reads.append((idb, id_path(idb)))
    if o.data is not None:
        add(o.data)
        add(getattr(o.data, "shape_keys", None))
        if o.type == "FONT":
            for f in ("font", "font_bold", "font_italic", "font_bold_italic"):
                add(getattr(o.data, f, None))
        for attr in ("bevel_object", "taper_object"):
            ob = getattr(o.data, attr, None)
            if ob is not None:
                others.append(ob)
    for m in o.modifiers:
        for p in m.bl_rna.properties:
            if p.type != "POINTER" or p.identifier == "rna_type":
                continue
            v = getattr(m, p.identifier, None)
            if isinstance(v, bpy.types.Object):
                others.append(v)
            elif isinstance(v, bpy.types.Collection):
                add(v)
                others.extend(v.all_objects)
            elif isinstance(v, bpy.types.ID):
                add(v)
        if m.type == "PARTICLE_SYSTEM":
            st = m.particle_system.settings
            add(st)
            # Hair paths are exported as strands (`hair_strands`).
            if st.instance_object is not None:
                others.append(st.instance_object)
            if st.instance_collection is not None:
                others.extend(st.instance_collection.all_objects)
    if o.type == "META":
        # Metaballs of one family (same base name) melt into its first object.
        base = o.name.split(".")[0]
        others.extend(x for x in bpy.data.objects if x.type == "META" and x != o and x.name.split(".")[0] == base)
    if o.instance_type in ("VERTS", "FACES"):
        others.extend(o.children)
    if o.instance_type == "COLLECTION" and o.instance_collection is not None:
        add(o.instance_collection)
        others.extend(o.instance_collection.all_objects)
    if others:
        # Another object's transform acts relative to this one's.
        reads[0] = (o, id_path(o))
    for x in others:
        add(x)
        if x.data is not None:
            add(x.data)
            add(getattr(x.data, "shape_keys", None))
    animated = []
    # Modifiers whose result moves with the frame without any F-curve: simulations,
    # particles, time-driven deformers, Geometry Nodes reading the scene time.
    for m in o.modifiers:
        if m.show_render and (m.type in TIME_MODIFIERS or (m.type == "NODES" and m.node_group is not None
                                                          and tree_reads_time(m.node_group, set()))):
            animated.append(f"{id_path(o)}.modifiers[{q(m.name)}] ({m.type} depends on the frame)")
    for idb, prefix in reads:
        ad = getattr(idb, "animation_data", None)
        if ad is None:
            continue
        for fc, kind in [(fc, "") for fc in action_fcurves(ad)] + [(fc, " (driver)") for fc in ad.drivers]:
            full = f"{id_path(idb)}.{fc.data_path}"
            if under(full, prefix):
                animated.append(f"{full}[{fc.array_index}]{kind}")
        if len(ad.nla_tracks):
            animated.append(f"{id_path(idb)} (NLA tracks)")
    return sorted({r[1] for r in reads}), sorted(set(animated)), unsupported


# ---------------------------------------------------------------- other datablocks

# ---------------------------------------------------------------- smoke domain grids

# The grids Cycles reads from a gas domain (blender/volume.cpp, sync_smoke_volume), by the
# attribute name materials read them with, and the channels Cycles 4.5 keeps of each (the
# RGBA colour grid becomes RGB: its NanoVDB grids have no four-channel type).
SMOKE_GRIDS = {"density": 1, "color": 3, "flame": 1, "heat": 1, "temperature": 1, "velocity": 3}
SMOKE_GRID_CHANNELS = {"color": 4, "velocity": 3}


def attribute_names_read(tree, seen):
    """Attribute names a node tree (and the groups in it) reads: Attribute nodes of
    Geometry type and Principled Volume's Density/Color/Temperature Attribute."""
    names = set()
    if tree is None or tree.as_pointer() in seen:
        return names
    seen.add(tree.as_pointer())
    for n in tree.nodes:
        if n.bl_idname == "ShaderNodeAttribute" and n.attribute_type == "GEOMETRY":
            names.add(n.attribute_name)
        elif n.bl_idname == "ShaderNodeVolumePrincipled":
            for s in ("Density Attribute", "Color Attribute", "Temperature Attribute"):
                if s in n.inputs and n.inputs[s].default_value:
                    names.add(n.inputs[s].default_value)
        elif getattr(n, "node_tree", None) is not None:
            names |= attribute_names_read(n.node_tree, seen)
    return names


def smoke_domain_entries(objs, out, depsgraph, suffix="", only=None):
    """Per gas domain with a material: the grids its materials read, as Blender gives them
    at the current frame (read from the evaluated object, as Cycles does; the original's
    would read a missing simulation), written as voxel grid files (FORMAT.md). SUFFIX goes
    into the file names (`.fN` for --frames); ONLY, a set of object keys, limits the
    domains."""
    entries = []
    frame = bpy.context.scene.frame_current + bpy.context.scene.frame_subframe
    for i, o in enumerate(objs):
        if only is not None and key(o) not in only:
            continue
        md = next((m for m in o.modifiers if m.type == "FLUID" and m.fluid_type == "DOMAIN"
                   and m.show_render), None)
        if md is None or o.type != "MESH" or md.domain_settings.domain_type != "GAS":
            continue
        wanted = set()
        for slot in o.material_slots:
            if slot.material is not None and slot.material.node_tree is not None:
                wanted |= attribute_names_read(slot.material.node_tree, set())
        wanted = sorted(n for n in wanted if n in SMOKE_GRIDS)
        ev = o.evaluated_get(depsgraph)
        ds = ev.modifiers[md.name].domain_settings
        entry = {"object": key(o), "modifier": md.name, "frame": frame,
                 "in_cache_range": ds.cache_frame_start <= frame <= ds.cache_frame_end,
                 "clipping": ds.clipping, "grids": [], "unread": []}
        lo = np.array(ev.data.texspace_location, dtype=np.float32)
        size = np.array(ev.data.texspace_size, dtype=np.float32)
        res = np.array(ds.domain_resolution, dtype=np.int64)
        for name in wanted:
            if not entry["in_cache_range"]:
                entry["unread"].append([name, f"frame {frame:g} is outside the cache's frames "
                                              f"{ds.cache_frame_start}..{ds.cache_frame_end}"])
                continue
            amplify = ds.noise_scale if ds.use_noise and name not in ("velocity", "heat") else 1
            dims = res * amplify
            channels = SMOKE_GRID_CHANNELS.get(name, 1)
            prop = getattr(ds, f"{name}_grid")
            expect = int(dims.prod()) * channels
            if len(prop) != expect or expect == 0:
                entry["unread"].append([name, f"Blender gives {len(prop)} values, not {expect} "
                                              f"(resolution {list(map(int, dims))}): not baked at the frame?"])
                continue
            values = np.empty(expect, dtype=np.float32)
            try:
                prop.foreach_get(values)
            except (AttributeError, TypeError):
                values = np.array(prop[:], dtype=np.float32)
            keep = SMOKE_GRIDS[name]
            values = values.reshape(-1, channels)[:, :keep]
            rel = f"volumes/{safe_name(i, key(o))[:-4]}_{name}{suffix}.grid"
            rel = write_grid_file(out, rel, keep, dims, np.concatenate([lo - size, lo + size]), values)
            entry["grids"].append({"name": name, "file": rel})
        entries.append(entry)
    return entries


# Grid files written in this run by content (sha256 -> relative path): --frames writes a
# grid again only where it changed (a sequence holding a file over several frames).
GRID_FILES = {}


def write_grid_file(out, rel, channels, dims, box, values):
    """Writes one voxel grid file (FORMAT.md, "Voxel grid files") at REL under OUT, or
    returns the path of an identical one written before."""
    import hashlib
    data = b"".join([b"BSVGRID1", struct.pack("<4I", channels, *map(int, dims)),
                     np.asarray(box).astype("<f4").tobytes(),
                     np.ascontiguousarray(values, dtype="<f4").tobytes()])
    digest = hashlib.sha256(data).hexdigest()
    if digest in GRID_FILES:
        return GRID_FILES[digest]
    os.makedirs(os.path.join(out, os.path.dirname(rel)), exist_ok=True)
    with open(os.path.join(out, rel), "wb") as f:
        f.write(data)
    GRID_FILES[digest] = rel
    return rel


def volume_grids_every_frame(o):
    """Whether Volume object O's evaluated grids are the same at every frame: one .vdb
    file (not a sequence), no modifier in renders, no animation on the Volume."""
    v = o.data
    return (not v.is_sequence and not any(m.show_render for m in o.modifiers)
            and v.animation_data is None)


# Volume grids the exporter writes densely: OpenVDB value type -> channels.
VDB_GRID_CHANNELS = {"float": 1, "vec3s": 3}
# Values (voxels times channels) of one exported Volume grid: 2^28 floats is 1 GiB.
MAX_VDB_GRID_VALUES = 1 << 28


def openvdb_module():
    """The OpenVDB Python module the bpy wheel ships beside Blender's own Python packages
    (not on sys.path), or the reason it cannot be loaded."""
    try:
        import openvdb  # noqa: F401 (a Blender build with it on the path)
        return openvdb, None
    except ImportError:
        pass
    import glob
    import importlib.util
    root = os.path.join(bpy.utils.resource_path("LOCAL"), "python", "lib")
    found = sorted(glob.glob(os.path.join(root, "python3*", "site-packages", "openvdb*.so")))
    if not found:
        return None, f"Blender's OpenVDB Python module was not found under {root}"
    try:
        spec = importlib.util.spec_from_file_location("openvdb", found[0])
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        return mod, None
    except Exception as e:  # a broken or foreign module: recorded, blendsynth refuses
        return None, f"Blender's OpenVDB Python module at {found[0]} does not load ({e})"


def index_to_object(grid):
    """Grid GRID's index-to-object transform as (origin, per-axis voxel size), or None
    when it rotates, shears or mirrors (not handled)."""
    t = grid.transform
    if not t.isLinear:
        return None
    o = np.array(t.indexToWorld((0, 0, 0)), dtype=np.float64)
    axes = np.array([np.array(t.indexToWorld(e), dtype=np.float64) - o
                     for e in ((1, 0, 0), (0, 1, 0), (0, 0, 1))])
    size = np.diag(axes).copy()
    off = axes - np.diag(size)
    if np.any(size <= 0) or np.any(np.abs(off) > 1e-6 * np.max(np.abs(size))):
        return None
    return o, size


def volume_grid_count(o):
    """Grids in the volume component of object O's evaluated geometry (Geometry Nodes on a
    mesh or curve), which its frozen mesh cannot carry."""
    try:
        ev = o.evaluated_get(bpy.context.evaluated_depsgraph_get())
        # The geometry set owns the volume: keep it alive while the grids are counted.
        geometry = ev.evaluated_geometry()
        vol = geometry.volume
        return len(vol.grids) if vol is not None else 0
    # TypeError: an object outside the view layer has no evaluated copy (evaluated_get
    # returns the original), so no evaluated geometry either.
    except (AttributeError, RuntimeError, ReferenceError, TypeError):
        return 0


def volume_object_entries(objs, out, depsgraph, suffix="", only=None):
    """Per Volume object: the grids its materials read (or the velocity grid), from its
    evaluated Volume at the current frame (the file sequence frame, Geometry Nodes or
    modifiers applied), saved by Blender to a .vdb and read with OpenVDB, each written
    densely over its active voxels' bounding box as a voxel grid file (FORMAT.md). SUFFIX
    goes into the file names (`.fN` for --frames); ONLY, a set of object keys, limits the
    objects."""
    entries = []
    frame = bpy.context.scene.frame_current + bpy.context.scene.frame_subframe
    vdb = None
    vdb_error = None
    for i, o in enumerate(objs):
        if o.type != "VOLUME" or o.data is None:
            continue
        if only is not None and key(o) not in only:
            continue
        if vdb is None and vdb_error is None:
            vdb, vdb_error = openvdb_module()
        v = o.data
        ev = o.evaluated_get(depsgraph).data
        materials = [key(m) if m else None for m in v.materials]
        wanted = set()
        for slot in o.material_slots:
            if slot.material is not None and slot.material.node_tree is not None:
                wanted |= attribute_names_read(slot.material.node_tree, set())
        r = v.render
        entry = {"object": key(o), "volume": key(v), "frame": frame,
                 "every_frame": volume_grids_every_frame(o), "materials": materials,
                 "space": r.space, "step_size": r.step_size, "clipping": r.clipping,
                 "precision": r.precision, "velocity_grid": None,
                 "velocity_scale": v.velocity_scale, "grids": [], "unread": [], "error": None}
        if vdb is None:
            entry["error"] = vdb_error
            entries.append(entry)
            continue
        grids = ev.grids
        if not grids.load():
            entry["error"] = f"Blender could not load its grids: {grids.error_message or 'no message'}"
            entries.append(entry)
            continue
        names = [g.name for g in grids]
        vel = [n for n in (v.velocity_grid, v.velocity_x_grid, v.velocity_y_grid, v.velocity_z_grid)
               if n and n in names]
        entry["velocity_grid"] = vel[0] if vel else None
        wanted = sorted(n for n in wanted if n in names)
        if not wanted:
            entries.append(entry)
            continue
        os.makedirs(os.path.join(out, "volumes"), exist_ok=True)
        tmp = os.path.join(out, "volumes", f"{safe_name(i, key(o))[:-4]}{suffix}.evaluated.vdb")
        try:
            grids.save(filepath=tmp)
            read, _meta = vdb.readAll(tmp)
        except Exception as e:
            entry["error"] = f"its evaluated grids could not be saved and read back ({e})"
            entries.append(entry)
            continue
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
        by_name = {g.name: g for g in read}
        for name in wanted:
            g = by_name.get(name)
            if g is None:
                entry["unread"].append([name, "Blender's saved grids do not hold it"])
                continue
            channels = VDB_GRID_CHANNELS.get(g.valueTypeName)
            if channels is None:
                entry["unread"].append([name, f"OpenVDB value type {g.valueTypeName} is not handled (float and vec3s are)"])
                continue
            if "level" in str(g.gridClass).lower():
                entry["unread"].append([name, "a level set grid is not handled"])
                continue
            tfm = index_to_object(g)
            if tfm is None:
                entry["unread"].append([name, "its transform rotates, shears or mirrors the voxels, which is not handled"])
                continue
            if g.activeVoxelCount() == 0:
                # Cycles builds nothing from an empty fog grid and reads 0 from it (a
                # Volume whose grids are all empty renders nothing): not written, read as
                # a missing grid.
                continue
            lo, hi = g.evalActiveVoxelBoundingBox()
            dims = [int(hi[k]) - int(lo[k]) + 1 for k in range(3)]
            if int(np.prod(dims)) * channels > MAX_VDB_GRID_VALUES:
                entry["unread"].append([name, f"its active voxels span {dims}, more than {MAX_VDB_GRID_VALUES} values"])
                continue
            # copyToArray fills a (x, y, z[, c]) array from the index LO.
            shape = tuple(dims) + ((3,) if channels == 3 else ())
            dense = np.zeros(shape, dtype=np.float32)
            g.copyToArray(dense, ijk=tuple(int(x) for x in lo))
            # The file is x fastest: transpose to (z, y, x[, c]).
            values = np.ascontiguousarray(dense.transpose((2, 1, 0) + ((3,) if channels == 3 else ())))
            origin, size = tfm
            # Cycles samples voxel ijk at index ijk + 0.5 (kernel_tex_image_interp_3d's
            # -0.5 after the inverse index-to-object transform): the box starts at LO.
            box_lo = origin + size * np.array(lo, dtype=np.float64)
            box_hi = box_lo + size * np.array(dims, dtype=np.float64)
            rel = f"volumes/{safe_name(i, key(o))[:-4]}_{name}{suffix}.grid"
            rel = write_grid_file(out, rel, channels, dims, np.concatenate([box_lo, box_hi]), values)
            entry["grids"].append({"name": name, "file": rel, "class": str(g.gridClass),
                                   "index_min": [int(x) for x in lo],
                                   "voxel_size": [float(x) for x in size]})
        entries.append(entry)
    return entries


def matrix(m):
    return [[float(m[r][c]) for c in range(4)] for r in range(4)]


def vec(v):
    return [float(x) for x in v]


def custom_props(idb, where):
    out = {}
    for k in idb.keys():
        if k.startswith("_") or k == "cycles":  # add-on bookkeeping, not user data
            continue
        try:
            out[k] = py_value(idb[k], f"{where}[{q(k)}]", 0)
        except Exception as e:
            WARNINGS.append(f"{where}[{q(k)}]: not exported ({e})")
    return out


def modifier_entry(m, where):
    d = {"name": m.name, "type": m.type, "show_render": m.show_render, "show_viewport": m.show_viewport,
         # A NODES modifier's bakes are `bake_states` below (their RNA repeats each
         # zone's whole node, tens of kB per modifier).
         "properties": rna_value(m, 0, where, skip={"name", "type", "show_render", "show_viewport", "bakes"}),
         "node_group": None, "inputs": {}}
    if m.type == "NODES":
        d["node_group"] = key(m.node_group) if m.node_group else None
        # Group input values live in the modifier's ID properties, keyed by the group's
        # interface identifiers (Socket_2, Socket_2_use_attribute, ...).
        d["inputs"] = {k: py_value(m[k], f"{where}[{q(k)}]", 0) for k in m.keys()}
        d["bake_states"] = [bake_state(m, b) for b in m.bakes]
    return d


def bake_state(m, b):
    """A Geometry Nodes modifier's bake item (one per Simulation zone or Bake node): its
    node, the frame range it sets, and whether baked data exists, which Blender reads
    instead of simulating. RNA does not say whether a packed bake exists; the DNA struct
    (NodesModifierBake: packed at byte 48, after id, flag, mode, target, directory,
    frame_start at 24 and frame_end at 28) does, read only when those fields match RNA;
    None when unknown. A disk bake exists when its folder holds meta/*.json files."""
    import ctypes
    node = b.node
    baked = None
    try:
        p = b.as_pointer()
        same = (ctypes.c_int32.from_address(p).value == b.bake_id
                and ctypes.c_int32.from_address(p + 24).value == b.frame_start
                and ctypes.c_int32.from_address(p + 28).value == b.frame_end)
        if same and bpy.app.version[:2] == (4, 5):
            baked = bool(ctypes.c_void_p.from_address(p + 48).value)
    except Exception:
        baked = None
    target = b.bake_target if b.bake_target != "INHERIT" else m.bake_target
    if target == "DISK" and not baked:
        folder = b.directory if b.use_custom_path else (
            os.path.join(m.bake_directory, str(b.bake_id)) if m.bake_directory else "")
        meta = os.path.join(bpy.path.abspath(folder), "meta") if folder else ""
        baked = bool(meta) and os.path.isdir(meta) and any(f.endswith(".json") for f in os.listdir(meta))
    return {"bake_id": b.bake_id, "node": node.name if node else None,
            "node_tree": node.id_data.name if node else None,
            "use_custom_simulation_frame_range": b.use_custom_simulation_frame_range,
            "frame_start": b.frame_start, "frame_end": b.frame_end,
            "target": target, "baked": baked}


RENDER_LAYER = set()  # as_pointer() of the objects the view layer renders (render_layer_objects)


def render_layer_objects(view_layer):
    """The objects the view layer renders through its collections: in a collection that
    is neither excluded from the view layer nor disabled in renders, nor is any collection
    above it. Others (in no scene collection, only in an excluded or render-disabled one,
    in another scene, or only in a library collection an empty instances) Cycles does not
    render themselves."""
    found = set()

    def walk(lc):
        if lc.exclude or lc.collection.hide_render:
            return
        found.update(o.as_pointer() for o in lc.collection.objects)
        for child in lc.children:
            walk(child)

    walk(view_layer.layer_collection)
    return found


def view_layer_entry(view_layer):
    """The rendered view layer's shader AOVs (Cycles writes one pass per valid AOV) and
    the alpha threshold Cycles' data and AOV passes stop at."""
    return {"name": view_layer.name,
            "pass_alpha_threshold": view_layer.pass_alpha_threshold,
            "aovs": [{"name": a.name, "type": a.type, "is_valid": a.is_valid} for a in view_layer.aovs]}


def in_view_layer(o, view_layer):
    """Whether object O is in the view layer (by identity: a linked object may share its
    name with a local one)."""
    x = view_layer.objects.get(o.name)
    return x is not None and (x == o or any(v == o for v in view_layer.objects))


def attribute_lookup_names():
    """Names read by Attribute nodes of type Object or Instancer in any node tree."""
    names = set()
    for t in list(bpy.data.node_groups) + [m.node_tree for m in bpy.data.materials if m.node_tree] + \
            [w.node_tree for w in bpy.data.worlds if w.node_tree] + [l.node_tree for l in bpy.data.lights if l.node_tree]:
        for n in t.nodes:
            if n.bl_idname == "ShaderNodeAttribute" and n.attribute_type in {"OBJECT", "INSTANCER"} and n.attribute_name:
                names.add(n.attribute_name)
    return sorted(names)


def rna_rgba(idb, name):
    """Blender's find_rna_property_rgba: a custom property of ID IDB named NAME, else the
    RNA path NAME on it, as RGBA (a number n as (n, n, n, 1); an array's first four
    values, alpha 1 when it has fewer); None when neither exists or it is not numeric."""
    if idb is None:
        return None
    try:
        v = idb[name] if name in idb.keys() else idb.path_resolve(name)
    except Exception:
        return None
    if isinstance(v, (bool, int, float)):
        return [float(v)] * 3 + [1.0]
    try:
        items = list(v)
    except Exception:
        return None
    if not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in items):
        return None  # Blender converts float and int arrays only
    xs = [float(x) for x in items]
    if not 1 <= len(xs) <= 4:
        return None
    return (xs + [0.0, 0.0, 0.0, 1.0][len(xs):])[:4]


ATTRIBUTE_LOOKUP_NAMES = []


def object_entry(o, view_layer):
    w = f"objects[{q(key(o))}]"
    return {
        "name": key(o), "type": o.type, "data": key(o.data) if o.data else None,
        "parent": key(o.parent) if o.parent else None, "parent_type": o.parent_type,
        "parent_bone": o.parent_bone or None,
        "matrix_world": matrix(o.matrix_world), "matrix_local": matrix(o.matrix_local),
        "matrix_basis": matrix(o.matrix_basis), "matrix_parent_inverse": matrix(o.matrix_parent_inverse),
        "location": vec(o.location), "rotation_mode": o.rotation_mode,
        "rotation_euler": vec(o.rotation_euler), "rotation_quaternion": vec(o.rotation_quaternion),
        "rotation_axis_angle": vec(o.rotation_axis_angle), "scale": vec(o.scale),
        "delta_location": vec(o.delta_location), "delta_rotation_euler": vec(o.delta_rotation_euler),
        "delta_rotation_quaternion": vec(o.delta_rotation_quaternion), "delta_scale": vec(o.delta_scale),
        "hide_render": o.hide_render, "hide_viewport": o.hide_viewport,
        # Object > Simulation Cache: without it a simulation keeps stepping past its end.
        "use_simulation_cache": o.use_simulation_cache,
        "in_render_layer": o.as_pointer() in RENDER_LAYER,
        "visible": o.visible_get(view_layer=view_layer) if in_view_layer(o, view_layer) else False,
        "pass_index": o.pass_index, "collections": [key(c) for c in o.users_collection],
        # Cycles' ray visibility (Object > Visibility > Ray Visibility); light objects
        # default to hidden from the camera in Blender 4.x.
        "visibility": {k: getattr(o, "visible_" + k) for k in ("camera", "diffuse", "glossy", "transmission", "volume_scatter", "shadow")},
        "is_holdout": o.is_holdout, "is_shadow_catcher": o.is_shadow_catcher,
        # Object > Shading > Shadow Terminator (Cycles' shadow ray and shading offsets).
        "shadow_terminator_geometry_offset": o.shadow_terminator_geometry_offset,
        "shadow_terminator_shading_offset": o.shadow_terminator_shading_offset,
        "color": vec(o.color),
        "material_slots": [{"material": key(s.material) if s.material else None, "link": s.link} for s in o.material_slots],
        "modifiers": [modifier_entry(m, f"{w}.modifiers[{q(m.name)}]") for m in o.modifiers],
        "constraints": [{"name": c.name, "type": c.type, "mute": c.mute, "influence": c.influence,
                         "properties": rna_value(c, 0, f"{w}.constraints[{q(c.name)}]")} for c in o.constraints],
        "custom_properties": custom_props(o, w),
        # What an Attribute node of type Object / Instancer named NAME finds on the object
        # and on its data (custom property or RNA path; null where neither has it).
        "attribute_lookups": {n: {"object": rna_rgba(o, n), "data": rna_rgba(o.data, n)}
                              for n in ATTRIBUTE_LOOKUP_NAMES},
        # Extra keys: Follow Path orients a child of a path by the object's own axes.
        "track_axis": o.track_axis, "up_axis": o.up_axis,
        "instance_type": o.instance_type,
        "instance_collection": key(o.instance_collection) if o.instance_collection else None,
        # Cycles' per-object motion blur settings (Object Properties > Motion Blur).
        "cycles": {"use_motion_blur": o.cycles.use_motion_blur, "use_deform_motion": o.cycles.use_deform_motion,
                   "motion_steps": o.cycles.motion_steps} if hasattr(o, "cycles") else None,
    }


def curve_entry(c):
    splines = []
    for s in c.splines:
        splines.append({
            "type": s.type, "use_cyclic_u": s.use_cyclic_u, "resolution_u": s.resolution_u, "order_u": s.order_u,
            "use_endpoint_u": s.use_endpoint_u, "use_bezier_u": s.use_bezier_u, "use_smooth": s.use_smooth,
            "material_index": s.material_index, "tilt_interpolation": s.tilt_interpolation,
            "radius_interpolation": s.radius_interpolation,
            "bezier_points": [{"co": vec(p.co), "handle_left": vec(p.handle_left), "handle_right": vec(p.handle_right),
                               "handle_left_type": p.handle_left_type, "handle_right_type": p.handle_right_type,
                               "radius": p.radius, "tilt": p.tilt, "weight_softbody": p.weight_softbody}
                              for p in s.bezier_points],
            "points": [{"co": vec(p.co), "radius": p.radius, "tilt": p.tilt, "weight": p.weight} for p in s.points],
        })
    return {"name": key(c),
            "properties": rna_value(c, 0, f"curves[{q(key(c))}]", skip={"splines", "materials", "animation_data", "shape_keys"}),
            "materials": [key(m) if m else None for m in c.materials], "splines": splines}


def save_generated(im, target):
    """Writes generated image IM's pixels to TARGET losslessly. A byte buffer: Image.save
    (8-bit PNG). A float buffer: Image.save would write a 16-bit PNG through the display
    transform whatever the extension, so it goes through save_render as a 32-bit EXR
    (scene-linear values, no view transform), with the scene's output format restored."""
    if not im.is_float:
        fmt = im.file_format
        im.file_format = "PNG"
        try:
            im.save(filepath=target, save_copy=True)
        finally:
            im.file_format = fmt
        return
    scene = bpy.context.scene
    f = scene.render.image_settings
    keep = {k: getattr(f, k) for k in ("file_format", "color_depth", "exr_codec", "color_mode")}
    try:
        f.file_format, f.color_depth, f.exr_codec, f.color_mode = "OPEN_EXR", "32", "ZIP", "RGBA"
        im.save_render(filepath=target, scene=scene)
    finally:
        for k in ("file_format", "color_depth", "exr_codec", "color_mode"):
            try:
                setattr(f, k, keep[k])
            except Exception:  # an option the restored format does not have
                pass


def image_entry(im, out_dir, used_names):
    d = {"name": key(im), "source": im.source, "filepath": im.filepath, "file": None,
         "packed": im.packed_file is not None, "missing": False,
         "colorspace": im.colorspace_settings.name, "alpha_mode": im.alpha_mode, "size": [int(x) for x in im.size]}
    generated = im.packed_file is None and im.source == "GENERATED"
    if im.packed_file is None and im.source not in ("FILE", "SEQUENCE", "MOVIE", "TILED") and not generated:
        return d
    base = re.sub(r"[^A-Za-z0-9._-]", "_", bpy.path.basename(im.filepath) or im.name) or "image"
    if generated:
        # Blender's own pixels (blank, UV grid or colour grid at the image's size, colour
        # and float/byte buffer), written losslessly: 8-bit PNG for a byte buffer (the
        # image's colour space applies as for a file), 32-bit EXR for a float one.
        base += ".exr" if im.is_float else ".png"
    elif im.packed_file is not None and not os.path.splitext(base)[1]:
        # A packed generated image has no file name: name it by its packed format.
        base += "." + {"JPEG": "jpg", "OPEN_EXR": "exr", "OPEN_EXR_MULTILAYER": "exr"}.get(im.file_format, im.file_format.lower())
    name, k = base, 1
    while name in used_names:
        stem, ext = os.path.splitext(base)
        name, k = f"{stem}.{k}{ext}", k + 1
    target = os.path.join(out_dir, "images", name)
    if generated:
        os.makedirs(os.path.dirname(target), exist_ok=True)
        try:
            save_generated(im, target)
        except Exception as e:
            WARNINGS.append(f"images[{q(key(im))}]: generated image not exported ({e})")
            return d
    elif im.packed_file is not None:
        os.makedirs(os.path.dirname(target), exist_ok=True)
        with open(target, "wb") as f:
            f.write(im.packed_file.data)
    else:
        src = bpy.path.abspath(im.filepath, library=im.library)
        # isfile follows symlinks and is false for folders, FIFOs and devices: those are
        # missing files (magenta, as in Cycles), never read.
        if not (src and os.path.isfile(src)):
            d["missing"] = True
            WARNINGS.append(f"images[{q(key(im))}]: file {im.filepath!r} not found and not packed")
            return d
        # The path policy: a .blend may name any file on the machine (an absolute path,
        # //../../..), and the export is meant to be shared, so only files under the
        # .blend's folder (or a folder the user allowed) are copied. Symlinks resolved.
        real = os.path.realpath(src)
        if not any(os.path.commonpath([real, root]) == root for root in ALLOWED_ROOTS):
            fail(f"images[{q(key(im))}]: file {im.filepath!r} resolves to {real}, outside the .blend's folder "
                 f"{ALLOWED_ROOTS[0]}; if you trust this file, allow its folder with --allow-path "
                 f"{os.path.dirname(real)} (or pack the image into the .blend)")
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(real, target)
        COPIED.append({"image": key(im), "from": real, "to": f"images/{name}"})
    used_names.add(name)
    d["file"] = f"images/{name}"
    return d


# ---------------------------------------------------------------- Import nodes' files

# What the Geometry Nodes Import nodes read (Import STL, PLY, OBJ, CSV, Text, VDB).
IMPORT_EXTENSIONS = (".stl", ".ply", ".obj", ".csv", ".txt", ".vdb")
MAX_IMPORT_BYTES = 1 << 30


def string_values_of_trees(data):
    """Every string a Geometry Nodes tree or NODES modifier holds: socket values (linked
    or not), String nodes, interface defaults and the modifiers' inputs. An Import node's
    Path comes from one of these unless the tree computes it (String Join, Value to
    String, ...), which the exporter cannot see."""
    found = []
    for g in data.node_groups:
        if g.bl_idname != "GeometryNodeTree":
            continue
        for n in g.nodes:
            for s in n.inputs:
                if s.type == "STRING" and isinstance(getattr(s, "default_value", None), str):
                    found.append(s.default_value)
            v = getattr(n, "string", None)
            if isinstance(v, str):
                found.append(v)
        for it in g.interface.items_tree:
            if it.item_type == "SOCKET" and isinstance(getattr(it, "default_value", None), str):
                found.append(it.default_value)
    for o in data.objects:
        for m in o.modifiers:
            if m.type != "NODES":
                continue
            for k in m.keys():
                v = m[k]
                if isinstance(v, str):
                    found.append(v)
    return found


def import_files(data, out):
    """Copies into DIR/imports/ every file an Import node may read: each string of the
    Geometry Nodes trees that names a file with an importable extension, as Blender
    resolves it (`//` against the .blend, absolute paths as they are). Only when some tree
    has an Import node. blendsynth reads these copies and nothing else (FORMAT.md)."""
    if not any(n.bl_idname.startswith("GeometryNodeImport")
               for g in data.node_groups if g.bl_idname == "GeometryNodeTree" for n in g.nodes):
        return []
    entries, used = [], set()
    for s in dict.fromkeys(string_values_of_trees(data)):
        if not s.lower().endswith(IMPORT_EXTENSIONS):
            continue
        if s.startswith("//"):
            src = bpy.path.abspath(s)
        elif os.path.isabs(s):
            src = s
        else:
            # Relative to Blender's working folder at evaluation: nothing to copy.
            continue
        entry = {"path": s, "file": None, "missing": False, "outside": False}
        if not os.path.isfile(src):
            entry["missing"] = True
            entries.append(entry)
            continue
        real = os.path.realpath(src)
        if not any(os.path.commonpath([real, root]) == root for root in ALLOWED_ROOTS):
            entry["outside"] = True
            WARNINGS.append(f"Import node file {s!r} resolves to {real}, outside the .blend's folder "
                            f"{ALLOWED_ROOTS[0]}: not copied (allow its folder with --allow-path "
                            f"{os.path.dirname(real)})")
            entries.append(entry)
            continue
        if os.path.getsize(real) > MAX_IMPORT_BYTES:
            fail(f"Import node file {real} is over {MAX_IMPORT_BYTES >> 20} MB")
        base = re.sub(r"[^A-Za-z0-9._-]", "_", os.path.basename(real))[:80] or "file"
        name = f"{len(entries):04d}_{base}"
        while name in used:
            name = "_" + name
        used.add(name)
        os.makedirs(os.path.join(out, "imports"), exist_ok=True)
        shutil.copyfile(real, os.path.join(out, "imports", name))
        COPIED.append({"import": s, "from": real, "to": f"imports/{name}"})
        entry["file"] = f"imports/{name}"
        entries.append(entry)
    return entries


# ---------------------------------------------------------------- animation

def action_fcurves(anim):
    """The F-curves that animate this ID. Layered actions (4.4+) may hold several slots,
    so read the channelbag of the slot assigned to this ID; legacy actions: fcurves."""
    act = anim.action
    if act is None:
        return []
    if getattr(act, "is_action_layered", False) and hasattr(act, "layers"):
        slot = getattr(anim, "action_slot", None)
        if slot is None:
            return []  # no slot assigned: the action animates nothing on this ID
        curves = []
        for layer in act.layers:
            for strip in layer.strips:
                bag = strip.channelbag(slot) if hasattr(strip, "channelbag") else None
                if bag is not None:
                    curves.extend(bag.fcurves)
        return curves
    return list(getattr(act, "fcurves", []))


def fcurve_entry(fc, where):
    return {
        "data_path": fc.data_path, "array_index": fc.array_index, "extrapolation": fc.extrapolation, "mute": fc.mute,
        "keyframes": [{"co": vec(k.co), "handle_left": vec(k.handle_left), "handle_right": vec(k.handle_right),
                       "handle_left_type": k.handle_left_type, "handle_right_type": k.handle_right_type,
                       "interpolation": k.interpolation, "easing": k.easing,
                       "back": k.back, "amplitude": k.amplitude, "period": k.period} for k in fc.keyframe_points],
        "modifiers": [{"type": m.type, "mute": m.mute,
                       "properties": rna_value(m, 0, f"{where}.modifiers[{i}]", skip={"type", "mute"})}
                      for i, m in enumerate(fc.modifiers)],
    }


def anim_entry(idb, id_path, id_type):
    anim = getattr(idb, "animation_data", None)
    if anim is None:
        return None
    if any(len(t.strips) for t in anim.nla_tracks):
        WARNINGS.append(f"{id_path}: NLA strips are not exported (only the active action and drivers)")
    fcs = [fcurve_entry(fc, f"{id_path}.{fc.data_path}[{fc.array_index}]") for fc in action_fcurves(anim)]
    drivers = []
    for fc in anim.drivers:
        w = f"{id_path}.{fc.data_path}[{fc.array_index}]"
        d = fcurve_entry(fc, w)
        d["driver"] = rna_value(fc.driver, 0, f"{w}.driver")
        drivers.append(d)
    if not fcs and not drivers and anim.action is None:
        return None
    return {"id_type": id_type, "id_name": key(idb), "id_path": id_path,
            "action": key(anim.action) if anim.action else None, "fcurves": fcs, "drivers": drivers}


def animation(data):
    out = []
    for coll_name in ("objects", "meshes", "curves", "cameras", "lights", "materials", "worlds", "scenes", "node_groups"):
        for idb in getattr(data, coll_name):
            path = f"{coll_name}[{q(key(idb))}]"
            e = anim_entry(idb, path, idb.id_type)
            if e:
                out.append(e)
            # Embedded node trees are IDs of their own with their own animation data.
            tree = getattr(idb, "node_tree", None) if coll_name in ("materials", "worlds") else None
            if tree is not None:
                e = anim_entry(tree, f"{path}.node_tree", "NODETREE")
                if e:
                    out.append(e)
    return out


# ---------------------------------------------------------------- main

def open_blend(path):
    if not os.path.isfile(path):
        fail(f"input file not found: {path}")
    # Never run Python carried by the file: neither registered text blocks nor
    # Python driver expressions. Set the preference too, in case anything re-reads it.
    bpy.context.preferences.filepaths.use_scripts_auto_execute = False
    try:
        bpy.ops.wm.open_mainfile(filepath=os.path.abspath(path), load_ui=False, use_scripts=False)
    except Exception as e:
        # Blender reports some problems as errors yet loads the file (sequencer strips in
        # channels above 128 are dropped, ...), as its window would: go on, with a warning.
        if os.path.abspath(bpy.data.filepath or "") != os.path.abspath(path):
            fail(f"Blender cannot open {path}: {e}")
        WARNINGS.append(f"Blender opened {path} with an error: {str(e).strip()}")


MAX_FRAMES = 10000


def frame_range(text):
    """`A..B` (inclusive, A <= B) for --frames."""
    try:
        a, b = (int(x) for x in text.split(".."))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a frame range A..B")
    if b < a or b - a >= MAX_FRAMES:
        raise argparse.ArgumentTypeError(f"{text!r}: need A <= B and at most {MAX_FRAMES} frames")
    return a, b


def evaluated_frames(evaluated, by_key, index, out, frames):
    """--frames A..B: Blender's evaluated mesh at every frame A+1..B of each object whose
    evaluation reads something animated (the entries at A are EVALUATED), one entry per
    object and frame, with the same reads and animated inputs."""
    scene = bpy.context.scene
    moving = [e for e in evaluated if e["animated"]]
    extra = []
    for f in range(frames[0] + 1, frames[1] + 1):
        if not moving:
            break
        scene.frame_set(f)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        got = evaluated_meshes([by_key[e["object"]] for e in moving], depsgraph)
        for e in moving:
            name = e["object"]
            (counts, arrays, attrs, uvs), realized, mats, (uv_layers, render_uv, color) = got[name]
            rel = f"evaluated/{safe_name(index[name], name)[:-4]}.f{f}.glb"
            write_mesh_glb(os.path.join(out, rel), name, counts, arrays, attrs, uvs)
            extra.append(dict(e, frame=scene.frame_current + scene.frame_subframe, file=rel,
                              vertex_count=counts[0], face_count=counts[2],
                              instances_realized=len(realized["instances"]) if realized else 0, realized=realized,
                              materials=mats, uv_layers=uv_layers, active_render_uv=render_uv,
                              default_color_attribute=color, volume_grids=volume_grid_count(by_key[name])))
    return extra


def grid_frames(smoke, volumes, out, frames):
    """--frames A..B: the grids of every smoke domain and of every Volume object whose
    grids change with the frame (`every_frame` false) at each frame A+1..B (the entries at
    A are SMOKE and VOLUMES), one entry per object and frame."""
    scene = bpy.context.scene
    objs = list(bpy.data.objects)
    smoke_only = {e["object"] for e in smoke}
    volume_only = {e["object"] for e in volumes if not e["every_frame"] and e["error"] is None}
    more_smoke, more_volumes = [], []
    if not smoke_only and not volume_only:
        return more_smoke, more_volumes
    for f in range(frames[0] + 1, frames[1] + 1):
        scene.frame_set(f)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        if smoke_only:
            more_smoke += smoke_domain_entries(objs, out, depsgraph, f".f{f}", smoke_only)
        if volume_only:
            more_volumes += volume_object_entries(objs, out, depsgraph, f".f{f}", volume_only)
    return more_smoke, more_volumes


def main():
    t0 = time.time()
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    ap = argparse.ArgumentParser(prog="export_scene.py", description="Export a .blend to blendsynth's scene format")
    ap.add_argument("--in", dest="input", help="the .blend to export (default: the file Blender already opened)")
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("--frame", type=int, help="frame to evaluate at (default: the file's current frame)")
    ap.add_argument("--frames", type=frame_range, metavar="A..B",
                    help="evaluate at frame A; also write the evaluated meshes of animated objects at A+1..B")
    ap.add_argument("--no-evaluated", action="store_true", help="skip the evaluated reference meshes")
    ap.add_argument("--allow-path", action="append", default=[], metavar="DIR",
                    help="a folder outside the .blend's own whose files (images) may be copied into the export")
    ap.add_argument("--copied-list", help="write the list of files copied into the export to this JSON file")
    args = ap.parse_args(argv)
    # Older Blenders keep nodes that 4.x's versioning rewrites on load (3.x's Musgrave
    # Texture becomes a Noise Texture plus Math nodes in 4.1), and their sockets differ.
    if tuple(bpy.app.version) < (4, 2, 0):
        fail(f"Blender {bpy.app.version_string} is too old: the exporter needs Blender 4.2 LTS or newer")
    if args.input is None:
        # `blender -b --disable-autoexec FILE --python export_scene.py -- --out DIR`:
        # Blender opened FILE itself, safe only when started with --disable-autoexec.
        if not bpy.data.filepath:
            fail("no input: pass --in FILE.blend")
        args.input = bpy.data.filepath
    else:
        open_blend(args.input)

    ALLOWED_ROOTS.append(os.path.dirname(os.path.realpath(args.input)))
    for a in args.allow_path:
        if not os.path.isdir(a):
            fail(f"--allow-path {a}: not a folder")
        ALLOWED_ROOTS.append(os.path.realpath(a))

    out = args.out
    try:
        for sub in ("", "meshes", "evaluated"):
            os.makedirs(os.path.join(out, sub), exist_ok=True)
    except OSError as e:
        fail(f"cannot create output folder {out}: {e}")

    POINT_DENSITY["out"] = out
    data = bpy.data
    scene = bpy.context.scene
    view_layer = bpy.context.view_layer
    ATTRIBUTE_LOOKUP_NAMES[:] = attribute_lookup_names()
    if args.frame is not None and args.frames is not None:
        fail("--frame and --frames exclude each other")
    if args.frames is not None:
        args.frame = args.frames[0]
    if args.frame is not None:
        scene.frame_set(args.frame)
    # Evaluates animation, drivers and constraints at the current frame and flushes the
    # results (matrix_world, animated properties) back to the original data we read.
    depsgraph = bpy.context.evaluated_depsgraph_get()

    meshes = []
    for i, me in enumerate(data.meshes):
        rel = f"meshes/{safe_name(i, key(me))}"
        counts, arrays, attrs, uvs = mesh_arrays(me, f"meshes[{q(key(me))}]")
        write_mesh_glb(os.path.join(out, rel), key(me), counts, arrays, attrs, uvs)
        nv, ne, nf, nc, _ = counts
        meshes.append({"name": key(me), "file": rel, "vertex_count": nv, "edge_count": ne, "face_count": nf,
                       "corner_count": nc, "materials": [key(m) if m else None for m in me.materials],
                       "uv_layers": [uv.name for uv in me.uv_layers],
                       "active_uv": me.uv_layers.active.name if me.uv_layers.active else None,
                       "active_render_uv": next((uv.name for uv in me.uv_layers if uv.active_render), None),
                       "attributes": [{"name": a.name, "domain": a.domain, "data_type": a.data_type}
                                      for a in me.attributes if not a.name.startswith(".")],
                       "texspace_location": vec(me.texspace_location), "texspace_size": vec(me.texspace_size),
                       "use_auto_texspace": me.use_auto_texspace,
                       "default_color_attribute": getattr(me.attributes, "default_color_name", None) or None,
                       "shape_keys": me.shape_keys is not None})

    evaluated = []
    if not args.no_evaluated:
        index = {key(o): i for i, o in enumerate(data.objects)}
        by_key = {key(o): o for o in data.objects}
        targets = [o for o in data.objects if frozen_target(o) and in_view_layer(o, view_layer)]
        with RenderSettings():
            frozen_meshes = evaluated_meshes(targets, bpy.context.evaluated_depsgraph_get())
            hair = export_hair(targets, out, index)
            hair.update(export_curves(targets, out, index, frozen_meshes))
            points = export_points(targets, out, index, frozen_meshes, bpy.context.evaluated_depsgraph_get())
            volume_grids = {key(o): volume_grid_count(o) for o in targets}
        for name, ((counts, arrays, attrs, uvs), realized, mats, (uv_layers, render_uv, color)) in frozen_meshes.items():
            rel = f"evaluated/{safe_name(index[name], name)}"
            write_mesh_glb(os.path.join(out, rel), name, counts, arrays, attrs, uvs)
            reads, animated, unsupported = frozen_inputs(by_key[name])
            evaluated.append({"object": name, "frame": scene.frame_current + scene.frame_subframe, "file": rel,
                              "vertex_count": counts[0], "face_count": counts[2], "instances_realized": len(realized["instances"]) if realized else 0,
                              "realized": realized, "reads": reads, "animated": animated, "unsupported": unsupported,
                              "materials": mats, "uv_layers": uv_layers, "active_render_uv": render_uv,
                              "default_color_attribute": color, "hair": hair.get(name),
                              "points": points.get(name), "volume_grids": volume_grids.get(name, 0)})

    with RenderSettings():
        smoke_domains = smoke_domain_entries(list(data.objects), out, bpy.context.evaluated_depsgraph_get())
        volume_objects = volume_object_entries(list(data.objects), out, bpy.context.evaluated_depsgraph_get())

    RENDER_LAYER.update(render_layer_objects(view_layer))
    used_images = set()
    images = [image_entry(im, out, used_images) for im in data.images
              if im.source != "VIEWER" and im.type not in ("RENDER_RESULT", "COMPOSITING")]

    cm = {"dir": None, "config": None}
    ims = scene.render.image_settings
    views = [(scene.view_settings, scene.display_settings)]
    if ims.color_management == "OVERRIDE":
        views.append((ims.view_settings, ims.display_settings))
    # Everything but Standard/Raw on sRGB without a look needs Blender's OCIO config and
    # LUTs (Filmic, AgX, looks, other displays); blendsynth reads them from the export.
    if any(v.view_transform not in ("Standard", "Raw") or v.look not in ("None", "") or d.display_device != "sRGB"
           for v, d in views):
        src = os.path.join(bpy.utils.resource_path("LOCAL"), "datafiles", "colormanagement")
        if os.path.isfile(os.path.join(src, "config.ocio")):
            shutil.copytree(src, os.path.join(out, "colormanagement"), dirs_exist_ok=True)
            cm = {"dir": "colormanagement", "config": "colormanagement/config.ocio"}
        else:
            WARNINGS.append(f"view transform {scene.view_settings.view_transform}: colour-management folder not found at {src}")

    doc = {
        "format": "blendsynth-scene", "version": 1, "exporter_version": EXPORTER_VERSION,
        "blender_version": bpy.app.version_string, "blender_version_tuple": list(bpy.app.version),
        "file_version": list(data.version), "source_file": os.path.basename(args.input),
        "scene": {
            "name": scene.name, "frame_start": scene.frame_start, "frame_end": scene.frame_end,
            "frame_current": scene.frame_current, "frame_step": scene.frame_step,
            # Where Geometry Nodes simulation zones start (the scene's custom simulation
            # range, else its frame range).
            "simulation_frame_start": (scene.simulation_frame_start if scene.use_custom_simulation_range
                                       else scene.frame_start),
            "simulation_frame_end": (scene.simulation_frame_end if scene.use_custom_simulation_range
                                     else scene.frame_end),
            "fps": scene.render.fps, "fps_base": scene.render.fps_base,
            "camera": key(scene.camera) if scene.camera else None, "world": key(scene.world) if scene.world else None,
            # Timeline markers bound to a camera switch the active camera during playback.
            "camera_markers": [{"frame": m.frame, "camera": key(m.camera)} for m in scene.timeline_markers
                               if m.camera],
            "render": rna_value(scene.render, 0, "scene.render"),
            "cycles": rna_value(scene.cycles, 0, "scene.cycles") if hasattr(scene, "cycles") else {},
            "cycles_curves": rna_value(scene.cycles_curves, 0, "scene.cycles_curves") if hasattr(scene, "cycles_curves") else {},
            "view_settings": rna_value(scene.view_settings, 0, "scene.view_settings"),
            "display_settings": rna_value(scene.display_settings, 0, "scene.display_settings"),
            "unit_settings": rna_value(scene.unit_settings, 0, "scene.unit_settings"),
            "view_layer": view_layer_entry(view_layer),
        },
        "objects": [object_entry(o, view_layer) for o in data.objects],
        "meshes": meshes,
        "curves": [curve_entry(c) for c in data.curves],
        "materials": [{"name": key(m), "use_nodes": m.use_nodes, "pass_index": m.pass_index,
                       "node_tree": node_tree_entry(m.node_tree, f"materials[{q(key(m))}].node_tree") if m.node_tree else None,
                       "properties": rna_value(m, 0, f"materials[{q(key(m))}]", skip={"node_tree", "animation_data", "grease_pencil"})}
                      for m in data.materials],
        "worlds": [{"name": key(w), "color": vec(w.color), "use_nodes": w.use_nodes,
                    "node_tree": node_tree_entry(w.node_tree, f"worlds[{q(key(w))}].node_tree") if w.node_tree else None,
                    "properties": rna_value(w, 0, f"worlds[{q(key(w))}]", skip={"node_tree", "animation_data"})}
                   for w in data.worlds],
        "node_groups": [node_tree_entry(g, f"node_groups[{q(key(g))}]") for g in data.node_groups],
        "collections": [{"name": key(c), "objects": [key(o) for o in c.objects],
                         "children": [key(ch) for ch in c.children],
                         "instance_offset": vec(c.instance_offset)}
                        for c in data.collections],
        "cameras": [{"name": key(c), "properties": rna_value(c, 0, f"cameras[{q(key(c))}]", skip={"animation_data"})}
                    for c in data.cameras],
        "lights": [{"name": key(l), "type": l.type,
                    "node_tree": node_tree_entry(l.node_tree, f"lights[{q(key(l))}].node_tree") if l.node_tree else None,
                    "properties": rna_value(l, 0, f"lights[{q(key(l))}]", skip={"node_tree", "animation_data"})}
                   for l in data.lights],
        "images": images,
        "import_files": import_files(data, out),
        "animation": animation(data),
        "evaluated": evaluated,
        "smoke_domains": smoke_domains,
        "volume_objects": volume_objects,
        "color_management": cm,
    }
    if args.frames is not None and not args.no_evaluated:
        # Last: frame_set flushes each frame's animated values into the data read above.
        with RenderSettings():
            doc["evaluated"] += evaluated_frames(evaluated, by_key, index, out, args.frames)
    if args.frames is not None:
        with RenderSettings():
            more_smoke, more_volumes = grid_frames(smoke_domains, volume_objects, out, args.frames)
        doc["smoke_domains"] += more_smoke
        doc["volume_objects"] += more_volumes
    nan_warnings = []
    doc = sanitize(doc, "", nan_warnings)
    doc["warnings"] = WARNINGS + nan_warnings

    tmp = os.path.join(out, "scene.json.tmp")
    with open(tmp, "w", encoding="utf-8") as f:
        json.dump(doc, f, indent=1, allow_nan=False)
    os.replace(tmp, os.path.join(out, "scene.json"))  # readers never see a half-written file
    if args.copied_list:
        with open(args.copied_list, "w", encoding="utf-8") as f:
            json.dump(COPIED, f)
    print(f"blendsynth-export: {os.path.basename(args.input)} -> {out}: {len(doc['objects'])} objects, "
          f"{len(meshes)} meshes, {len(doc['materials'])} materials, {len(doc['node_groups'])} node groups, "
          f"{len(doc['animation'])} animated IDs, {len(evaluated)} evaluated, {len(doc['warnings'])} warnings "
          f"in {time.time() - t0:.1f}s")


if __name__ == "__main__":
    code = 0
    try:
        main()
    except SystemExit as e:  # fail() and argparse
        code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    except BaseException as e:  # a clear last line and a non-zero exit, also under `blender -b --python`
        traceback.print_exc()
        msg = " ".join(str(e).split())
        print(f"blendsynth-export: error: export failed: {type(e).__name__}: {msg}", file=sys.stderr)
        code = 1
    # Leave without interpreter shutdown: once a .blend's Python driver has been
    # evaluated (even only to be refused), the bpy 4.5 module hangs forever in
    # shutdown. Every output file is already closed (and scene.json renamed into place).
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)
