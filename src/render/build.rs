//! The scene at one frame as the renderer needs it: mesh objects (their exported
//! meshes, or Geometry Nodes output realised) with world transforms, material slots,
//! and every triangle in world space for the acceleration structure.

use std::collections::HashMap;

use rayon::prelude::*;
use std::sync::Arc;

use crate::anim::EvaluatedScene;
use crate::scene::{AttributeData, MeshData, Scene};
use crate::shader::attributes::BoundAttributes;

use super::RenderError;
use crate::render::math::*;
use crate::render::volume_grid::{DomainGrids, GridStep};

/// One renderable mesh instance.
pub struct MeshInstance {
    pub object: usize,
    pub name: String,
    pub instance_index: Option<u32>,
    pub mesh: Arc<MeshData>,
    pub to_world: Affine,
    pub to_object: Affine,
    /// Global material index per slot (None: no material, Cycles' default surface).
    pub slots: Vec<Option<usize>>,
    /// Per face: slot index.
    pub face_slot: Vec<u32>,
    /// Active render UV map, per corner.
    pub uv: Option<Arc<Vec<[f32; 2]>>>,
    pub tex_loc: V3,
    pub tex_size: V3,
    pub world_bounds: (V3, V3),
    /// Object Info values and the world-to-object transform the shader reads.
    pub info: crate::shader::point::ObjectInfo,
    /// Transforms across the shutter when the object moves within it (`object_motion`).
    pub motion: Option<Arc<crate::render::motion::object::ObjectMotion>>,
    /// Object-space vertex positions before true displacement (`displace`), which
    /// Generated coordinates and the displacement bump read.
    pub undisplaced: Option<Arc<Vec<V3>>>,
    /// The mesh's active render UV map and default colour attribute by name (what
    /// tangents and Color Attribute without a name read).
    pub uv_name: Option<String>,
    pub default_color: Option<String>,
    /// Per slot: the attributes its material reads, bound to this mesh (`bind_attributes`);
    /// empty until then and for materials that read none.
    pub attributes: Vec<Option<Arc<BoundAttributes>>>,
    /// What an Instancer Attribute node reads on this instance, per name the file's
    /// nodes ask for (Blender's BKE_object_dupli_find_rgba_attribute): the Geometry
    /// Nodes instance attribute, else the object's then its data's custom property or
    /// RNA path, else zero.
    pub instancer_values: Vec<(String, [f32; 4])>,
    /// Names among those that sit on instances nested inside this instance's geometry
    /// (realised into its mesh here, where Cycles would read them per nested instance).
    pub nested_instancer_names: Vec<String>,
    /// The rays that see the instance, as `accel::visibility` bits (its object's Cycles
    /// ray visibility).
    pub visibility: u32,
    /// Object > Visibility > Holdout: a hole in the film for camera rays.
    pub holdout: bool,
    /// Object > Shading > Shadow Terminator > Geometry Offset (`terminator`).
    pub shadow_terminator: f32,
    /// Cycles' shadow terminator shading offset as its kernel keeps it, 1 / (1 - offset / 2)
    /// (1: none); see `terminator::shift_cos_in`.
    pub terminator_frequency: f32,
    /// Hair: the object's curves (`render::curves`); the instance then has no triangles
    /// and its prims are curve segments.
    pub curves: Option<Arc<crate::render::curves::ObjectCurves>>,
    /// A smoke domain's or Volume object's voxel grids (`volume_grid`); the instance's
    /// mesh is then a box around them.
    pub grids: Option<Arc<DomainGrids>>,
}

impl MeshInstance {
    /// The material of triangle `tri` of the mesh: its face's slot (slot 0 without
    /// per-face slots), None for an empty slot.
    #[inline]
    pub fn material_of(&self, tri: usize) -> Option<usize> {
        if let Some(c) = &self.curves {
            // A curve segment: its curve's slot.
            let curve = c.segments.get(tri).map_or(0, |s| s.0 as usize);
            let slot = c.slot.get(curve).copied().unwrap_or(0) as usize;
            return self.slots.get(slot).copied().flatten();
        }
        let face = self.mesh.triangle_faces[tri] as usize;
        let slot = self.face_slot.get(face).copied().unwrap_or(0) as usize;
        self.slots.get(slot).copied().flatten()
    }

    /// Texture Coordinate > Generated of object-space point `local`: 0..1 over the
    /// instance's texture space.
    pub fn generated(&self, local: V3) -> V3 {
        [0, 1, 2].map(|k| (local[k] - self.tex_loc[k]) / (2.0 * self.tex_size[k]) + 0.5)
    }
}

/// World-space bounds of `positions` placed by `to_world`.
pub fn world_bounds(positions: &[V3], to_world: &Affine) -> (V3, V3) {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in positions {
        let w = to_world.point(*p);
        lo = vmin(lo, w);
        hi = vmax(hi, w);
    }
    (lo, hi)
}

/// Per triangle: which instance and which of its mesh's triangles.
#[derive(Debug, Clone, Copy)]
pub struct TriRef {
    pub inst: u32,
    pub tri: u32,
}

pub struct Geometry {
    pub instances: Vec<MeshInstance>,
    pub tris: Vec<[V3; 3]>,
    pub refs: Vec<TriRef>,
    /// Objects blendsynth evaluates but renders from Blender's evaluated mesh instead
    /// (`geometry::source::frozen_instead`), so `inspect` lists them as frozen.
    pub frozen_instead: Vec<FrozenInstead>,
}

/// An object rendered from the export's evaluated mesh although blendsynth evaluates it.
#[derive(Debug, Clone)]
pub struct FrozenInstead {
    pub object: String,
    /// Its entry in `scene.file.evaluated`.
    pub evaluated: usize,
    pub reason: &'static str,
}

fn material_index(scene: &Scene, name: &Option<String>) -> Option<usize> {
    name.as_ref()
        .and_then(|n| scene.file.materials.iter().position(|m| &m.name == n))
}

/// What an instance's mesh carries beside its triangles: material slots, the UV map and
/// colour attribute unnamed reads use, and the texture space (None: the mesh's bounds).
struct MeshInfo<'a> {
    materials: &'a [Option<String>],
    uv_name: Option<String>,
    default_color: Option<String>,
    texspace: Option<(V3, V3)>,
}

impl<'a> MeshInfo<'a> {
    fn of_mesh(m: &'a crate::scene::MeshRef) -> MeshInfo<'a> {
        MeshInfo {
            materials: &m.materials,
            uv_name: m
                .active_render_uv
                .clone()
                .or_else(|| m.uv_layers.first().cloned()),
            default_color: m.default_color_attribute.clone(),
            texspace: match (m.texspace_location, m.texspace_size) {
                (Some(l), Some(s)) => Some((l.map(|x| x as f32), s.map(|x| x as f32))),
                _ => None,
            },
        }
    }
}

/// Whether Blender renders the object itself: in a collection the view layer renders,
/// not hidden in render, seen by some ray, and not the child of a vertex or face
/// instancer (Blender renders only its instances).
pub fn renders_itself(eval: &EvaluatedScene, obj: &crate::scene::Object) -> bool {
    if !obj.in_render_layer || obj.hide_render || object_visibility(obj) == 0 {
        return false;
    }
    let instanced_by_parent = obj.parent.as_deref().is_some_and(|p| {
        eval.data
            .objects
            .iter()
            .find(|o| o.name == p)
            .is_some_and(|o| matches!(o.instance_type.as_deref(), Some("VERTS" | "FACES")))
    });
    !instanced_by_parent
}

// Long because one pass over the objects, every per-object decision (visibility, geometry source, materials) in Cycles' sync order.
pub fn build(
    scene: &Scene,
    eval: &EvaluatedScene,
    overrides: &[(String, serde_json::Value)],
) -> Result<Geometry, RenderError> {
    use crate::geometry::source::{object_source, Source};
    let mut cache: HashMap<usize, Arc<MeshData>> = HashMap::new();
    let mut instances = Vec::new();
    let mut frozen_instead = Vec::new();
    let overridden: Vec<String> = overrides.iter().map(|(p, _)| p.clone()).collect();
    for (oi, obj) in eval.data.objects.iter().enumerate() {
        // Cycles does not sync an object no ray can see.
        if !renders_itself(eval, obj) {
            continue;
        }
        if let Some((di, _)) = scene.smoke_domain(&obj.name, eval.frame) {
            let to_world = Affine::from_rows(&eval.world_matrices[oi]);
            push_smoke_domain(&mut instances, scene, (oi, obj), di, eval.frame, to_world)?;
            continue;
        }
        if obj.kind == "VOLUME" {
            let to_world = Affine::from_rows(&eval.world_matrices[oi]);
            push_volume_object(&mut instances, scene, (oi, obj), eval.frame, to_world)?;
            continue;
        }
        let source = object_source(scene, obj, eval.frame, &overridden)
            .map_err(|e| RenderError(e.to_string()))?;
        if source == Source::None {
            continue;
        }
        if obj.is_shadow_catcher {
            warn_shadow_catcher(&obj.name);
        }
        let to_world = Affine::from_rows(&eval.world_matrices[oi]);
        let mesh_ref = obj
            .data
            .as_deref()
            .and_then(|d| scene.file.meshes.iter().find(|m| m.name == d));
        let start = instances.len();
        let mut source = source;
        loop {
            match source {
                Source::None => {}
                Source::Mesh(mi) => {
                    let info = &scene.file.meshes[mi];
                    let m = match cache.get(&mi) {
                        Some(m) => m.clone(),
                        None => {
                            let m = Arc::new(
                                scene
                                    .load_mesh(mi)
                                    .map_err(|e| RenderError(e.to_string()))?,
                            );
                            cache.insert(mi, m.clone());
                            m
                        }
                    };
                    push_instance(
                        &mut instances,
                        scene,
                        oi,
                        obj,
                        &MeshInfo::of_mesh(info),
                        m,
                        to_world,
                        None,
                    )?;
                }
                Source::Frozen(ei) => {
                    let e = &scene.file.evaluated[ei];
                    let m = Arc::new(
                        scene
                            .load_evaluated(ei)
                            .map_err(|err| RenderError(format!("object {:?}: {err}", obj.name)))?,
                    );
                    // Cycles' Generated coordinates of a modified mesh follow the mesh's
                    // texture space; other types' follow the evaluated bounds.
                    let texspace = mesh_ref.and_then(|r| MeshInfo::of_mesh(r).texspace);
                    let info = MeshInfo {
                        materials: &e.materials,
                        uv_name: e
                            .active_render_uv
                            .clone()
                            .or_else(|| e.uv_layers.first().cloned()),
                        default_color: e.default_color_attribute.clone(),
                        texspace,
                    };
                    let before = instances.len();
                    match &e.realized {
                        Some(r) => push_realized(
                            &mut instances,
                            scene,
                            (oi, obj),
                            &info,
                            &m,
                            r,
                            &eval.world_matrices[oi],
                        )?,
                        None => {
                            push_instance(&mut instances, scene, oi, obj, &info, m, to_world, None)?
                        }
                    }
                    if e.instances_realized.unwrap_or(0) > 0 {
                        // Blender realised instances into this mesh; Cycles would read an
                        // Instancer attribute per nested instance (refused in bind_attributes).
                        for pushed in &mut instances[before..] {
                            pushed.nested_instancer_names =
                                obj.attribute_lookups.keys().cloned().collect();
                        }
                    }
                    let hair = scene
                        .load_hair(ei)
                        .map_err(|err| RenderError(format!("object {:?}: {err}", obj.name)))?;
                    if let Some(h) = hair {
                        push_curves(&mut instances, scene, oi, obj, &info, &h, to_world)?;
                    }
                    let points = scene
                        .load_points(ei)
                        .map_err(|err| RenderError(format!("object {:?}: {err}", obj.name)))?;
                    if let Some((keys, slots)) = points.filter(|p| !p.0.is_empty()) {
                        // The export carries no point attributes (reads are refused).
                        push_points(
                            &mut instances,
                            scene,
                            oi,
                            obj,
                            &info,
                            (&keys, &slots),
                            Vec::new(),
                            to_world,
                        )?;
                    }
                }
                Source::Evaluate => {
                    let curve_materials = obj
                        .data
                        .as_deref()
                        .and_then(|d| scene.file.curves.iter().find(|c| c.name == d))
                        .map(|c| c.materials.clone())
                        .unwrap_or_default();
                    let base = match mesh_ref {
                        Some(r) => MeshInfo::of_mesh(r),
                        None => MeshInfo {
                            materials: &curve_materials,
                            uv_name: None,
                            default_color: None,
                            texspace: None,
                        },
                    };
                    let set =
                        crate::geometry::evaluate_object(scene, &obj.name, eval.frame, overrides)
                            .map_err(|e| RenderError(format!("object {:?}: {e}", obj.name)))?;
                    // Top-level instances stay separate, each with its own id, sharing the
                    // realised mesh of its reference; the rest of the set is one mesh.
                    let mut rest = set.clone();
                    let instances_component = rest.instances.take();
                    let realise = |g: &crate::geometry::GeometrySet| -> Result<(Arc<MeshData>, Vec<Option<String>>), RenderError> {
                    let (g, points) = cycles_renders(g);
                    if let Some(p) = points {
                        return Err(RenderError(format!("object {:?}: its Geometry Nodes instances hold a point cloud ({} points), which Cycles renders as spheres: points in instances are not supported by the renderer yet", obj.name, p.len())));
                    }
                    let m = crate::geometry::realize_to_mesh(&g).map_err(|e| RenderError(format!("object {:?}: {e}", obj.name)))?;
                    let mats = if m.materials.is_empty() { base.materials.to_vec() } else { m.materials.clone() };
                    Ok((Arc::new(m.to_scene(&obj.name)), mats))
                };
                    if let Some(inst) = &instances_component {
                        if inst
                            .references
                            .iter()
                            .filter_map(|r| r.geometry())
                            .any(holds_volume)
                        {
                            return Err(RenderError(format!("object {:?}: its Geometry Nodes instances hold a volume, which Cycles renders per instance: volumes in instances are not supported by the renderer yet (Realize Instances keeps the first one, as Blender does)", obj.name)));
                        }
                    }
                    let (rest, points) = cycles_renders(&rest);
                    if let Some(v) = &rest.volume {
                        push_gn_volume(&mut instances, scene, (oi, obj), v, to_world)?;
                    }
                    let (mesh, mats) = realise(&rest)?;
                    let info = MeshInfo {
                        materials: &mats,
                        uv_name: base.uv_name.clone(),
                        default_color: base.default_color.clone(),
                        // Generated geometry: the bounds.
                        texspace: None,
                    };
                    // The set without its instances holds no dupli for Cycles (a mesh that
                    // Realize Instances made is one mesh): an Instancer attribute reads the
                    // object's value there, as for any object (parity scene
                    // instancer_realised_mesh: Molecular Nodes' Ball and Stick).
                    push_instance(&mut instances, scene, oi, obj, &info, mesh, to_world, None)?;
                    if let Some(p) = points {
                        let radius = match p.attributes.named("radius").map(|a| &a.data) {
                            Some(crate::geometry::types::Array::Float(r)) if r.len() == p.len() => {
                                r.clone()
                            }
                            _ => vec![0.01; p.len()],
                        };
                        let keys: Vec<[f32; 4]> = p
                            .positions
                            .iter()
                            .zip(&radius)
                            .map(|(q, &r)| [q[0], q[1], q[2], r])
                            .collect();
                        let materials = vec![p.materials.first().cloned().flatten()];
                        let info = MeshInfo {
                            materials: &materials,
                            uv_name: None,
                            default_color: None,
                            texspace: None,
                        };
                        let slots = vec![0; keys.len()];
                        // Generic point attributes, as Cycles' copy_attributes gives them to
                        // the Attribute node (position and radius are the points themselves).
                        let attributes = p
                            .attributes
                            .iter()
                            .filter(|a| a.domain == crate::geometry::types::Domain::Point)
                            .filter_map(|a| {
                                let name = a.id.name()?;
                                (name != "position" && name != "radius").then(|| {
                                    (
                                        name.to_string(),
                                        false,
                                        crate::geometry::mesh::scene_data(&a.data),
                                    )
                                })
                            })
                            .collect();
                        push_points(
                            &mut instances,
                            scene,
                            oi,
                            obj,
                            &info,
                            (&keys, &slots),
                            attributes,
                            to_world,
                        )?;
                    }
                    if let Some(inst) = instances_component {
                        let mut by_handle: HashMap<u32, (Arc<MeshData>, Vec<Option<String>>)> =
                            HashMap::new();
                        for (i, (&h, t)) in inst.handles.iter().zip(&inst.transforms).enumerate() {
                            let Some(g) =
                                inst.references.get(h as usize).and_then(|r| r.geometry())
                            else {
                                continue;
                            };
                            let (mesh, mats) = match by_handle.get(&h) {
                                Some(x) => x.clone(),
                                None => {
                                    let x = realise(g)?;
                                    by_handle.insert(h, x.clone());
                                    x
                                }
                            };
                            // Instance transforms are column-major (`m[col][row]`).
                            let mut local = Affine { m: [[0.0; 4]; 3] };
                            for r in 0..3 {
                                for c in 0..4 {
                                    local.m[r][c] = t[c][r];
                                }
                            }
                            let world = compose(&to_world, &local);
                            let info = MeshInfo {
                                materials: &mats,
                                uv_name: base.uv_name.clone(),
                                default_color: base.default_color.clone(),
                                texspace: None,
                            };
                            let before = instances.len();
                            push_instance(
                                &mut instances,
                                scene,
                                oi,
                                obj,
                                &info,
                                mesh,
                                world,
                                Some(i as u32),
                            )?;
                            if instances.len() > before {
                                let pushed = instances.last_mut().expect("pushed");
                                pushed.nested_instancer_names = obj
                                    .attribute_lookups
                                    .keys()
                                    .filter(|n| nested_instance_attribute(g, n))
                                    .cloned()
                                    .collect();
                                for (name, value) in &mut pushed.instancer_values {
                                    if let Some(v) = inst.attributes.named(name).and_then(|a| {
                                        crate::geometry::instances::instance_rgba(&a.data, i)
                                    }) {
                                        *value = v;
                                    }
                                }
                            }
                        }
                    }
                    // Instances realised into the mesh whose Instancer attributes its materials
                    // read: Blender's evaluated mesh carries them per instance, where ours would
                    // be refused (bind_attributes), so the frozen mesh renders while it is valid.
                    if instances[start..]
                        .iter()
                        .any(|i| !i.nested_instancer_names.is_empty())
                    {
                        const REASON: &str =
                            "its materials read Instancer attributes of instances it realises";
                        if let Some(ei) = crate::geometry::source::frozen_instead(
                            scene,
                            obj,
                            eval.frame,
                            &overridden,
                            REASON,
                        ) {
                            frozen_instead.push(FrozenInstead {
                                object: obj.name.clone(),
                                evaluated: ei,
                                reason: REASON,
                            });
                            instances.truncate(start);
                            source = Source::Frozen(ei);
                            continue;
                        }
                    }
                }
            }
            break;
        }
    }
    let (tris, refs) = world_triangles(&instances);
    Ok(Geometry {
        instances,
        tris,
        refs,
        frozen_instead,
    })
}

/// The `accel::visibility` mask of an object: the ray types its Cycles ray visibility
/// shows it to (Cycles' object_ray_visibility); everything without the setting.
pub fn object_visibility(obj: &crate::scene::Object) -> u32 {
    use crate::shader::point::ray;
    let Some(v) = &obj.visibility else {
        return crate::render::accel::visibility::ALL;
    };
    [
        (v.camera, ray::CAMERA),
        (v.diffuse, ray::DIFFUSE),
        (v.glossy, ray::GLOSSY),
        (v.transmission, ray::TRANSMIT),
        (v.shadow, ray::SHADOW),
        (v.volume_scatter, ray::VOLUME_SCATTER),
    ]
    .iter()
    .filter(|(on, _)| *on)
    .fold(0, |m, (_, bit)| m | bit)
}

/// Per scene triangle: its instance's visibility mask (for `Bvh::build_masked`).
pub fn triangle_masks(geo: &Geometry) -> Vec<u32> {
    geo.refs
        .iter()
        .map(|r| geo.instances[r.inst as usize].visibility)
        .collect()
}

/// Says once per process that shadow catchers are rendered as ordinary objects.
fn warn_shadow_catcher(name: &str) {
    static WARN: std::sync::Once = std::sync::Once::new();
    WARN.call_once(|| eprintln!("warning: object {name:?} is a shadow catcher, which the renderer does not support: it is rendered as an ordinary object"));
}

/// Every instance's triangles in world space, skipping those with non-finite corners;
/// then every curve segment (a degenerate triangle at its first key, so that per-prim
/// arrays line up: `render::curves`).
pub fn world_triangles(instances: &[MeshInstance]) -> (Vec<[V3; 3]>, Vec<TriRef>) {
    let mut tris = Vec::new();
    let mut refs = Vec::new();
    for (ii, inst) in instances.iter().enumerate() {
        let Some(c) = &inst.curves else {
            continue;
        };
        for (s, &(_, k0)) in c.segments.iter().enumerate() {
            let k = c.keys[k0 as usize];
            tris.push([[k[0], k[1], k[2]]; 3]);
            refs.push(TriRef {
                inst: ii as u32,
                tri: s as u32,
            });
        }
    }
    let (mut tris, mut refs) = {
        let (t, r) = (tris, refs);
        let (mut mt, mut mr) = mesh_triangles(instances);
        mt.extend(t);
        mr.extend(r);
        (mt, mr)
    };
    tris.shrink_to_fit();
    refs.shrink_to_fit();
    (tris, refs)
}

/// How many of `geo`'s prims are triangles (the curve segments follow them).
pub fn triangle_count(geo: &Geometry) -> usize {
    geo.refs
        .iter()
        .position(|r| geo.instances[r.inst as usize].curves.is_some())
        .unwrap_or(geo.refs.len())
}

fn mesh_triangles(instances: &[MeshInstance]) -> (Vec<[V3; 3]>, Vec<TriRef>) {
    let mut tris = Vec::new();
    let mut refs = Vec::new();
    for (ii, inst) in instances.iter().enumerate() {
        if inst.curves.is_some() {
            continue;
        }
        let m = &inst.mesh;
        // On rayon's threads (a serial part of the published colon's set-up: 1.3 M
        // triangles, twice with displacement); collected in triangle order.
        let world: Vec<V3> = m
            .positions
            .par_iter()
            .map(|p| inst.to_world.point(*p))
            .collect();
        let (t, r): (Vec<[V3; 3]>, Vec<TriRef>) = m
            .triangles
            .par_iter()
            .enumerate()
            .filter_map(|(t, tri)| {
                let v = tri.map(|c| world[m.corner_verts[c as usize] as usize]);
                v.iter()
                    .all(|p| p.iter().all(|x| x.is_finite()))
                    .then_some((
                        v,
                        TriRef {
                            inst: ii as u32,
                            tri: t as u32,
                        },
                    ))
            })
            .unzip();
        // The first mesh's lists are taken as they are: copying them (1.3 M triangles for
        // the published colon) was a serial part of the set-up.
        if tris.is_empty() {
            (tris, refs) = (t, r);
        } else {
            tris.extend(t);
            refs.extend(r);
        }
    }
    (tris, refs)
}

fn compose(a: &Affine, b: &Affine) -> Affine {
    let mut o = Affine { m: [[0.0; 4]; 3] };
    for r in 0..3 {
        for c in 0..4 {
            let mut v = a.m[r][0] * b.m[0][c] + a.m[r][1] * b.m[1][c] + a.m[r][2] * b.m[2][c];
            if c == 3 {
                v += a.m[r][3];
            }
            o.m[r][c] = v;
        }
    }
    o
}

#[allow(clippy::too_many_arguments)]
fn push_instance(
    instances: &mut Vec<MeshInstance>,
    scene: &Scene,
    oi: usize,
    obj: &crate::scene::Object,
    info: &MeshInfo,
    mesh: Arc<MeshData>,
    to_world: Affine,
    instance_index: Option<u32>,
) -> Result<(), RenderError> {
    if mesh.triangles.is_empty() {
        return Ok(());
    }
    instances.push(new_instance(
        scene,
        oi,
        obj,
        info,
        mesh,
        to_world,
        instance_index,
    )?);
    Ok(())
}

/// A smoke domain as Cycles renders it: its grids (exported at the frame) over the box
/// of its texture space, with the domain mesh's materials; nothing when no grid has a
/// voxel above the clipping (Cycles' volume mesh is then empty).
fn push_smoke_domain(
    instances: &mut Vec<MeshInstance>,
    scene: &Scene,
    (oi, obj): (usize, &crate::scene::Object),
    di: usize,
    frame: f64,
    to_world: Affine,
) -> Result<(), RenderError> {
    let d = &scene.file.smoke_domains[di];
    let valid = d.frame == frame || d.grids.is_empty();
    let grids = grids_at(scene, obj, "smoke", valid, frame, || {
        scene.load_smoke_grids(di)
    })?;
    if let Some(g) = grids
        .iter()
        .find(|g| g.min != grids[0].min || g.max != grids[0].max)
    {
        return Err(RenderError(format!(
            "object {:?}: smoke grid {:?} covers another box than {:?}",
            obj.name, g.name, grids[0].name
        )));
    }
    let Some(domain) = DomainGrids::new(grids, d.clipping) else {
        return Ok(());
    };
    let mesh_materials = obj
        .data
        .as_deref()
        .and_then(|n| scene.file.meshes.iter().find(|m| m.name == n))
        .map_or(&[][..], |m| &m.materials[..]);
    push_grid_volume(
        instances,
        scene,
        (oi, obj),
        mesh_materials,
        domain,
        to_world,
    )
}

/// The `what` grids (smoke, Volume) of `obj` the export holds, read by `load` when the
/// record `Scene::smoke_domain` / `volume_object` found is `valid` at `frame`; otherwise
/// an error naming the object and the frames the export has grids of.
fn grids_at(
    scene: &Scene,
    obj: &crate::scene::Object,
    what: &str,
    valid: bool,
    frame: f64,
    load: impl FnOnce() -> Result<Vec<crate::scene::volume_grid::VoxelGrid>, crate::scene::SceneError>,
) -> Result<Vec<crate::scene::volume_grid::VoxelGrid>, RenderError> {
    if !valid {
        let frames: Vec<String> = scene
            .grid_frames(&obj.name)
            .iter()
            .map(|f| f.to_string())
            .collect();
        return Err(RenderError(format!(
            "object {:?}: its {what} grids were exported at frame{} {}, not {frame}: convert the file at this frame, or with --frames over a range holding it",
            obj.name,
            if frames.len() > 1 { "s" } else { "" },
            frames.join(", ")
        )));
    }
    load().map_err(|e| RenderError(format!("object {:?}: {e}", obj.name)))
}

/// A Volume object (OpenVDB) as Cycles renders it (blender/volume.cpp, scene/volume.cpp):
/// its grids from the export at the frame, each over its box of active voxels, with the
/// Volume's materials, its Render settings' clipping and step size, and Object space's
/// density scaling; nothing when no voxel is above the clipping.
fn push_volume_object(
    instances: &mut Vec<MeshInstance>,
    scene: &Scene,
    (oi, obj): (usize, &crate::scene::Object),
    frame: f64,
    to_world: Affine,
) -> Result<(), RenderError> {
    // `volume::check_objects` has refused a Volume object without a readable record.
    let Some((vi, v)) = scene.volume_object(&obj.name, frame) else {
        return Ok(());
    };
    let valid = v.frame == frame || v.every_frame || v.grids.is_empty();
    let grids = grids_at(scene, obj, "Volume", valid, frame, || {
        scene.load_volume_grids(vi)
    })?;
    let Some(mut domain) = DomainGrids::new(grids, v.clipping) else {
        return Ok(());
    };
    let object_space = v.space != "WORLD";
    domain.step = match (v.step_size > 0.0, object_space) {
        (false, _) => GridStep::Voxel,
        (true, true) => GridStep::Object(v.step_size),
        (true, false) => GridStep::World(v.step_size),
    };
    if object_space {
        domain.density_scale = crate::render::volume_grid::object_space_density(&to_world);
    }
    push_grid_volume(instances, scene, (oi, obj), &v.materials, domain, to_world)
}

/// Whether a geometry set or any geometry its instances reference holds a volume.
fn holds_volume(g: &crate::geometry::GeometrySet) -> bool {
    g.volume.is_some()
        || g.instances.as_ref().is_some_and(|i| {
            i.references
                .iter()
                .filter_map(|r| r.geometry())
                .any(holds_volume)
        })
}

/// Render > Clipping of the Volume Geometry Nodes make (`BKE_id_new_nomain`'s defaults:
/// Step Size 0, Space Object).
const GN_VOLUME_CLIPPING: f32 = 0.001;

/// A volume Geometry Nodes made on a mesh or curve object, as Cycles renders it: its
/// grids (each dense over its active voxels, its index-to-object transform axis-aligned)
/// with the volume's material (Set Material; the object's mesh materials are not its),
/// the default Volume render settings (clipping 0.001, step from the voxels, Object
/// space). Refused by name: a volume without a material (Cycles' default volume shader),
/// a grid whose background is not 0 or whose transform rotates, shears or mirrors.
fn push_gn_volume(
    instances: &mut Vec<MeshInstance>,
    scene: &Scene,
    (oi, obj): (usize, &crate::scene::Object),
    v: &crate::geometry::volume::Volume,
    to_world: Affine,
) -> Result<(), RenderError> {
    let refuse = |why: String| {
        Err(RenderError(format!(
            "object {:?}: its Geometry Nodes volume {why}",
            obj.name
        )))
    };
    let mut grids = Vec::new();
    for g in &v.grids {
        if g.background != 0.0 {
            return refuse(format!(
                "grid {:?} has background {} (Cycles reads the background outside the active voxels): a background other than 0 is not supported by the renderer yet",
                g.name, g.background
            ));
        }
        let Some((origin, size)) = g.axis_aligned() else {
            return refuse(format!(
                "grid {:?} has a transform that rotates, shears or mirrors the voxels, which the renderer does not handle yet",
                g.name
            ));
        };
        if g.active_voxel_count() == 0 {
            // Cycles builds nothing from an empty grid; a material reading it reads 0.
            continue;
        }
        let lo = [0, 1, 2].map(|k| origin[k] + size[k] * g.origin[k] as f64);
        let hi = [0, 1, 2].map(|k| lo[k] + size[k] * g.dims[k] as f64);
        grids.push(crate::scene::volume_grid::VoxelGrid {
            name: g.name.clone(),
            channels: 1,
            resolution: g.dims,
            min: lo.map(|x| x as f32),
            max: hi.map(|x| x as f32),
            values: g.values.clone(),
        });
    }
    let materials: Vec<Option<String>> = if v.materials.is_empty() {
        vec![None]
    } else {
        v.materials.clone()
    };
    let from_object = obj
        .material_slots
        .first()
        .filter(|s| s.link.as_deref() == Some("OBJECT"))
        .map(|s| s.material.clone());
    if from_object
        .unwrap_or_else(|| materials[0].clone())
        .is_none()
    {
        // The mesh's materials are not the volume's (checked with Cycles: another mesh
        // material gives the same image).
        return refuse(
            "has no material (Set Material): Cycles renders it with its default volume shader (a Principled Volume), which the renderer does not do yet".into(),
        );
    }
    let Some(mut domain) = DomainGrids::new(grids, GN_VOLUME_CLIPPING) else {
        return Ok(());
    };
    domain.step = GridStep::Voxel;
    domain.density_scale = crate::render::volume_grid::object_space_density(&to_world);
    push_grid_volume(instances, scene, (oi, obj), &materials, domain, to_world)
}

/// Voxel grids in an object (a smoke domain, a Volume object) as the instance Cycles
/// builds for them: a box around the grids with the data's materials (`materials`, the
/// object's slots overriding them).
fn push_grid_volume(
    instances: &mut Vec<MeshInstance>,
    scene: &Scene,
    (oi, obj): (usize, &crate::scene::Object),
    materials: &[Option<String>],
    domain: DomainGrids,
    to_world: Affine,
) -> Result<(), RenderError> {
    let (lo, hi) = (domain.min, domain.max);
    let info = MeshInfo {
        materials,
        uv_name: None,
        default_color: None,
        texspace: Some(centre_and_half(lo, hi)),
    };
    // Cycles' volume mesh bounds the active voxels dilated by the interpolation's reach
    // (1 voxel linear, 2 cubic; GeometryManager::create_volume_mesh): two voxels of the
    // coarsest grid around the box cover both. Past it every value is 0.
    let pad = domain.grids.iter().fold([0.0f32; 3], |p, g| {
        [0, 1, 2].map(|k| p[k].max(2.0 * (g.max[k] - g.min[k]) / g.resolution[k] as f32))
    });
    let mut inst = new_instance(
        scene,
        oi,
        obj,
        &info,
        Arc::new(box_mesh(
            (Vec3::from(lo) - pad.into()).into(),
            (Vec3::from(hi) + pad.into()).into(),
        )),
        to_world,
        None,
    )?;
    inst.grids = Some(Arc::new(domain));
    instances.push(inst);
    Ok(())
}

/// An axis-aligned box from `lo` to `hi` as a closed mesh of six outward-facing quads.
fn box_mesh(lo: V3, hi: V3) -> MeshData {
    let positions: Vec<V3> = (0..8)
        .map(|i| {
            [
                if i & 1 != 0 { hi[0] } else { lo[0] },
                if i & 2 != 0 { hi[1] } else { lo[1] },
                if i & 4 != 0 { hi[2] } else { lo[2] },
            ]
        })
        .collect();
    // Counter-clockwise seen from outside.
    let quads: [[u32; 4]; 6] = [
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
    ];
    let normals: [V3; 6] = [
        [0.0, 0.0, -1.0],
        [0.0, 0.0, 1.0],
        [0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
    ];
    let mut edges: Vec<[u32; 2]> = Vec::new();
    let mut corner_edges = Vec::new();
    for q in &quads {
        for k in 0..4 {
            let (a, b) = (q[k], q[(k + 1) % 4]);
            let e = [a.min(b), a.max(b)];
            let at = edges.iter().position(|x| *x == e).unwrap_or_else(|| {
                edges.push(e);
                edges.len() - 1
            });
            corner_edges.push(at as u32);
        }
    }
    MeshData {
        name: "smoke domain".into(),
        positions,
        edges,
        face_offsets: (0..=6).map(|f| 4 * f).collect(),
        corner_verts: quads.iter().flatten().copied().collect(),
        corner_edges,
        corner_normals: normals.iter().flat_map(|n| [*n; 4]).collect(),
        triangles: (0..6u32)
            .flat_map(|f| [[4 * f, 4 * f + 1, 4 * f + 2], [4 * f, 4 * f + 2, 4 * f + 3]])
            .collect(),
        triangle_faces: (0..6u32).flat_map(|f| [f, f]).collect(),
        attributes: Vec::new(),
    }
}

/// An evaluated mesh with realised instances (`render::realized`) as the objects Cycles
/// renders: the instancer's own geometry, then each instance in its own object space at
/// the instancer's transform times its own, with its Object Info (random id, colour, pass
/// index) and texture space, numbered as instances are.
fn push_realized(
    instances: &mut Vec<MeshInstance>,
    scene: &Scene,
    (oi, obj): (usize, &crate::scene::Object),
    info: &MeshInfo,
    mesh: &MeshData,
    realized: &crate::scene::Realized,
    world: &[[f64; 4]; 4],
) -> Result<(), RenderError> {
    let parts = crate::render::realized::split(mesh, realized)
        .map_err(|e| RenderError(format!("object {:?}: evaluated mesh: {e}", obj.name)))?;
    for part in parts {
        let Some((k, inst)) = part.instance else {
            push_instance(
                instances,
                scene,
                oi,
                obj,
                info,
                Arc::new(part.mesh),
                Affine::from_rows(world),
                None,
            )?;
            continue;
        };
        let rows: [[f64; 4]; 4] = std::array::from_fn(|r| {
            std::array::from_fn(|c| (0..4).map(|j| world[r][j] * inst.matrix[j][c]).sum())
        });
        let texspace = inst.texspace_location.zip(inst.texspace_size);
        let part_info = MeshInfo {
            materials: info.materials,
            uv_name: info.uv_name.clone(),
            default_color: info.default_color.clone(),
            texspace,
        };
        let before = instances.len();
        push_instance(
            instances,
            scene,
            oi,
            obj,
            &part_info,
            Arc::new(part.mesh),
            Affine::from_rows(&rows),
            Some(k as u32),
        )?;
        if let Some(pushed) = instances.get_mut(before) {
            // Cycles syncs an instance as an object: Object Info reads the dupli's random
            // id and the instanced object's colour and pass index.
            pushed.info.random = inst.random_id as f32 * (1.0 / 0xFFFF_FFFFu32 as f32);
            pushed.info.color = inst.color.map(|c| c as f32);
            pushed.info.pass_index = inst.pass_index as f32;
            pushed.info.particle = inst.particle.flatten();
        }
    }
    Ok(())
}

/// What Cycles renders of a mesh or curve object's Geometry Nodes output, instances
/// realised: the mesh, and the point cloud apart (`push_points`). Blender hands a curve
/// component on such an object to render engines as a legacy curve object, which Cycles
/// does not render (its object_is_geometry takes Curves, point clouds and meshes only),
/// so it is dropped.
fn cycles_renders(
    g: &crate::geometry::GeometrySet,
) -> (
    crate::geometry::GeometrySet,
    Option<Arc<crate::geometry::pointcloud::PointCloud>>,
) {
    let mut r = crate::geometry::realize::realize_instances(g);
    r.curves = None;
    let points = r.points.take().filter(|p| !p.is_empty());
    (r, points)
}

/// A point cloud as an instance of its own (`render::points`): a sphere per key (x, y,
/// z, radius in object space) in material slot `slots[i]` of `info`'s materials (Cycles
/// gives every point of a cloud shader 0: its first material), with its generic
/// attributes per point (`ObjectCurves::attributes`, one "curve" per point).
#[allow(clippy::too_many_arguments)]
fn push_points(
    instances: &mut Vec<MeshInstance>,
    scene: &Scene,
    oi: usize,
    obj: &crate::scene::Object,
    info: &MeshInfo,
    (pts, slots): (&[[f32; 4]], &[u32]),
    attributes: Vec<(String, bool, crate::scene::mesh::AttributeData)>,
    to_world: Affine,
) -> Result<(), RenderError> {
    if let Some(k) = pts
        .iter()
        .position(|k| !k.iter().all(|x| x.is_finite()) || k[3] < 0.0)
    {
        return Err(RenderError(format!(
            "object {:?}: point {k} of its point cloud is {:?}: positions must be finite, radii finite and >= 0",
            obj.name, pts[k]
        )));
    }
    let mut points = crate::render::points::object_points(pts, &to_world);
    points.slot = slots.to_vec();
    points.point_index = crate::render::points::index_in_cloud(slots);
    points.attributes = attributes;
    // Generated spans the points' object-space bounds, whatever the mesh's texture space.
    push_prims(
        instances,
        scene,
        (oi, obj),
        info,
        points,
        pts,
        to_world,
        false,
    )
}

/// An object's hair as an instance of its own: the object's material slots, no mesh.
fn push_curves(
    instances: &mut Vec<MeshInstance>,
    scene: &Scene,
    oi: usize,
    obj: &crate::scene::Object,
    info: &MeshInfo,
    hair: &crate::scene::hair::HairData,
    to_world: Affine,
) -> Result<(), RenderError> {
    if hair.curves.is_empty() {
        return Ok(());
    }
    let c = crate::scene::settings::CurveSettings::of(&scene.file.scene);
    let thick = match c.shape.as_str() {
        "RIBBONS" => false,
        "THICK" => true,
        other => {
            return Err(RenderError(format!(
                "object {:?}: hair curve shape {other:?} (Render > Curves > Shape) is not supported: Rounded Ribbons (RIBBONS) and 3D Curves (THICK) are rendered",
                obj.name
            )))
        }
    };
    if thick && !crate::render::points::similarity(&to_world) {
        // Cycles keeps such hair in object space (its transform is not applied): tubes of
        // elliptical section, which blendsynth does not intersect.
        return Err(RenderError(format!(
            "object {:?}: 3D Curves (Render > Curves > Shape THICK) under a non-uniform scale or shear are not supported",
            obj.name
        )));
    }
    let curves = crate::render::curves::ObjectCurves::new(hair, &to_world, c.subdivisions, thick);
    let keep = info.texspace.is_some();
    push_prims(
        instances,
        scene,
        (oi, obj),
        info,
        curves,
        &hair.keys,
        to_world,
        keep,
    )
}

/// Hair or points (`prims`, made from `keys` in object space) as an instance of their
/// own, with no mesh: world bounds over the segments, and Generated over the keys'
/// bounds unless the mesh's texture space is kept (`keep_texspace`).
#[allow(clippy::too_many_arguments)]
fn push_prims(
    instances: &mut Vec<MeshInstance>,
    scene: &Scene,
    (oi, obj): (usize, &crate::scene::Object),
    info: &MeshInfo,
    prims: crate::render::curves::ObjectCurves,
    keys: &[[f32; 4]],
    to_world: Affine,
    keep_texspace: bool,
) -> Result<(), RenderError> {
    let mut inst = new_instance(
        scene,
        oi,
        obj,
        info,
        Arc::new(MeshData::default()),
        to_world,
        None,
    )?;
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for s in 0..prims.segments.len() {
        let (a, b) = prims.segment_bounds(s as u32);
        lo = vmin(lo, a);
        hi = vmax(hi, b);
    }
    inst.world_bounds = (lo, hi);
    if !keep_texspace {
        let (mut a, mut b) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for k in keys {
            a = vmin(a, [k[0], k[1], k[2]]);
            b = vmax(b, [k[0], k[1], k[2]]);
        }
        let (loc, half) = centre_and_half(a, b);
        inst.tex_loc = loc;
        inst.tex_size = half.map(|x| if x > 0.0 { x } else { 1.0 });
    }
    inst.curves = Some(Arc::new(prims));
    instances.push(inst);
    Ok(())
}

fn new_instance(
    scene: &Scene,
    oi: usize,
    obj: &crate::scene::Object,
    info: &MeshInfo,
    mesh: Arc<MeshData>,
    to_world: Affine,
    instance_index: Option<u32>,
) -> Result<MeshInstance, RenderError> {
    // Object-linked slots override the mesh's materials (Blender's slot link). A slot
    // linked to the data takes the (evaluated) geometry's material only: a mesh Geometry
    // Nodes made anew has none there, and Cycles gives it the default surface, not the
    // material the object's original mesh had (BKE_object_material_get_eval).
    let mesh_materials = info.materials;
    let nslots = mesh_materials.len().max(obj.material_slots.len()).max(1);
    let slots: Vec<Option<usize>> = (0..nslots)
        .map(|s| {
            let from_obj = obj
                .material_slots
                .get(s)
                .filter(|sl| sl.link.as_deref() == Some("OBJECT"))
                .map(|sl| sl.material.clone());
            let name = from_obj.unwrap_or_else(|| mesh_materials.get(s).cloned().flatten());
            material_index(scene, &name)
        })
        .collect();
    let face_slot: Vec<u32> = match mesh.attribute("material_index").map(|a| &a.data) {
        Some(AttributeData::Int(v)) if v.len() == mesh.face_count() => v
            .iter()
            .map(|&i| (i.max(0) as u32).min(nslots as u32 - 1))
            .collect(),
        _ => vec![0; mesh.face_count()],
    };
    let uv_name = info.uv_name.clone();
    let uv = uv_name
        .as_deref()
        .and_then(|n| mesh.attribute(n))
        .and_then(|a| match &a.data {
            AttributeData::Float2(v) if v.len() == mesh.corner_count() => Some(Arc::new(v.clone())),
            _ => None,
        });
    let to_object = to_world
        .inverse()
        .ok_or_else(|| RenderError(format!("object {:?} has a singular transform", obj.name)))?;
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in &mesh.positions {
        lo = vmin(lo, *p);
        hi = vmax(hi, *p);
    }
    let (wlo, whi) = world_bounds(&mesh.positions, &to_world);
    // The exported texture space for plain meshes; the bounds for generated geometry.
    let (tex_loc, tex_size) = match info.texspace {
        Some(t) => t,
        None => {
            let (loc, half) = centre_and_half(lo, hi);
            (loc, half.map(|x| if x == 0.0 { 1.0 } else { x }))
        }
    };
    Ok(MeshInstance {
        object: oi,
        name: obj.name.clone(),
        instance_index,
        mesh,
        to_world,
        to_object,
        slots,
        face_slot,
        uv,
        tex_loc,
        tex_size,
        world_bounds: (wlo, whi),
        info: {
            let m = to_world.m;
            let rows: [[f64; 4]; 4] = std::array::from_fn(|r| {
                if r < 3 {
                    m[r].map(|x| x as f64)
                } else {
                    [0.0, 0.0, 0.0, 1.0]
                }
            });
            crate::shader::view::object_info(obj, &rows)
        },
        motion: None,
        undisplaced: None,
        uv_name,
        default_color: info.default_color.clone(),
        attributes: Vec::new(),
        instancer_values: obj
            .attribute_lookups
            .iter()
            .map(|(n, l)| (n.clone(), l.object.or(l.data).unwrap_or([0.0; 4])))
            .collect(),
        nested_instancer_names: Vec::new(),
        visibility: object_visibility(obj),
        holdout: obj.is_holdout,
        shadow_terminator: obj.shadow_terminator_geometry_offset,
        // Cycles' kernel keeps the shading offset as a frequency multiplier (object.cpp).
        terminator_frequency: 1.0 / (1.0 - 0.5 * obj.shadow_terminator_shading_offset),
        curves: None,
        grids: None,
    })
}

/// Whether instances inside `g` (at any depth) carry an attribute named `name`.
fn nested_instance_attribute(g: &crate::geometry::GeometrySet, name: &str) -> bool {
    g.instances.as_ref().is_some_and(|i| {
        i.attributes.named(name).is_some()
            || i.references
                .iter()
                .filter_map(|r| r.geometry())
                .any(|r| nested_instance_attribute(r, name))
    })
}

/// Binds, for every instance and slot, the mesh attributes its material reads (Cycles
/// syncs them once per mesh): instances sharing a mesh and material share one binding.
/// Call before true displacement, which Cycles also runs after the attributes are made.
pub fn bind_attributes(
    geo: &mut Geometry,
    materials: &[crate::render::integrator::shade::Material],
) -> Result<(), RenderError> {
    let mut done: HashMap<(*const MeshData, usize), Arc<BoundAttributes>> = HashMap::new();
    for inst in &mut geo.instances {
        let mut per_slot = Vec::with_capacity(inst.slots.len());
        for slot in &inst.slots {
            let Some((mi, p)) = slot.and_then(|mi| {
                materials
                    .get(mi)
                    .and_then(|m| m.program.as_ref())
                    .map(|p| (mi, p))
            }) else {
                per_slot.push(None);
                continue;
            };
            if p.attributes.is_empty() {
                per_slot.push(None);
                continue;
            }
            if let Some(c) = inst.curves.as_ref().filter(|c| c.points) {
                use crate::shader::attributes::AttributeRequest;
                // Only generic attributes of points blendsynth evaluated itself are carried.
                let builtin = p.attributes.iter().any(
                    |r| matches!(r, AttributeRequest::Named(n) if n == "position" || n == "radius"),
                );
                if c.attributes.is_empty() || builtin {
                    return Err(RenderError(format!("object {:?}: material {:?} on its point cloud reads attributes ({:?}), which blendsynth does not carry for these points yet (only generic attributes of Geometry Nodes points it evaluates)", inst.name, materials[mi].name, p.attributes)));
                }
            }
            if let Some(c) = &inst.curves {
                let b = BoundAttributes::bind_curves(
                    &c.attributes,
                    &p.attributes,
                    inst.default_color.as_deref(),
                )
                .map_err(|e| {
                    RenderError(format!(
                        "object {:?}, material {:?} on its hair: {e}",
                        inst.name, materials[mi].name
                    ))
                })?;
                per_slot.push(Some(Arc::new(b)));
                continue;
            }
            for r in &p.attributes {
                if let crate::shader::attributes::AttributeRequest::Instancer(name) = r {
                    let carried = inst
                        .mesh
                        .attribute(&format!(
                            "{}{name}",
                            crate::shader::attributes::NESTED_INSTANCER_PREFIX
                        ))
                        .is_some();
                    if inst.nested_instancer_names.contains(name) && !carried {
                        return Err(RenderError(format!("object {:?}: material {:?} reads the Instancer attribute {name:?}, on instances realised into its mesh (not supported: Blender reads it per instance, blendsynth renders them as one mesh)", inst.name, materials[mi].name)));
                    }
                }
            }
            if crate::render::integrator::shade::displacement_reads_attributes(p) {
                return Err(RenderError(format!("object {:?}: material {:?} truly displaces by mesh attributes or tangents, which the renderer does not support yet", inst.name, materials[mi].name)));
            }
            let key = (Arc::as_ptr(&inst.mesh), mi);
            let bound = match done.get(&key) {
                Some(b) => b.clone(),
                None => {
                    let b = BoundAttributes::bind(
                        &inst.mesh,
                        &p.attributes,
                        inst.uv_name.as_deref(),
                        inst.default_color.as_deref(),
                    )
                    .map_err(|e| {
                        RenderError(format!(
                            "object {:?}, material {:?}: {e}",
                            inst.name, materials[mi].name
                        ))
                    })?;
                    let b = Arc::new(b);
                    done.insert(key, b.clone());
                    b
                }
            };
            per_slot.push(Some(bound));
        }
        inst.attributes = per_slot;
    }
    Ok(())
}

/// The centre and half size of the box `lo`..`hi` (a texture space).
fn centre_and_half(lo: V3, hi: V3) -> (V3, V3) {
    let (lo, hi) = (Vec3::from(lo), Vec3::from(hi));
    (((lo + hi) * 0.5).into(), ((hi - lo) * 0.5).into())
}

#[cfg(test)]
mod tests {
    use super::cycles_renders;
    use crate::geometry::{curves::Curves, pointcloud::PointCloud, GeometrySet};
    use std::sync::Arc;

    /// Curves in a mesh object's Geometry Nodes output render as nothing (as in Cycles);
    /// points are taken apart to render as spheres.
    #[test]
    fn mesh_objects_drop_their_curves_and_keep_their_points_apart() {
        let curves = Curves {
            positions: vec![[0.0; 3], [0.0, 0.0, 1.0]],
            curve_offsets: vec![0, 2],
            ..Default::default()
        };
        let set = GeometrySet {
            curves: Some(Arc::new(curves)),
            ..Default::default()
        };
        let (r, points) = cycles_renders(&set);
        assert!(r.curves.is_none() && r.mesh.is_none() && points.is_none());
        let points = PointCloud {
            positions: vec![[0.0; 3]; 3],
            ..Default::default()
        };
        let set = GeometrySet {
            points: Some(Arc::new(points)),
            ..set
        };
        let (r, points) = cycles_renders(&set);
        assert!(r.points.is_none());
        assert_eq!(points.map(|p| p.len()), Some(3));
    }
}
