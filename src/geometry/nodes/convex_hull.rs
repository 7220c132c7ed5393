//! Convex Hull (`node_geo_convex_hull.cc`): one hull mesh of every position of a geometry
//! (mesh vertices, point cloud points and curves' evaluated points together), per
//! geometry its instances reference (instances are kept, each hulled in its own space).
//!
//! Blender hands the positions to Bullet's `btConvexHullComputer`, which decides the hull
//! in integers: each axis is quantized to 10216 steps of the input's extent on that axis
//! (truncated toward zero from the box centre). Points that coincide, are collinear or
//! coplanar on that grid are treated so, and coplanar triangles form one n-gon: a cube
//! with face and edge points is 8 vertices and 6 quads, a flat set is its outline twice
//! (one face each way), a collinear set is its two ends joined by an edge, one point is
//! one vertex. The output vertices are the input positions of the points kept. We make
//! the same quantization (in f32, as Bullet does) and decide with exact integer
//! predicates, so the same points are kept and merged.
//!
//! Element order is not Bullet's: it follows its divide-and-conquer hull's internal edge
//! rings, which only a port of that algorithm would reproduce. Ours is fixed instead:
//! vertices by input index, each face from its lowest vertex, faces sorted; the parity
//! test compares this node's cases up to element order (tests/geometry.rs).
//!
//! When the geometry has a mesh, the hull takes its material slots and attribute layout
//! (values at their defaults), as Blender's template mesh does; the faces are flat.

use std::collections::HashMap;
use std::sync::Arc;

use super::super::curve_eval::Evaluated;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::math::V3;
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::value::SocketValue;
use super::geometry_ops::modify_geometry_sets;

pub fn convex_hull(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let mut positions: Vec<V3> = Vec::new();
        let mut any = false;
        if let Some(m) = &s.mesh {
            any = true;
            positions.extend_from_slice(&m.positions);
        }
        if let Some(p) = &s.points {
            any = true;
            positions.extend_from_slice(&p.positions);
        }
        if let Some(c) = &s.curves {
            any = true;
            let ev = Evaluated::new(c)?;
            positions.extend(ev.positions(c));
        }
        let template = s.mesh.clone();
        let instances = s.instances.take();
        *s = GeometrySet::default();
        s.instances = instances;
        if any {
            s.mesh = Some(Arc::new(hull_mesh(&positions, template.as_deref())));
        }
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Convex Hull", SocketValue::Geometry(g))]))
}

/// The hull as vertex indices into the input and faces over those (output numbering).
#[derive(Debug, Default, PartialEq)]
pub struct Hull {
    pub vertices: Vec<usize>,
    pub faces: Vec<Vec<u32>>,
}

fn hull_mesh(positions: &[V3], template: Option<&Mesh>) -> Mesh {
    let h = hull(positions);
    let mut m = Mesh::new();
    m.positions = h.vertices.iter().map(|&i| positions[i]).collect();
    for f in &h.faces {
        m.corner_verts.extend_from_slice(f);
        m.face_offsets.push(m.corner_verts.len() as u32);
    }
    let mut edges: Vec<[u32; 2]> = Vec::new();
    for f in &h.faces {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            edges.push([a.min(b), a.max(b)]);
        }
    }
    if h.vertices.len() == 2 {
        edges.push([0, 1]);
    }
    edges.sort_unstable();
    edges.dedup();
    m.corner_edges = Vec::with_capacity(m.corner_verts.len());
    for f in &h.faces {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            let e = edges.binary_search(&[a.min(b), a.max(b)]).unwrap_or(0);
            m.corner_edges.push(e as u32);
        }
    }
    m.edges = edges;
    match template {
        Some(t) => {
            m.materials = t.materials.clone();
            for a in t.attributes.iter() {
                let mut data = a.data.empty_like();
                data.extend_default(m.domain_size(a.domain));
                m.attributes.set(a.id.clone(), a.domain, data);
            }
        }
        None => m.materials = vec![None],
    }
    m.set_smooth(false);
    m
}

type P = [i64; 3];

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: P, b: P) -> P {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn dot(a: P, b: P) -> i64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Bullet's integer grid (`btConvexHullInternal::compute`), in the input's axis order:
/// Bullet permutes the axes and may negate the scale, neither of which changes which
/// points are coincident, collinear or coplanar, since truncation is symmetric about 0.
fn quantize(positions: &[V3]) -> Vec<P> {
    let mut mn = [1e30f32; 3];
    let mut mx = [-1e30f32; 3];
    for p in positions {
        for k in 0..3 {
            if p[k] < mn[k] {
                mn[k] = p[k];
            }
            if mx[k] < p[k] {
                mx[k] = p[k];
            }
        }
    }
    let mut inv = [0.0f32; 3];
    let mut centre = [0.0f32; 3];
    for k in 0..3 {
        // btVector3 /= s multiplies by 1 / s.
        let s = (mx[k] - mn[k]) * (1.0f32 / 10216.0);
        if s != 0.0 {
            inv[k] = 1.0 / s;
        }
        centre[k] = (mn[k] + mx[k]) * 0.5;
    }
    positions
        .iter()
        .map(|p| {
            let mut q = [0i64; 3];
            for k in 0..3 {
                // `as i32` truncates toward zero like the C cast (NaN becomes 0).
                q[k] = ((p[k] - centre[k]) * inv[k]) as i32 as i64;
            }
            q
        })
        .collect()
}

/// The convex hull of `positions` as Blender's Convex Hull node makes it (see the module
/// comment): kept input indices and faces, outward wound.
pub fn hull(positions: &[V3]) -> Hull {
    if positions.is_empty() {
        return Hull::default();
    }
    let q = quantize(positions);
    // One point per grid position: the first in input order.
    let mut order: Vec<usize> = (0..q.len()).collect();
    order.sort_by_key(|&i| (q[i], i));
    order.dedup_by_key(|i| q[*i]);
    let pts: Vec<P> = order.iter().map(|&i| q[i]).collect();
    let (verts, faces) = hull_of_distinct(&pts);
    // Output numbering: kept points by input index.
    let mut kept: Vec<usize> = verts.iter().map(|&v| order[v as usize]).collect();
    kept.sort_unstable();
    let new_of: HashMap<usize, u32> = kept
        .iter()
        .enumerate()
        .map(|(n, &i)| (i, n as u32))
        .collect();
    let mut faces: Vec<Vec<u32>> = faces
        .into_iter()
        .map(|f| {
            let mut f: Vec<u32> = f.iter().map(|&v| new_of[&order[v as usize]]).collect();
            let lo = (0..f.len()).min_by_key(|&k| f[k]).unwrap_or(0);
            f.rotate_left(lo);
            f
        })
        .collect();
    faces.sort();
    Hull {
        vertices: kept,
        faces,
    }
}

/// Hull of distinct integer points: the extreme points (indices into `pts`) and the
/// faces over them (also indices into `pts`).
fn hull_of_distinct(pts: &[P]) -> (Vec<u32>, Vec<Vec<u32>>) {
    let n = pts.len();
    if n == 1 {
        return (vec![0], vec![]);
    }
    let a = pts[0];
    let d = sub(pts[1], a);
    let Some(c) = (2..n).find(|&i| cross(d, sub(pts[i], a)) != [0; 3]) else {
        // Collinear: the two ends.
        let lo = (0..n).min_by_key(|&i| dot(d, pts[i])).unwrap();
        let hi = (0..n).max_by_key(|&i| dot(d, pts[i])).unwrap();
        return (vec![lo as u32, hi as u32], vec![]);
    };
    let normal = cross(d, sub(pts[c], a));
    let Some(top) = (2..n).find(|&i| dot(normal, sub(pts[i], a)) != 0) else {
        return planar(pts, normal);
    };
    spatial(pts, [0, 1, c, top])
}

/// A flat set: its strictly convex outline, as two faces of opposite winding.
fn planar(pts: &[P], normal: P) -> (Vec<u32>, Vec<Vec<u32>>) {
    // Drop the axis the normal leans on most; the two left (in cyclic order) give a
    // projection that keeps the plane's orientation up to the sign of that component.
    let k = (0..3).max_by_key(|&k| normal[k].abs()).unwrap();
    let (u, v) = ((k + 1) % 3, (k + 2) % 3);
    let mut idx: Vec<u32> = (0..pts.len() as u32).collect();
    idx.sort_by_key(|&i| (pts[i as usize][u], pts[i as usize][v]));
    let turn = |o: u32, a: u32, b: u32| {
        let (o, a, b) = (pts[o as usize], pts[a as usize], pts[b as usize]);
        (a[u] - o[u]) * (b[v] - o[v]) - (a[v] - o[v]) * (b[u] - o[u])
    };
    // Andrew's monotone chain, dropping collinear points.
    let mut ring: Vec<u32> = Vec::with_capacity(2 * idx.len());
    for pass in 0..2 {
        let start = ring.len();
        let seq: Box<dyn Iterator<Item = &u32>> = if pass == 0 {
            Box::new(idx.iter())
        } else {
            Box::new(idx.iter().rev())
        };
        for &p in seq {
            while ring.len() >= start + 2
                && turn(ring[ring.len() - 2], ring[ring.len() - 1], p) <= 0
            {
                ring.pop();
            }
            ring.push(p);
        }
        ring.pop();
    }
    // Counter-clockwise in (u, v): along +axis k, so along the normal iff its k part is > 0.
    let mut up = ring.clone();
    if normal[k] < 0 {
        up.reverse();
    }
    let mut down = up.clone();
    down.reverse();
    (ring, vec![up, down])
}

struct Face {
    v: [u32; 3],
    normal: P,
    offset: i64,
    alive: bool,
    /// Points strictly in front of this face and of no face made before it.
    outside: Vec<u32>,
}

impl Face {
    fn new(pts: &[P], v: [u32; 3]) -> Face {
        let [a, b, c] = v.map(|i| pts[i as usize]);
        let normal = cross(sub(b, a), sub(c, a));
        Face {
            v,
            normal,
            offset: dot(normal, a),
            alive: true,
            outside: Vec::new(),
        }
    }
    /// > 0 in front, 0 on the plane.
    fn height(&self, p: P) -> i64 {
        dot(self.normal, p) - self.offset
    }
}

/// Quickhull over the integer points from a first tetrahedron; exact (coordinates are
/// within +-10216, so every product fits in i64). Coplanar triangles are then merged into
/// polygons and points on their edges dropped.
fn spatial(pts: &[P], first: [usize; 4]) -> (Vec<u32>, Vec<Vec<u32>>) {
    let mut faces: Vec<Face> = Vec::new();
    let mut edge_face: HashMap<(u32, u32), usize> = HashMap::new();
    let f4 = first.map(|i| i as u32);
    for (x, y, z, w) in [(0, 1, 2, 3), (0, 1, 3, 2), (0, 2, 3, 1), (1, 2, 3, 0)] {
        let mut v = [f4[x], f4[y], f4[z]];
        if Face::new(pts, v).height(pts[f4[w] as usize]) > 0 {
            v.swap(1, 2);
        }
        add_face(pts, &mut faces, &mut edge_face, v);
    }
    for i in 0..pts.len() as u32 {
        if f4.contains(&i) {
            continue;
        }
        if let Some(f) = faces.iter_mut().find(|f| f.height(pts[i as usize]) > 0) {
            f.outside.push(i);
        }
    }
    let mut visible: Vec<usize> = Vec::new();
    let mut is_visible: Vec<bool> = vec![false; faces.len()];
    let mut horizon: Vec<(u32, u32)> = Vec::new();
    let mut orphans: Vec<u32> = Vec::new();
    let mut fi = 0;
    while fi < faces.len() {
        if !faces[fi].alive || faces[fi].outside.is_empty() {
            fi += 1;
            continue;
        }
        let f = &faces[fi];
        let apex = *f
            .outside
            .iter()
            .max_by_key(|&&p| (f.height(pts[p as usize]), std::cmp::Reverse(p)))
            .unwrap();
        let ap = pts[apex as usize];
        // The faces the apex sees, found from this one across edges (they are connected).
        visible.clear();
        is_visible.resize(faces.len(), false);
        visible.push(fi);
        is_visible[fi] = true;
        let mut k = 0;
        while k < visible.len() {
            let v = faces[visible[k]].v;
            for j in 0..3 {
                let twin = edge_face[&(v[(j + 1) % 3], v[j])];
                if !is_visible[twin] && faces[twin].height(ap) > 0 {
                    is_visible[twin] = true;
                    visible.push(twin);
                }
            }
            k += 1;
        }
        horizon.clear();
        orphans.clear();
        for &vf in &visible {
            let v = faces[vf].v;
            for j in 0..3 {
                let (x, y) = (v[j], v[(j + 1) % 3]);
                if !is_visible[edge_face[&(y, x)]] {
                    horizon.push((x, y));
                }
            }
        }
        for &vf in &visible {
            let f = &mut faces[vf];
            f.alive = false;
            orphans.extend(f.outside.drain(..).filter(|&p| p != apex));
            let v = f.v;
            for j in 0..3 {
                edge_face.remove(&(v[j], v[(j + 1) % 3]));
            }
        }
        for &vf in &visible {
            is_visible[vf] = false;
        }
        let first_new = faces.len();
        for &(x, y) in &horizon {
            add_face(pts, &mut faces, &mut edge_face, [x, y, apex]);
        }
        for &p in &orphans {
            if let Some(f) = faces[first_new..]
                .iter_mut()
                .find(|f| f.height(pts[p as usize]) > 0)
            {
                f.outside.push(p);
            }
        }
        fi += 1;
    }
    merge_coplanar(pts, &faces, &edge_face)
}

fn add_face(
    pts: &[P],
    faces: &mut Vec<Face>,
    edge_face: &mut HashMap<(u32, u32), usize>,
    v: [u32; 3],
) {
    let i = faces.len();
    faces.push(Face::new(pts, v));
    for j in 0..3 {
        edge_face.insert((v[j], v[(j + 1) % 3]), i);
    }
}

/// Joins triangles sharing a plane into one polygon (its boundary loop, points on its
/// sides dropped); returns the polygon corners and the points they use.
fn merge_coplanar(
    pts: &[P],
    faces: &[Face],
    edge_face: &HashMap<(u32, u32), usize>,
) -> (Vec<u32>, Vec<Vec<u32>>) {
    let mut parent: Vec<usize> = (0..faces.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let alive: Vec<usize> = (0..faces.len()).filter(|&i| faces[i].alive).collect();
    for &f in &alive {
        let v = faces[f].v;
        for j in 0..3 {
            let twin = edge_face[&(v[(j + 1) % 3], v[j])];
            let tv = faces[twin].v;
            let opposite = tv.iter().copied().find(|x| !v.contains(x)).unwrap();
            if faces[f].height(pts[opposite as usize]) == 0 {
                let (ra, rb) = (root(&mut parent, f), root(&mut parent, twin));
                parent[ra] = rb;
            }
        }
    }
    let mut groups: HashMap<usize, Vec<usize>> = HashMap::new();
    let mut group_order: Vec<usize> = Vec::new();
    for &f in &alive {
        let r = root(&mut parent, f);
        groups
            .entry(r)
            .or_insert_with(|| {
                group_order.push(r);
                Vec::new()
            })
            .push(f);
    }
    let mut polygons = Vec::new();
    let mut used: Vec<u32> = Vec::new();
    for r in group_order {
        let members = &groups[&r];
        let mut next: HashMap<u32, u32> = HashMap::new();
        for &f in members {
            let v = faces[f].v;
            for j in 0..3 {
                let (x, y) = (v[j], v[(j + 1) % 3]);
                if root(&mut parent, edge_face[&(y, x)]) != r {
                    next.insert(x, y);
                }
            }
        }
        let start = *next.keys().min().unwrap();
        let mut ring = vec![start];
        let mut at = next[&start];
        while at != start && ring.len() <= next.len() {
            ring.push(at);
            at = next[&at];
        }
        let normal = faces[r].normal;
        let m = ring.len();
        let poly: Vec<u32> = (0..m)
            .filter(|&k| {
                let (u, v, w) = (ring[(k + m - 1) % m], ring[k], ring[(k + 1) % m]);
                let t = cross(
                    sub(pts[v as usize], pts[u as usize]),
                    sub(pts[w as usize], pts[v as usize]),
                );
                dot(t, normal) != 0
            })
            .map(|k| ring[k])
            .collect();
        used.extend_from_slice(&poly);
        polygons.push(poly);
    }
    used.sort_unstable();
    used.dedup();
    (used, polygons)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_with_face_and_edge_points_is_six_quads() {
        let mut p = Vec::new();
        for x in 0..3 {
            for y in 0..3 {
                for z in 0..3 {
                    p.push([x as f32 - 1.0, y as f32 - 1.0, z as f32 - 1.0]);
                }
            }
        }
        let h = hull(&p);
        assert_eq!(h.vertices.len(), 8);
        assert_eq!(h.faces.len(), 6);
        assert!(h.faces.iter().all(|f| f.len() == 4));
    }

    #[test]
    fn many_points_on_a_sphere_stay_quick() {
        // Every point near the hull: the worst case for the conflict lists.
        let p: Vec<V3> = (0..50_000)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / 50_000.0;
                let r = (1.0 - z * z).sqrt();
                let a = i as f32 * 2.399_963;
                [r * a.cos(), r * a.sin(), z]
            })
            .collect();
        let t = std::time::Instant::now();
        let h = hull(&p);
        assert!(h.vertices.len() > 1000 && h.faces.len() > 1000);
        assert!(t.elapsed().as_secs_f32() < 5.0, "{:?}", t.elapsed());
    }

    #[test]
    fn degenerate_sets() {
        assert_eq!(hull(&[]), Hull::default());
        assert_eq!(hull(&[[1.0, 2.0, 3.0]]).vertices, vec![0]);
        let line: Vec<V3> = (0..5).map(|i| [0.0, 0.0, i as f32]).collect();
        let h = hull(&line);
        assert_eq!(h.vertices, vec![0, 4]);
        assert!(h.faces.is_empty());
        let flat = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 0.5, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let h = hull(&flat);
        assert_eq!(h.vertices, vec![0, 1, 3, 4]);
        assert_eq!(h.faces.len(), 2);
    }
}
