//! The attributes Cycles derives from a mesh itself when a material asks for them
//! (intern/cycles/blender/mesh.cpp): Pointiness (per vertex, the angle between the
//! vertex normal and its mean edge direction, blurred once over the edges, with
//! coincident vertices welded) and Random Per Island (per face, a hash of the
//! connected-component root of its vertices). Computed once per bound mesh.

use std::collections::HashSet;

use crate::foundation::math::{Vec3, V3};
use crate::nodes::random::hash_to_float1;
use crate::scene::MeshData;

/// Cycles' Pointiness per vertex, in 0..1 (0.5 on flat ground, more on ridges).
/// `vertex_normals` are Blender's vertex normals of `mesh`.
pub fn pointiness(mesh: &MeshData, vertex_normals: &[V3]) -> Vec<f32> {
    let n = mesh.vertex_count();
    let pos = &mesh.positions;
    let orig = weld(pos);
    // Welded normals: summed on the kept vertex, normalised and shared, in Cycles' order
    // (a kept vertex earlier in index order is already normalised when a later
    // duplicate reads it).
    let pos = |v: usize| Vec3::from(pos[v]);
    let mut normal = vec![Vec3::ZERO; n];
    for v in 0..n {
        let o = orig[v] as usize;
        normal[o] += vertex_normals.get(v).map_or(Vec3::ZERO, |&n| n.into());
    }
    for v in 0..n {
        // Cycles' normalize: a true division by the length.
        let s = normal[orig[v] as usize];
        normal[v] = s / s.length();
    }
    // Each welded edge once.
    let mut edges = Vec::with_capacity(mesh.edges.len());
    let mut seen = HashSet::with_capacity(mesh.edges.len());
    for e in &mesh.edges {
        let (a, b) = (orig[e[0] as usize], orig[e[1] as usize]);
        if (a as usize) < n && (b as usize) < n && seen.insert((a.min(b), a.max(b))) {
            edges.push((a as usize, b as usize));
        }
    }
    let mut count = vec![0u32; n];
    let mut accum = vec![Vec3::ZERO; n];
    for &(a, b) in &edges {
        // Cycles' safe_normalize, by the reciprocal length (a zero edge stays zero).
        let d = pos(b) - pos(a);
        let l = d.length();
        let e = if l != 0.0 { d * (1.0 / l) } else { d };
        accum[a] += e;
        accum[b] -= e;
        count[a] += 1;
        count[b] += 1;
    }
    let mut raw = vec![0.0f32; n];
    for v in 0..n {
        if orig[v] as usize == v && count[v] > 0 {
            let mean = accum[v] * (1.0 / count[v] as f32);
            raw[v] = normal[v].dot(mean).clamp(-1.0, 1.0).acos() * std::f32::consts::FRAC_1_PI;
        }
    }
    // One blur over the one-ring approximates a two-ring neighbourhood.
    let mut data = raw.clone();
    count.iter_mut().for_each(|c| *c = 0);
    for &(a, b) in &edges {
        data[a] += raw[b];
        data[b] += raw[a];
        count[a] += 1;
        count[b] += 1;
    }
    for v in 0..n {
        data[v] /= (count[v] + 1) as f32;
    }
    (0..n).map(|v| data[orig[v] as usize]).collect()
}

/// Per vertex, the vertex it is welded to (itself when unique): Cycles' sort by
/// coordinate sum, each vertex pointing to the first later one within sqrt(FLT_EPSILON),
/// chains followed to their end. Exact duplicates sort by descending index, so they
/// end at the lowest index.
fn weld(pos: &[V3]) -> Vec<u32> {
    let n = pos.len();
    let sum = |p: V3| p[0] + p[1] + p[2];
    let mut sorted: Vec<u32> = (0..n as u32).collect();
    sorted.sort_by(|&a, &b| {
        let (pa, pb) = (pos[a as usize], pos[b as usize]);
        if pa == pb {
            return b.cmp(&a);
        }
        // Cycles orders only by the sum; ties of distinct points get a fixed order here.
        sum(pa)
            .total_cmp(&sum(pb))
            .then_with(|| pa[0].total_cmp(&pb[0]))
            .then_with(|| pa[1].total_cmp(&pb[1]))
            .then_with(|| pa[2].total_cmp(&pb[2]))
    });
    let mut orig: Vec<u32> = (0..n as u32).collect();
    for i in 0..n {
        let v = sorted[i] as usize;
        let co = pos[v];
        for &o in &sorted[i + 1..] {
            let other = pos[o as usize];
            if sum(other) - sum(co) > 3.0 * f32::EPSILON {
                break;
            }
            let d = Vec3::from(other) - co.into();
            if d.dot(d) < f32::EPSILON {
                orig[v] = o;
                break;
            }
        }
    }
    for v in 0..n {
        let mut o = orig[v];
        while o != orig[o as usize] {
            o = orig[o as usize];
        }
        orig[v] = o;
    }
    orig
}

/// Cycles' Random Per Island per face: vertices joined over the edges by a union-find
/// (union by rank, path compression, in edge order, as Cycles' DisjointSet), and the
/// root of each face's first vertex hashed to 0..1.
pub fn random_per_island(mesh: &MeshData) -> Vec<f32> {
    let n = mesh.vertex_count();
    let mut parent: Vec<usize> = (0..n).collect();
    let mut rank = vec![0u32; n];
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        let mut root = x;
        while parent[root] != root {
            root = parent[root];
        }
        while parent[x] != root {
            let p = parent[x];
            parent[x] = root;
            x = p;
        }
        root
    }
    for e in &mesh.edges {
        let (a, b) = (e[0] as usize, e[1] as usize);
        if a >= n || b >= n {
            continue;
        }
        let (mut ra, mut rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra == rb {
            continue;
        }
        if rank[ra] < rank[rb] {
            std::mem::swap(&mut ra, &mut rb);
        }
        parent[rb] = ra;
        if rank[ra] == rank[rb] {
            rank[ra] += 1;
        }
    }
    (0..mesh.face_count())
        .map(|f| {
            let v = mesh
                .corner_verts
                .get(mesh.face_offsets[f] as usize)
                .map_or(0, |&v| v as usize);
            if v < n {
                hash_to_float1(find(&mut parent, v) as u32)
            } else {
                0.0
            }
        })
        .collect()
}
