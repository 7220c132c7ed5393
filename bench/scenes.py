"""Authors the benchmark's own scenes with bpy (bench/speed.py runs it; nothing is committed
but this script).

    .venv/bin/python bench/scenes.py NAME OUT.blend

NAME is one of:
- endo_colon: an endoscopic-scale colon (scene units metres): the inside of a 15 mm
  radius tube with haustral folds, 192 x 90 quads (34,560 triangles, smooth), a Principled
  BSDF with random-walk subsurface of millimetre radii, base colour from a 6-octave Noise
  Texture through a ColorRamp and a bump from a second 6-octave Noise Texture; a spot
  light on the scope (parented to the camera) and depth of field. 64 samples.
- shading_light: no textures: a floor, a sphere, a cube and a torus with Principled
  (coat, metal, glass, sheen) lit by a spot, a point, an area light and a grey world.
  64 samples.
- texture_heavy: a plane and a sphere whose Principled inputs come from Voronoi (F1 and
  Smooth F1, 3D and 4D), Noise (8 octaves), Wave, Magic and Gradient textures mixed by
  ColorRamps and Mix nodes, with a Voronoi bump; sun and world light. 32 samples.

Each is 256x256 with adaptive sampling and denoising off (speed.py sets size and samples
again on both sides).
"""
import math
import os
import sys

import bpy


def reset(samples):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    s = bpy.context.scene
    s.render.engine = "CYCLES"
    s.cycles.device = "CPU"
    s.render.resolution_x = s.render.resolution_y = 256
    s.render.resolution_percentage = 100
    s.cycles.samples = samples
    s.cycles.use_adaptive_sampling = False
    s.cycles.use_denoising = False
    s.view_settings.view_transform = "Standard"
    w = bpy.data.worlds.new("World")
    w.use_nodes = True
    w.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    s.world = w
    return s


def link(nt, a, b):
    nt.links.new(a, b)


def noise(nt, scale, detail, coord=None):
    n = nt.nodes.new("ShaderNodeTexNoise")
    n.inputs["Scale"].default_value = scale
    n.inputs["Detail"].default_value = detail
    if coord is not None:
        link(nt, coord, n.inputs["Vector"])
    return n


def mesh(name, verts, faces, mat):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    me.update()
    for p in me.polygons:
        p.use_smooth = True
    me.materials.append(mat)
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def endo_colon():
    s = reset(64)
    radius, length, around, along = 0.015, 0.2, 192, 90
    verts = []
    for j in range(along + 1):
        z = length * j / along
        # Haustral folds every 25 mm and a slow bend, as a colon's wall.
        fold = 1.0 - 0.18 * math.exp(-(((z % 0.025) - 0.0125) / 0.002) ** 2)
        cx, cy = 0.004 * math.sin(z * 9.0), 0.003 * math.cos(z * 13.0)
        for i in range(around):
            a = 2 * math.pi * i / around
            r = radius * fold * (1.0 + 0.04 * math.sin(3 * a + z * 40))
            verts.append((cx + r * math.cos(a), cy + r * math.sin(a), z))
    faces = []
    for j in range(along):
        for i in range(around):
            i2 = (i + 1) % around
            faces.append((j * around + i, j * around + i2, (j + 1) * around + i2, (j + 1) * around + i))
    m = bpy.data.materials.new("Mucosa")
    m.use_nodes = True
    nt = m.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    coord = nt.nodes.new("ShaderNodeTexCoord").outputs["Object"]
    col = noise(nt, 180.0, 6.0, coord)
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.45, 0.08, 0.06, 1)
    ramp.color_ramp.elements[1].color = (0.85, 0.35, 0.28, 1)
    link(nt, col.outputs["Fac"], ramp.inputs["Fac"])
    link(nt, ramp.outputs["Color"], bsdf.inputs["Base Color"])
    bump_noise = noise(nt, 400.0, 6.0, coord)
    bump = nt.nodes.new("ShaderNodeBump")
    bump.inputs["Strength"].default_value = 0.4
    bump.inputs["Distance"].default_value = 0.0005
    link(nt, bump_noise.outputs["Fac"], bump.inputs["Height"])
    link(nt, bump.outputs["Normal"], bsdf.inputs["Normal"])
    bsdf.inputs["Roughness"].default_value = 0.35
    bsdf.inputs["Subsurface Weight"].default_value = 1.0
    bsdf.inputs["Subsurface Radius"].default_value = (1.0, 0.35, 0.2)
    bsdf.inputs["Subsurface Scale"].default_value = 0.001
    mesh("Colon", verts, faces, m)
    cam_data = bpy.data.cameras.new("Scope")
    cam_data.lens = 12.0
    cam_data.clip_start = 0.0005
    cam_data.dof.use_dof = True
    cam_data.dof.focus_distance = 0.03
    cam_data.dof.aperture_fstop = 2.0
    cam = bpy.data.objects.new("Scope", cam_data)
    s.collection.objects.link(cam)
    cam.location = (0.0, 0.0, 0.01)
    # Looking down +z: rotate the camera's -z onto +z.
    cam.rotation_euler = (math.pi, 0.0, 0.0)
    s.camera = cam
    spot_data = bpy.data.lights.new("ScopeLight", "SPOT")
    spot_data.energy = 0.02
    spot_data.spot_size = math.radians(120)
    spot_data.shadow_soft_size = 0.001
    spot = bpy.data.objects.new("ScopeLight", spot_data)
    s.collection.objects.link(spot)
    spot.parent = cam
    spot.location = (0.002, 0.0, 0.0)


def principled(name, **inputs):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    b = m.node_tree.nodes["Principled BSDF"]
    for k, v in inputs.items():
        b.inputs[k].default_value = v
    return m


def add(op, mat, **kw):
    op(**kw)
    ob = bpy.context.active_object
    ob.data.materials.append(mat)
    for p in ob.data.polygons:
        p.use_smooth = True
    return ob


def stage_camera(s, loc=(0, -6, 3.2), target=(0, 0, 0.4)):
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    s.collection.objects.link(cam)
    cam.location = loc
    d = [t - l for t, l in zip(target, loc)]
    cam.rotation_euler = (math.atan2(math.hypot(d[0], d[1]), -d[2]), 0.0, math.atan2(d[1], d[0]) - math.pi / 2)
    s.camera = cam


def light(kind, loc, energy, **props):
    d = bpy.data.lights.new(kind, kind)
    d.energy = energy
    for k, v in props.items():
        setattr(d, k, v)
    ob = bpy.data.objects.new(kind, d)
    bpy.context.scene.collection.objects.link(ob)
    ob.location = loc
    return ob


def shading_light():
    s = reset(64)
    s.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.05, 0.05, 0.06, 1)
    floor = principled("Floor", **{"Base Color": (0.6, 0.6, 0.55, 1), "Roughness": 0.6})
    add(bpy.ops.mesh.primitive_plane_add, floor, size=10)
    coat = principled("Coat", **{"Base Color": (0.7, 0.1, 0.1, 1), "Coat Weight": 1.0, "Roughness": 0.5})
    add(bpy.ops.mesh.primitive_uv_sphere_add, coat, location=(-1.2, 0, 1), segments=64, ring_count=32)
    metal = principled("Metal", **{"Base Color": (0.9, 0.7, 0.4, 1), "Metallic": 1.0, "Roughness": 0.25})
    add(bpy.ops.mesh.primitive_cube_add, metal, location=(1.2, 0.3, 0.6), size=1.2)
    glass = principled("Glass", **{"Transmission Weight": 1.0, "Roughness": 0.05, "IOR": 1.45})
    add(bpy.ops.mesh.primitive_torus_add, glass, location=(0, -1.3, 0.35), major_radius=0.6, minor_radius=0.25)
    sheen = principled("Sheen", **{"Base Color": (0.2, 0.3, 0.8, 1), "Sheen Weight": 1.0, "Subsurface Weight": 0.2})
    add(bpy.ops.mesh.primitive_uv_sphere_add, sheen, location=(0.2, 1.5, 0.5), radius=0.5)
    stage_camera(s)
    spot = light("SPOT", (3, -3, 5), 800.0, spot_size=math.radians(50), shadow_soft_size=0.2)
    spot.rotation_euler = (math.radians(40), 0, math.radians(45))
    light("POINT", (-3, -2, 3), 300.0, shadow_soft_size=0.3)
    area = light("AREA", (0, 2, 4), 400.0, size=2.0)
    area.rotation_euler = (math.radians(-25), 0, 0)


def texture_heavy():
    s = reset(32)
    s.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.2, 0.22, 0.25, 1)
    m = bpy.data.materials.new("Textures")
    m.use_nodes = True
    nt = m.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    coord = nt.nodes.new("ShaderNodeTexCoord").outputs["Object"]
    vor = nt.nodes.new("ShaderNodeTexVoronoi")
    vor.inputs["Scale"].default_value = 6.0
    link(nt, coord, vor.inputs["Vector"])
    vor4 = nt.nodes.new("ShaderNodeTexVoronoi")
    vor4.voronoi_dimensions = "4D"
    vor4.feature = "SMOOTH_F1"
    vor4.inputs["Scale"].default_value = 3.0
    vor4.inputs["W"].default_value = 0.7
    link(nt, coord, vor4.inputs["Vector"])
    n8 = noise(nt, 4.0, 8.0, coord)
    wave = nt.nodes.new("ShaderNodeTexWave")
    wave.inputs["Scale"].default_value = 3.0
    wave.inputs["Distortion"].default_value = 4.0
    link(nt, coord, wave.inputs["Vector"])
    magic = nt.nodes.new("ShaderNodeTexMagic")
    magic.turbulence_depth = 4
    link(nt, coord, magic.inputs["Vector"])
    grad = nt.nodes.new("ShaderNodeTexGradient")
    link(nt, coord, grad.inputs["Vector"])
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.05, 0.1, 0.3, 1)
    ramp.color_ramp.elements[1].color = (0.9, 0.6, 0.2, 1)
    link(nt, vor.outputs["Distance"], ramp.inputs["Fac"])
    mix1 = nt.nodes.new("ShaderNodeMix")
    mix1.data_type = "RGBA"
    link(nt, n8.outputs["Fac"], mix1.inputs["Factor"])
    link(nt, ramp.outputs["Color"], mix1.inputs[6])
    link(nt, magic.outputs["Color"], mix1.inputs[7])
    mix2 = nt.nodes.new("ShaderNodeMix")
    mix2.data_type = "RGBA"
    mix2.blend_type = "MULTIPLY"
    link(nt, wave.outputs["Fac"], mix2.inputs["Factor"])
    link(nt, mix1.outputs[2], mix2.inputs[6])
    link(nt, vor4.outputs["Color"], mix2.inputs[7])
    link(nt, mix2.outputs[2], bsdf.inputs["Base Color"])
    rough = nt.nodes.new("ShaderNodeMath")
    rough.operation = "MULTIPLY_ADD"
    link(nt, grad.outputs["Fac"], rough.inputs[0])
    rough.inputs[1].default_value = 0.5
    rough.inputs[2].default_value = 0.2
    link(nt, rough.outputs[0], bsdf.inputs["Roughness"])
    bump = nt.nodes.new("ShaderNodeBump")
    bump.inputs["Strength"].default_value = 0.5
    link(nt, vor4.outputs["Distance"], bump.inputs["Height"])
    link(nt, bump.outputs["Normal"], bsdf.inputs["Normal"])
    add(bpy.ops.mesh.primitive_plane_add, m, size=8)
    add(bpy.ops.mesh.primitive_uv_sphere_add, m, location=(0, 0, 1.2), radius=1.2, segments=64, ring_count=32)
    stage_camera(s)
    sun = light("SUN", (0, 0, 5), 3.0, angle=math.radians(3))
    sun.rotation_euler = (math.radians(35), 0, math.radians(30))


SCENES = {"endo_colon": endo_colon, "shading_light": shading_light, "texture_heavy": texture_heavy}

if __name__ == "__main__":
    name, out = sys.argv[-2], sys.argv[-1]
    SCENES[name]()
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(out))
    sys.stdout.flush()
    os._exit(0)
