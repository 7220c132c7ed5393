//! Blender's 2D constrained Delaunay triangulation (`BLI_delaunay_2d`) with the two output
//! types Fill Curve asks for, built on spade's CDT:
//!
//! - vertices: the input points, exact duplicates merged (the first keeps its place), then
//!   the points where constraint edges cross (Blender never adds other Steiner points);
//! - constraints: every input face of 3+ points, closed, its zero-length edges skipped;
//! - holes by the even-odd rule (`detect_holes`): faces joined through non-constraint edges
//!   form a region, and a region is filled when an odd number of constraint edges separate
//!   it from the outside;
//! - `InsideWithHoles` (`CDT_INSIDE_WITH_HOLES`) keeps the filled regions' triangles;
//!   `ValidBmeshWithHoles` (`CDT_CONSTRAINTS_VALID_BMESH_WITH_HOLES`) then dissolves their
//!   non-constraint edges, shortest first, unless the two faces would share a second edge
//!   or another vertex (`remove_non_constraint_edges_leave_valid_bmesh`), so what remains
//!   are the input faces as n-gons, cut only where a hole needs a bridge.
//!
//! Counts and surface are Blender's; where Delaunay has ties (cocircular points, as on a
//! circle) spade may pick other diagonals than Blender's divide and conquer, so the
//! triangle set and face order can differ while covering the same region.

use std::collections::HashMap;

use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Output {
    InsideWithHoles,
    ValidBmeshWithHoles,
}

#[derive(Debug, Clone, Default, PartialEq)]
pub struct CdtResult {
    pub verts: Vec<[f64; 2]>,
    /// Constraint edges (Blender outputs them even where no face uses them).
    pub edges: Vec<[u32; 2]>,
    /// Faces, counter-clockwise.
    pub faces: Vec<Vec<u32>>,
}

/// spade refuses magnitudes below 2^-142 (other than zero); such coordinates are zero for
/// any purpose here.
fn coordinate(x: f64) -> f64 {
    if x.abs() < 1e-40 {
        0.0
    } else {
        x
    }
}

struct Tri {
    v: [u32; 3],
    /// Face across edge k (v[k] -> v[k + 1]); 0 is the outer face.
    nb: [usize; 3],
    constraint: [bool; 3],
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Triangulates `verts` with the closed polygons `faces` (indices into `verts`) as
/// constraints.
pub fn triangulate(
    verts: &[[f64; 2]],
    faces: &[Vec<u32>],
    output: Output,
) -> Result<CdtResult, String> {
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::new();
    let mut handle = Vec::with_capacity(verts.len());
    for (i, p) in verts.iter().enumerate() {
        if !p[0].is_finite() || !p[1].is_finite() {
            return Err(format!("point {i} ({}, {}) is not finite", p[0], p[1]));
        }
        let h = cdt
            .insert(Point2::new(coordinate(p[0]), coordinate(p[1])))
            .map_err(|e| format!("point {i} ({}, {}): {e:?}", p[0], p[1]))?;
        handle.push(h);
    }
    for f in faces {
        if f.len() < 3 {
            continue;
        }
        for k in 0..f.len() {
            let (a, b) = (handle[f[k] as usize], handle[f[(k + 1) % f.len()] as usize]);
            if a != b {
                let _ = cdt.add_constraint_and_split(a, b, |p| p);
            }
        }
    }

    let out_verts: Vec<[f64; 2]> = cdt
        .vertices()
        .map(|v| [v.position().x, v.position().y])
        .collect();
    let edges: Vec<[u32; 2]> = cdt
        .undirected_edges()
        .filter(|e| cdt.is_constraint_edge(e.fix()))
        .map(|e| {
            let [a, b] = e.vertices();
            [a.fix().index() as u32, b.fix().index() as u32]
        })
        .collect();

    // Plain arrays of the triangulation, indexed by spade's face index (0: outer face).
    let nf = cdt.num_all_faces();
    let mut tris: Vec<Option<Tri>> = (0..nf).map(|_| None).collect();
    for f in cdt.inner_faces() {
        let es = f.adjacent_edges();
        let mut t = Tri {
            v: [0; 3],
            nb: [0; 3],
            constraint: [false; 3],
        };
        for (k, e) in es.iter().enumerate() {
            t.v[k] = e.from().fix().index() as u32;
            t.nb[k] = e.rev().face().fix().index();
            t.constraint[k] = cdt.is_constraint_edge(e.fix().as_undirected());
        }
        tris[f.fix().index()] = Some(t);
    }

    // Regions: faces joined through non-constraint edges; the outer face is region 0.
    let mut region = vec![usize::MAX; nf];
    region[0] = 0;
    let mut n_regions = 1;
    let mut stack = Vec::new();
    for start in 1..nf {
        if tris[start].is_none() || region[start] != usize::MAX {
            continue;
        }
        // A region touching the outer face through a non-constraint edge is outside.
        let mut members = Vec::new();
        let mut outside = false;
        stack.push(start);
        region[start] = n_regions;
        while let Some(f) = stack.pop() {
            members.push(f);
            let t = tris[f].as_ref().unwrap();
            for k in 0..3 {
                if t.constraint[k] {
                    continue;
                }
                let g = t.nb[k];
                if g == 0 {
                    outside = true;
                } else if region[g] == usize::MAX {
                    region[g] = n_regions;
                    stack.push(g);
                }
            }
        }
        if outside {
            for f in members {
                region[f] = 0;
            }
        } else {
            n_regions += 1;
        }
    }
    // Even-odd parity across constraint edges between different regions, from outside.
    let mut adjacent: Vec<Vec<usize>> = vec![Vec::new(); n_regions];
    for f in 1..nf {
        let Some(t) = &tris[f] else { continue };
        for k in 0..3 {
            if t.constraint[k] {
                let (a, b) = (region[f], region[t.nb[k]]);
                if a != b {
                    adjacent[a].push(b);
                    adjacent[b].push(a);
                }
            }
        }
    }
    let mut parity = vec![u8::MAX; n_regions];
    parity[0] = 0;
    let mut queue = std::collections::VecDeque::from([0usize]);
    while let Some(r) = queue.pop_front() {
        for &s in &adjacent[r] {
            if parity[s] == u8::MAX {
                parity[s] = parity[r] ^ 1;
                queue.push_back(s);
            }
        }
    }
    let kept = |f: usize| f != 0 && tris[f].is_some() && parity[region[f]] == 1;

    let faces_out = match output {
        Output::InsideWithHoles => (1..nf)
            .filter(|&f| kept(f))
            .map(|f| tris[f].as_ref().unwrap().v.to_vec())
            .collect(),
        Output::ValidBmeshWithHoles => dissolve(&tris, &out_verts, &kept),
    };
    Ok(CdtResult {
        verts: out_verts,
        edges,
        faces: faces_out,
    })
}

/// `remove_non_constraint_edges_leave_valid_bmesh` on the kept triangles: edges by
/// increasing length, each dissolved unless its two faces share another edge or another
/// vertex; then each face's boundary as one counter-clockwise loop.
fn dissolve(
    tris: &[Option<Tri>],
    verts: &[[f64; 2]],
    kept: &dyn Fn(usize) -> bool,
) -> Vec<Vec<u32>> {
    let nf = tris.len();
    let mut candidates: Vec<(f64, usize, usize)> = Vec::new();
    let mut adj: Vec<HashMap<usize, u32>> = vec![HashMap::new(); nf];
    let mut face_verts: Vec<Vec<u32>> = vec![Vec::new(); nf];
    for f in 0..nf {
        if !kept(f) {
            continue;
        }
        let t = tris[f].as_ref().unwrap();
        face_verts[f] = t.v.to_vec();
        for k in 0..3 {
            let g = t.nb[k];
            if g > f && kept(g) {
                *adj[f].entry(g).or_insert(0) += 1;
                *adj[g].entry(f).or_insert(0) += 1;
                if !t.constraint[k] {
                    let (a, b) = (verts[t.v[k] as usize], verts[t.v[(k + 1) % 3] as usize]);
                    candidates.push(((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2), f, k));
                }
            }
        }
    }
    candidates.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut parent: Vec<usize> = (0..nf).collect();
    let mut dissolved: std::collections::HashSet<(usize, usize)> = std::collections::HashSet::new();
    for &(_, f, k) in &candidates {
        let g = tris[f].as_ref().unwrap().nb[k];
        let (a, b) = (find(&mut parent, f), find(&mut parent, g));
        if a == b || adj[a].get(&b).copied().unwrap_or(0) > 1 {
            continue;
        }
        let (small, large) = if face_verts[a].len() < face_verts[b].len() {
            (a, b)
        } else {
            (b, a)
        };
        let shared = face_verts[small]
            .iter()
            .filter(|v| face_verts[large].contains(v))
            .count();
        if shared > 2 {
            continue;
        }
        // Merge `small` into `large`.
        dissolved.insert((f, k));
        let gt = tris[g].as_ref().unwrap();
        if let Some(kg) = (0..3).find(|&j| gt.nb[j] == f) {
            dissolved.insert((g, kg));
        }
        parent[small] = large;
        let moved = std::mem::take(&mut face_verts[small]);
        for v in moved {
            if !face_verts[large].contains(&v) {
                face_verts[large].push(v);
            }
        }
        let moved = std::mem::take(&mut adj[small]);
        for (c, n) in moved {
            if c == large {
                adj[large].remove(&small);
                continue;
            }
            adj[c].remove(&small);
            *adj[c].entry(large).or_insert(0) += n;
            *adj[large].entry(c).or_insert(0) += n;
        }
    }
    // Boundaries of the merged faces, in order of their first triangle.
    let mut groups: HashMap<usize, Vec<usize>> = HashMap::new();
    let mut roots = Vec::new();
    for f in 0..nf {
        if kept(f) {
            let r = find(&mut parent, f);
            groups.entry(r).or_insert_with(|| {
                roots.push(r);
                Vec::new()
            });
            groups.get_mut(&r).unwrap().push(f);
        }
    }
    let mut out = Vec::with_capacity(roots.len());
    for r in roots {
        let mut next: HashMap<u32, u32> = HashMap::new();
        let mut first = None;
        for &f in &groups[&r] {
            let t = tris[f].as_ref().unwrap();
            for k in 0..3 {
                if !dissolved.contains(&(f, k)) {
                    next.insert(t.v[k], t.v[(k + 1) % 3]);
                    first.get_or_insert(t.v[k]);
                }
            }
        }
        let Some(start) = first else { continue };
        let mut face = vec![start];
        let mut v = next.get(&start).copied();
        while let Some(w) = v.filter(|&w| w != start && face.len() <= next.len()) {
            face.push(w);
            v = next.get(&w).copied();
        }
        out.push(face);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f64, y0: f64, s: f64) -> Vec<[f64; 2]> {
        vec![[x0, y0], [x0 + s, y0], [x0 + s, y0 + s], [x0, y0 + s]]
    }

    #[test]
    fn square_with_square_hole() {
        let mut v = square(0.0, 0.0, 4.0);
        v.extend(square(1.0, 1.0, 2.0));
        let faces = vec![vec![0, 1, 2, 3], vec![4, 5, 6, 7]];
        let t = triangulate(&v, &faces, Output::InsideWithHoles).unwrap();
        assert_eq!(t.verts.len(), 8);
        // An annulus of 8 boundary vertices and one hole: 8 triangles.
        assert_eq!(t.faces.len(), 8);
        let area: f64 = t
            .faces
            .iter()
            .map(|f| {
                let (a, b, c) = (
                    t.verts[f[0] as usize],
                    t.verts[f[1] as usize],
                    t.verts[f[2] as usize],
                );
                ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])) / 2.0
            })
            .sum();
        assert!((area - 12.0).abs() < 1e-12, "{area}");
        let n = triangulate(&v, &faces, Output::ValidBmeshWithHoles).unwrap();
        assert_eq!(n.faces.len(), 2, "{:?}", n.faces);
        assert_eq!(n.faces.iter().map(Vec::len).sum::<usize>(), 8 + 2 * 2);
    }

    #[test]
    fn crossing_constraints_add_vertices_and_duplicates_merge() {
        // A bow tie: the crossing becomes a vertex, both lobes are filled.
        let v = vec![[0.0, 0.0], [2.0, 2.0], [2.0, 0.0], [0.0, 2.0], [0.0, 2.0]];
        let t = triangulate(&v, &[vec![0, 1, 2, 3, 4]], Output::InsideWithHoles).unwrap();
        assert_eq!(t.verts.len(), 5);
        assert_eq!(t.verts[4], [1.0, 1.0]);
        assert_eq!(t.faces.len(), 2);
    }
}
