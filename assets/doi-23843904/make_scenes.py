"""Authors the built-in scenes of `blendsynth replicate --dataset doi-23843904` with bpy.

Procedural stand-ins for the study's scenes (Dowrick et al., DOI 10.5522/04/23843904),
built only from mesh primitives and Principled BSDF materials with procedural noise:

- colonoscopy.blend: a colon as a tube swept along a Bezier centre line, its wall
  displaced by haustral folds and smooth noise (computed here, so the mesh is plain);
  sessile polyps (flattened spheres) and stalked polyps (stalk + head) on the wall, each
  its own object with custom property class = "polyp"; a camera following the centre
  line (Follow Path, animated eval_time as in the published scene) with a spot light
  parented to it.
- laparoscopy.blend: an abdominal cavity (inward-facing flattened sphere), a liver
  (two joined lobes, class = "liver"), a gallbladder (class = "gallbladder"), bowel
  loops, a laparoscope camera with a spot light.

Scene units are metres. Run, then export with the project's exporter:
    .venv/bin/python assets/doi-23843904/make_scenes.py /tmp/replicate-blend
    blendsynth convert /tmp/replicate-blend/colonoscopy.blend -o assets/doi-23843904/colonoscopy --no-evaluated
(`assets/doi-23843904/regenerate.sh` does both.)
"""
import math, os, sys
import bpy, bmesh
from mathutils import Vector, Matrix, geometry

OUT = sys.argv[-1] if len(sys.argv) > 1 and not sys.argv[-1].endswith(".py") else "/tmp/replicate-blend"
os.makedirs(OUT, exist_ok=True)


def reset(name):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    s = bpy.context.scene
    s.name = name
    s.render.engine = "CYCLES"
    s.render.resolution_x = 512
    s.render.resolution_y = 512
    s.render.resolution_percentage = 100
    s.cycles.samples = 256
    s.cycles.use_adaptive_sampling = True
    s.cycles.adaptive_threshold = 0.1
    s.cycles.use_denoising = True
    s.view_settings.view_transform = "Standard"
    w = bpy.data.worlds.new("World")
    w.use_nodes = True
    w.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    s.world = w
    return s


def tissue(name, base, ramp_dark, ramp_light, noise_scale, detail, roughness, sss_radius):
    """Principled BSDF whose base colour is a ColorRamp over a Noise Texture."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    coord = nt.nodes.new("ShaderNodeTexCoord")
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.name = "Noise Texture"
    noise.inputs["Scale"].default_value = noise_scale
    noise.inputs["Detail"].default_value = detail
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.name = "ColorRamp"
    ramp.color_ramp.elements[0].color = ramp_dark
    ramp.color_ramp.elements[1].color = ramp_light
    nt.links.new(coord.outputs["Object"], noise.inputs["Vector"])
    nt.links.new(noise.outputs["Fac"], ramp.inputs["Fac"])
    nt.links.new(ramp.outputs["Color"], bsdf.inputs["Base Color"])
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Subsurface Weight"].default_value = 0.3
    bsdf.inputs["Subsurface Radius"].default_value = sss_radius
    bsdf.inputs["Subsurface Scale"].default_value = 0.005
    bsdf.inputs["Specular IOR Level"].default_value = 0.5
    bsdf.inputs["Coat Weight"].default_value = 0.3  # wet mucosa
    return m


def mesh_object(name, bm, material, props=None):
    me = bpy.data.meshes.new(name)
    bm.to_mesh(me)
    bm.free()
    for p in me.polygons:
        p.use_smooth = True
    me.materials.append(material)
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    for k, v in (props or {}).items():
        ob[k] = v
    return ob


def smooth_noise(t, a, seed):
    """Smooth periodic noise from a few sines (deterministic; no Blender noise)."""
    v = 0.0
    for k in range(1, 5):
        v += math.sin(k * 2.3 * a + seed * 1.7 * k + t * 9.1 * k) / k + math.cos(k * 1.3 * t * 17 + seed * k) / (2 * k)
    return v / 2.5


def colonoscopy():
    s = reset("Colonoscopy")
    s.frame_start, s.frame_end, s.frame_current = 1, 1000, 1
    # Centre line: a meandering Bezier curve, ~0.5 m.
    pts = [(0, 0, 0), (0.08, 0.012, 0.004), (0.16, -0.008, 0.012), (0.24, 0.016, 0.0), (0.33, 0.0, -0.012), (0.42, -0.02, 0.0), (0.5, 0.0, 0.008)]
    cu = bpy.data.curves.new("Centreline", "CURVE")
    cu.dimensions = "3D"
    cu.resolution_u = 24
    cu.use_path = True
    cu.path_duration = 1000
    sp = cu.splines.new("BEZIER")
    sp.bezier_points.add(len(pts) - 1)
    for bp, p in zip(sp.bezier_points, pts):
        bp.co = p
        bp.handle_left_type = bp.handle_right_type = "AUTO"
    centre = bpy.data.objects.new("Centreline", cu)
    s.collection.objects.link(centre)
    cu.eval_time = 0
    cu.keyframe_insert("eval_time", frame=1)
    cu.eval_time = 900
    cu.keyframe_insert("eval_time", frame=1000)
    for fc in cu.animation_data.action.fcurves:
        for k in fc.keyframe_points:
            k.interpolation = "LINEAR"

    # Sample the centre line (the same Bezier segments Blender evaluates).
    samples = []
    for a, b in zip(sp.bezier_points[:-1], sp.bezier_points[1:]):
        seg = geometry.interpolate_bezier(a.co, a.handle_right, b.handle_left, b.co, 40)
        samples.extend(seg[:-1])
    samples.append(sp.bezier_points[-1].co.copy())
    n_ring, radius = 40, 0.025
    frames = []
    up = Vector((0, 0, 1))
    for i, p in enumerate(samples):
        t = (samples[min(i + 1, len(samples) - 1)] - samples[max(i - 1, 0)]).normalized()
        x = up.cross(t).normalized()
        y = t.cross(x).normalized()
        frames.append((p, t, x, y))
    bm = bmesh.new()
    rings = []
    for i, (p, t, x, y) in enumerate(frames):
        u = i / (len(frames) - 1)
        ring = []
        for j in range(n_ring):
            a = 2 * math.pi * j / n_ring
            fold = 0.3 * max(0.0, math.sin(u * 2 * math.pi * 14)) ** 4  # haustral folds
            r = radius * (1 - fold + 0.08 * smooth_noise(u, a, 3.0))
            ring.append(bm.verts.new(p + r * (math.cos(a) * x + math.sin(a) * y)))
        rings.append(ring)
    for r0, r1 in zip(rings[:-1], rings[1:]):
        for j in range(n_ring):
            k = (j + 1) % n_ring
            bm.faces.new((r0[j], r0[k], r1[k], r1[j]))  # normals face the lumen
    bm.normal_update()
    wall = tissue("Colon Wall", None, (0.35, 0.06, 0.05, 1), (0.8, 0.35, 0.3, 1), 60.0, 6.0, 0.35, (1.0, 0.3, 0.2))
    mesh_object("Colon", bm, wall)
    polyp_mat = tissue("Polyp", None, (0.45, 0.08, 0.08, 1), (0.85, 0.45, 0.4, 1), 120.0, 4.0, 0.3, (1.0, 0.3, 0.2))

    # Polyps on the wall: (position along the line, angle, kind, size in m).
    placements = [(0.12, 0.5, "sessile", 0.006), (0.22, 2.6, "stalked", 0.005), (0.31, 4.4, "sessile", 0.009),
                  (0.40, 1.4, "stalked", 0.007), (0.52, 3.5, "sessile", 0.005), (0.63, 5.6, "stalked", 0.006),
                  (0.72, 0.9, "sessile", 0.008), (0.83, 3.0, "stalked", 0.005)]
    for n, (u, a, kind, size) in enumerate(placements):
        i = int(u * (len(frames) - 1))
        p, t, x, y = frames[i]
        out = math.cos(a) * x + math.sin(a) * y  # outward (towards the wall)
        wall_r = radius * 0.92
        bm = bmesh.new()
        if kind == "sessile":
            bmesh.ops.create_uvsphere(bm, u_segments=24, v_segments=12, radius=size)
            bmesh.ops.scale(bm, vec=(1, 1, 0.55), verts=bm.verts)
        else:
            bmesh.ops.create_cone(bm, cap_ends=True, segments=12, radius1=size * 0.25, radius2=size * 0.25, depth=size * 1.4)
            bmesh.ops.translate(bm, vec=(0, 0, size * 0.7), verts=bm.verts)
            head = bmesh.new()
            bmesh.ops.create_uvsphere(head, u_segments=20, v_segments=10, radius=size * 0.6)
            bmesh.ops.translate(head, vec=(0, 0, size * 1.5), verts=head.verts)
            me = bpy.data.meshes.new("tmp")
            head.to_mesh(me)
            head.free()
            bm.from_mesh(me)
            bpy.data.meshes.remove(me)
        name = f"Polyp.{kind}.{n:03d}"
        ob = mesh_object(name, bm, polyp_mat, {"class": "polyp", "polyp_type": kind})
        # Local +Z points into the lumen (-out); the base sits on the wall.
        z = -out
        xx = t.cross(z).normalized()
        yy = z.cross(xx)
        rot = Matrix((xx, yy, z)).transposed().to_4x4()
        ob.matrix_world = Matrix.Translation(p + wall_r * out) @ rot

    cam_data = bpy.data.cameras.new("Camera")
    cam_data.lens = 29.96
    cam_data.sensor_width = 36
    cam_data.clip_start = 0.001
    cam_data.clip_end = 10
    cam_data.dof.use_dof = True
    cam_data.dof.focus_distance = 0.04
    cam_data.dof.aperture_fstop = 2.0
    cam = bpy.data.objects.new("Camera", cam_data)
    s.collection.objects.link(cam)
    c = cam.constraints.new("FOLLOW_PATH")
    c.target = centre
    c.use_curve_follow = True
    c.forward_axis = "TRACK_NEGATIVE_Z"
    c.up_axis = "UP_Y"
    s.camera = cam
    spot = bpy.data.lights.new("Spot", "SPOT")
    spot.energy = 0.5
    spot.spot_size = math.radians(45)
    spot.spot_blend = 0.15
    spot.shadow_soft_size = 0.0025
    light = bpy.data.objects.new("Spot", spot)
    s.collection.objects.link(light)
    light.parent = cam
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(OUT, "colonoscopy.blend"))


def laparoscopy():
    s = reset("Laparoscopy")
    s.frame_start, s.frame_end, s.frame_current = 1, 1, 1
    # Abdominal cavity: an inward-facing flattened sphere.
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=48, v_segments=24, radius=0.18)
    bmesh.ops.scale(bm, vec=(1.2, 1.0, 0.6), verts=bm.verts)
    for v in bm.verts:
        n = v.co.normalized()
        v.co += 0.01 * smooth_noise(v.co.x * 4, math.atan2(v.co.y, v.co.x), 1.0) * n
    bmesh.ops.reverse_faces(bm, faces=bm.faces)
    wall = tissue("Peritoneum", None, (0.45, 0.12, 0.1, 1), (0.9, 0.55, 0.5, 1), 30.0, 5.0, 0.4, (1.0, 0.3, 0.2))
    mesh_object("Abdominal Cavity", bm, wall)
    # Liver: two lobes joined.
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=40, v_segments=20, radius=1.0)
    bmesh.ops.scale(bm, vec=(0.09, 0.07, 0.03), verts=bm.verts)
    lobe = bmesh.new()
    bmesh.ops.create_uvsphere(lobe, u_segments=32, v_segments=16, radius=1.0)
    bmesh.ops.scale(lobe, vec=(0.06, 0.05, 0.025), verts=lobe.verts)
    bmesh.ops.translate(lobe, vec=(0.08, -0.03, -0.005), verts=lobe.verts)
    me = bpy.data.meshes.new("tmp")
    lobe.to_mesh(me)
    lobe.free()
    bm.from_mesh(me)
    bpy.data.meshes.remove(me)
    for v in bm.verts:
        v.co.z += 0.006 * smooth_noise(v.co.x * 10, v.co.y * 10, 2.0)
    liver_mat = tissue("Liver", None, (0.18, 0.03, 0.02, 1), (0.45, 0.1, 0.06, 1), 80.0, 6.0, 0.25, (0.8, 0.2, 0.1))
    liver = mesh_object("Liver", bm, liver_mat, {"class": "liver"})
    liver.location = (0.0, 0.02, -0.02)
    # Gallbladder under the liver's edge.
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=24, v_segments=12, radius=1.0)
    bmesh.ops.scale(bm, vec=(0.035, 0.016, 0.016), verts=bm.verts)
    gb_mat = tissue("Gallbladder", None, (0.2, 0.3, 0.05, 1), (0.55, 0.6, 0.2, 1), 40.0, 3.0, 0.2, (0.5, 0.6, 0.2))
    gb = mesh_object("Gallbladder", bm, gb_mat, {"class": "gallbladder"})
    gb.location = (0.03, -0.05, -0.035)
    gb.rotation_euler = (0, 0.2, 0.5)
    # Bowel loops below.
    fat_mat = tissue("Bowel", None, (0.6, 0.4, 0.25, 1), (0.95, 0.8, 0.55, 1), 25.0, 4.0, 0.35, (1.0, 0.6, 0.3))
    for n, (x, y, r) in enumerate([(-0.08, -0.06, 0.4), (-0.02, -0.1, 1.3), (0.07, -0.1, 2.2)]):
        bm = bmesh.new()
        bmesh.ops.create_uvsphere(bm, u_segments=32, v_segments=12, radius=1.0)
        bmesh.ops.scale(bm, vec=(0.05, 0.025, 0.02), verts=bm.verts)
        ob = mesh_object(f"Bowel.{n:03d}", bm, fat_mat)
        ob.location = (x, y, -0.06)
        ob.rotation_euler = (0, 0, r)
    cam_data = bpy.data.cameras.new("Laparoscope")
    cam_data.lens = 18
    cam_data.sensor_width = 36
    cam_data.clip_start = 0.002
    cam_data.clip_end = 10
    cam_data.dof.use_dof = True
    cam_data.dof.focus_distance = 0.1
    cam_data.dof.aperture_fstop = 4.0
    cam = bpy.data.objects.new("Laparoscope", cam_data)
    s.collection.objects.link(cam)
    cam.location = (0.0, -0.02, 0.08)
    cam.rotation_euler = (math.radians(20), 0, 0)
    s.camera = cam
    spot = bpy.data.lights.new("Spot", "SPOT")
    spot.energy = 2.0
    spot.spot_size = math.radians(120)
    spot.spot_blend = 0.5
    spot.shadow_soft_size = 0.003
    light = bpy.data.objects.new("Spot", spot)
    s.collection.objects.link(light)
    light.parent = cam
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(OUT, "laparoscopy.blend"))


colonoscopy()
laparoscopy()
print("wrote", OUT)
sys.stdout.flush()
os._exit(0)
