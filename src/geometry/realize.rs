//! Joining geometry and realizing instances, as Blender's `join_geometries` and
//! `realize_instances` lay the result out: parts in order (a set's own mesh first, then
//! its instances in instance order, recursing into nested instances), indices offset,
//! positions moved by the accumulated instance transforms, attributes merged by id
//! (the most complex type and highest-priority domain win; parts without an attribute
//! get the type's default), and material slots merged in order of first use with
//! `material_index` remapped.

use std::collections::HashMap;
use std::sync::Arc;

use super::attribute::{AttrId, Attributes};
use super::curves::Curves;
use super::field::ComponentRef;
use super::instances::Instances;
use super::math::{mat4_mul, transform_normals, transform_point, Mat4f, MAT4_IDENTITY};
use super::mesh::Mesh;
use super::pointcloud::PointCloud;
use super::set::GeometrySet;
use super::types::{Array, DataType, Domain};

/// Attribute ids, types and domains over several parts of one component type.
fn merged_layout<'a>(
    parts: impl Iterator<Item = &'a Attributes>,
) -> Vec<(AttrId, DataType, Domain)> {
    let mut order: Vec<AttrId> = Vec::new();
    let mut info: HashMap<AttrId, (DataType, Domain)> = HashMap::new();
    for attrs in parts {
        for a in attrs.iter() {
            match info.get_mut(&a.id) {
                Some((t, d)) => {
                    if a.data_type().complexity() > t.complexity() {
                        *t = a.data_type();
                    }
                    if a.domain.priority() > d.priority() {
                        *d = a.domain;
                    }
                }
                None => {
                    order.push(a.id.clone());
                    info.insert(a.id.clone(), (a.data_type(), a.domain));
                }
            }
        }
    }
    order
        .into_iter()
        .map(|id| {
            let (t, d) = info[&id];
            (id, t, d)
        })
        .collect()
}

/// Material slots of all parts, in order of first use; per part the index map.
fn merge_materials(parts: &[&Vec<Option<String>>]) -> (Vec<Option<String>>, Vec<Vec<i32>>) {
    let mut all: Vec<Option<String>> = Vec::new();
    let mut maps = Vec::new();
    for mats in parts {
        let list: Vec<Option<String>> = if mats.is_empty() {
            vec![None]
        } else {
            mats.to_vec()
        };
        let map = list
            .iter()
            .map(|m| match all.iter().position(|x| x == m) {
                Some(i) => i as i32,
                None => {
                    all.push(m.clone());
                    (all.len() - 1) as i32
                }
            })
            .collect();
        maps.push(map);
    }
    if all.iter().all(|m| m.is_none()) {
        all.clear();
    }
    (all, maps)
}

/// Concatenates meshes, each moved by its transform.
pub fn join_meshes(parts: &[(&Mesh, Mat4f)]) -> Mesh {
    let mut out = Mesh::new();
    if parts.is_empty() {
        return out;
    }
    let layout = merged_layout(parts.iter().map(|(m, _)| &m.attributes));
    let mat_lists: Vec<&Vec<Option<String>>> = parts.iter().map(|(m, _)| &m.materials).collect();
    let (materials, maps) = merge_materials(&mat_lists);
    let any_material_index = parts
        .iter()
        .any(|(m, _)| m.attributes.named("material_index").is_some())
        || materials.len() > 1;
    let mut material_index: Vec<i32> = Vec::new();
    for (k, (m, t)) in parts.iter().enumerate() {
        let (v0, e0, c0) = (
            out.positions.len() as u32,
            out.edges.len() as u32,
            out.corner_verts.len() as u32,
        );
        if *t == MAT4_IDENTITY {
            out.positions.extend_from_slice(&m.positions);
        } else {
            out.positions
                .extend(m.positions.iter().map(|p| transform_point(t, *p)));
        }
        out.edges
            .extend(m.edges.iter().map(|e| [e[0] + v0, e[1] + v0]));
        out.face_offsets
            .extend(m.face_offsets[1..].iter().map(|o| o + c0));
        out.corner_verts
            .extend(m.corner_verts.iter().map(|v| v + v0));
        out.corner_edges
            .extend(m.corner_edges.iter().map(|e| e + e0));
        let src_mi = m
            .attributes
            .named("material_index")
            .map(|a| a.data.as_int().into_owned())
            .unwrap_or_else(|| vec![0; m.face_count()]);
        let map = &maps[k];
        material_index.extend(src_mi.iter().map(|&i| {
            map.get(i.max(0) as usize)
                .copied()
                .unwrap_or(map.last().copied().unwrap_or(0))
        }));
    }
    for (id, t, d) in &layout {
        if id.name() == Some("material_index") {
            continue;
        }
        let mut data = Array::zeros(*t, 0);
        for (m, tm) in parts {
            let n = m.domain_size(*d);
            match m.attributes.get(id) {
                Some(a) => {
                    let mut adapted = ComponentRef::Mesh(m)
                        .adapt(&a.data, a.domain, *d)
                        .convert(*t);
                    // Free normals turn with the instance, as on curves (checked against
                    // Blender 4.5: set_mesh_normal/smn_free_realize).
                    if id.name() == Some("custom_normal") && *tm != MAT4_IDENTITY {
                        if let Array::Vector(v) = &mut adapted {
                            transform_normals(tm, v);
                        }
                    }
                    data.extend(&adapted);
                }
                None => data.extend_default(n),
            }
        }
        out.attributes.set(id.clone(), *d, data);
    }
    if any_material_index {
        out.attributes.set(
            AttrId::named("material_index"),
            Domain::Face,
            Array::Int(material_index),
        );
    }
    out.materials = materials;
    out
}

pub fn join_points(parts: &[(&PointCloud, Mat4f)]) -> PointCloud {
    let mut out = PointCloud::default();
    let layout = merged_layout(parts.iter().map(|(p, _)| &p.attributes));
    for (p, t) in parts {
        out.positions
            .extend(p.positions.iter().map(|x| transform_point(t, *x)));
    }
    for (id, ty, _) in &layout {
        let mut data = Array::zeros(*ty, 0);
        for (p, _) in parts {
            match p.attributes.get(id) {
                Some(a) => data.extend(&a.data.convert(*ty)),
                // A point cloud without radii has Blender's 0.01 once joined.
                None if id.name() == Some("radius") && *ty == DataType::Float => {
                    data.extend(&Array::Float(vec![0.01; p.len()]))
                }
                None => data.extend_default(p.len()),
            }
        }
        out.attributes.set(id.clone(), Domain::Point, data);
    }
    let mats: Vec<&Vec<Option<String>>> = parts.iter().map(|(p, _)| &p.materials).collect();
    out.materials = merge_materials(&mats).0;
    out
}

pub fn join_curves(parts: &[(&Curves, Mat4f)]) -> Curves {
    let mut out = Curves {
        curve_offsets: vec![0],
        ..Default::default()
    };
    let layout = merged_layout(parts.iter().map(|(c, _)| &c.attributes));
    for (c, t) in parts {
        let p0 = out.positions.len() as u32;
        out.positions
            .extend(c.positions.iter().map(|x| transform_point(t, *x)));
        out.curve_offsets
            .extend(c.curve_offsets[1..].iter().map(|o| o + p0));
    }
    for (id, ty, d) in &layout {
        let mut data = Array::zeros(*ty, 0);
        for (c, t) in parts {
            match c.attributes.get(id) {
                Some(a) => {
                    let mut v = ComponentRef::Curves(c)
                        .adapt(&a.data, a.domain, *d)
                        .convert(*ty);
                    // Bezier handles are positions too.
                    if matches!(id.name(), Some("handle_left" | "handle_right")) {
                        if let Array::Vector(h) = &mut v {
                            for x in h.iter_mut() {
                                *x = transform_point(t, *x);
                            }
                        }
                    }
                    // Free curve normals turn with the instance (as Transform Geometry's
                    // `transform_custom_normal_attribute`).
                    if id.name() == Some("custom_normal") && *t != MAT4_IDENTITY {
                        if let Array::Vector(n) = &mut v {
                            transform_normals(t, n);
                        }
                    }
                    data.extend(&v);
                }
                // Built-ins a part lacks get Blender's defaults, which the join writes
                // out (realize_instances fills them so), not zero: resolution 12,
                // radius and nurbs_weight 1 (handles stay zero, as in Blender).
                None if id.name() == Some("resolution") && *ty == DataType::Int => {
                    data.extend(&Array::Int(vec![12; c.domain_size(*d)]))
                }
                None if matches!(id.name(), Some("radius" | "nurbs_weight"))
                    && *ty == DataType::Float =>
                {
                    data.extend(&Array::Float(vec![1.0; c.domain_size(*d)]))
                }
                None => data.extend_default(c.domain_size(*d)),
            }
        }
        out.attributes.set(id.clone(), *d, data);
    }
    let mats: Vec<&Vec<Option<String>>> = parts.iter().map(|(c, _)| &c.materials).collect();
    out.materials = merge_materials(&mats).0;
    out
}

pub fn join_instances(parts: &[&Instances]) -> Instances {
    let mut out = Instances::default();
    let layout = merged_layout(parts.iter().map(|i| &i.attributes));
    for i in parts {
        let base = out.references.len() as u32;
        out.references.extend(i.references.iter().cloned());
        out.handles.extend(i.handles.iter().map(|h| h + base));
        out.transforms.extend_from_slice(&i.transforms);
    }
    for (id, ty, _) in &layout {
        let mut data = Array::zeros(*ty, 0);
        for i in parts {
            match i.attributes.get(id) {
                Some(a) => data.extend(&a.data.convert(*ty)),
                None => data.extend_default(i.len()),
            }
        }
        out.attributes.set(id.clone(), Domain::Instance, data);
    }
    out
}

/// Join Geometry: each component type concatenated over the inputs, in input order.
pub fn join_geometries(sets: &[GeometrySet]) -> GeometrySet {
    let mut out = GeometrySet::default();
    let meshes: Vec<(&Mesh, Mat4f)> = sets
        .iter()
        .filter_map(|s| s.mesh.as_deref())
        .map(|m| (m, MAT4_IDENTITY))
        .collect();
    if meshes.len() == 1 {
        out.mesh = sets.iter().find_map(|s| s.mesh.clone());
    } else if !meshes.is_empty() {
        out.mesh = Some(Arc::new(join_meshes(&meshes)));
    }
    let points: Vec<(&PointCloud, Mat4f)> = sets
        .iter()
        .filter_map(|s| s.points.as_deref())
        .map(|m| (m, MAT4_IDENTITY))
        .collect();
    if points.len() == 1 {
        out.points = sets.iter().find_map(|s| s.points.clone());
    } else if !points.is_empty() {
        out.points = Some(Arc::new(join_points(&points)));
    }
    let curves: Vec<(&Curves, Mat4f)> = sets
        .iter()
        .filter_map(|s| s.curves.as_deref())
        .map(|m| (m, MAT4_IDENTITY))
        .collect();
    if curves.len() == 1 {
        out.curves = sets.iter().find_map(|s| s.curves.clone());
    } else if !curves.is_empty() {
        out.curves = Some(Arc::new(join_curves(&curves)));
    }
    // Blender 4.5 joins no volumes: one passes through, two or more are dropped.
    let mut volumes = sets.iter().filter_map(|s| s.volume.clone());
    if let (Some(v), None) = (volumes.next(), volumes.next()) {
        out.volume = Some(v);
    }
    let inst: Vec<&Instances> = sets.iter().filter_map(|s| s.instances.as_deref()).collect();
    if inst.len() == 1 {
        out.instances = sets.iter().find_map(|s| s.instances.clone());
    } else if !inst.is_empty() {
        out.instances = Some(Arc::new(join_instances(&inst)));
    }
    out
}

/// One piece of geometry with its accumulated transform, the instance attributes it
/// inherits and its instance id (Blender's `InstanceContext::id`).
struct Part<'a> {
    set: &'a GeometrySet,
    transform: Mat4f,
    /// Instance-domain attribute values of the instances this part came from.
    inherited: Vec<(AttrId, crate::geometry::types::Value)>,
    id: u32,
}

fn gather<'a>(
    set: &'a GeometrySet,
    transform: Mat4f,
    inherited: Vec<(AttrId, crate::geometry::types::Value)>,
    id: u32,
    out: &mut Vec<Part<'a>>,
) {
    out.push(Part {
        set,
        transform,
        inherited: inherited.clone(),
        id,
    });
    if let Some(inst) = &set.instances {
        let stored = inst
            .attributes
            .named("id")
            .map(|a| a.data.as_int().into_owned());
        for i in 0..inst.len() {
            let r = &inst.references[inst.handles[i] as usize];
            let Some(g) = r.geometry() else { continue };
            let t = mat4_mul(&transform, &inst.transforms[i]);
            let mut inh = inherited.clone();
            for a in inst.attributes.iter() {
                if a.id.name() != Some("id") && !inh.iter().any(|(x, _)| x == &a.id) {
                    inh.push((a.id.clone(), a.data.get(i)));
                }
            }
            let local = stored.as_ref().map(|s| s[i] as u32).unwrap_or(i as u32);
            gather(g, t, inh, crate::nodes::random::hash2(id, local), out);
        }
    }
}

/// Whether any instances component in the tree has an `id` attribute.
fn instances_have_ids(set: &GeometrySet) -> bool {
    set.instances.as_ref().is_some_and(|i| {
        i.attributes.named("id").is_some()
            || i.references
                .iter()
                .filter_map(|r| r.geometry())
                .any(instances_have_ids)
    })
}

/// Realized ids: each point's stored id (or index) hashed with its instance's id.
fn realized_ids(stored: Option<Vec<i32>>, n: usize, id: u32) -> Array {
    Array::Int(
        (0..n)
            .map(|i| {
                crate::nodes::random::hash2(
                    id,
                    stored.as_ref().map(|s| s[i] as u32).unwrap_or(i as u32),
                ) as i32
            })
            .collect(),
    )
}

/// Realize Instances: every instance's geometry moved into place and joined with the
/// set's own components; instance attributes become point attributes of what they
/// instanced, and `id` (when any part has one) is rehashed per instance as Blender does.
pub fn realize_instances(set: &GeometrySet) -> GeometrySet {
    if set.instances.is_none() {
        return set.clone();
    }
    let mut parts = Vec::new();
    gather(set, MAT4_IDENTITY, Vec::new(), 0, &mut parts);
    let inst_ids = instances_have_ids(set);
    let mesh_ids = inst_ids
        || parts.iter().any(|p| {
            p.set
                .mesh
                .as_ref()
                .is_some_and(|m| m.attributes.named("id").is_some())
        });
    let point_ids = inst_ids
        || parts.iter().any(|p| {
            p.set
                .points
                .as_ref()
                .is_some_and(|m| m.attributes.named("id").is_some())
        });
    let curve_ids = inst_ids
        || parts.iter().any(|p| {
            p.set
                .curves
                .as_ref()
                .is_some_and(|m| m.attributes.named("id").is_some())
        });
    // Apply inherited instance attributes as point attributes on copies.
    let with_inherited = |attrs: &Attributes,
                          n: usize,
                          inh: &[(AttrId, crate::geometry::types::Value)],
                          domain: Domain,
                          ids: bool,
                          id: u32| {
        let mut a = attrs.clone();
        for (aid, v) in inh {
            if !a.contains(aid) && aid.name() != Some("position") {
                a.set(aid.clone(), domain, Array::filled(*v, n));
            }
        }
        if ids {
            let stored = a.named("id").map(|x| x.data.as_int().into_owned());
            a.set(
                AttrId::named("id"),
                Domain::Point,
                realized_ids(stored, n, id),
            );
        }
        a
    };
    let meshes: Vec<(Mesh, Mat4f)> = parts
        .iter()
        .filter_map(|p| {
            p.set.mesh.as_deref().map(|m| {
                let mut m2 = m.clone();
                m2.attributes = with_inherited(
                    &m.attributes,
                    m.vertex_count(),
                    &p.inherited,
                    Domain::Point,
                    mesh_ids,
                    p.id,
                );
                (m2, p.transform)
            })
        })
        .collect();
    let points: Vec<(PointCloud, Mat4f)> = parts
        .iter()
        .filter_map(|p| {
            p.set.points.as_deref().map(|m| {
                let mut m2 = m.clone();
                m2.attributes = with_inherited(
                    &m.attributes,
                    m.len(),
                    &p.inherited,
                    Domain::Point,
                    point_ids,
                    p.id,
                );
                (m2, p.transform)
            })
        })
        .collect();
    let curves: Vec<(Curves, Mat4f)> = parts
        .iter()
        .filter_map(|p| {
            p.set.curves.as_deref().map(|m| {
                let mut m2 = m.clone();
                m2.attributes = with_inherited(
                    &m.attributes,
                    m.point_count(),
                    &p.inherited,
                    Domain::Point,
                    curve_ids,
                    p.id,
                );
                (m2, p.transform)
            })
        })
        .collect();
    let mut out = GeometrySet::default();
    if !meshes.is_empty() {
        let refs: Vec<(&Mesh, Mat4f)> = meshes.iter().map(|(m, t)| (m, *t)).collect();
        out.mesh = Some(Arc::new(join_meshes(&refs)));
    }
    if !points.is_empty() {
        let refs: Vec<(&PointCloud, Mat4f)> = points.iter().map(|(m, t)| (m, *t)).collect();
        out.points = Some(Arc::new(join_points(&refs)));
    }
    if !curves.is_empty() {
        let refs: Vec<(&Curves, Mat4f)> = curves.iter().map(|(m, t)| (m, *t)).collect();
        out.curves = Some(Arc::new(join_curves(&refs)));
    }
    // Blender 4.5 realizes no volumes: the first one found is kept as it is, its instance
    // transform not applied (`first_volume` in realize_instances.cc).
    out.volume = parts.iter().find_map(|p| p.set.volume.clone());
    out
}

/// Everything as one mesh, as the exporter's evaluated reference holds it: the realized
/// mesh, then point clouds as loose vertices. Curves alone become Blender's wire mesh of
/// them (a bare curve path); curves beside a mesh or points are an error.
pub fn to_mesh(set: &GeometrySet) -> Result<Mesh, String> {
    let r = realize_instances(set);
    if let (Some(c), None, None) = (&r.curves, &r.mesh, &r.points) {
        return super::nodes::curve::curves_to_wire_mesh(c);
    }
    if r.curves.is_some() {
        return Err(
            "the geometry holds curves, which blendsynth cannot convert to a mesh yet".into(),
        );
    }
    let mut m = r.mesh.as_deref().cloned().unwrap_or_else(Mesh::new);
    if let Some(p) = &r.points {
        let pm = Mesh {
            positions: p.positions.clone(),
            face_offsets: vec![0],
            ..Default::default()
        };
        m = join_meshes(&[(&m, MAT4_IDENTITY), (&pm, MAT4_IDENTITY)]);
    }
    Ok(m)
}
