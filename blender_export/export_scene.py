"""Export a .blend file to blendsynth's scene exchange format (blender_export/FORMAT.md).

Run inside Blender 4.2+:
    blender -b --factory-startup --disable-autoexec --python export_scene.py -- --in F.blend --out DIR
or with the bpy module:
    python export_scene.py --in F.blend --out DIR

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

import bpy
import numpy as np

EXPORTER_VERSION = 1
FLT_MAX = 3.4028234663852886e38
MAX_DEPTH = 5

WARNINGS = []


def fail(msg):
    print(f"blendsynth-export: error: {msg}", file=sys.stderr)
    sys.exit(1)


# ---------------------------------------------------------------- generic RNA values

def finite(x, where):
    if math.isfinite(x):
        return x
    if math.isnan(x):
        WARNINGS.append(f"{where}: NaN replaced by 0")
        return 0.0
    return FLT_MAX if x > 0 else -FLT_MAX


def plain(v, where="", depth=0):
    """A Python/bpy value as JSON-ready data (ID pointers as {id_type, name})."""
    if v is None or isinstance(v, (bool, str)):
        return v
    if isinstance(v, int):
        return v
    if isinstance(v, float):
        return finite(v, where)
    if isinstance(v, bpy.types.ID):
        return {"id_type": v.id_type, "name": v.name}
    if isinstance(v, bpy.types.bpy_struct):
        return rna(v, depth + 1, where) if depth < MAX_DEPTH else None
    if isinstance(v, (set, frozenset)):
        return sorted(v)
    if hasattr(v, "to_list"):  # IDPropertyArray
        return [plain(x, where, depth) for x in v.to_list()]
    if hasattr(v, "to_dict"):  # IDPropertyGroup
        return {k: plain(x, where, depth) for k, x in v.to_dict().items()}
    if isinstance(v, dict):
        return {str(k): plain(x, where, depth) for k, x in v.items()}
    try:
        return [plain(x, where, depth) for x in v]  # mathutils types, bpy arrays
    except TypeError:
        return str(v)


def rna(struct_, depth=0, where="", skip=()):
    """All RNA properties of a struct, recursively (ID pointers by name)."""
    out = {}
    for prop in struct_.bl_rna.properties:
        ident = prop.identifier
        if ident == "rna_type" or ident in skip:
            continue
        try:
            value = getattr(struct_, ident)
        except Exception:
            continue
        w = f"{where}.{ident}"
        try:
            if prop.type == "POINTER":
                if value is None:
                    out[ident] = None
                elif isinstance(value, bpy.types.ID):
                    out[ident] = {"id_type": value.id_type, "name": value.name}
                elif depth < MAX_DEPTH:
                    out[ident] = rna(value, depth + 1, w)
            elif prop.type == "COLLECTION":
                if depth < MAX_DEPTH:
                    out[ident] = [
                        {"id_type": x.id_type, "name": x.name} if isinstance(x, bpy.types.ID) else rna(x, depth + 1, f"{w}[{i}]")
                        for i, x in enumerate(value)
                    ]
            else:
                out[ident] = plain(value, w, depth)
        except Exception as e:  # a property that cannot be read in this context
            WARNINGS.append(f"{w}: not exported ({e})")
    return out


# Properties every node has (exported explicitly or bookkeeping), not node settings.
NODE_BASE = {p.identifier for p in bpy.types.Node.bl_rna.properties}
SOCKET_SKIP_TYPES = {"SHADER", "GEOMETRY", "CUSTOM"}


def socket(s, index, where):
    d = {
        "index": index,
        "identifier": s.identifier,
        "name": s.name,
        "type": s.type,
        "bl_idname": s.bl_idname,
        "is_linked": s.is_linked,
        "hide": s.hide,
        "enabled": s.enabled,
        "hide_value": s.hide_value,
        "is_multi_input": s.is_multi_input,
    }
    if hasattr(s, "default_value") and s.type not in SOCKET_SKIP_TYPES:
        try:
            d["default_value"] = plain(s.default_value, f"{where}.default_value")
        except Exception as e:
            WARNINGS.append(f"{where}.default_value: not exported ({e})")
    return d


def node_tree(tree, where):
    nodes = []
    for n in tree.nodes:
        nw = f'{where}.nodes["{n.name}"]'
        group = getattr(n, "node_tree", None) if n.bl_idname in ("ShaderNodeGroup", "GeometryNodeGroup") or hasattr(n, "node_tree") else None
        nodes.append({
            "name": n.name,
            "bl_idname": n.bl_idname,
            "label": n.label,
            "mute": n.mute,
            "parent": n.parent.name if n.parent else None,
            "location": [finite(n.location[0], nw), finite(n.location[1], nw)],
            "hide": n.hide,
            "node_tree": group.name if isinstance(group, bpy.types.NodeTree) else None,
            "properties": rna(n, 0, nw, skip=NODE_BASE),
            "inputs": [socket(s, i, f"{nw}.inputs[{i}]") for i, s in enumerate(n.inputs)],
            "outputs": [socket(s, i, f"{nw}.outputs[{i}]") for i, s in enumerate(n.outputs)],
        })
    links = []
    for l in tree.links:
        links.append({
            "from_node": l.from_node.name,
            "from_socket": l.from_socket.identifier,
            "from_index": list(l.from_node.outputs).index(l.from_socket),
            "to_node": l.to_node.name,
            "to_socket": l.to_socket.identifier,
            "to_index": list(l.to_node.inputs).index(l.to_socket),
            "is_muted": l.is_muted,
            "is_valid": l.is_valid,
        })
    interface = []
    if hasattr(tree, "interface"):
        for item in tree.interface.items_tree:
            iw = f"{where}.interface[{item.name}]"
            d = {"item_type": item.item_type, "name": item.name,
                 "parent": item.parent.name if getattr(item, "parent", None) and item.parent.parent else None}
            if item.item_type == "SOCKET":
                d.update({"in_out": item.in_out, "identifier": item.identifier, "socket_type": item.socket_type})
                for k in ("default_value", "min_value", "max_value"):
                    if hasattr(item, k):
                        d[k] = plain(getattr(item, k), f"{iw}.{k}")
            d["properties"] = rna(item, 0, iw, skip={"parent", "default_value", "min_value", "max_value"})
            interface.append(d)
    return {"name": tree.name, "bl_idname": tree.bl_idname, "interface": interface, "nodes": nodes, "links": links}


# ---------------------------------------------------------------- meshes (glb)

def safe_name(index, name):
    return f"{index:04d}_{re.sub(r'[^A-Za-z0-9._-]', '_', name)[:80]}.glb"


class Glb:
    """Accumulates accessors in one BIN buffer."""

    def __init__(self):
        self.chunks, self.offset, self.views, self.accessors = [], 0, [], []

    def add(self, array, gltf_type, component):
        a = np.ascontiguousarray(array)
        data = a.tobytes()
        count = a.shape[0]
        if count == 0:
            return None
        self.views.append({"buffer": 0, "byteOffset": self.offset, "byteLength": len(data)})
        acc = {"bufferView": len(self.views) - 1, "componentType": component, "count": int(count), "type": gltf_type}
        if gltf_type == "VEC3" and component == 5126 and a.ndim == 2:
            acc["min"] = [float(x) for x in a.min(axis=0)]
            acc["max"] = [float(x) for x in a.max(axis=0)]
        self.accessors.append(acc)
        self.chunks.append(data)
        pad = (-len(data)) % 4
        self.chunks.append(b"\0" * pad)
        self.offset += len(data) + pad
        return len(self.accessors) - 1

    def write(self, path, extras, primitive):
        binary = b"".join(self.chunks)
        doc = {"asset": {"version": "2.0", "generator": f"blendsynth export_scene.py v{EXPORTER_VERSION}"},
               "buffers": [{"byteLength": len(binary)}] if binary else [],
               "bufferViews": self.views, "accessors": self.accessors,
               "extras": {"blendsynth": extras}}
        if primitive:
            doc["meshes"] = [{"name": extras["name"], "primitives": [primitive]}]
            doc["nodes"] = [{"mesh": 0, "name": extras["name"]}]
            doc["scenes"] = [{"nodes": [0]}]
            doc["scene"] = 0
        js = json.dumps(doc, allow_nan=False, separators=(",", ":")).encode()
        js += b" " * ((-len(js)) % 4)
        chunks = struct.pack("<II", len(js), 0x4E4F534A) + js
        if binary:
            chunks += struct.pack("<II", len(binary), 0x004E4942) + binary
        tmp = path + ".tmp"
        with open(tmp, "wb") as f:
            f.write(struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks)
        os.replace(tmp, path)


def get(coll, attr, n, width, dtype):
    a = np.empty(n * width, dtype=dtype)
    if n:
        coll.foreach_get(attr, a)
    return a.reshape(n, width) if width > 1 else a


ATTR_LAYOUT = {  # data_type -> (foreach attribute, width, numpy dtype, glTF type, component)
    "FLOAT": ("value", 1, np.float32, "SCALAR", 5126),
    "FLOAT2": ("vector", 2, np.float32, "VEC2", 5126),
    "FLOAT_VECTOR": ("vector", 3, np.float32, "VEC3", 5126),
    "FLOAT_COLOR": ("color", 4, np.float32, "VEC4", 5126),
    "BYTE_COLOR": ("color", 4, np.float32, "VEC4", 5126),
    "QUATERNION": ("value", 4, np.float32, "VEC4", 5126),
    "FLOAT4X4": ("value", 16, np.float32, "MAT4", 5126),
    "INT": ("value", 1, np.int32, "SCALAR", 5125),
    "INT32_2D": ("value", 2, np.int32, "VEC2", 5125),
    "INT8": ("value", 1, np.int8, "SCALAR", 5120),
    "BOOLEAN": ("value", 1, bool, "SCALAR", 5121),
}


def mesh_arrays(me):
    """Blender's exact mesh as numpy arrays: (counts, dict of arrays, attributes)."""
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
    starts = get(me.polygons, "loop_start", nf, 1, np.uint32)
    arrays["face_offsets"] = np.append(starts, np.uint32(nc)).astype(np.uint32) if nf else np.zeros(0, np.uint32)
    if nf:
        normals = me.corner_normals if hasattr(me, "corner_normals") else None
        if normals is not None:
            arrays["corner_normals"] = get(normals, "vector", nc, 3, np.float32)
        else:  # Blender before 4.1
            me.calc_normals_split()
            arrays["corner_normals"] = get(me.loops, "normal", nc, 3, np.float32)
    attrs = []
    for a in me.attributes:
        if a.name.startswith(".") or a.name == "position":
            continue
        layout = ATTR_LAYOUT.get(a.data_type)
        if layout is None:
            WARNINGS.append(f'meshes["{me.name}"].attributes["{a.name}"]: data type {a.data_type} not exported')
            continue
        field, width, dtype, _, _ = layout
        if a.data_type == "FLOAT4X4":
            data = get(a.data, "value", len(a.data), 16, np.float32)
            # Blender's foreach gives rows; glTF MAT4 is column-major.
            data = data.reshape(-1, 4, 4).transpose(0, 2, 1).reshape(-1, 16)
        else:
            data = get(a.data, field, len(a.data), width, dtype)
        attrs.append((a.name, a.domain, a.data_type, data))
    return (nv, ne, nf, nc, nt), arrays, attrs


def write_mesh_glb(path, name, counts, arrays, attrs, uv_names):
    nv, ne, nf, nc, nt = counts
    g = Glb()
    ex = {"version": 1, "name": name, "vertex_count": nv, "edge_count": ne, "face_count": nf,
          "corner_count": nc, "triangle_count": nt, "attributes": []}
    layout = {"vertex_positions": ("VEC3", 5126), "edge_verts": ("VEC2", 5125), "face_offsets": ("SCALAR", 5125),
              "corner_verts": ("SCALAR", 5125), "corner_edges": ("SCALAR", 5125), "corner_normals": ("VEC3", 5126),
              "triangle_corners": ("SCALAR", 5125), "triangle_faces": ("SCALAR", 5125)}
    for key, (ty, comp) in layout.items():
        if key in arrays:
            idx = g.add(arrays[key], ty, comp)
            if idx is not None:
                ex[key] = idx
    uv_accessors = {}
    for aname, domain, dtype, data in attrs:
        _, _, npt, ty, comp = ATTR_LAYOUT[dtype]
        idx = g.add(data.astype(np.uint8) if dtype == "BOOLEAN" else data, ty, comp)
        if idx is not None:
            ex["attributes"].append({"name": aname, "domain": domain, "data_type": dtype, "accessor": idx})
            if aname in uv_names and domain == "CORNER" and dtype == "FLOAT2":
                uv_accessors[aname] = data
    primitive = None
    if nt:
        # The viewable primitive: one glTF vertex per face corner.
        cv = arrays["corner_verts"]
        prim = {"attributes": {"POSITION": g.add(arrays["vertex_positions"][cv], "VEC3", 5126)},
                "indices": ex["triangle_corners"], "mode": 4}
        if "corner_normals" in ex:
            prim["attributes"]["NORMAL"] = ex["corner_normals"]
        for i, uv in enumerate(uv_names):
            if uv in uv_accessors:
                flipped = uv_accessors[uv].copy()
                flipped[:, 1] = 1.0 - flipped[:, 1]
                prim["attributes"][f"TEXCOORD_{i}"] = g.add(flipped, "VEC2", 5126)
        primitive = prim
    g.write(path, ex, primitive)


def export_mesh(me, path):
    counts, arrays, attrs = mesh_arrays(me)
    write_mesh_glb(path, me.name, counts, arrays, attrs, [uv.name for uv in me.uv_layers])
    return counts


def concat_meshes(parts):
    """Joins (counts, arrays, attrs) triples into one mesh, offsetting indices;
    attributes are kept where every part has them with the same type and domain."""
    if len(parts) == 1:
        return parts[0]
    keys = ["vertex_positions", "edge_verts", "corner_verts", "corner_edges", "triangle_corners",
            "triangle_faces", "corner_normals"]
    out, offs = {k: [] for k in keys}, [0, 0, 0, 0]  # vertex, edge, corner, face
    face_offsets = [np.zeros(1, np.uint32)]
    for counts, arrays, _ in parts:
        nv, ne, nf, nc, nt = counts
        out["vertex_positions"].append(arrays["vertex_positions"])
        out["edge_verts"].append(arrays["edge_verts"] + offs[0])
        out["corner_verts"].append(arrays["corner_verts"] + offs[0])
        out["corner_edges"].append(arrays["corner_edges"] + offs[1])
        out["triangle_corners"].append(arrays["triangle_corners"] + offs[2])
        out["triangle_faces"].append(arrays["triangle_faces"] + offs[3])
        out["corner_normals"].append(arrays.get("corner_normals", np.zeros((nc, 3), np.float32)))
        if nf:
            face_offsets.append(arrays["face_offsets"][1:] + offs[2])
        offs = [offs[0] + nv, offs[1] + ne, offs[2] + nc, offs[3] + nf]
    arrays = {k: np.concatenate(v).astype(v[0].dtype) for k, v in out.items()}
    arrays["face_offsets"] = np.concatenate(face_offsets).astype(np.uint32) if offs[3] else np.zeros(0, np.uint32)
    common = None
    for _, _, attrs in parts:
        sig = {(a[0], a[1], a[2]) for a in attrs}
        common = sig if common is None else common & sig
    attrs = []
    for name, domain, dtype in sorted(common or []):
        attrs.append((name, domain, dtype, np.concatenate([d for _, _, p in parts for (n, dm, dt, d) in p if (n, dm, dt) == (name, domain, dtype)])))
    nt = len(arrays["triangle_faces"])
    return (offs[0], offs[1], offs[3], offs[2], nt), arrays, attrs


def evaluated_mesh(obj, depsgraph):
    """The object's evaluated mesh plus realised instances, in the object's local space."""
    ev = obj.evaluated_get(depsgraph)
    parts, uv_names, n_inst = [], [], 0
    me = ev.to_mesh()
    try:
        parts.append(mesh_arrays(me))
        uv_names = [uv.name for uv in me.uv_layers]
    finally:
        ev.to_mesh_clear()
    inv = np.array(ev.matrix_world.inverted(), dtype=np.float64)
    for inst in depsgraph.object_instances:
        if not inst.is_instance or inst.parent is None or inst.parent.original != obj:
            continue
        io = inst.object  # the instanced geometry (instance_object is the instancer)
        try:
            ime = io.to_mesh()
        except RuntimeError:
            continue
        if ime is None:
            continue
        try:
            counts, arrays, attrs = mesh_arrays(ime)
        finally:
            io.to_mesh_clear()
        m = inv @ np.array(inst.matrix_world, dtype=np.float64)
        p = arrays["vertex_positions"].astype(np.float64)
        arrays["vertex_positions"] = (p @ m[:3, :3].T + m[:3, 3]).astype(np.float32)
        if "corner_normals" in arrays:
            nm = np.linalg.inv(m[:3, :3]).T
            n = arrays["corner_normals"].astype(np.float64) @ nm.T
            n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
            arrays["corner_normals"] = n.astype(np.float32)
        parts.append((counts, arrays, attrs))
        n_inst += 1
    return concat_meshes(parts), uv_names, n_inst


# ---------------------------------------------------------------- other datablocks

def matrix(m):
    return [[finite(float(m[r][c]), "matrix") for c in range(4)] for r in range(4)]


def custom_props(idb):
    out = {}
    for k in idb.keys():
        if k.startswith("_") or k == "cycles":
            continue
        try:
            out[k] = plain(idb[k], f"{idb.name}[{k}]")
        except Exception:
            pass
    return out


def obj_entry(o):
    w = f'objects["{o.name}"]'
    mods = []
    for m in o.modifiers:
        d = {"name": m.name, "type": m.type, "show_render": m.show_render, "show_viewport": m.show_viewport,
             "properties": rna(m, 0, f"{w}.modifiers[{m.name}]", skip={"name", "type", "show_render", "show_viewport"}),
             "node_group": None, "inputs": {}}
        if m.type == "NODES":
            d["node_group"] = m.node_group.name if m.node_group else None
            d["inputs"] = {k: plain(m[k], f"{w}.modifiers[{m.name}][{k}]") for k in m.keys()}
        mods.append(d)
    cons = [{"name": c.name, "type": c.type, "mute": c.mute, "influence": c.influence,
             "properties": rna(c, 0, f"{w}.constraints[{c.name}]")} for c in o.constraints]
    return {
        "name": o.name, "type": o.type, "data": o.data.name if o.data else None,
        "parent": o.parent.name if o.parent else None, "parent_type": o.parent_type,
        "matrix_world": matrix(o.matrix_world), "matrix_local": matrix(o.matrix_local),
        "matrix_basis": matrix(o.matrix_basis), "matrix_parent_inverse": matrix(o.matrix_parent_inverse),
        "location": plain(o.location), "rotation_mode": o.rotation_mode,
        "rotation_euler": plain(o.rotation_euler), "rotation_quaternion": plain(o.rotation_quaternion),
        "rotation_axis_angle": plain(o.rotation_axis_angle), "scale": plain(o.scale),
        "delta_location": plain(o.delta_location), "delta_rotation_euler": plain(o.delta_rotation_euler),
        "delta_rotation_quaternion": plain(o.delta_rotation_quaternion), "delta_scale": plain(o.delta_scale),
        "hide_render": o.hide_render, "hide_viewport": o.hide_viewport,
        "visible": o.visible_get() if bpy.context.view_layer.objects.get(o.name) else False,
        "pass_index": o.pass_index, "collections": [c.name for c in o.users_collection],
        "material_slots": [{"material": s.material.name if s.material else None, "link": s.link} for s in o.material_slots],
        "modifiers": mods, "constraints": cons, "custom_properties": custom_props(o),
        "track_axis": o.track_axis, "up_axis": o.up_axis,
        "instance_type": o.instance_type,
        "instance_collection": o.instance_collection.name if o.instance_collection else None,
    }


def curve_entry(c):
    splines = []
    for s in c.splines:
        d = {"type": s.type, "use_cyclic_u": s.use_cyclic_u, "resolution_u": s.resolution_u, "order_u": s.order_u,
             "use_endpoint_u": s.use_endpoint_u, "use_bezier_u": s.use_bezier_u, "use_smooth": s.use_smooth,
             "material_index": s.material_index, "tilt_interpolation": s.tilt_interpolation,
             "radius_interpolation": s.radius_interpolation,
             "bezier_points": [{"co": plain(p.co), "handle_left": plain(p.handle_left), "handle_right": plain(p.handle_right),
                                "handle_left_type": p.handle_left_type, "handle_right_type": p.handle_right_type,
                                "radius": p.radius, "tilt": p.tilt, "weight_softbody": p.weight_softbody}
                               for p in s.bezier_points],
             "points": [{"co": plain(p.co), "radius": p.radius, "tilt": p.tilt, "weight": p.weight} for p in s.points]}
        splines.append(d)
    return {"name": c.name, "properties": rna(c, 0, f'curves["{c.name}"]', skip={"splines", "materials", "animation_data", "shape_keys"}),
            "materials": [m.name if m else None for m in c.materials], "splines": splines}


def image_entry(im, out_dir, used_names):
    d = {"name": im.name, "source": im.source, "filepath": im.filepath, "file": None, "packed": im.packed_file is not None,
         "missing": False, "colorspace": im.colorspace_settings.name, "alpha_mode": im.alpha_mode, "size": list(im.size)}
    if im.packed_file is None and im.source not in ("FILE", "SEQUENCE", "MOVIE", "TILED"):
        if im.source == "GENERATED":
            WARNINGS.append(f'images["{im.name}"]: generated image not packed; its pixels are not exported')
        return d
    os.makedirs(os.path.join(out_dir, "images"), exist_ok=True)
    base = re.sub(r"[^A-Za-z0-9._-]", "_", os.path.basename(im.filepath) or im.name) or "image"
    if im.packed_file is not None and not os.path.splitext(base)[1]:
        base += "." + {"JPEG": "jpg", "OPEN_EXR": "exr", "OPEN_EXR_MULTILAYER": "exr"}.get(im.file_format, im.file_format.lower())
    name = base
    k = 1
    while name in used_names:
        stem, ext = os.path.splitext(base)
        name = f"{stem}.{k}{ext}"
        k += 1
    target = os.path.join(out_dir, "images", name)
    if im.packed_file is not None:
        with open(target, "wb") as f:
            f.write(im.packed_file.data)
    else:
        src = bpy.path.abspath(im.filepath)
        if src and os.path.isfile(src):
            shutil.copyfile(src, target)
        else:
            d["missing"] = True
            WARNINGS.append(f'images["{im.name}"]: file {im.filepath!r} not found and not packed')
            return d
    used_names.add(name)
    d["file"] = f"images/{name}"
    return d


# ---------------------------------------------------------------- animation

def action_fcurves(anim):
    act = anim.action
    if act is None:
        return []
    slot = getattr(anim, "action_slot", None)
    if getattr(act, "is_action_layered", False) and hasattr(act, "layers") and slot is not None:
        curves = []
        for layer in act.layers:
            for strip in layer.strips:
                bag = strip.channelbag(slot) if hasattr(strip, "channelbag") else None
                if bag is not None:
                    curves.extend(bag.fcurves)
        return curves
    return list(getattr(act, "fcurves", []))


def fcurve(fc, where):
    return {
        "data_path": fc.data_path, "array_index": fc.array_index, "extrapolation": fc.extrapolation, "mute": fc.mute,
        "keyframes": [{"co": plain(k.co, where), "handle_left": plain(k.handle_left, where),
                       "handle_right": plain(k.handle_right, where), "handle_left_type": k.handle_left_type,
                       "handle_right_type": k.handle_right_type, "interpolation": k.interpolation, "easing": k.easing,
                       "back": k.back, "amplitude": k.amplitude, "period": k.period} for k in fc.keyframe_points],
        "modifiers": [{"type": m.type, "mute": m.mute, "properties": rna(m, 0, where)} for m in fc.modifiers],
    }


def anim_entry(idb, id_path):
    anim = getattr(idb, "animation_data", None)
    if anim is None:
        return None
    fcs = [fcurve(fc, f"{id_path}.{fc.data_path}") for fc in action_fcurves(anim)]
    drivers = []
    for fc in anim.drivers:
        d = fcurve(fc, f"{id_path}.{fc.data_path}")
        d["driver"] = rna(fc.driver, 0, f"{id_path}.driver")
        drivers.append(d)
    if not fcs and not drivers and anim.action is None:
        return None
    return {"id_type": idb.id_type if hasattr(idb, "id_type") else "NODETREE", "id_name": idb.name, "id_path": id_path,
            "action": anim.action.name if anim.action else None, "fcurves": fcs, "drivers": drivers}


def q(name):
    return '"' + name.replace("\\", "\\\\").replace('"', '\\"') + '"'


# ---------------------------------------------------------------- main

def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    ap = argparse.ArgumentParser(prog="export_scene.py")
    ap.add_argument("--in", dest="input", help="the .blend to export (default: the file Blender already opened)")
    ap.add_argument("--out", required=True)
    ap.add_argument("--frame", type=int)
    ap.add_argument("--no-evaluated", action="store_true")
    args = ap.parse_args(argv)
    if args.input is None:
        # `blender -b FILE --python export_scene.py -- --out DIR`: Blender opened FILE
        # itself, so it is only safe when Blender was started with --disable-autoexec.
        if not bpy.data.filepath:
            fail("no input: pass --in FILE.blend (or open the file with `blender -b --disable-autoexec FILE`)")
        args.input = bpy.data.filepath
    else:
        if not os.path.isfile(args.input):
            fail(f"input file not found: {args.input}")
        # Never run Python carried by the file.
        bpy.context.preferences.filepaths.use_scripts_auto_execute = False
        try:
            bpy.ops.wm.open_mainfile(filepath=os.path.abspath(args.input), load_ui=False, use_scripts=False)
        except Exception as e:
            fail(f"Blender cannot open {args.input}: {e}")

    out = args.out
    for sub in ("", "meshes", "evaluated"):
        os.makedirs(os.path.join(out, sub), exist_ok=True)
    scene = bpy.context.scene
    if args.frame is not None:
        scene.frame_set(args.frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()

    data = bpy.data
    meshes = []
    for i, me in enumerate(data.meshes):
        rel = f"meshes/{safe_name(i, me.name)}"
        nv, ne, nf, nc, _ = export_mesh(me, os.path.join(out, rel))
        meshes.append({"name": me.name, "file": rel, "vertex_count": nv, "edge_count": ne, "face_count": nf,
                       "corner_count": nc, "materials": [m.name if m else None for m in me.materials],
                       "uv_layers": [uv.name for uv in me.uv_layers],
                       "active_uv": me.uv_layers.active.name if me.uv_layers.active else None,
                       "active_render_uv": next((uv.name for uv in me.uv_layers if uv.active_render), None),
                       "attributes": [{"name": a.name, "domain": a.domain, "data_type": a.data_type}
                                      for a in me.attributes if not a.name.startswith(".")],
                       "texspace_location": plain(me.texspace_location), "texspace_size": plain(me.texspace_size),
                       "use_auto_texspace": me.use_auto_texspace})

    evaluated = []
    if not args.no_evaluated:
        for i, o in enumerate(data.objects):
            if o.type != "MESH" or not o.modifiers:
                continue
            (counts, arrays, attrs), uv_names, n_inst = evaluated_mesh(o, depsgraph)
            rel = f"evaluated/{safe_name(i, o.name)}"
            write_mesh_glb(os.path.join(out, rel), o.name, counts, arrays, attrs, uv_names)
            evaluated.append({"object": o.name, "frame": scene.frame_current + scene.frame_subframe, "file": rel,
                              "vertex_count": counts[0], "face_count": counts[2], "instances_realized": n_inst})

    used_images = set()
    images = [image_entry(im, out, used_images) for im in data.images if im.source != "VIEWER" and im.type != "RENDER_RESULT"]

    animation = []
    collections = [("objects", data.objects), ("meshes", data.meshes), ("curves", data.curves), ("cameras", data.cameras),
                   ("lights", data.lights), ("materials", data.materials), ("worlds", data.worlds),
                   ("scenes", data.scenes), ("node_groups", data.node_groups)]
    for coll_name, coll in collections:
        for idb in coll:
            e = anim_entry(idb, f"{coll_name}[{q(idb.name)}]")
            if e:
                animation.append(e)
            if coll_name in ("materials", "worlds") and idb.node_tree is not None:
                e = anim_entry(idb.node_tree, f"{coll_name}[{q(idb.name)}].node_tree")
                if e:
                    e["id_type"] = "NODETREE"
                    animation.append(e)

    cm = {"dir": None, "config": None}
    if scene.view_settings.view_transform not in ("Standard", "Raw"):
        src = os.path.join(bpy.utils.resource_path("LOCAL"), "datafiles", "colormanagement")
        if os.path.isdir(src):
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
            "fps": scene.render.fps, "fps_base": scene.render.fps_base,
            "camera": scene.camera.name if scene.camera else None, "world": scene.world.name if scene.world else None,
            "render": rna(scene.render, 2, "scene.render"), "cycles": rna(scene.cycles, 2, "scene.cycles") if hasattr(scene, "cycles") else {},
            "view_settings": rna(scene.view_settings, 1, "scene.view_settings"),
            "display_settings": rna(scene.display_settings, 1, "scene.display_settings"),
            "unit_settings": rna(scene.unit_settings, 1, "scene.unit_settings"),
        },
        "objects": [obj_entry(o) for o in data.objects],
        "meshes": meshes,
        "curves": [curve_entry(c) for c in data.curves],
        "materials": [{"name": m.name, "use_nodes": m.use_nodes, "pass_index": m.pass_index,
                       "node_tree": node_tree(m.node_tree, f"materials[{q(m.name)}].node_tree") if m.node_tree else None,
                       "properties": rna(m, 2, f"materials[{q(m.name)}]", skip={"node_tree", "animation_data", "grease_pencil"})}
                      for m in data.materials],
        "worlds": [{"name": w.name, "color": plain(w.color), "use_nodes": w.use_nodes,
                    "node_tree": node_tree(w.node_tree, f"worlds[{q(w.name)}].node_tree") if w.node_tree else None,
                    "properties": rna(w, 2, f"worlds[{q(w.name)}]", skip={"node_tree", "animation_data"})} for w in data.worlds],
        "node_groups": [node_tree(g, f"node_groups[{q(g.name)}]") for g in data.node_groups],
        "cameras": [{"name": c.name, "properties": rna(c, 1, f"cameras[{q(c.name)}]", skip={"animation_data"})} for c in data.cameras],
        "lights": [{"name": l.name, "type": l.type, "properties": rna(l, 2, f"lights[{q(l.name)}]", skip={"node_tree", "animation_data"})}
                   for l in data.lights],
        "images": images,
        "animation": animation,
        "evaluated": evaluated,
        "color_management": cm,
        "warnings": WARNINGS,
    }
    tmp = os.path.join(out, "scene.json.tmp")
    with open(tmp, "w") as f:
        json.dump(doc, f, indent=1, allow_nan=False)
    os.replace(tmp, os.path.join(out, "scene.json"))
    print(f"blendsynth-export: {os.path.basename(args.input)} -> {out}: {len(doc['objects'])} objects, {len(meshes)} meshes, "
          f"{len(doc['materials'])} materials, {len(doc['node_groups'])} node groups, {len(evaluated)} evaluated, "
          f"{len(WARNINGS)} warnings")


if __name__ == "__main__":
    main()
