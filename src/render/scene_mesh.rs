//! The evaluated scene as one world-space mesh, for reconstruction ground truth: every
//! instance the renderer traces (Geometry Nodes realised, modifiers and true
//! displacement applied, at the frame's transforms), as the triangles it traces.

use std::collections::HashMap;

use crate::geometry::attribute::AttrId;
use crate::geometry::mesh::Mesh;
use crate::geometry::types::{Array, Domain};
use crate::render::build::Geometry;

/// One mesh of the geometry's instances in world space: each instance's vertices
/// (transformed, in its mesh's order, instances one after another), one triangular face
/// per traced triangle (the renderer's triangulation), and the face attribute
/// `instance_id`, the instance's id in the renderer's instance pass (1 + its index, as
/// `Passes::instance_id` and the dataset's masks number them).
pub fn scene_mesh(geo: &Geometry) -> Mesh {
    let mut m = Mesh::new();
    let mut instance = Vec::new();
    let mut edges: HashMap<[u32; 2], u32> = HashMap::new();
    let mut base = Vec::with_capacity(geo.instances.len());
    for inst in &geo.instances {
        base.push(m.positions.len() as u32);
        let mesh = &inst.mesh;
        m.positions
            .extend(mesh.positions.iter().map(|p| inst.to_world.point(*p)));
    }
    for r in &geo.refs {
        let inst = &geo.instances[r.inst as usize];
        let mesh = &inst.mesh;
        let t = mesh.triangles[r.tri as usize];
        let v = t.map(|c| base[r.inst as usize] + mesh.corner_verts[c as usize]);
        for k in 0..3 {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            let key = [a.min(b), a.max(b)];
            let n = edges.len() as u32;
            let e = *edges.entry(key).or_insert_with(|| {
                m.edges.push(key);
                n
            });
            m.corner_verts.push(a);
            m.corner_edges.push(e);
        }
        m.face_offsets.push(m.corner_verts.len() as u32);
        instance.push(r.inst as i32 + 1);
    }
    m.attributes.set(
        AttrId::Named("instance_id".into()),
        Domain::Face,
        Array::Int(instance),
    );
    m
}
