//! Duplicate Elements (`node_geo_duplicate_elements`): each selected element of the
//! domain copied Amount times (negative amounts count as 0), the copies of one element
//! next to each other in selection order, as separate geometry: duplicated edges and faces
//! get their own vertices (and edges), duplicated points become loose vertices or
//! one-point curves. Attributes go along (Duplicate Index numbers the copies 0..Amount);
//! a stable `id` is kept on the first copy and hashed with the copy number on the others,
//! reading the source ids as Blender does (see `copy_point_ids`).
//!
//! Which components survive is Blender's: Point keeps every component (meshes lose their
//! edges and faces); Edge replaces only the mesh (the set is cleared without one); Face
//! keeps only the mesh; Spline only curves; Instance only the instances. Layer (Grease
//! Pencil, which blendsynth has no component for) leaves no real geometry, as in Blender
//! without Grease Pencil.

use std::sync::Arc;

use super::super::attribute::{AttrId, Attributes};
use super::super::curves::Curves;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{AttributeInput, ComponentRef, Field};
use super::super::instances::Instances;
use super::super::mesh::Mesh;
use super::super::pointcloud::PointCloud;
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::{eval_fields, modify_geometry_sets};
use crate::nodes::random::hash2;

/// The selected elements with their copy counts: `selected[k]` is copied into
/// `offsets[k]..offsets[k + 1]` of the result.
struct Duplicates {
    selected: Vec<usize>,
    offsets: Vec<usize>,
}

impl Duplicates {
    fn new(
        comp: ComponentRef,
        domain: Domain,
        sel: &Field,
        amount: &Field,
    ) -> Result<Self, String> {
        let r = eval_fields(
            comp,
            domain,
            &[(sel, DataType::Bool), (amount, DataType::Int)],
        )?;
        let (s, a) = (r[0].as_bool(), r[1].as_int());
        let selected: Vec<usize> = (0..s.len()).filter(|&i| s[i]).collect();
        let mut offsets = Vec::with_capacity(selected.len() + 1);
        offsets.push(0);
        let mut total = 0usize;
        for &i in &selected {
            total += a[i].max(0) as usize;
            offsets.push(total);
        }
        Ok(Duplicates { selected, offsets })
    }
    fn total(&self) -> usize {
        *self.offsets.last().unwrap()
    }
    fn range(&self, k: usize) -> std::ops::Range<usize> {
        self.offsets[k]..self.offsets[k + 1]
    }
    /// For each result element, its source element (Blender's `gather_to_groups`).
    fn sources(&self) -> Vec<usize> {
        let mut out = Vec::with_capacity(self.total());
        for (k, &i) in self.selected.iter().enumerate() {
            out.extend(std::iter::repeat_n(i, self.range(k).len()));
        }
        out
    }
    /// The Duplicate Index values: 0..count in each group.
    fn copy_numbers(&self) -> Vec<i32> {
        let mut out = Vec::with_capacity(self.total());
        for k in 0..self.selected.len() {
            out.extend(0..self.range(k).len() as i32);
        }
        out
    }
}

/// Attributes of `src` on `domains` (the stable `id` left out), each gathered from the
/// elements `map` gives for its domain.
fn transfer(
    src: &Attributes,
    domains: &[Domain],
    map: impl Fn(Domain) -> Option<Vec<usize>>,
) -> Attributes {
    let mut out = Attributes::default();
    for d in domains {
        let Some(idx) = map(*d) else { continue };
        for a in src.on(*d) {
            if a.id.name() == Some("id") {
                continue;
            }
            out.set(a.id.clone(), *d, a.data.gather(&idx));
        }
    }
    out
}

/// Blender's point-domain id copy (`threaded_id_offset_copy`): the copies of the k-th
/// selected element read the k-th source id, which is that element's id only when
/// everything before it is selected; the first copy keeps it, the others hash it with
/// the copy number.
fn copy_point_ids(src: &Attributes, dup: &Duplicates, out: &mut Attributes) {
    let Some(a) = src.named("id") else { return };
    let ids = a.data.as_int();
    let mut dst = Vec::with_capacity(dup.total());
    for k in 0..dup.selected.len() {
        for c in 0..dup.range(k).len() {
            let id = ids[k];
            dst.push(if c == 0 {
                id
            } else {
                hash2(id as u32, c as u32) as i32
            });
        }
    }
    out.set(AttrId::named("id"), Domain::Point, Array::Int(dst));
}

fn hashed(id: i32, copy: usize) -> i32 {
    if copy == 0 {
        id
    } else {
        hash2(id as u32, copy as u32) as i32
    }
}

fn duplicate_mesh_points(m: &Mesh, dup: &Duplicates) -> Mesh {
    let src = dup.sources();
    let mut out = Mesh::new();
    out.positions = src.iter().map(|&i| m.positions[i]).collect();
    out.custom_vert_normals = m
        .custom_vert_normals
        .as_ref()
        .map(|n| src.iter().map(|&i| n[i]).collect());
    out.attributes = transfer(&m.attributes, &[Domain::Point], |_| Some(src.clone()));
    copy_point_ids(&m.attributes, dup, &mut out.attributes);
    out.materials = m.materials.clone();
    out
}

fn duplicate_mesh_edges(m: &Mesh, dup: &Duplicates) -> Mesh {
    let src = dup.sources();
    let verts: Vec<usize> = src
        .iter()
        .flat_map(|&e| [m.edges[e][0] as usize, m.edges[e][1] as usize])
        .collect();
    let mut out = Mesh::new();
    out.positions = verts.iter().map(|&v| m.positions[v]).collect();
    out.edges = (0..src.len() as u32).map(|e| [2 * e, 2 * e + 1]).collect();
    out.attributes = transfer(&m.attributes, &[Domain::Point, Domain::Edge], |d| {
        Some(if d == Domain::Point {
            verts.clone()
        } else {
            src.clone()
        })
    });
    if let Some(a) = m.attributes.named("id") {
        let ids = a.data.as_int();
        let mut dst = Vec::with_capacity(verts.len());
        for (k, &e) in dup.selected.iter().enumerate() {
            for c in 0..dup.range(k).len() {
                dst.push(hashed(ids[m.edges[e][0] as usize], c));
                dst.push(hashed(ids[m.edges[e][1] as usize], c));
            }
        }
        out.attributes
            .set(AttrId::named("id"), Domain::Point, Array::Int(dst));
    }
    out.materials = m.materials.clone();
    out
}

fn duplicate_mesh_faces(m: &Mesh, dup: &Duplicates) -> Mesh {
    let src = dup.sources();
    // One new vertex and edge per corner: corner c of the result uses vertex c and
    // edge c, from the source corner `corners[c]`.
    let mut corners = Vec::new();
    let mut out = Mesh::new();
    for &f in &src {
        let start = corners.len() as u32;
        let r = m.face(f);
        let n = r.len() as u32;
        corners.extend(r);
        for k in 0..n {
            out.edges.push([start + k, start + (k + 1) % n]);
        }
        out.face_offsets.push(corners.len() as u32);
    }
    let verts: Vec<usize> = corners
        .iter()
        .map(|&c| m.corner_verts[c] as usize)
        .collect();
    let edges: Vec<usize> = corners
        .iter()
        .map(|&c| m.corner_edges[c] as usize)
        .collect();
    out.positions = verts.iter().map(|&v| m.positions[v]).collect();
    out.corner_verts = (0..corners.len() as u32).collect();
    out.corner_edges = out.corner_verts.clone();
    out.attributes = transfer(
        &m.attributes,
        &[Domain::Point, Domain::Edge, Domain::Face, Domain::Corner],
        |d| {
            Some(match d {
                Domain::Point => verts.clone(),
                Domain::Edge => edges.clone(),
                Domain::Face => src.clone(),
                _ => corners.clone(),
            })
        },
    );
    // Blender's `copy_stable_id_faces` walks the k-th selected face's copies with the
    // corner count of face k (not of the selected face); a walk past the result stops.
    if let Some(a) = m.attributes.named("id") {
        let ids = a.data.as_int();
        let mut dst = vec![0i32; verts.len()];
        let mut c = 0usize;
        'faces: for k in 0..dup.selected.len() {
            let copies = dup.range(k).len();
            if copies == 0 || k >= m.face_count() {
                continue;
            }
            for copy in 0..copies {
                for _ in 0..m.face_size(k) {
                    if c >= dst.len() {
                        break 'faces;
                    }
                    dst[c] = hashed(ids[verts[c]], copy);
                    c += 1;
                }
            }
        }
        out.attributes
            .set(AttrId::named("id"), Domain::Point, Array::Int(dst));
    }
    out.materials = m.materials.clone();
    out
}

fn duplicate_points(p: &PointCloud, dup: &Duplicates) -> PointCloud {
    let src = dup.sources();
    let mut attributes = transfer(&p.attributes, &[Domain::Point], |_| Some(src.clone()));
    copy_point_ids(&p.attributes, dup, &mut attributes);
    PointCloud {
        positions: src.iter().map(|&i| p.positions[i]).collect(),
        attributes,
        materials: p.materials.clone(),
    }
}

/// Each copied control point becomes a curve of its own, with its curve's values.
fn duplicate_curve_points(c: &Curves, dup: &Duplicates) -> Curves {
    let src = dup.sources();
    let point_curve = c.point_to_curve();
    let curve_src: Vec<usize> = src.iter().map(|&p| point_curve[p]).collect();
    let mut attributes = transfer(&c.attributes, &[Domain::Point, Domain::Curve], |d| {
        Some(if d == Domain::Point {
            src.clone()
        } else {
            curve_src.clone()
        })
    });
    copy_point_ids(&c.attributes, dup, &mut attributes);
    Curves {
        positions: src.iter().map(|&i| c.positions[i]).collect(),
        curve_offsets: (0..=src.len() as u32).collect(),
        attributes,
        materials: c.materials.clone(),
    }
}

fn duplicate_curves(c: &Curves, dup: &Duplicates) -> Curves {
    let src = dup.sources();
    let mut points = Vec::new();
    let mut offsets = vec![0u32];
    for &k in &src {
        points.extend(c.points(k));
        offsets.push(points.len() as u32);
    }
    let mut attributes = transfer(&c.attributes, &[Domain::Point, Domain::Curve], |d| {
        Some(if d == Domain::Point {
            points.clone()
        } else {
            src.clone()
        })
    });
    // The first copy keeps its points' ids (Blender leaves it to the write; the ids are
    // its source's), the others hash them with the copy number.
    if let Some(a) = c.attributes.named("id") {
        let ids = a.data.as_int();
        let mut dst = Vec::with_capacity(points.len());
        for (k, &curve) in dup.selected.iter().enumerate() {
            for copy in 0..dup.range(k).len() {
                dst.extend(c.points(curve).map(|p| hashed(ids[p], copy)));
            }
        }
        attributes.set(AttrId::named("id"), Domain::Point, Array::Int(dst));
    }
    Curves {
        positions: points.iter().map(|&i| c.positions[i]).collect(),
        curve_offsets: offsets,
        attributes,
        materials: c.materials.clone(),
    }
}

fn duplicate_instances(inst: &Instances, dup: &Duplicates) -> Instances {
    let src = dup.sources();
    let mut out = Instances::default();
    for (k, &i) in dup.selected.iter().enumerate() {
        let n = dup.range(k).len();
        if n == 0 {
            continue;
        }
        let h = out.add_reference(inst.references[inst.handles[i] as usize].clone());
        out.handles.extend(std::iter::repeat_n(h, n));
    }
    out.transforms = src.iter().map(|&i| inst.transforms[i]).collect();
    out.attributes = transfer(&inst.attributes, &[Domain::Instance], |_| Some(src.clone()));
    out
}

fn set_index(attrs: &mut Attributes, id: &Option<AttrId>, domain: Domain, dup: &Duplicates) {
    if let Some(id) = id {
        attrs.set(id.clone(), domain, Array::Int(dup.copy_numbers()));
    }
}

pub fn duplicate_elements(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let amount = ctx.field("Amount", DataType::Int)?;
    let mode = ctx.prop_str("domain")?;
    let index_id = ctx
        .output_used("Duplicate Index")
        .then(|| AttrId::anonymous("Duplicate Index"));
    let id = &index_id;
    match mode {
        "INSTANCE" => {
            g = match g.instances.clone() {
                Some(inst) => {
                    let dup = Duplicates::new(
                        ComponentRef::Instances(&inst),
                        Domain::Instance,
                        &sel,
                        &amount,
                    )
                    .map_err(|e| ctx.err(e))?;
                    if dup.total() == 0 {
                        GeometrySet::default()
                    } else {
                        let mut out = duplicate_instances(&inst, &dup);
                        set_index(&mut out.attributes, id, Domain::Instance, &dup);
                        GeometrySet::from_instances(out)
                    }
                }
                None => GeometrySet::default(),
            };
        }
        "POINT" | "EDGE" | "FACE" | "SPLINE" | "LAYER" => {
            modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
                duplicate_real(s, mode, &sel, &amount, id)
            })
            .map_err(|e| ctx.err(e))?;
        }
        other => return Err(ctx.err(format!("unknown domain {other}"))),
    }
    let mut o = outputs([("Geometry", SocketValue::Geometry(g))]);
    if let Some(id) = index_id {
        o.insert(
            "Duplicate Index".into(),
            SocketValue::Field(Field::input(AttributeInput {
                id,
                ty: DataType::Int,
            })),
        );
    }
    Ok(o)
}

/// One set's real components (its instances stay as they are; the geometry they
/// reference is visited on its own).
fn duplicate_real(
    s: &mut GeometrySet,
    mode: &str,
    sel: &Field,
    amount: &Field,
    id: &Option<AttrId>,
) -> Result<(), String> {
    let clear = |s: &mut GeometrySet| {
        s.mesh = None;
        s.curves = None;
        s.points = None;
    };
    match mode {
        "POINT" => {
            if let Some(m) = s.mesh.clone() {
                let dup = Duplicates::new(ComponentRef::Mesh(&m), Domain::Point, sel, amount)?;
                let mut out = duplicate_mesh_points(&m, &dup);
                set_index(&mut out.attributes, id, Domain::Point, &dup);
                s.mesh = Some(Arc::new(out));
            }
            if let Some(p) = s.points.clone() {
                let dup = Duplicates::new(ComponentRef::Points(&p), Domain::Point, sel, amount)?;
                let mut out = duplicate_points(&p, &dup);
                set_index(&mut out.attributes, id, Domain::Point, &dup);
                s.points = Some(Arc::new(out));
            }
            if let Some(c) = s.curves.clone() {
                if c.point_count() > 0 {
                    let dup =
                        Duplicates::new(ComponentRef::Curves(&c), Domain::Point, sel, amount)?;
                    let mut out = duplicate_curve_points(&c, &dup);
                    set_index(&mut out.attributes, id, Domain::Point, &dup);
                    s.curves = Some(Arc::new(out));
                }
            }
        }
        "EDGE" => match s.mesh.clone() {
            // Only the mesh is replaced: Blender's edge mode leaves the other
            // components as they are.
            Some(m) => {
                let dup = Duplicates::new(ComponentRef::Mesh(&m), Domain::Edge, sel, amount)?;
                let mut out = duplicate_mesh_edges(&m, &dup);
                set_index(&mut out.attributes, id, Domain::Edge, &dup);
                s.mesh = Some(Arc::new(out));
            }
            None => clear(s),
        },
        "FACE" => {
            let mesh = s.mesh.clone();
            clear(s);
            if let Some(m) = mesh {
                let dup = Duplicates::new(ComponentRef::Mesh(&m), Domain::Face, sel, amount)?;
                let mut out = duplicate_mesh_faces(&m, &dup);
                set_index(&mut out.attributes, id, Domain::Face, &dup);
                s.mesh = Some(Arc::new(out));
            }
        }
        "SPLINE" => {
            let curves = s.curves.clone();
            clear(s);
            if let Some(c) = curves {
                let dup = Duplicates::new(ComponentRef::Curves(&c), Domain::Curve, sel, amount)?;
                // No points copied: Blender returns empty curves.
                let mut out = if c.point_count() == 0 || dup.total() == 0 {
                    Curves {
                        curve_offsets: vec![0],
                        ..Default::default()
                    }
                } else {
                    duplicate_curves(&c, &dup)
                };
                if out.curve_count() > 0 {
                    set_index(&mut out.attributes, id, Domain::Curve, &dup);
                }
                out.materials = c.materials.clone();
                s.curves = Some(Arc::new(out));
            }
        }
        // Grease Pencil layers: no such component here, so nothing real is left.
        _ => clear(s),
    }
    Ok(())
}
