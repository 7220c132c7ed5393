//! Evaluating a material over an object's UV map, as Cycles' EMIT bake does: one shading
//! point per texel centre that a UV triangle covers, the surface point and normal
//! interpolated from the mesh, the surface's total emission recorded.

use std::path::Path;

use crate::foundation::math::{Vec3, V3};
use crate::scene::{AttributeData, Scene};

use crate::shader::bump::{
    attribute_differential, differential_dudv, differential_from_compact,
    differential_make_compact, ObjectTransform,
};
use crate::shader::compile::compile_material;
use crate::shader::point::ShadingPoint;
use crate::shader::program::Program;

#[derive(Debug, Clone)]
pub struct BakeOptions {
    pub object: String,
    /// UV map name (default: the mesh's active render UV map).
    pub uv: Option<String>,
    /// Image width and height in texels.
    pub size: u32,
}

/// A baked image: RGBA floats, rows bottom to top as Blender stores images (row 0 is v
/// near 0). Texels no triangle covers stay (0, 0, 0, 0).
#[derive(Debug, Clone)]
pub struct Baked {
    pub size: u32,
    pub pixels: Vec<[f32; 4]>,
}

// Long because the bake driver: UV rasterisation, the texel loop and writing, in Cycles' EMIT bake order.
pub fn bake_emission(scene: &Scene, opts: &BakeOptions) -> Result<Baked, String> {
    let size = opts.size;
    if size == 0 || size > 16384 {
        return Err(format!("--size {size}: must be 1 to 16384"));
    }
    let obj = scene
        .object(&opts.object)
        .ok_or_else(|| format!("no object {:?}", opts.object))?;
    if obj.kind != "MESH" {
        return Err(format!(
            "object {:?} is a {}, not a mesh",
            obj.name, obj.kind
        ));
    }
    let mesh_name = obj
        .data
        .as_deref()
        .ok_or_else(|| format!("object {:?} has no mesh", obj.name))?;
    let mesh_index = scene
        .file
        .meshes
        .iter()
        .position(|m| m.name == mesh_name)
        .ok_or_else(|| format!("mesh {mesh_name:?} missing"))?;
    let info = &scene.file.meshes[mesh_index];
    let mesh = scene.load_mesh(mesh_index).map_err(|e| e.to_string())?;
    let uv_name = opts
        .uv
        .clone()
        .or_else(|| info.active_render_uv.clone())
        .ok_or_else(|| format!("mesh {mesh_name:?} has no UV map"))?;
    let uvs = match mesh.attribute(&uv_name).map(|a| &a.data) {
        Some(AttributeData::Float2(v)) if v.len() == mesh.corner_count() => v,
        _ => return Err(format!("mesh {mesh_name:?} has no UV map {uv_name:?}")),
    };
    let material_index: Vec<i32> = match mesh.attribute("material_index").map(|a| &a.data) {
        Some(AttributeData::Int(v)) => v.clone(),
        _ => vec![0; mesh.face_count()],
    };

    let flat: Vec<bool> = match mesh.attribute("sharp_face").map(|a| &a.data) {
        Some(AttributeData::Bool(v)) => v.clone(),
        _ => vec![false; mesh.face_count()],
    };
    // Cycles shades smooth triangles with Blender's vertex normals, unless the mesh has
    // custom normals (then its corner normals).
    let vertex_normals = crate::shader::tangent::vertex_normals(&mesh);
    let custom = mesh.attribute("custom_normal").is_some();
    let smooth_normal = |c: usize| -> V3 {
        if custom {
            mesh.corner_normals
                .get(c)
                .copied()
                .unwrap_or([0.0, 0.0, 1.0])
        } else {
            vertex_normals[mesh.corner_verts[c] as usize]
        }
    };
    // One program per material slot; a face without a material emits nothing.
    let mut programs: Vec<Option<Program>> = Vec::new();
    let slots = if obj.material_slots.is_empty() {
        info.materials.clone()
    } else {
        obj.material_slots
            .iter()
            .map(|s| s.material.clone())
            .collect()
    };
    for m in &slots {
        programs.push(match m {
            Some(name) => {
                let p = compile_material(scene, name).map_err(|e| e.to_string())?;
                // Cycles' bake traces them against the whole scene; this bake has none.
                if p.traces_rays() {
                    return Err(format!(
                        "material {name:?}: Ambient Occlusion and Bevel nodes trace rays, which the bake does not support (render the scene instead)"
                    ));
                }
                // A bake evaluates surfaces; a volume is rendered (render/volume.rs), not
                // baked.
                if p.volume.is_some() {
                    return Err(format!(
                        "material {name:?}: Material Output: volume shading (its Volume input is linked) is not supported by bake"
                    ));
                }
                Some(p)
            }
            None => None,
        });
    }

    let world = obj.matrix_world;
    let inverse = crate::shader::view::invert_affine(&world)
        .ok_or_else(|| format!("object {:?} has a singular transform", obj.name))?;
    let normal_matrix = inverse_transpose3(&world)
        .ok_or_else(|| format!("object {:?} has a singular transform", obj.name))?;
    let (tex_loc, tex_size) = (
        info.texspace_location.unwrap_or([0.0; 3]),
        info.texspace_size.unwrap_or([1.0; 3]),
    );
    let f32_rows = |m: &[[f64; 4]; 4]| -> [[f32; 4]; 3] {
        std::array::from_fn(|r| std::array::from_fn(|k| m[r][k] as f32))
    };
    let transform = ObjectTransform {
        to_world: f32_rows(&world),
        to_object: f32_rows(&inverse),
    };

    // What Cycles' EMIT bake gives the context-reading nodes: the scene camera, the object.
    let view = scene_view(scene)?.unwrap_or_default();
    let object = crate::shader::view::object_info(obj, &world);
    // Instancer attributes of an object that is no instance: its own and its data's.
    let instancer_values: Vec<(String, [f32; 4])> = obj
        .attribute_lookups
        .iter()
        .map(|(n, l)| (n.clone(), l.object.or(l.data).unwrap_or([0.0; 4])))
        .collect();
    let n = size as usize;
    let mut pixels = vec![[0.0f32; 4]; n * n];
    let bound = programs
        .iter()
        .map(|p| match p {
            Some(p) => crate::shader::attributes::BoundAttributes::bind(
                &mesh,
                &p.attributes,
                info.active_render_uv.as_deref(),
                info.default_color_attribute.as_deref(),
            )
            .map_err(|e| format!("mesh {mesh_name:?}: {e}")),
            None => Ok(Default::default()),
        })
        .collect::<Result<Vec<_>, String>>()?;
    let mut stacks: Vec<Vec<f32>> = programs
        .iter()
        .map(|p| p.as_ref().map(Program::new_stack).unwrap_or_default())
        .collect();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let face = mesh.triangle_faces[t] as usize;
        let slot = (material_index[face].max(0) as usize).min(programs.len().saturating_sub(1));
        let Some(program) = programs.get(slot).and_then(Option::as_ref) else {
            continue;
        };
        let stack = &mut stacks[slot];
        let c = tri.map(|c| c as usize);
        let uv = c.map(|c| uvs[c]);
        let px = uv.map(|u| [u[0] * size as f32, u[1] * size as f32]);
        let (x0, x1) = span(px.map(|p| p[0]), n);
        let (y0, y1) = span(px.map(|p| p[1]), n);
        let area = edge(px[0], px[1], px[2]);
        if area == 0.0 {
            continue;
        }
        let diff = TriangleDifferentials::new(
            &world,
            uv,
            size,
            c.map(|c| mesh.positions[mesh.corner_verts[c] as usize]),
            tex_loc,
            tex_size,
        );
        for y in y0..y1 {
            for x in x0..x1 {
                // Blender's bake rasteriser samples slightly off the texel centre
                // (measured: +0.001 texel in u, +0.002 in v), so values match at its points.
                let p = [x as f32 + 0.501, y as f32 + 0.502];
                let (w0, w1, w2) = (
                    edge(px[1], px[2], p) / area,
                    edge(px[2], px[0], p) / area,
                    edge(px[0], px[1], p) / area,
                );
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let w = [w0, w1, w2];
                let lerp = |v: [V3; 3]| -> V3 {
                    std::array::from_fn(|k| w[0] * v[0][k] + w[1] * v[1][k] + w[2] * v[2][k])
                };
                let local = lerp(c.map(|c| mesh.positions[mesh.corner_verts[c] as usize]));
                // Cycles moves vertices to world space and derives object coordinates back
                // through the inverse transform; doing the same keeps its rounding.
                let position = lerp(c.map(|c| {
                    transform_point(&world, mesh.positions[mesh.corner_verts[c] as usize])
                }));
                // Cycles applies the object transform to a single-user mesh: vertex normals
                // go to world space (normalised) before interpolation, and the object-space
                // normal (Texture Coordinate > Normal, box projection) comes back through
                // the transpose.
                let world_n = normalize3(lerp(
                    c.map(|c| normalize3(mul3x3(&normal_matrix, smooth_normal(c)))),
                ));
                // A flat face shades with its triangle's normal (Cycles' sd->N = Ng), which
                // differs from Blender's face normal where a quad is not planar.
                let world_n = if flat[face] {
                    flat_normal(c.map(|c| {
                        transform_point(&world, mesh.positions[mesh.corner_verts[c] as usize])
                    }))
                } else {
                    world_n
                };
                let sp = ShadingPoint {
                    position,
                    normal: world_n,
                    object_position: transform_point(&inverse, position),
                    object_normal: normalize3(mul3x3_transposed(&world, world_n)),
                    generated: std::array::from_fn(|k| {
                        ((local[k] as f64 - tex_loc[k]) / (2.0 * tex_size[k]) + 0.5) as f32
                    }),
                    uv: {
                        let u = lerp(c.map(|c| [uvs[c][0], uvs[c][1], 0.0]));
                        [u[0], u[1], 0.0]
                    },
                    ..diff.point(transform)
                };
                let mut sp = bake_context(
                    sp,
                    &view,
                    object,
                    c.map(|c| {
                        transform_point(&world, mesh.positions[mesh.corner_verts[c] as usize])
                    }),
                    w,
                );
                bound[slot].fill(&mesh, t, c, face, w, &instancer_values, &mut sp);
                program.run(&sp, stack);
                let e = program.surface_emission(stack);
                pixels[y * n + x] = [e[0], e[1], e[2], 1.0];
            }
        }
    }
    Ok(Baked { size, pixels })
}

/// Texel columns (or rows) whose centres can fall inside `[min, max]` of the coordinates.
fn span(v: [f32; 3], n: usize) -> (usize, usize) {
    let lo = v.iter().copied().fold(f32::INFINITY, f32::min);
    let hi = v.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let a = (lo - 0.5).ceil().max(0.0) as usize;
    let b = ((hi - 0.5).floor() + 1.0).clamp(0.0, n as f32) as usize;
    (a.min(n), b)
}

fn edge(a: [f32; 2], b: [f32; 2], p: [f32; 2]) -> f32 {
    (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
}

fn transform_point(m: &[[f64; 4]; 4], p: V3) -> V3 {
    std::array::from_fn(|r| {
        (m[r][0] * p[0] as f64 + m[r][1] * p[1] as f64 + m[r][2] * p[2] as f64 + m[r][3]) as f32
    })
}

fn mul3x3(m: &[[f64; 3]; 3], v: V3) -> V3 {
    std::array::from_fn(|r| {
        (m[r][0] * v[0] as f64 + m[r][1] * v[1] as f64 + m[r][2] * v[2] as f64) as f32
    })
}

fn inverse_transpose3(m: &[[f64; 4]; 4]) -> Option<[[f64; 3]; 3]> {
    // The transposed upper 3x3 of the inverse (the same cofactors over the same determinant).
    let inv = crate::shader::view::invert_affine(m)?;
    Some(std::array::from_fn(|r| std::array::from_fn(|c| inv[c][r])))
}

/// Writes a baked image as a 32-bit float RGBA EXR (top row first, as image files are),
/// atomically: to a temporary file beside `path`, then renamed.
pub fn write_exr(b: &Baked, path: &Path) -> Result<(), String> {
    let n = b.size as usize;
    let mut rows = vec![[0.0f32; 4]; n * n];
    for y in 0..n {
        rows[(n - 1 - y) * n..(n - y) * n].copy_from_slice(&b.pixels[y * n..(y + 1) * n]);
    }
    crate::color::write_exr(path, b.size, b.size, &rows).map_err(|e| e.to_string())
}

/// The transpose of the 3x3 part of `m` times `v` (world to object for normals).
fn mul3x3_transposed(m: &[[f64; 4]; 4], v: V3) -> V3 {
    std::array::from_fn(|c| {
        (m[0][c] * v[0] as f64 + m[1][c] * v[1] as f64 + m[2][c] * v[2] as f64) as f32
    })
}

/// A bake triangle's ray differentials as Cycles gets them for a bake: Blender's
/// bake_differentials (half-texel steps of the barycentrics), turned into dP/dx, dP/dy on
/// the world-space triangle, compacted to one radius (init_from_bake.h) and expanded again
/// around the geometric normal when shading, as every Cycles shading point is.
struct TriangleDifferentials {
    ng: V3,
    dp: [V3; 2],
    generated: [V3; 2],
    uv: [V3; 2],
}

impl TriangleDifferentials {
    fn new(
        world: &[[f64; 4]; 4],
        uv: [[f32; 2]; 3],
        size: u32,
        local: [V3; 3],
        tex_loc: [f64; 3],
        tex_size: [f64; 3],
    ) -> Self {
        let p = local.map(|l| transform_point(world, l));
        let ng = flat_normal(p);
        let (dpdu, dpdv): (V3, V3) = (
            (Vec3::from(p[1]) - p[0].into()).into(),
            (Vec3::from(p[2]) - p[0].into()).into(),
        );
        // Blender's rasteriser coordinates (texel centres at integers).
        let v = uv.map(|t| {
            [
                t[0] * size as f32 - (0.5 + 0.001),
                t[1] * size as f32 - (0.5 + 0.002),
            ]
        });
        let mut a =
            (v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1]);
        let (du_dx, dv_dx, du_dy, dv_dy) = if a.abs() > f32::EPSILON {
            a = 0.5 / a;
            (
                (v[1][1] - v[2][1]) * a,
                (v[2][1] - v[0][1]) * a,
                (v[2][0] - v[1][0]) * a,
                (v[0][0] - v[2][0]) * a,
            )
        } else {
            (0.0, 0.0, 0.0, 0.0)
        };
        // Blender weighs (corner 0, 1, 2) by (u, v, 1-u-v); Cycles by (1-u-v, u, v).
        let (cu_dx, cv_dx, cu_dy, cv_dy) = (dv_dx, -du_dx - dv_dx, dv_dy, -du_dy - dv_dy);
        let lin =
            |a: V3, s: f32, b: V3, t: f32| -> V3 { std::array::from_fn(|k| a[k] * s + b[k] * t) };
        let full = [lin(dpdu, cu_dx, dpdv, cv_dx), lin(dpdu, cu_dy, dpdv, cv_dy)];
        let (dx, dy) = differential_from_compact(ng, differential_make_compact(full[0], full[1]));
        let duv = differential_dudv(dpdu, dpdv, [dx, dy], ng);
        let generated = local.map(|l| {
            std::array::from_fn(|k| ((l[k] as f64 - tex_loc[k]) / (2.0 * tex_size[k]) + 0.5) as f32)
        });
        let uvs = uv.map(|t| [t[0], t[1], 0.0]);
        TriangleDifferentials {
            ng,
            dp: [dx, dy],
            generated: [
                attribute_differential(generated, duv[0]),
                attribute_differential(generated, duv[1]),
            ],
            uv: [
                attribute_differential(uvs, duv[0]),
                attribute_differential(uvs, duv[1]),
            ],
        }
    }

    /// The differential fields of a shading point on this triangle.
    fn point(&self, transform: ObjectTransform) -> ShadingPoint {
        ShadingPoint {
            ng: self.ng,
            dp_dx: self.dp[0],
            dp_dy: self.dp[1],
            generated_dx: self.generated[0],
            generated_dy: self.generated[1],
            uv_dx: self.uv[0],
            uv_dy: self.uv[1],
            transform,
            ..ShadingPoint::default()
        }
    }
}

/// The rest of the shading context as Cycles' EMIT bake sets it: a ray of length 1
/// arriving along the shading normal (so Incoming is the normal), a camera ray's path
/// state, the true normal of the world-space triangle, barycentrics as Cycles stores
/// them, and the scene camera's view of the point.
fn bake_context(
    mut sp: ShadingPoint,
    view: &crate::shader::view::View,
    object: crate::shader::point::ObjectInfo,
    tri: [V3; 3],
    w: [f32; 3],
) -> ShadingPoint {
    let ng = Vec3::from(flat_normal(tri));
    sp.incoming = sp.normal;
    sp.backfacing = ng.dot(sp.incoming.into()) < 0.0;
    if sp.backfacing {
        sp.true_normal = (-ng).into();
        sp.normal = (-Vec3::from(sp.normal)).into();
    } else {
        sp.true_normal = ng.into();
    }
    // Cycles' (u, v) are the weights of the triangle's second and third corners.
    sp.parametric = [w[1], w[2]];
    sp.ray_length = 1.0;
    sp.path = crate::shader::point::PathState::CAMERA;
    sp.camera_position = view.camera_space(sp.position);
    sp.camera = view.camera();
    sp.triangle = tri;
    sp.window = view.window(sp.camera_position);
    sp.object = object;
    sp
}

/// The unit normal of a triangle (corners counter-clockwise).
fn flat_normal(p: [V3; 3]) -> V3 {
    let p = p.map(Vec3::from);
    normalize3((p[1] - p[0]).cross(p[2] - p[0]).into())
}

/// Cycles' `normalize`: each component divided by the length (NaN for a zero vector).
fn normalize3(v: V3) -> V3 {
    let v = Vec3::from(v);
    (v / v.length()).into()
}

/// The scene camera's view at the scene's current frame and render resolution, for an
/// EMIT bake (None: the scene has no camera, and the default view stands in as Cycles'
/// default camera does).
fn scene_view(scene: &crate::scene::Scene) -> Result<Option<crate::shader::view::View>, String> {
    if scene.file.scene.camera.is_none() {
        return Ok(None);
    }
    let (w, h) = crate::scene::settings::Output::of(&scene.file.scene).size()?;
    let eval = crate::anim::evaluate_scene(scene, scene.file.scene.frame_current as f64)
        .map_err(|e| format!("evaluating the scene for its camera: {e}"))?;
    let cam = crate::render::camera::Camera::new(scene, &eval, w, h).map_err(|e| e.0)?;
    Ok(Some(cam.view()))
}
