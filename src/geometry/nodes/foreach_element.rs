//! The For Each Geometry Element zone (`GeometryNodeForeachGeometryElementInput` /
//! `...Output`), as Blender 4.5 evaluates it
//! (`geometry_nodes_foreach_geometry_element_zone.cc`, `GEO_extract_elements`):
//!
//! - every component of the input geometry with elements on the zone's domain is
//!   iterated, in Blender's component order (mesh, point cloud, instances, curves), each
//!   over its selected elements in index order;
//! - a run sees the element's Index, the element as its own geometry (Element: a one-vertex,
//!   one-edge or one-face mesh, a one-point cloud or one instance, with the element's
//!   attributes) and the input items evaluated at the element;
//! - main items become attributes on the iterated domain of the output Geometry (zero on
//!   unselected elements), output as fields reading them;
//! - generation items: each geometry item is the runs' geometries joined in run order,
//!   each run's geometry first given the element's attributes (on its points, curves or
//!   instances) and the field items after it captured on it.

use std::collections::HashMap;

use serde_json::Value as Json;

use super::super::attribute::AttrId;
use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::field::{AttributeInput, ComponentRef, Field, FieldContext};
use super::super::instances::Instances;
use super::super::mesh::Mesh;
use super::super::pointcloud::PointCloud;
use super::super::realize::join_geometries;
use super::super::set::{ComponentType, GeometrySet};
use super::super::types::{Array, DataType, Domain, Value};
use super::super::value::SocketValue;
use super::super::zones::{item_ids, Zone};

/// Mesh attributes Blender keeps on a fixed domain (built-in): they are propagated only
/// to that domain.
const MESH_BUILTIN: &[(&str, Domain)] = &[
    ("material_index", Domain::Face),
    ("sharp_face", Domain::Face),
    ("sharp_edge", Domain::Edge),
];

/// The input node is only evaluated through its zone (see `repeat_zone::repeat_input`).
pub fn foreach_input(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    Err(ctx.err("is read outside its For Each Geometry Element zone"))
}

/// One iterated component: its elements' indices and the input items at each.
struct Component {
    kind: ComponentType,
    size: usize,
    selected: Vec<usize>,
    inputs: Vec<Array>,
}

fn component_ref(g: &GeometrySet, kind: ComponentType) -> Option<ComponentRef<'_>> {
    Some(match kind {
        ComponentType::Mesh => ComponentRef::Mesh(g.mesh.as_deref()?),
        ComponentType::PointCloud => ComponentRef::Points(g.points.as_deref()?),
        ComponentType::Instances => ComponentRef::Instances(g.instances.as_deref()?),
        ComponentType::Curves => ComponentRef::Curves(g.curves.as_deref()?),
    })
}

pub fn foreach_output(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let zone = Zone::of(ctx, "GeometryNodeForeachGeometryElementInput")?;
    let input = zone.input_ctx(ctx);
    let domain_name = ctx.prop_str("domain")?;
    let domain = Domain::parse(domain_name)
        .filter(|d| *d != Domain::Layer)
        .ok_or_else(|| ctx.err(format!("domain {domain_name:?} is not supported")))?;
    let main = input.geometry("Geometry")?;
    let selection = input.field("Selection", DataType::Bool)?;
    let in_ids = item_ids(&input.node().inputs, "Input_");
    let mut in_fields = Vec::new();
    for id in &in_ids {
        let kind = socket_kind(&input.node().inputs, id);
        let ty = DataType::from_socket(kind)
            .ok_or_else(|| ctx.err(format!("input item {id:?} of type {kind} is not supported")))?;
        in_fields.push((input.field(id, ty)?, ty));
    }
    let main_ids = item_ids(&ctx.node().inputs, "Main_");
    let gen_ids = item_ids(&ctx.node().inputs, "Generation_");

    let mut comps = Vec::new();
    for kind in main.component_types() {
        let c = component_ref(&main, kind).expect("present component");
        if !c.has_domain(domain) || c.domain_size(domain) == 0 {
            continue;
        }
        let fc = FieldContext::new(c);
        let sel = fc
            .eval(&selection, domain, DataType::Bool)
            .map_err(|e| ctx.err(e))?;
        let selected = sel
            .as_bool()
            .iter()
            .enumerate()
            .filter(|(_, s)| **s)
            .map(|(i, _)| i)
            .collect();
        let mut inputs = Vec::new();
        for (f, ty) in &in_fields {
            inputs.push(fc.eval(f, domain, *ty).map_err(|e| ctx.err(e))?);
        }
        comps.push(Component {
            kind,
            size: c.domain_size(domain),
            selected,
            inputs,
        });
    }
    let runs: usize = comps.iter().map(|c| c.selected.len()).sum();
    zone.spend(ctx, runs as u64, &format!("{runs} elements"))?;

    let element_used = domain != Domain::Corner && input.output_used("Element");
    let ids: Vec<String> = main_ids.iter().chain(&gen_ids).cloned().collect();
    // Per component, per selected element: the run's output items.
    let mut results: Vec<Vec<Vec<SocketValue>>> = Vec::new();
    for comp in &comps {
        let c = component_ref(&main, comp.kind).expect("present component");
        let mut per = Vec::with_capacity(comp.selected.len());
        for &i in &comp.selected {
            let mut values = Outputs::new();
            values.insert("Index".into(), SocketValue::int(i as i32));
            let element = if element_used {
                extract(ctx, c, domain, i)?
            } else {
                GeometrySet::default()
            };
            values.insert("Element".into(), SocketValue::Geometry(element));
            for (k, id) in in_ids.iter().enumerate() {
                let v = comp.inputs[k].get(i);
                values.insert(id.clone(), SocketValue::Field(Field::Constant(v)));
            }
            per.push(zone.run(ctx, values, &ids)?);
        }
        results.push(per);
    }

    let mut out = Outputs::new();
    // Main items: attributes on the iterated domain of the input geometry.
    let mut geometry = main.clone();
    for (k, id) in main_ids.iter().enumerate() {
        let kind = socket_kind(&ctx.node().inputs, id);
        let Some(ty) = DataType::from_socket(kind) else {
            continue;
        };
        let attr = AttrId::anonymous(id);
        for (comp, per) in comps.iter().zip(&results) {
            let mut data = Array::zeros(ty, comp.size);
            for (&i, run) in comp.selected.iter().zip(per) {
                data.set(i, single(&run[k], ty));
            }
            attributes_of(&mut geometry, comp.kind).set(attr.clone(), domain, data);
        }
        out.insert(
            id.clone(),
            SocketValue::Field(Field::input(AttributeInput { id: attr, ty })),
        );
    }
    out.insert("Geometry".into(), SocketValue::Geometry(geometry));

    // Generation items: groups of a geometry and the fields after it.
    let gen_domains: Vec<Domain> = ctx
        .prop("generation_items")
        .and_then(Json::as_array)
        .map(|items| {
            items
                .iter()
                .map(|it| {
                    it.get("domain")
                        .and_then(Json::as_str)
                        .and_then(Domain::parse)
                        .unwrap_or(Domain::Point)
                })
                .collect()
        })
        .unwrap_or_default();
    let mut group: Option<usize> = None;
    for (g, id) in gen_ids.iter().enumerate() {
        let kind = socket_kind(&ctx.node().inputs, id);
        if kind == "GEOMETRY" {
            group = Some(g);
            let fields: Vec<usize> = (g + 1..gen_ids.len())
                .take_while(|&f| socket_kind(&ctx.node().inputs, &gen_ids[f]) != "GEOMETRY")
                .collect();
            generate(
                ctx,
                &main,
                domain,
                &comps,
                &results,
                main_ids.len(),
                g,
                &fields,
                &gen_ids,
                &gen_domains,
                &mut out,
            )?;
            continue;
        }
        if group.is_none() {
            // Fields before any geometry have nothing to live on: their zero value.
            out.insert(id.clone(), SocketValue::zero(kind));
        }
    }
    Ok(out)
}

fn socket_kind<'a>(sockets: &'a [crate::scene::Socket], id: &str) -> &'a str {
    sockets
        .iter()
        .find(|s| s.identifier == id)
        .map(|s| s.kind.as_str())
        .unwrap_or("")
}

/// A run's value as one value: fields that depend on the geometry have none in a run,
/// and give their type's zero (Blender evaluates them without a context).
fn single(v: &SocketValue, ty: DataType) -> Value {
    match v {
        SocketValue::Field(Field::Constant(c)) => c.convert(ty),
        _ => Value::zero(ty),
    }
}

fn attributes_of(
    g: &mut GeometrySet,
    kind: ComponentType,
) -> &mut super::super::attribute::Attributes {
    match kind {
        ComponentType::Mesh => &mut g.mesh_mut().expect("mesh").attributes,
        ComponentType::PointCloud => &mut g.points_mut().expect("points").attributes,
        ComponentType::Instances => &mut g.instances_mut().expect("instances").attributes,
        ComponentType::Curves => &mut g.curves_mut().expect("curves").attributes,
    }
}

/// A component's attributes (position included), each with its domain.
fn attribute_list(c: ComponentRef) -> Vec<(AttrId, Domain, Array)> {
    let mut out = Vec::new();
    let attrs = match c {
        ComponentRef::Mesh(m) => {
            out.push((
                AttrId::named("position"),
                Domain::Point,
                Array::Vector(m.positions.clone()),
            ));
            &m.attributes
        }
        ComponentRef::Points(p) => {
            out.push((
                AttrId::named("position"),
                Domain::Point,
                Array::Vector(p.positions.clone()),
            ));
            &p.attributes
        }
        ComponentRef::Curves(c) => {
            out.push((
                AttrId::named("position"),
                Domain::Point,
                Array::Vector(c.positions.clone()),
            ));
            &c.attributes
        }
        ComponentRef::Instances(i) => &i.attributes,
    };
    for a in attrs.iter() {
        out.push((a.id.clone(), a.domain, a.data.clone()));
    }
    out
}

/// The element as its own geometry (`GEO_extract_elements`).
fn extract(
    ctx: &NodeCtx,
    c: ComponentRef,
    domain: Domain,
    i: usize,
) -> Result<GeometrySet, GeometryError> {
    match (c, domain) {
        (ComponentRef::Mesh(m), Domain::Point | Domain::Edge | Domain::Face) => {
            Ok(GeometrySet::from_mesh(extract_mesh(m, domain, i)))
        }
        (ComponentRef::Points(p), Domain::Point) => {
            let mut e = PointCloud {
                positions: vec![p.positions[i]],
                materials: p.materials.clone(),
                ..Default::default()
            };
            for a in p.attributes.iter().filter(|a| a.domain == Domain::Point) {
                e.attributes
                    .set(a.id.clone(), Domain::Point, a.data.gather(&[i]));
            }
            Ok(GeometrySet::from_points(e))
        }
        (ComponentRef::Instances(inst), Domain::Instance) => {
            let mut e = Instances::default();
            let h = e.add_reference(inst.references[inst.handles[i] as usize].clone());
            e.handles.push(h);
            e.transforms.push(inst.transforms[i]);
            for a in inst.attributes.iter() {
                e.attributes
                    .set(a.id.clone(), Domain::Instance, a.data.gather(&[i]));
            }
            Ok(GeometrySet::from_instances(e))
        }
        (ComponentRef::Curves(_), _) => Err(ctx.err(
            "the Element geometry of curves is not supported by blendsynth (the Index and \
             input items are)",
        )),
        _ => Ok(GeometrySet::default()),
    }
}

fn extract_mesh(m: &Mesh, domain: Domain, i: usize) -> Mesh {
    let c = ComponentRef::Mesh(m);
    let mut e = Mesh::new();
    e.materials = m.materials.clone();
    // Which source element each element of the new mesh takes its values from, per domain.
    let mut from: HashMap<Domain, Vec<usize>> = HashMap::new();
    match domain {
        Domain::Point => {
            e.positions.push(m.positions[i]);
            from.insert(Domain::Point, vec![i]);
        }
        Domain::Edge => {
            let [a, b] = m.edges[i];
            e.positions = vec![m.positions[a as usize], m.positions[b as usize]];
            e.edges = vec![[0, 1]];
            from.insert(Domain::Point, vec![a as usize, b as usize]);
            from.insert(Domain::Edge, vec![i]);
        }
        _ => {
            let corners: Vec<usize> = m.face(i).collect();
            let n = corners.len() as u32;
            for (k, &cr) in corners.iter().enumerate() {
                e.positions.push(m.positions[m.corner_verts[cr] as usize]);
                e.edges.push([k as u32, (k as u32 + 1) % n]);
                e.corner_verts.push(k as u32);
                e.corner_edges.push(k as u32);
            }
            e.face_offsets = vec![0, n];
            from.insert(
                Domain::Point,
                corners
                    .iter()
                    .map(|&cr| m.corner_verts[cr] as usize)
                    .collect(),
            );
            from.insert(
                Domain::Edge,
                corners
                    .iter()
                    .map(|&cr| m.corner_edges[cr] as usize)
                    .collect(),
            );
            from.insert(Domain::Corner, corners.clone());
            from.insert(Domain::Face, vec![i]);
        }
    }
    for (id, d, data) in attribute_list(c) {
        if id.name() == Some("position") {
            continue;
        }
        // Faces and corners exist only in a face's mesh; a vertex's takes everything on
        // points, an edge's takes corners on points and faces on edges.
        let target = match (domain, d) {
            (Domain::Face, d) => d,
            (Domain::Edge, Domain::Point | Domain::Corner) => Domain::Point,
            (Domain::Edge, _) => Domain::Edge,
            _ => Domain::Point,
        };
        if let Some((_, fixed)) = MESH_BUILTIN.iter().find(|(n, _)| id.name() == Some(*n)) {
            if *fixed != target {
                continue;
            }
        }
        let adapted = c.adapt(&data, d, target);
        let idx = &from[&target];
        e.attributes.set(id, target, adapted.gather(idx));
    }
    e
}

/// The joined geometry of one generation group and its field items.
#[allow(clippy::too_many_arguments)]
fn generate(
    ctx: &NodeCtx,
    main: &GeometrySet,
    domain: Domain,
    comps: &[Component],
    results: &[Vec<Vec<SocketValue>>],
    main_count: usize,
    g: usize,
    fields: &[usize],
    gen_ids: &[String],
    gen_domains: &[Domain],
    out: &mut Outputs,
) -> Result<(), GeometryError> {
    let attr_ids: Vec<(AttrId, DataType)> = fields
        .iter()
        .map(|&f| {
            let kind = socket_kind(&ctx.node().inputs, &gen_ids[f]);
            let ty = DataType::from_socket(kind).unwrap_or(DataType::Float);
            (AttrId::anonymous(&gen_ids[f]), ty)
        })
        .collect();
    let mut parts = Vec::new();
    for (comp, per) in comps.iter().zip(results) {
        let src = component_ref(main, comp.kind).expect("present component");
        // The source's attributes on the iterated domain (built-ins stay behind).
        let propagate: Vec<(AttrId, Array)> = attribute_list(src)
            .into_iter()
            .filter(|(id, _, _)| !is_builtin(comp.kind, id))
            .map(|(id, d, data)| (id, src.adapt(&data, d, domain)))
            .collect();
        for (&i, run) in comp.selected.iter().zip(per) {
            let mut geo = match &run[main_count + g] {
                SocketValue::Geometry(geo) => geo.clone(),
                _ => GeometrySet::default(),
            };
            for kind in geo.component_types() {
                let n = component_ref(&geo, kind)
                    .map(|c| c.domain_size(propagation_domain(kind)))
                    .unwrap_or(0);
                let attrs = attributes_of(&mut geo, kind);
                for (id, data) in &propagate {
                    if attrs.contains(id) || is_builtin(kind, id) {
                        continue;
                    }
                    attrs.set(
                        id.clone(),
                        propagation_domain(kind),
                        Array::filled(data.get(i), n),
                    );
                }
            }
            for ((id, ty), &f) in attr_ids.iter().zip(fields) {
                let field = match &run[main_count + f] {
                    SocketValue::Field(field) => field.clone().convert(*ty),
                    _ => Field::Constant(Value::zero(*ty)),
                };
                let d = gen_domains.get(f).copied().unwrap_or(Domain::Point);
                capture(&mut geo, id, d, &field, *ty).map_err(|e| ctx.err(e))?;
            }
            parts.push(geo);
        }
    }
    let joined = join_geometries(&parts);
    out.insert(gen_ids[g].clone(), SocketValue::Geometry(joined));
    for ((id, ty), &f) in attr_ids.into_iter().zip(fields) {
        out.insert(
            gen_ids[f].clone(),
            SocketValue::Field(Field::input(AttributeInput { id, ty })),
        );
    }
    Ok(())
}

/// Where element attributes land on generated geometry: the domain with the fewest
/// elements that always exists.
fn propagation_domain(kind: ComponentType) -> Domain {
    match kind {
        ComponentType::Mesh | ComponentType::PointCloud => Domain::Point,
        ComponentType::Curves => Domain::Curve,
        ComponentType::Instances => Domain::Instance,
    }
}

/// Whether `id` is one of Blender's built-in attributes on a component of this type.
pub(crate) fn is_builtin(kind: ComponentType, id: &AttrId) -> bool {
    let Some(name) = id.name() else { return false };
    match kind {
        ComponentType::Mesh => name == "position" || MESH_BUILTIN.iter().any(|(n, _)| *n == name),
        ComponentType::PointCloud => matches!(name, "position" | "radius"),
        ComponentType::Curves => matches!(
            name,
            "position"
                | "radius"
                | "tilt"
                | "resolution"
                | "cyclic"
                | "curve_type"
                | "handle_left"
                | "handle_right"
                | "handle_type_left"
                | "handle_type_right"
                | "nurbs_weight"
                | "nurbs_order"
                | "knots_mode"
                | "normal_mode"
        ),
        ComponentType::Instances => matches!(name, "instance_transform" | ".reference_index"),
    }
}

/// Captures `field` on domain `d` of the generated geometry's components (instances for
/// the Instance domain, else its real components).
fn capture(
    geo: &mut GeometrySet,
    id: &AttrId,
    d: Domain,
    field: &Field,
    ty: DataType,
) -> Result<(), String> {
    let kinds: Vec<ComponentType> = geo
        .component_types()
        .into_iter()
        .filter(|k| (*k == ComponentType::Instances) == (d == Domain::Instance))
        .collect();
    for kind in kinds {
        let Some(c) = component_ref(geo, kind) else {
            continue;
        };
        if !c.has_domain(d) {
            continue;
        }
        let values = FieldContext::new(c).eval(field, d, ty)?;
        attributes_of(geo, kind).set(id.clone(), d, values);
    }
    Ok(())
}
