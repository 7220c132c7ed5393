//! Welding mesh vertices as Blender's `geometry::mesh_merge_by_distance` does: which
//! vertices merge ("All": every selected vertex within the distance of a lower-index one
//! that is not itself merged away; "Connected": along edges shorter than the distance), and
//! the merged mesh in Blender's order. Each cluster keeps its lowest-index vertex, at the
//! average of the cluster; edges that collapse go, and duplicate edges keep the first;
//! face corners on collapsed edges go, faces left with fewer than three corners go, and
//! faces made of the same edges as an earlier face go. Attributes are averaged over what
//! merged (booleans: any).
//!
//! A face that folds onto itself (the same vertex twice, not next to each other) is split
//! by Blender into several faces; that case is reported as an error rather than guessed.

use super::attribute::Attributes;
use super::mesh::Mesh;
use super::types::{Array, Domain};

/// Not part of any merge.
const OUT: i32 = -1;
/// An edge whose two vertices merged.
const COLLAPSED: i32 = -2;

/// `kdtree_calc_duplicates_fast` in index order: each selected vertex not yet merged takes
/// every unmerged selected vertex within `distance`. Returns the destination map (-1 for
/// vertices left alone, the vertex itself for cluster targets) and the number merged away.
pub fn duplicates_all(
    positions: &[[f32; 3]],
    selection: &[bool],
    distance: f32,
) -> (Vec<i32>, usize) {
    let order: Vec<usize> = (0..positions.len()).filter(|&i| selection[i]).collect();
    duplicates_in_order(positions, &order, distance)
}

/// The shared search: targets are tried in `order` (the selected vertices); each one not
/// yet merged takes every unmerged vertex of `order` within `distance`.
fn duplicates_in_order(
    positions: &[[f32; 3]],
    order: &[usize],
    distance: f32,
) -> (Vec<i32>, usize) {
    let mut dest = vec![OUT; positions.len()];
    let range_sq = distance * distance;
    // Candidates sorted by x, so each search scans a slab only.
    let mut by_x: Vec<usize> = order.to_vec();
    by_x.sort_by(|&a, &b| positions[a][0].total_cmp(&positions[b][0]).then(a.cmp(&b)));
    let xs: Vec<f32> = by_x.iter().map(|&i| positions[i][0]).collect();
    let mut found = 0;
    for &i in order {
        if !(dest[i] == OUT || dest[i] == i as i32) {
            continue;
        }
        let p = positions[i];
        let lo = xs.partition_point(|&x| x < p[0] - distance);
        let hi = xs.partition_point(|&x| x <= p[0] + distance);
        let before = found;
        for &j in &by_x[lo..hi] {
            if j == i || dest[j] != OUT {
                continue;
            }
            let q = positions[j];
            let (dx, dy, dz) = (q[0] - p[0], q[1] - p[1], q[2] - p[2]);
            if dx * dx + dy * dy + dz * dz <= range_sq {
                dest[j] = i as i32;
                found += 1;
            }
        }
        if found != before {
            dest[i] = i as i32;
        }
    }
    (dest, found)
}

/// `mesh_merge_by_distance_connected`: edges in order collapse when their (cluster root)
/// vertices are both selected and within `distance`; the higher root joins the lower.
pub fn duplicates_connected(mesh: &Mesh, selection: &[bool], distance: f32) -> (Vec<i32>, usize) {
    let n = mesh.vertex_count();
    let mut map: Vec<usize> = (0..n).collect();
    // Blender moves the cluster's position as it grows and measures from there.
    let mut co = mesh.positions.clone();
    let mut merged = vec![0u32; n];
    let dist_sq = distance * distance;
    let mut killed = 0;
    for e in &mesh.edges {
        let (mut v1, mut v2) = (e[0] as usize, e[1] as usize);
        while v1 != map[v1] {
            v1 = map[v1];
        }
        while v2 != map[v2] {
            v2 = map[v2];
        }
        if v1 == v2 || !selection[v1] || !selection[v2] {
            continue;
        }
        if v1 > v2 {
            std::mem::swap(&mut v1, &mut v2);
        }
        let dir = [
            co[v2][0] - co[v1][0],
            co[v2][1] - co[v1][1],
            co[v2][2] - co[v1][2],
        ];
        if dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2] <= dist_sq {
            let influence = (merged[v2] + 1) as f32 / (merged[v1] + merged[v2] + 2) as f32;
            for k in 0..3 {
                co[v1][k] += dir[k] * influence;
            }
            merged[v1] += merged[v2] + 1;
            map[v2] = v1;
            killed += 1;
        }
    }
    let mut dest = vec![OUT; n];
    if killed == 0 {
        return (dest, 0);
    }
    for i in 0..n {
        if map[i] != i {
            let mut v = i;
            while map[v] != v {
                v = map[v];
            }
            dest[v] = v as i32;
            dest[i] = v as i32;
        }
    }
    (dest, killed)
}

/// Averages `data` over each output element's source group (Blender's default mixers:
/// sum from zero, times the reciprocal of the count; booleans mix to "any").
pub fn mix_groups(data: &Array, groups: &[Vec<u32>]) -> Array {
    fn avg<const K: usize>(v: &[[f32; K]], groups: &[Vec<u32>]) -> Vec<[f32; K]> {
        groups
            .iter()
            .map(|g| {
                if g.len() == 1 {
                    return v[g[0] as usize];
                }
                let mut s = [0.0f32; K];
                for &i in g {
                    for k in 0..K {
                        s[k] += v[i as usize][k];
                    }
                }
                let inv = 1.0 / g.len() as f32;
                s.map(|x| x * inv)
            })
            .collect()
    }
    fn avg_i<const K: usize>(v: &[[i32; K]], groups: &[Vec<u32>]) -> Vec<[i32; K]> {
        groups
            .iter()
            .map(|g| {
                let mut s = [0.0f64; K];
                for &i in g {
                    for k in 0..K {
                        s[k] += v[i as usize][k] as f64;
                    }
                }
                let inv = (1.0 / g.len() as f32) as f64;
                s.map(|x| (x * inv).round() as i32)
            })
            .collect()
    }
    let first = |g: &Vec<u32>| g[0] as usize;
    match data {
        Array::Float(v) => Array::Float(
            avg(&v.iter().map(|x| [*x]).collect::<Vec<_>>(), groups)
                .into_iter()
                .map(|x| x[0])
                .collect(),
        ),
        Array::Float2(v) => Array::Float2(avg(v, groups)),
        Array::Vector(v) => Array::Vector(avg(v, groups)),
        Array::Color(v) => Array::Color(avg(v, groups)),
        Array::ByteColor(v) => Array::ByteColor(avg(v, groups)),
        Array::Int(v) => Array::Int(
            avg_i(&v.iter().map(|x| [*x]).collect::<Vec<_>>(), groups)
                .into_iter()
                .map(|x| x[0])
                .collect(),
        ),
        Array::Int2(v) => Array::Int2(avg_i(v, groups)),
        Array::Int8(v) => Array::Int8(
            avg_i(&v.iter().map(|x| [*x as i32]).collect::<Vec<_>>(), groups)
                .into_iter()
                .map(|x| x[0].clamp(-128, 127) as i8)
                .collect(),
        ),
        Array::Bool(v) => Array::Bool(
            groups
                .iter()
                .map(|g| g.iter().any(|&i| v[i as usize]))
                .collect(),
        ),
        Array::Quaternion(v) => Array::Quaternion(groups.iter().map(|g| v[first(g)]).collect()),
        Array::Matrix(v) => Array::Matrix(groups.iter().map(|g| v[first(g)]).collect()),
    }
}

fn mix_domain(src: &Attributes, dst: &mut Attributes, domain: Domain, groups: &[Vec<u32>]) {
    for a in src.on(domain) {
        dst.set(a.id.clone(), domain, mix_groups(&a.data, groups));
    }
}

/// The mesh with vertices merged by `dest` (from `duplicates_all` / `duplicates_connected`).
pub fn merge(m: &Mesh, dest: &[i32]) -> Result<Mesh, String> {
    merge_with(m, dest, true)
}

/// `merge` as Blender's `mesh_merge_verts` without mixing (`do_mix_data` false, as the
/// Screw modifier asks): merged vertices and edges keep their target's data (position
/// included); corners still mix.
pub fn merge_keeping_targets(m: &Mesh, dest: &[i32]) -> Result<Mesh, String> {
    merge_with(m, dest, false)
}

// Long because it follows Blender's vertex merge step by step.
fn merge_with(m: &Mesh, dest: &[i32], mix: bool) -> Result<Mesh, String> {
    let nv = m.vertex_count();
    let in_ctx = |v: usize| dest[v] != OUT;
    let vmap = |v: usize| if dest[v] == OUT { v } else { dest[v] as usize };

    // Vertices: survivors in order, each with its cluster (ascending).
    let mut vert_final = vec![0u32; nv];
    let mut vgroups: Vec<Vec<u32>> = Vec::new();
    let mut group_of = vec![usize::MAX; nv];
    for v in 0..nv {
        if dest[v] == OUT || dest[v] == v as i32 {
            group_of[v] = vgroups.len();
            vert_final[v] = vgroups.len() as u32;
            vgroups.push(vec![v as u32]);
        }
    }
    for v in 0..nv {
        if dest[v] != OUT && dest[v] != v as i32 {
            let d = dest[v] as usize;
            vert_final[v] = vert_final[d];
            vgroups[group_of[d]].push(v as u32);
        }
    }
    if !mix {
        // The target was pushed first.
        for g in vgroups.iter_mut() {
            g.truncate(1);
        }
    }
    for g in vgroups.iter_mut() {
        g.sort_unstable();
    }

    // Edges: collapsed ones go; doubles (same welded ends) join the first.
    let ne = m.edge_count();
    let mut edge_dest = vec![OUT; ne];
    let mut first_edge: std::collections::HashMap<(usize, usize), usize> =
        std::collections::HashMap::new();
    for (e, ev) in m.edges.iter().enumerate() {
        let (a, b) = (ev[0] as usize, ev[1] as usize);
        if !in_ctx(a) && !in_ctx(b) {
            continue;
        }
        let (a, b) = (vmap(a), vmap(b));
        if a == b {
            edge_dest[e] = COLLAPSED;
            continue;
        }
        let key = (a.min(b), a.max(b));
        edge_dest[e] = *first_edge.entry(key).or_insert(e) as i32;
    }
    let mut edge_final = vec![0u32; ne];
    let mut egroups: Vec<Vec<u32>> = Vec::new();
    let mut egroup_of = vec![usize::MAX; ne];
    for e in 0..ne {
        if edge_dest[e] == OUT || edge_dest[e] == e as i32 {
            egroup_of[e] = egroups.len();
            edge_final[e] = egroups.len() as u32;
            egroups.push(vec![e as u32]);
        } else if edge_dest[e] >= 0 {
            let d = edge_dest[e] as usize;
            edge_final[e] = edge_final[d];
            egroups[egroup_of[d]].push(e as u32);
        }
    }
    let emap = |e: usize| -> i32 {
        if edge_dest[e] == OUT {
            e as i32
        } else {
            edge_dest[e]
        }
    };

    // Faces: corners on collapsed edges go; short faces go; then doubles.
    struct Face {
        src: usize,
        /// (welded vertex, welded edge, source corners mixed into this corner)
        corners: Vec<(usize, usize, Vec<u32>)>,
        in_ctx: bool,
    }
    let mut faces: Vec<Face> = Vec::with_capacity(m.face_count());
    for f in 0..m.face_count() {
        let r = m.face(f);
        let ctx_face = r.clone().any(|c| in_ctx(m.corner_verts[c] as usize));
        let mut corners = Vec::with_capacity(r.len());
        if !ctx_face {
            for c in r.clone() {
                corners.push((
                    m.corner_verts[c] as usize,
                    m.corner_edges[c] as usize,
                    vec![c as u32],
                ));
            }
            faces.push(Face {
                src: f,
                corners,
                in_ctx: false,
            });
            continue;
        }
        // Corners "in context" (their vertex or the next one merges) mix with every such
        // corner of the face welded to the same vertex, collapsed ones included.
        let ctx_corner: Vec<bool> = r
            .clone()
            .map(|c| {
                in_ctx(m.corner_verts[c] as usize)
                    || in_ctx(m.corner_verts[m.next_corner(f, c)] as usize)
            })
            .collect();
        for (k, c) in r.clone().enumerate() {
            let v = vmap(m.corner_verts[c] as usize);
            let e = emap(m.corner_edges[c] as usize);
            if e == COLLAPSED {
                continue;
            }
            let group = if ctx_corner[k] {
                r.clone()
                    .enumerate()
                    .filter(|&(j, c2)| ctx_corner[j] && vmap(m.corner_verts[c2] as usize) == v)
                    .map(|(_, c2)| c2 as u32)
                    .collect()
            } else {
                vec![c as u32]
            };
            corners.push((v, e as usize, group));
        }
        if corners.len() < 3 {
            continue;
        }
        let mut seen: Vec<usize> = corners.iter().map(|c| c.0).collect();
        seen.sort_unstable();
        if seen.windows(2).any(|w| w[0] == w[1]) {
            return Err(format!("face {f} folds onto itself when merged (Blender splits such faces; not supported yet)"));
        }
        faces.push(Face {
            src: f,
            corners,
            in_ctx: true,
        });
    }
    // Doubles: an in-context face made of edges all shared by a later face removes it.
    let mut edge_faces: std::collections::HashMap<usize, Vec<usize>> =
        std::collections::HashMap::new();
    for (i, f) in faces.iter().enumerate() {
        if f.in_ctx {
            for c in &f.corners {
                edge_faces.entry(c.1).or_default().push(i);
            }
        }
    }
    let mut double = vec![false; faces.len()];
    for i in 0..faces.len() {
        if !faces[i].in_ctx || double[i] {
            continue;
        }
        let mut cand: Vec<usize> = edge_faces[&faces[i].corners[0].1]
            .iter()
            .copied()
            .filter(|&j| j > i && !double[j])
            .collect();
        for c in &faces[i].corners[1..] {
            let list = &edge_faces[&c.1];
            cand.retain(|j| list.contains(j));
            if cand.is_empty() {
                break;
            }
        }
        for j in cand {
            double[j] = true;
        }
    }

    let mut out = Mesh::new();
    out.materials = m.materials.clone();
    out.positions = mix_groups(&Array::Vector(m.positions.clone()), &vgroups)
        .as_vector()
        .into_owned();
    mix_domain(&m.attributes, &mut out.attributes, Domain::Point, &vgroups);
    out.edges = egroups
        .iter()
        .map(|g| {
            let e = m.edges[g[0] as usize];
            [vert_final[e[0] as usize], vert_final[e[1] as usize]]
        })
        .collect();
    if !mix {
        for g in egroups.iter_mut() {
            g.truncate(1);
        }
    }
    mix_domain(&m.attributes, &mut out.attributes, Domain::Edge, &egroups);
    let mut face_src = Vec::new();
    let mut cgroups: Vec<Vec<u32>> = Vec::new();
    for (i, f) in faces.iter().enumerate() {
        if double[i] {
            continue;
        }
        face_src.push(f.src);
        for (v, e, g) in &f.corners {
            out.corner_verts.push(vert_final[*v]);
            out.corner_edges.push(edge_final[*e]);
            cgroups.push(g.clone());
        }
        out.face_offsets.push(out.corner_verts.len() as u32);
    }
    for a in m.attributes.on(Domain::Face) {
        out.attributes
            .set(a.id.clone(), Domain::Face, a.data.gather(&face_src));
    }
    mix_domain(&m.attributes, &mut out.attributes, Domain::Corner, &cgroups);
    // Keep Blender's attribute order (creation order of the source).
    let order: Vec<_> = m.attributes.iter().map(|a| a.id.clone()).collect();
    out.attributes.0.sort_by_key(|a| {
        order
            .iter()
            .position(|id| id == &a.id)
            .unwrap_or(usize::MAX)
    });
    Ok(out)
}

/// The order `BLI_kdtree_3d_balance` leaves points in (a quick-select about the median on
/// x, y, z in turn, recursively), which is the order `calc_duplicates_fast` visits them
/// when it is not asked for index order.
pub(crate) fn kdtree_balanced_order(positions: &[[f32; 3]], nodes: &mut [usize], axis: usize) {
    let n = nodes.len();
    if n <= 1 {
        return;
    }
    let (mut left, mut right) = (0usize, n - 1);
    let median = n / 2;
    while right > left {
        let co = positions[nodes[right]][axis];
        let mut i = left as isize - 1;
        let mut j = right as isize;
        loop {
            i += 1;
            while positions[nodes[i as usize]][axis] < co {
                i += 1;
            }
            j -= 1;
            while positions[nodes[j as usize]][axis] > co && j > left as isize {
                j -= 1;
            }
            if i >= j {
                break;
            }
            nodes.swap(i as usize, j as usize);
        }
        let i = i as usize;
        nodes.swap(i, right);
        if i >= median {
            right = i.wrapping_sub(1);
        }
        if i <= median {
            left = i + 1;
        }
        if right == usize::MAX {
            break;
        }
    }
    let next = (axis + 1) % 3;
    let (lo, hi) = nodes.split_at_mut(median);
    kdtree_balanced_order(positions, lo, next);
    kdtree_balanced_order(positions, &mut hi[1..], next);
}

/// `kdtree_calc_duplicates_fast` without index order (as point clouds merge): targets are
/// tried in the balanced tree's node order.
pub fn duplicates_tree_order(
    positions: &[[f32; 3]],
    selection: &[bool],
    distance: f32,
) -> (Vec<i32>, usize) {
    let mut order: Vec<usize> = (0..positions.len()).filter(|&i| selection[i]).collect();
    kdtree_balanced_order(positions, &mut order, 0);
    duplicates_in_order(positions, &order, distance)
}
