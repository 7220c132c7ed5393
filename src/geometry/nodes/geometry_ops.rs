//! Geometry operations: Transform Geometry, Set Position, Join Geometry, Set Material,
//! Set Shade Smooth, Realize Instances, Instance on Points, Mesh to Points, Points to
//! Vertices.

use std::sync::Arc;

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext};
use super::super::instances::{InstanceReference, Instances};
use super::super::math::{from_loc_rot_scale, mat4_mul, transform_normals, transform_point, Mat4f};
use super::super::mesh::Mesh;
use super::super::pointcloud::PointCloud;
use super::super::realize::{join_geometries, realize_instances};
use super::super::set::{ComponentType, GeometrySet};
use super::super::types::{Array, DataType, Domain, Value};
use super::super::value::SocketValue;
use super::foreach_element::is_builtin;

pub fn geo(g: GeometrySet) -> SocketValue {
    SocketValue::Geometry(g)
}

/// Evaluates `fields` on `domain` of a component.
pub fn eval_fields(
    comp: ComponentRef,
    domain: Domain,
    fields: &[(&Field, DataType)],
) -> Result<Vec<Array>, String> {
    let ctx = FieldContext::new(comp);
    fields
        .iter()
        .map(|(f, t)| ctx.eval(f, domain, *t))
        .collect()
}

/// Applies `f` to a geometry set and to every geometry its instances reference, as
/// Blender's `modify_geometry_sets` does.
pub fn modify_geometry_sets(
    set: &mut GeometrySet,
    f: &mut dyn FnMut(&mut GeometrySet) -> Result<(), String>,
) -> Result<(), String> {
    // Blender gathers every set first and then modifies each, so references the callback
    // adds to this set are not visited: children first, then the set itself.
    if let Some(inst) = set.instances_mut() {
        for r in inst.references.iter_mut() {
            match r {
                InstanceReference::Geometry(g) | InstanceReference::Object(_, g) => {
                    modify_geometry_sets(g, f)?
                }
                InstanceReference::None => {}
            }
        }
    }
    f(set)
}

pub fn join(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut sets = Vec::new();
    for v in ctx.inputs_multi("Geometry")? {
        if let SocketValue::Geometry(g) = v {
            sets.push(g);
        }
    }
    Ok(outputs([("Geometry", geo(join_geometries(&sets)))]))
}

/// Moves everything in the set's top level by `m` (instances get `m * transform`).
pub fn transform_set(g: &mut GeometrySet, m: &Mat4f) {
    if let Some(mesh) = g.mesh_mut() {
        for p in mesh.positions.iter_mut() {
            *p = transform_point(m, *p);
        }
        mesh.custom_vert_normals = None;
        // `bke::mesh_transform`: free normals turn with the mesh (set_mesh_normal/
        // smn_free_transform).
        if let Some(a) = mesh.attributes.get_mut(&AttrId::named("custom_normal")) {
            if let Array::Vector(v) = &mut a.data {
                transform_normals(m, v);
            }
        }
    }
    if let Some(pc) = g.points_mut() {
        for p in pc.positions.iter_mut() {
            *p = transform_point(m, *p);
        }
    }
    if let Some(c) = g.curves_mut() {
        for p in c.positions.iter_mut() {
            *p = transform_point(m, *p);
        }
        for name in ["handle_left", "handle_right"] {
            if let Some(a) = c.attributes.get_mut(&AttrId::named(name)) {
                if let Array::Vector(v) = &mut a.data {
                    for p in v.iter_mut() {
                        *p = transform_point(m, *p);
                    }
                }
            }
        }
        c.transform_custom_normals(m);
    }
    if let Some(v) = g.volume_mut() {
        v.apply_transform(m);
    }
    if let Some(inst) = g.instances_mut() {
        for t in inst.transforms.iter_mut() {
            *t = mat4_mul(m, t);
        }
    }
}

pub fn transform(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let mode = ctx
        .prop("mode")
        .and_then(|v| v.as_str())
        .unwrap_or("COMPONENTS");
    let m = if mode == "MATRIX" {
        ctx.single("Transform", DataType::Matrix)?.as_matrix()
    } else {
        let t = ctx.vector("Translation")?;
        let r = ctx.single("Rotation", DataType::Quaternion)?.as_quat();
        let s = ctx.vector("Scale")?;
        from_loc_rot_scale(t, r, s)
    };
    transform_set(&mut g, &m);
    Ok(outputs([("Geometry", geo(g))]))
}

pub fn set_position(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let pos = ctx.field("Position", DataType::Vector)?;
    let off = ctx.field("Offset", DataType::Vector)?;
    let fields = [
        (&sel, DataType::Bool),
        (&pos, DataType::Vector),
        (&off, DataType::Vector),
    ];
    let apply = |positions: &mut Vec<[f32; 3]>, r: Vec<Array>| {
        let (s, p, o) = (r[0].as_bool(), r[1].as_vector(), r[2].as_vector());
        for i in 0..positions.len() {
            if s[i] {
                positions[i] = [p[i][0] + o[i][0], p[i][1] + o[i][1], p[i][2] + o[i][2]];
            }
        }
    };
    let e = |x: String| ctx.err(x);
    if let Some(m) = g.mesh.clone() {
        let r = eval_fields(ComponentRef::Mesh(&m), Domain::Point, &fields).map_err(e)?;
        let mm = g.mesh_mut().unwrap();
        apply(&mut mm.positions, r);
        mm.custom_vert_normals = None;
    }
    if let Some(p) = g.points.clone() {
        let r = eval_fields(ComponentRef::Points(&p), Domain::Point, &fields).map_err(e)?;
        apply(&mut g.points_mut().unwrap().positions, r);
    }
    if let Some(c) = g.curves.clone() {
        let r = eval_fields(ComponentRef::Curves(&c), Domain::Point, &fields).map_err(e)?;
        let cm = g.curves_mut().unwrap();
        match (
            cm.point_vectors("handle_left"),
            cm.point_vectors("handle_right"),
        ) {
            // Blender (node_geo_set_position) moves both handles of a moved point by its
            // move, then recomputes the auto and vector handles from the new positions.
            (Some(mut hl), Some(mut hr)) => {
                let before = cm.positions.clone();
                apply(&mut cm.positions, r);
                for (i, (new, old)) in cm.positions.iter().zip(&before).enumerate() {
                    if new != old {
                        let d = [new[0] - old[0], new[1] - old[1], new[2] - old[2]];
                        hl[i] = [hl[i][0] + d[0], hl[i][1] + d[1], hl[i][2] + d[2]];
                        hr[i] = [hr[i][0] + d[0], hr[i][1] + d[1], hr[i][2] + d[2]];
                    }
                }
                for (name, v) in [("handle_left", hl), ("handle_right", hr)] {
                    cm.attributes
                        .set(AttrId::named(name), Domain::Point, Array::Vector(v));
                }
                crate::geometry::bezier_handles::calculate_auto_handles(cm);
            }
            _ => apply(&mut cm.positions, r),
        }
    }
    if let Some(inst) = g.instances.clone() {
        let r =
            eval_fields(ComponentRef::Instances(&inst), Domain::Instance, &fields).map_err(e)?;
        let mut pos: Vec<[f32; 3]> = inst
            .transforms
            .iter()
            .map(|t| [t[3][0], t[3][1], t[3][2]])
            .collect();
        apply(&mut pos, r);
        for (t, p) in g.instances_mut().unwrap().transforms.iter_mut().zip(pos) {
            t[3][0] = p[0];
            t[3][1] = p[1];
            t[3][2] = p[2];
        }
    }
    Ok(outputs([("Geometry", geo(g))]))
}

fn material_name(v: SocketValue) -> Option<String> {
    match v {
        SocketValue::Material(m) => m,
        _ => None,
    }
}

pub fn set_material(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let material = material_name(ctx.input("Material")?);
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        if let Some(m) = s.mesh.clone() {
            if m.face_count() == 0 {
                return Ok(());
            }
            let r = eval_fields(
                ComponentRef::Mesh(&m),
                Domain::Face,
                &[(&sel, DataType::Bool)],
            )?;
            let sel = r[0].as_bool();
            let count = sel.iter().filter(|x| **x).count();
            // Our reference would make `mesh_mut` deep-copy the mesh.
            drop(m);
            let mm = s.mesh_mut().unwrap();
            if count != mm.face_count() && mm.materials.is_empty() {
                mm.materials.push(None);
            }
            let index = match mm.materials.iter().position(|x| *x == material) {
                Some(i) => i,
                None => {
                    mm.materials.push(material.clone());
                    mm.materials.len() - 1
                }
            } as i32;
            let mut mi = mm
                .attributes
                .named("material_index")
                .map(|a| a.data.as_int().into_owned())
                .unwrap_or_else(|| vec![0; mm.face_count()]);
            for (i, s) in sel.iter().enumerate() {
                if *s {
                    mi[i] = index;
                }
            }
            mm.attributes.set(
                AttrId::named("material_index"),
                Domain::Face,
                Array::Int(mi),
            );
        }
        if let Some(p) = s.points_mut() {
            p.materials = vec![material.clone()];
        }
        if let Some(c) = s.curves_mut() {
            c.materials = vec![material.clone()];
        }
        // A volume takes the material whatever the selection (Blender warns that volumes
        // support one material and assigns it to the first slot).
        if let Some(v) = s.volume_mut() {
            v.materials = vec![material.clone()];
        }
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Geometry", geo(g))]))
}

pub fn set_shade_smooth(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let domain = match ctx
        .prop("domain")
        .and_then(|v| v.as_str())
        .unwrap_or("FACE")
    {
        "EDGE" => Domain::Edge,
        _ => Domain::Face,
    };
    let name = if domain == Domain::Edge {
        "sharp_edge"
    } else {
        "sharp_face"
    };
    let sel = ctx.field("Selection", DataType::Bool)?;
    let smooth = ctx.field("Shade Smooth", DataType::Bool)?;
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let Some(m) = s.mesh.clone() else {
            return Ok(());
        };
        let n = m.domain_size(domain);
        if n == 0 {
            return Ok(());
        }
        // `try_removing_sharp_attribute`: constant inputs either change nothing (nothing
        // selected) or, all smooth, remove the attribute rather than store falses (Cycles
        // tells the two apart: see `Mesh::shading_corner_normals`).
        if let (Some(sel), Some(smooth)) = (sel.as_constant(), smooth.as_constant()) {
            if !sel.as_bool() {
                return Ok(());
            }
            if smooth.as_bool() {
                drop(m);
                s.mesh_mut()
                    .unwrap()
                    .attributes
                    .remove(&AttrId::named(name));
                return Ok(());
            }
        }
        let r = eval_fields(
            ComponentRef::Mesh(&m),
            domain,
            &[(&sel, DataType::Bool), (&smooth, DataType::Bool)],
        )?;
        let (sel, smooth) = (r[0].as_bool(), r[1].as_bool());
        // Our reference would make `mesh_mut` deep-copy the mesh.
        drop(m);
        let mm = s.mesh_mut().unwrap();
        let mut sharp = match mm.attributes.named(name) {
            Some(a) if a.domain == domain => a.data.as_bool().into_owned(),
            _ => vec![false; n],
        };
        for i in 0..n {
            if sel[i] {
                sharp[i] = !smooth[i];
            }
        }
        mm.attributes
            .set(AttrId::named(name), domain, Array::Bool(sharp));
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Geometry", geo(g))]))
}

pub fn realize(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let g = ctx.geometry("Geometry")?;
    if ctx.has_input("Selection") {
        let sel = ctx.field("Selection", DataType::Bool)?;
        let all = ctx.field("Realize All", DataType::Bool)?;
        let depth = ctx.field("Depth", DataType::Int)?;
        let ok = matches!(sel, Field::Constant(Value::Bool(true)))
            && matches!(all, Field::Constant(Value::Bool(true)))
            && matches!(depth, Field::Constant(_));
        if !ok {
            return Err(
                ctx.err("only realizing all instances (Selection on, Realize All on) is supported")
            );
        }
    }
    Ok(outputs([("Geometry", geo(realize_instances(&g)))]))
}

/// Point attributes a component hands on to what is made from its points.
fn point_attributes(comp: ComponentRef) -> Vec<(AttrId, Domain, Array)> {
    let attrs = match comp {
        ComponentRef::Mesh(m) => &m.attributes,
        ComponentRef::Points(p) => &p.attributes,
        ComponentRef::Curves(c) => &c.attributes,
        ComponentRef::Instances(i) => &i.attributes,
    };
    attrs
        .iter()
        .map(|a| (a.id.clone(), a.domain, a.data.clone()))
        .collect()
}

pub fn instance_on_points(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Points")?;
    let instance = ctx.geometry("Instance")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let pick = ctx.field("Pick Instance", DataType::Bool)?;
    let index = ctx.field("Instance Index", DataType::Int)?;
    let rot = ctx.field("Rotation", DataType::Quaternion)?;
    let scale = ctx.field("Scale", DataType::Vector)?;
    let e = |x: String| ctx.err(x);
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let mut dst = s.instances.as_deref().cloned().unwrap_or_default();
        let comps: Vec<GeometrySet> = vec![
            GeometrySet {
                mesh: s.mesh.clone(),
                ..Default::default()
            },
            GeometrySet {
                points: s.points.clone(),
                ..Default::default()
            },
            GeometrySet {
                curves: s.curves.clone(),
                ..Default::default()
            },
        ];
        for c in &comps {
            let (comp, kind) = if let Some(m) = &c.mesh {
                (ComponentRef::Mesh(m), ComponentType::Mesh)
            } else if let Some(p) = &c.points {
                (ComponentRef::Points(p), ComponentType::PointCloud)
            } else if let Some(cu) = &c.curves {
                (ComponentRef::Curves(cu), ComponentType::Curves)
            } else {
                continue;
            };
            let r = eval_fields(
                comp,
                Domain::Point,
                &[
                    (&sel, DataType::Bool),
                    (&pick, DataType::Bool),
                    (&index, DataType::Int),
                    (&rot, DataType::Quaternion),
                    (&scale, DataType::Vector),
                ],
            )?;
            let (sel, pick, index, rot, scale) = (
                r[0].as_bool(),
                r[1].as_bool(),
                r[2].as_int(),
                r[3].as_quat(),
                r[4].as_vector(),
            );
            let selected: Vec<usize> = (0..sel.len()).filter(|&i| sel[i]).collect();
            if selected.is_empty() {
                continue;
            }
            let (_, pos) = comp
                .attribute(&AttrId::named("position"))
                .ok_or("no positions")?;
            let pos = pos.as_vector().into_owned();
            let start = dst.len();
            // Pick Instance: the Instance Index-th top-level instance of the Instance
            // input (wrapping, -1 the last), its transform after the point's; none when
            // the input has no instances. References are added only where used.
            let src_inst = instance.instances.as_deref();
            let mut picked: Vec<Option<u32>> =
                vec![None; src_inst.map_or(0, |s| s.references.len())];
            let mut whole = None;
            let mut empty = None;
            for &i in &selected {
                let base = from_loc_rot_scale(pos[i], rot[i], scale[i]);
                let (handle, transform) = if !pick[i] {
                    let h = *whole.get_or_insert_with(|| {
                        dst.add_reference(InstanceReference::Geometry(instance.clone()))
                    });
                    (h, base)
                } else {
                    match src_inst.filter(|s| !s.is_empty()) {
                        Some(s) => {
                            let k = index[i].rem_euclid(s.len() as i32) as usize;
                            let src_handle = s.handles[k] as usize;
                            let h = *picked[src_handle].get_or_insert_with(|| {
                                dst.add_reference(s.references[src_handle].clone())
                            });
                            (h, mat4_mul(&base, &s.transforms[k]))
                        }
                        None => {
                            let h = *empty
                                .get_or_insert_with(|| dst.add_reference(InstanceReference::None));
                            (h, base)
                        }
                    }
                };
                dst.transforms.push(transform);
                dst.handles.push(handle);
            }
            // Point attributes move to the new instances.
            for (id, domain, data) in point_attributes(comp) {
                if id
                    .name()
                    .is_some_and(|n| n == "position" || n.starts_with('.'))
                {
                    continue;
                }
                // A source built-in goes along only where instances have it built in too
                // (`gather_attributes_for_propagation`): a mesh's sharp_face or
                // material_index, a point cloud's radius, a curve's tilt stay behind.
                if is_builtin(kind, &id) && !is_builtin(ComponentType::Instances, &id) {
                    continue;
                }
                let on_points = comp.adapt(&data, domain, Domain::Point).gather(&selected);
                match dst.attributes.get_mut(&id) {
                    Some(a) => {
                        a.data.extend(&on_points);
                    }
                    None => {
                        let mut arr = Array::zeros(on_points.data_type(), start);
                        arr.extend(&on_points);
                        dst.attributes.set(id, Domain::Instance, arr);
                    }
                }
            }
            let n = dst.len();
            for a in dst.attributes.0.iter_mut() {
                if a.data.len() < n {
                    let k = n - a.data.len();
                    a.data.extend_default(k);
                }
            }
        }
        s.mesh = None;
        s.points = None;
        s.curves = None;
        s.instances = if dst.is_empty() && dst.references.is_empty() {
            None
        } else {
            Some(Arc::new(dst))
        };
        Ok(())
    })
    .map_err(e)?;
    Ok(outputs([("Instances", geo(g))]))
}

pub fn mesh_to_points(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Mesh")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let pos = ctx.field("Position", DataType::Vector)?;
    let radius = ctx.field("Radius", DataType::Float)?;
    let domain = match ctx.prop_str("mode")? {
        "VERTICES" => Domain::Point,
        "EDGES" => Domain::Edge,
        "FACES" => Domain::Face,
        "CORNERS" => Domain::Corner,
        m => return Err(ctx.err(format!("mode {m} is not supported"))),
    };
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let Some(m) = s.mesh.clone() else {
            return Ok(());
        };
        let r = eval_fields(
            ComponentRef::Mesh(&m),
            domain,
            &[
                (&sel, DataType::Bool),
                (&pos, DataType::Vector),
                (&radius, DataType::Float),
            ],
        )?;
        let (sel, pos, rad) = (r[0].as_bool(), r[1].as_vector(), r[2].as_float());
        let idx: Vec<usize> = (0..sel.len()).filter(|&i| sel[i]).collect();
        let mut pc = PointCloud {
            positions: idx.iter().map(|&i| pos[i]).collect(),
            ..Default::default()
        };
        for a in m.attributes.iter() {
            if a.id.name().is_some_and(|n| {
                n.starts_with('.')
                    || n == "sharp_face"
                    || n == "material_index"
                    || n == "sharp_edge"
            }) {
                continue;
            }
            let on = ComponentRef::Mesh(&m)
                .adapt(&a.data, a.domain, domain)
                .gather(&idx);
            pc.attributes.set(a.id.clone(), Domain::Point, on);
        }
        pc.attributes.set(
            AttrId::named("radius"),
            Domain::Point,
            Array::Float(idx.iter().map(|&i| rad[i]).collect()),
        );
        s.mesh = None;
        s.points = Some(Arc::new(pc));
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Points", geo(g))]))
}

pub fn points_to_vertices(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Points")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let Some(p) = s.points.clone() else {
            return Ok(());
        };
        let r = eval_fields(
            ComponentRef::Points(&p),
            Domain::Point,
            &[(&sel, DataType::Bool)],
        )?;
        let sel = r[0].as_bool();
        let idx: Vec<usize> = (0..sel.len()).filter(|&i| sel[i]).collect();
        let mut m = Mesh::new();
        m.positions = idx.iter().map(|&i| p.positions[i]).collect();
        for a in p.attributes.iter() {
            if a.id.name() == Some("radius") {
                continue;
            }
            m.attributes
                .set(a.id.clone(), Domain::Point, a.data.gather(&idx));
        }
        m.materials = p.materials.clone();
        s.points = None;
        s.mesh = Some(Arc::new(m));
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Mesh", geo(g))]))
}

/// For other modules: a new instances component holding one reference.
pub fn single_instance(reference: InstanceReference, transform: Mat4f) -> Instances {
    let mut i = Instances::default();
    let h = i.add_reference(reference);
    i.handles.push(h);
    i.transforms.push(transform);
    i
}
