//! BMesh's `BM_mesh_bisect_plane` (`bmesh_bisect_plane.cc`) and the vertex removal the
//! Mirror modifier's Bisect follows it with (`BKE_mesh_mirror_bisect_on_mirror_plane_for_modifier`):
//! vertices are classed by side of the plane (within `eps` they are on it, and snapped
//! onto it), edges crossing it are split where they cross (edge order), the faces touched
//! are cut between their on-plane vertices (last touched first), then every vertex more
//! than `eps` on the plane's positive side goes, with its edges and faces.

use super::bmesh::{BMesh, NONE};
use super::mesh::Mesh;

fn side(plane: &[f32; 4], co: [f32; 3]) -> f32 {
    plane[0] * co[0] + plane[1] * co[1] + plane[2] * co[2] + plane[3]
}

/// `m` cut by `plane` (normal, offset), keeping its negative side.
pub fn bisect_and_keep_negative(m: &Mesh, plane: [f32; 4], eps: f32) -> Result<Mesh, String> {
    let mut bm = BMesh::from_mesh(m);
    let nv = bm.co.len();
    let mut dir = vec![0i8; nv];
    let mut dist = vec![0.0f32; nv];
    let mut center = vec![false; nv];
    let len_sq = plane[0] * plane[0] + plane[1] * plane[1] + plane[2] * plane[2];
    for v in 0..nv {
        let f = side(&plane, bm.co[v]);
        dist[v] = f;
        dir[v] = if f <= -eps {
            -1
        } else if f >= eps {
            1
        } else {
            0
        };
        if dir[v] == 0 {
            // `closest_to_plane_v3`.
            let t = -f / len_sq;
            let c = bm.co[v];
            bm.co[v] = [
                c[0] + plane[0] * t,
                c[1] + plane[1] * t,
                c[2] + plane[2] * t,
            ];
        }
    }
    let mut in_stack = vec![false; bm.faces.len()];
    let mut stack: Vec<u32> = Vec::new();
    let push = |f: u32, in_stack: &mut Vec<bool>, stack: &mut Vec<u32>| {
        if !in_stack[f as usize] {
            in_stack[f as usize] = true;
            stack.push(f);
        }
    };
    let n_edges = bm.edges.len();
    for e in 0..n_edges as u32 {
        let [v1, v2] = bm.edges[e as usize].v;
        let s = [dir[v1 as usize], dir[v2 as usize]];
        let d = [dist[v1 as usize], dist[v2 as usize]];
        if s[0] != 0 && s[1] != 0 && s[0] != s[1] {
            let fac = d[0] / (d[0] - d[1]);
            let l0 = bm.edges[e as usize].l;
            if l0 != NONE {
                let mut l = l0;
                loop {
                    push(bm.loops[l as usize].f, &mut in_stack, &mut stack);
                    l = bm.loops[l as usize].radial_next;
                    if l == l0 {
                        break;
                    }
                }
            }
            let v_new = bm.split_edge(e, v1, fac);
            dir.push(0);
            dist.push(0.0);
            center.push(true);
            debug_assert_eq!(v_new as usize, dir.len() - 1);
        } else if s[0] == 0 || s[1] == 0 {
            for (j, v) in [v1, v2].into_iter().enumerate() {
                if s[j] == 0 && !center[v as usize] {
                    center[v as usize] = true;
                    for l in bm.vert_loops(v) {
                        push(bm.loops[l as usize].f, &mut in_stack, &mut stack);
                    }
                }
            }
        }
    }
    while let Some(f) = stack.pop() {
        bisect_face(&mut bm, f, &plane, &dir, &center);
    }
    let mut offset = plane;
    offset[3] -= eps;
    for v in 0..bm.co.len() {
        if bm.vert_alive[v] && side(&offset, bm.co[v]) > 0.0 {
            bm.kill_vert(v as u32);
        }
    }
    bm.into_mesh(m)
}

/// `bm_face_bisect_verts`: a face with vertices on the plane and on both sides is cut
/// between them; two is the common case, more are sorted across the face and cut in
/// pairs, inside spans only.
fn bisect_face(bm: &mut BMesh, f: u32, plane: &[f32; 4], dir: &[i8], center: &[bool]) {
    let loops = bm.face_loops(f);
    let f_len_orig = loops.len();
    let vof = |l: u32| bm.loops[l as usize].v as usize;
    let mut split: Vec<u32> = Vec::new();
    let mut skip = vec![false; bm.co.len()];
    let mut use_dirs = [false; 3];
    let mut center_edge = false;
    for &l in &loops {
        let lp = bm.loops[l as usize];
        let v = lp.v as usize;
        if center[v] {
            skip[v] = (dir[vof(lp.prev)] ^ dir[vof(lp.next)]) == 0;
            split.push(lp.v);
            if center[vof(lp.prev)] {
                center_edge = true;
            }
        }
        use_dirs[(dir[v] + 1) as usize] = true;
    }
    if split.len() < 2 || !(use_dirs[0] && use_dirs[2]) {
        return;
    }
    if split.len() == 2 {
        let la = bm.face_vert_loop(f, split[0]);
        let lb = bm.face_vert_loop(f, split[1]);
        if let (Some(la), Some(lb)) = (la, lb) {
            if !adjacent(bm, la, lb) {
                bm.split_face(f, la, lb, true);
            }
        }
        return;
    }
    let mut loop_index = vec![0usize; bm.co.len()];
    if center_edge {
        for (i, &l) in loops.iter().enumerate() {
            loop_index[vof(l)] = i;
        }
        let start = loops.iter().position(|&l| !center[vof(l)]).unwrap_or(0);
        let l_first = loops[start];
        let mut l = l_first;
        loop {
            let v = vof(l);
            let next = bm.loops[l as usize].next;
            if !skip[v] && center[v] && center[vof(next)] {
                let l_prev = bm.loops[l as usize].prev;
                let mut l_next = bm.loops[next as usize].next;
                while center[vof(l_next)] {
                    l_next = bm.loops[l_next as usize].next;
                }
                if (dir[vof(l_prev)] ^ dir[vof(l_next)]) == 0 {
                    let mut it = bm.loops[l_prev as usize].next;
                    while it != l_next {
                        skip[vof(it)] = true;
                        it = bm.loops[it as usize].next;
                    }
                }
                l = bm.loops[l_next as usize].prev;
            }
            l = bm.loops[l as usize].next;
            if l == l_first {
                break;
            }
        }
    }
    // Sort across the face: along face normal x plane normal.
    let no = bm.faces[f as usize].no;
    let mut sort_dir = [
        no[1] * plane[2] - no[2] * plane[1],
        no[2] * plane[0] - no[0] * plane[2],
        no[0] * plane[1] - no[1] * plane[0],
    ];
    let len =
        (sort_dir[0] * sort_dir[0] + sort_dir[1] * sort_dir[1] + sort_dir[2] * sort_dir[2]).sqrt();
    if len == 0.0 {
        // A face without area: Blender gives up on it too (barring coincident vertices).
        return;
    }
    for c in sort_dir.iter_mut() {
        *c /= len;
    }
    let key = |v: u32| {
        let c = bm.co[v as usize];
        sort_dir[0] * c[0] + sort_dir[1] * c[1] + sort_dir[2] * c[2]
    };
    let keys: Vec<f32> = split.iter().map(|&v| key(v)).collect();
    let mut order: Vec<usize> = (0..split.len()).collect();
    order.sort_by(|&a, &b| keys[a].total_cmp(&keys[b]));
    let split: Vec<u32> = order.iter().map(|&i| split[i]).collect();
    let mut faces = vec![f];
    let mut inside = false;
    for i in 0..split.len() - 1 {
        let (va, vb) = (split[i], split[i + 1]);
        if center_edge {
            let d = loop_index[va as usize].abs_diff(loop_index[vb as usize]);
            if d == 1 || d == f_len_orig - 1 {
                continue;
            }
        }
        if !skip[va as usize] {
            inside = !inside;
        }
        if !inside {
            continue;
        }
        let found = faces.iter().enumerate().find_map(|(j, &fj)| {
            let la = bm.face_vert_loop(fj, va)?;
            let lb = bm.face_vert_loop(fj, vb)?;
            Some((j, la, lb))
        });
        if let Some((j, la, lb)) = found {
            if !adjacent(bm, la, lb) {
                let f_new = bm.split_face(faces[j], la, lb, true);
                if f_new != faces[j] {
                    faces.push(f_new);
                }
            }
        }
    }
}

fn adjacent(bm: &BMesh, a: u32, b: u32) -> bool {
    bm.loops[a as usize].next == b || bm.loops[a as usize].prev == b
}
