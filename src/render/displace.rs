//! True displacement, as Cycles does it for the "Displacement Only" and "Both" methods
//! (scene/mesh_displace.cpp, kernel/bake/bake.h kernel_displace): before the scene is
//! traced, each vertex of a mesh whose material displaces moves by the material's
//! Displacement evaluated there. The shading point at a vertex is that of the first
//! triangle (in order) using it, at its corner, with the vertex normal (Cycles forces
//! smooth shading there) and no differentials. "Both" keeps the vertex normals as they
//! were (its bump supplies the detail, read at the undisplaced surface); "Displacement
//! Only" recomputes them from the moved triangles. The mesh is displaced once, with the
//! first instance's transform, and shared by every instance of it, as in Cycles.

use std::collections::HashMap;
use std::sync::Arc;

use rayon::prelude::*;

use crate::scene::{AttributeData, MeshData};
use crate::shader::bump::ObjectTransform;
use crate::shader::ShadingPoint;

use crate::render::build::{Geometry, MeshInstance};
use crate::render::integrator::shade::Material;
use crate::render::math::*;

/// Displaces every mesh that uses a truly displacing material; returns how many vertices
/// moved. The caller rebuilds the world triangles afterwards.
pub fn apply(geo: &mut Geometry, materials: &[Material]) -> usize {
    let displacing = |m: &Option<usize>| {
        m.and_then(|m| materials[m].program.as_ref())
            .is_some_and(|p| p.displacement.is_some())
    };
    let mut done: HashMap<*const MeshData, (Arc<MeshData>, Arc<Vec<V3>>)> = HashMap::new();
    let mut moved = 0;
    for inst in &mut geo.instances {
        if !inst.slots.iter().any(displacing) {
            continue;
        }
        let key = Arc::as_ptr(&inst.mesh);
        if let std::collections::hash_map::Entry::Vacant(e) = done.entry(key) {
            let undisplaced = Arc::new(inst.mesh.positions.clone());
            let (offsets, recompute) = displace(inst, materials);
            moved += offsets.len();
            // In place when this instance holds the only reference (the published colon:
            // copying its 1.3 M-triangle mesh was a serial part of the set-up); a copy
            // otherwise, so the other holders keep the undisplaced mesh.
            let mesh = Arc::make_mut(&mut inst.mesh);
            for (v, d) in offsets {
                let p = &mut mesh.positions[v as usize];
                *p = (Vec3::from(*p) + d.into()).into();
            }
            if recompute.iter().any(|&r| r) {
                recompute_normals(mesh, &recompute);
            }
            e.insert((inst.mesh.clone(), undisplaced));
        }
        let (mesh, undisplaced) = done[&key].clone();
        inst.mesh = mesh;
        inst.undisplaced = Some(undisplaced);
        inst.world_bounds =
            crate::render::build::world_bounds(&inst.mesh.positions, &inst.to_world);
    }
    moved
}

/// The material program of triangle `t` of `inst`, if it truly displaces.
fn program_of<'m>(
    inst: &MeshInstance,
    materials: &'m [Material],
    t: usize,
) -> Option<(usize, &'m crate::shader::program::Program)> {
    let mi = inst.material_of(t)?;
    let p = materials[mi].program.as_ref()?;
    p.displacement.map(|_| (mi, p))
}

/// Each displaced vertex with its object-space offset, and per triangle whether its
/// normals are recomputed from the moved vertices.
fn displace(inst: &MeshInstance, materials: &[Material]) -> (Vec<(u32, V3)>, Vec<bool>) {
    let m = &inst.mesh;
    // Per vertex: the first displacing triangle corner that uses it (3 * triangle + k).
    let mut owner = vec![u32::MAX; m.vertex_count()];
    let mut recompute = vec![false; m.triangles.len()];
    for (t, tri) in m.triangles.iter().enumerate() {
        let Some((_, p)) = program_of(inst, materials, t) else {
            continue;
        };
        // "Displacement Only" triangles get new normals; "Both" keeps the old ones.
        recompute[t] = p.displacement.is_some_and(|d| d.bump_end.is_none());
        for (k, &c) in tri.iter().enumerate() {
            let v = m.corner_verts[c as usize] as usize;
            if owner[v] == u32::MAX {
                owner[v] = (3 * t + k) as u32;
            }
        }
    }
    let vertex_normals = crate::shader::tangent::vertex_normals(m);
    let jobs: Vec<(u32, u32)> = owner
        .iter()
        .enumerate()
        .filter(|(_, o)| **o != u32::MAX)
        .map(|(v, o)| (v as u32, *o))
        .collect();
    let transform = ObjectTransform {
        to_world: inst.to_world.m,
        to_object: inst.to_object.m,
    };
    let offsets: Vec<(u32, V3)> = jobs
        .par_iter()
        .map_init(
            || vec![Vec::new(); materials.len()],
            |stacks, &(v, o)| {
                let (t, k) = ((o / 3) as usize, (o % 3) as usize);
                let Some((mi, p)) = program_of(inst, materials, t) else {
                    return (v, [0.0; 3]);
                };
                let sp = vertex_point(inst, &vertex_normals, transform, t, k, v as usize);
                let stack = &mut stacks[mi];
                if stack.len() != p.initial.len() {
                    *stack = p.new_stack();
                }
                let d = p.displacement_at(&sp, stack).unwrap_or([0.0; 3]);
                // Cycles' ensure_finite, then back to object space (the mesh's).
                let d = inst
                    .to_object
                    .vector(d.map(|x| if x.is_finite() { x } else { 0.0 }));
                (v, d)
            },
        )
        .collect();
    (offsets, recompute)
}

/// The shading point Cycles' displacement shader sees at vertex `v`, corner `k` of
/// triangle `t` (shader_setup_from_displace).
fn vertex_point(
    inst: &MeshInstance,
    vertex_normals: &[V3],
    transform: ObjectTransform,
    t: usize,
    k: usize,
    v: usize,
) -> ShadingPoint {
    let m = &inst.mesh;
    let tri = m.triangles[t];
    let local = m.positions[v];
    let world = inst.to_world.point(local);
    let wv = tri.map(|c| {
        Vec3::from(
            inst.to_world
                .point(m.positions[m.corner_verts[c as usize] as usize]),
        )
    });
    let ng: V3 = (wv[1] - wv[0]).cross(wv[2] - wv[0]).normalize().into();
    let n_obj: V3 = Vec3::from(vertex_normals[v]).normalize().into();
    let mut n = Vec3::from(Affine::normal_by_inverse(&inst.to_object, n_obj)).normalize();
    if !n.is_finite() || n.is_zero() {
        n = ng.into();
    }
    let n: V3 = n.into();
    let mut sp = ShadingPoint {
        position: world,
        normal: n,
        object_position: local,
        object_normal: n_obj,
        ..Default::default()
    };
    sp.generated = inst.generated(local);
    if let Some(uv) = &inst.uv {
        let c = tri[k] as usize;
        sp.uv = [uv[c][0], uv[c][1], 0.0];
    }
    sp.ng = ng;
    sp.true_normal = ng;
    // Cycles gives the displacement shader an incoming direction along the normal.
    sp.incoming = n;
    sp.parametric = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]][k];
    sp.transform = transform;
    sp.object = inst.info;
    sp
}

/// "Displacement Only": corner normals of the moved triangles from the new geometry,
/// as Cycles' compute_vertex_normals (unit triangle normals summed per vertex); flat
/// faces take their triangle's normal.
fn recompute_normals(m: &mut MeshData, recompute: &[bool]) {
    let mut acc = vec![Vec3::ZERO; m.vertex_count()];
    let tri_normal = |m: &MeshData, tri: &[u32; 3]| {
        let p = tri.map(|c| Vec3::from(m.positions[m.corner_verts[c as usize] as usize]));
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        if n.is_zero() {
            Vec3::X
        } else {
            n.normalize()
        }
    };
    for (t, tri) in m.triangles.iter().enumerate() {
        if recompute[t] {
            let n = tri_normal(m, tri);
            for &c in tri {
                let v = m.corner_verts[c as usize] as usize;
                acc[v] += n;
            }
        }
    }
    let flat = match m.attribute("sharp_face").map(|a| &a.data) {
        Some(AttributeData::Bool(v)) => v.clone(),
        _ => Vec::new(),
    };
    if m.corner_normals.len() != m.corner_count() {
        m.corner_normals = vec![[0.0, 0.0, 1.0]; m.corner_count()];
    }
    for t in 0..m.triangles.len() {
        if !recompute[t] {
            continue;
        }
        let tri = m.triangles[t];
        let is_flat = flat
            .get(m.triangle_faces[t] as usize)
            .copied()
            .unwrap_or(false);
        let fno = tri_normal(m, &tri);
        for &c in &tri {
            let v = m.corner_verts[c as usize] as usize;
            let n = if is_flat { fno } else { acc[v].normalize() };
            m.corner_normals[c as usize] = n.into();
        }
    }
}
