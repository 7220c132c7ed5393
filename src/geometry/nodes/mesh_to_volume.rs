//! Mesh to Volume (`node_geo_mesh_to_volume.cc` -> `geometry::fog_volume_grid_add_from_mesh`
//! -> OpenVDB `tools::meshToVolume` and `tools::sdfToFogVolume`): a `density` fog grid of
//! each mesh's inside.
//!
//! Blender's part: the voxel size is Voxel Size, or the bounding box diagonal over Voxel
//! Amount; below 1e-5 the volume has no grid. The mesh's loop triangles go to index space
//! as `p / voxel_size - 0.5` in single precision while the grid transform is a plain
//! scale by the voxel size (so voxel `ijk` sampled the mesh at `(ijk + 0.5) * size`). The
//! interior band is `max(1, Interior Band Width / voxel_size)` voxels, the exterior one 1.
//! Every mesh component is replaced by its volume and every other component dropped; a
//! geometry without a mesh passes unchanged.
//!
//! OpenVDB's part, followed step by step (`MeshToVolume.h`, voxel units until step 6):
//! 1. Each triangle (split in four while wider than 16 voxels and the mesh has fewer than
//!    1000 of them) floods its voxels from `floor(a)` through 26-neighbours, continuing
//!    from those within squared distance 0.75 ("intersecting"); every voxel reached keeps
//!    its smallest squared distance (f32) and the lowest triangle index at a tie.
//! 2. Voxels not intersecting are exterior when outside the mesh (OpenVDB sweeps and
//!    floods them from the band's boundary; here: the winding number, so the mesh must be
//!    closed). An intersecting voxel turns exterior when it lies on the side of an
//!    exterior neighbour as seen from that neighbour's closest point; one left with no
//!    exterior neighbour becomes 0.75 + 1e-7 (`ValidateIntersectingVoxels`), and an
//!    interior voxel with no neighbour at or below 0.75 leaves the band.
//! 3. Distances become `sqrt * voxel_size`, negative inside; inactive voxels take the band
//!    widths (`signedFloodFillWithValues`).
//! 4. Above two voxels of interior band, the band grows layer by layer, each new voxel
//!    measured to the triangles its neighbours within Manhattan distance 5 (6 for the
//!    second layer inside a leaf) are closest to (`ExpandNarrowband`), so a deep voxel can
//!    read a triangle that is not its nearest.
//! 5. One Godunov renormalization step on the field offset by 0.8 voxels, kept where it
//!    lowers the value, then trimming to the band.
//! 6. `sdfToFogVolume`: every negative voxel becomes value / cutoff, the cutoff the most
//!    negative value (the interior band width as soon as any interior voxel lies beyond
//!    the band, which then reads 1), times Density.
//!
//! OpenVDB's leaf nodes (8^3 voxels) matter in steps 2 and 4; they are kept as 8-aligned
//! blocks of a dense box around the mesh. Not matched, refused naming the node: a mesh
//! that is not closed (an edge used by an odd number of faces), where OpenVDB's exterior
//! flood fill leaks in ways the winding number does not follow.

use std::collections::HashMap;
use std::sync::Arc;

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::value::SocketValue;
use super::super::volume::{Volume, VolumeGrid, MAX_VOXELS};
use super::distribute::corner_tris;
use super::geometry_ops::modify_geometry_sets;

pub fn mesh_to_volume(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mode = ctx.prop_str("resolution_mode")?;
    let density = ctx.float("Density")?;
    let interior_width = ctx.float("Interior Band Width")?;
    let resolution = match mode {
        "VOXEL_AMOUNT" => Resolution::Amount(ctx.float("Voxel Amount")?),
        "VOXEL_SIZE" => Resolution::Size(ctx.float("Voxel Size")?),
        m => return Err(ctx.err(format!("Resolution {m:?} is not a Mesh to Volume mode"))),
    };
    let mut g = ctx.geometry("Mesh")?;
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let Some(mesh) = s.mesh.as_deref() else {
            return Ok(());
        };
        let volume = volume_from_mesh(mesh, resolution, interior_width, density)?;
        // `keep_only({Volume, Edit})`.
        *s = GeometrySet {
            volume: volume.map(Arc::new),
            ..Default::default()
        };
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Volume", SocketValue::Geometry(g))]))
}

#[derive(Clone, Copy)]
enum Resolution {
    Amount(f32),
    Size(f32),
}

/// `create_volume_from_mesh`: None where Blender makes no volume, a volume without grids
/// where the voxel size is too small.
fn volume_from_mesh(
    mesh: &Mesh,
    res: Resolution,
    interior_width: f32,
    density: f32,
) -> Result<Option<Volume>, String> {
    if matches!(res, Resolution::Amount(a) | Resolution::Size(a) if a <= 0.0) {
        return Ok(None);
    }
    if mesh.vertex_count() == 0 || mesh.face_count() == 0 {
        return Ok(None);
    }
    if mesh.positions.iter().flatten().any(|c| !c.is_finite()) {
        return Err("the mesh has non-finite vertex positions".into());
    }
    let voxel_size = match res {
        Resolution::Size(s) => s,
        Resolution::Amount(amount) => {
            // `volume_compute_voxel_size` (no exterior band, no simplification).
            let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
            for p in &mesh.positions {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
            }
            let d: [f32; 3] = std::array::from_fn(|a| hi[a] - lo[a]);
            let diagonal = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            diagonal / amount.max(1.0)
        }
    };
    let mut volume = Volume::default();
    if voxel_size < 1e-5 || interior_width <= 0.0 {
        return Ok(Some(volume));
    }
    let (corners, _) = corner_tris(mesh)?;
    let tris: Vec<[u32; 3]> = corners
        .iter()
        .map(|t| t.map(|c| mesh.corner_verts[c as usize]))
        .collect();
    check_closed(&tris)?;
    let inv = 1.0f32 / voxel_size;
    let points: Vec<[f64; 3]> = mesh
        .positions
        .iter()
        .map(|p| p.map(|c| (c * inv - 0.5) as f64))
        .collect();
    let interior = (interior_width / voxel_size).max(1.0);
    let (origin, dims, values, active) = fog_grid(&points, &tris, voxel_size, interior, density)?;
    let mut t = [[0.0f64; 4]; 4];
    for (k, col) in t.iter_mut().enumerate().take(3) {
        col[k] = voxel_size as f64;
    }
    t[3][3] = 1.0;
    volume.grids.push(VolumeGrid::from_dense_active(
        "density", t, 0.0, origin, dims, &values, &active,
    ));
    Ok(Some(volume))
}

/// Every edge of the triangulation used by an even number of triangles.
fn check_closed(tris: &[[u32; 3]]) -> Result<(), String> {
    let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
    for t in tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut open: Vec<(u32, u32)> = uses
        .into_iter()
        .filter(|(_, n)| n % 2 == 1)
        .map(|(e, _)| e)
        .collect();
    open.sort_unstable();
    if let Some((a, b)) = open.first() {
        return Err(format!(
            "the mesh is not closed ({} open edges, the first between vertices {a} and {b}); OpenVDB's exterior flood fill of an open mesh is not evaluated",
            open.len()
        ));
    }
    Ok(())
}

/// The 26 neighbour offsets.
fn neighbours26() -> impl Iterator<Item = [i32; 3]> {
    (-1..=1)
        .flat_map(|x| (-1..=1).flat_map(move |y| (-1..=1).map(move |z| [x, y, z])))
        .filter(|o| *o != [0, 0, 0])
}

const FACE6: [[i32; 3]; 6] = [
    [1, 0, 0],
    [-1, 0, 0],
    [0, 1, 0],
    [0, -1, 0],
    [0, 0, 1],
    [0, 0, -1],
];

/// The dense box of voxels OpenVDB's trees touch, 8-aligned so its 8^3 blocks are the
/// leaf nodes.
struct Grid {
    lo: [i32; 3],
    n: [usize; 3],
}

impl Grid {
    fn at(&self, c: [i32; 3]) -> Option<usize> {
        let mut i = 0usize;
        let mut stride = 1usize;
        for a in 0..3 {
            let r = c[a] - self.lo[a];
            if r < 0 || r as usize >= self.n[a] {
                return None;
            }
            i += r as usize * stride;
            stride *= self.n[a];
        }
        Some(i)
    }
    fn coord(&self, i: usize) -> [i32; 3] {
        let x = i % self.n[0];
        let y = (i / self.n[0]) % self.n[1];
        let z = i / (self.n[0] * self.n[1]);
        [
            self.lo[0] + x as i32,
            self.lo[1] + y as i32,
            self.lo[2] + z as i32,
        ]
    }
    fn len(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }
    fn leaf(&self, c: [i32; 3]) -> usize {
        let l = [0, 1, 2].map(|a| ((c[a] - self.lo[a]) >> 3) as usize);
        (l[2] * (self.n[1] / 8) + l[1]) * (self.n[0] / 8) + l[0]
    }
    fn leaf_count(&self) -> usize {
        self.len() / 512
    }
}

type P3 = [f64; 3];

fn sub(a: P3, b: P3) -> P3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: P3, b: P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn madd(a: P3, s: f64, b: P3) -> P3 {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}

/// OpenVDB's `closestPointOnSegmentToPoint`.
fn closest_on_segment(a: P3, b: P3, p: P3) -> P3 {
    let ab = sub(b, a);
    let t = dot(sub(p, a), ab);
    if t <= 0.0 {
        return a;
    }
    let denom = dot(ab, ab);
    if t >= denom {
        return b;
    }
    madd(a, t / denom, ab)
}

/// OpenVDB's `closestPointOnTriangleToPoint` (Ericson's regions, degenerate triangles as
/// segments).
fn closest_on_triangle(a: P3, b: P3, c: P3, p: P3) -> P3 {
    if a == b && a == c {
        return a;
    }
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if a == b {
        return closest_on_segment(a, c, p);
    } else if a == c || b == c {
        return closest_on_segment(a, b, p);
    }
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return madd(a, d1 / (d1 - d3), ab);
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return madd(a, d2 / (d2 - d6), ac);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return madd(b, w, sub(c, b));
    }
    let denom = 1.0 / (va + vb + vc);
    let w = vc * denom;
    let v = vb * denom;
    madd(madd(a, v, ab), w, ac)
}

fn to_p3(c: [i32; 3]) -> P3 {
    c.map(|x| x as f64)
}

/// Squared distance from voxel `c` to triangle (a, b, c) as OpenVDB orders it (a, c, b).
fn dist_sq(t: &[P3; 3], c: [i32; 3]) -> f64 {
    let p = to_p3(c);
    let q = closest_on_triangle(t[0], t[2], t[1], p);
    let d = sub(p, q);
    dot(d, d)
}

/// `Vec3d::normalize`: scaled by the reciprocal length, unchanged when (nearly) zero.
fn normalized(v: P3) -> P3 {
    let l = dot(v, v).sqrt();
    if l.abs() <= 1e-7 {
        return v;
    }
    let r = 1.0 / l;
    v.map(|x| x * r)
}

/// Step 1's sub-triangles: OpenVDB splits a triangle wider than 16 voxels in four, again
/// while the count allows (`evalSubdivisionCount`, `spawnTasks`).
fn sub_triangles(t: [P3; 3], tri_count: usize, out: &mut Vec<[P3; 3]>) {
    fn split(t: [P3; 3], count: i32, polys: usize, out: &mut Vec<[P3; 3]>) {
        let (count, polys) = (count - 1, polys * 4);
        let mid = |p: P3, q: P3| [0, 1, 2].map(|k| (p[k] + q[k]) * 0.5);
        let (a, b, c) = (t[0], t[1], t[2]);
        let (ac, bc, ab) = (mid(a, c), mid(b, c), mid(a, b));
        for s in [[a, ab, ac], [ab, bc, ac], [ab, b, bc], [ac, bc, c]] {
            if count <= 0 || polys >= 1000 {
                out.push(s);
            } else {
                split(s, count, polys, out);
            }
        }
    }
    let count = if tri_count < 1000 {
        let extent = (0..3)
            .map(|k| {
                let v = [t[0][k], t[1][k], t[2][k]];
                v.iter().cloned().fold(f64::MIN, f64::max)
                    - v.iter().cloned().fold(f64::MAX, f64::min)
            })
            .fold(f64::MIN, f64::max);
        (extent / 16.0) as i32
    } else {
        0
    };
    if count <= 0 {
        out.push(t);
    } else {
        split(t, count, tri_count, out);
    }
}

/// Whether each voxel is inside the closed mesh: the winding number of a ray towards +x
/// (counted per row from the triangles' yz-projections; an edge's side is decided once for
/// both its triangles, so a row through a shared edge crosses exactly one).
fn inside_flags(g: &Grid, points: &[P3], tris: &[[u32; 3]]) -> Vec<bool> {
    // Rows sit a hair off the integer lattice, off vertices that land on it.
    let (dy, dz) = (3.1e-7, 1.7e-7);
    let side = |u: u32, v: u32, q: [f64; 2]| -> (bool, f64) {
        let (s, t) = (u.min(v), u.max(v));
        let (p, r) = (points[s as usize], points[t as usize]);
        let c = (r[1] - p[1]) * (q[1] - p[2]) - (r[2] - p[2]) * (q[0] - p[1]);
        let positive = if u < v { c >= 0.0 } else { c < 0.0 };
        (positive, if u < v { c } else { -c })
    };
    let mut crossings: Vec<(usize, f64, i32)> = Vec::new();
    for t in tris {
        let p = t.map(|i| points[i as usize]);
        let ys = [p[0][1], p[1][1], p[2][1]];
        let zs = [p[0][2], p[1][2], p[2][2]];
        let j0 = (ys.iter().cloned().fold(f64::MAX, f64::min) - dy).ceil() as i32;
        let j1 = (ys.iter().cloned().fold(f64::MIN, f64::max) - dy).floor() as i32;
        let k0 = (zs.iter().cloned().fold(f64::MAX, f64::min) - dz).ceil() as i32;
        let k1 = (zs.iter().cloned().fold(f64::MIN, f64::max) - dz).floor() as i32;
        for k in k0.max(g.lo[2])..=k1.min(g.lo[2] + g.n[2] as i32 - 1) {
            for j in j0.max(g.lo[1])..=j1.min(g.lo[1] + g.n[1] as i32 - 1) {
                let q = [j as f64 + dy, k as f64 + dz];
                let (s0, e0) = side(t[0], t[1], q);
                let (s1, e1) = side(t[1], t[2], q);
                let (s2, e2) = side(t[2], t[0], q);
                if s0 != s1 || s1 != s2 {
                    continue;
                }
                let sum = e0 + e1 + e2;
                if sum == 0.0 {
                    continue;
                }
                // Barycentric weights: each edge's function weighs the opposite vertex.
                let x = (e1 * p[0][0] + e2 * p[1][0] + e0 * p[2][0]) / sum;
                let row = (k - g.lo[2]) as usize * g.n[1] + (j - g.lo[1]) as usize;
                crossings.push((row, x, if s0 { 1 } else { -1 }));
            }
        }
    }
    crossings.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut inside = vec![false; g.len()];
    let mut c = 0;
    for row in 0..g.n[1] * g.n[2] {
        let start = c;
        while c < crossings.len() && crossings[c].0 == row {
            c += 1;
        }
        let row_x = &crossings[start..c];
        if row_x.is_empty() {
            continue;
        }
        // Sweep from +x: the winding of voxel i counts crossings beyond it.
        let mut w = 0;
        let mut next = row_x.len();
        for i in (0..g.n[0]).rev() {
            let x = g.lo[0] + i as i32;
            while next > 0 && row_x[next - 1].1 > x as f64 {
                next -= 1;
                w += row_x[next].2;
            }
            inside[row * g.n[0] + i] = w != 0;
        }
    }
    inside
}

/// The fog grid: box origin, dims, values and active flags over the box.
// Long because it runs OpenVDB's meshToVolume steps in their order (voxelize, signs,
// band growth, renormalize, trim, fog), each reading the previous one's arrays.
#[allow(clippy::type_complexity)]
fn fog_grid(
    points: &[P3],
    tris: &[[u32; 3]],
    vs: f32,
    interior: f32,
    density: f32,
) -> Result<([i32; 3], [usize; 3], Vec<f32>, Vec<bool>), String> {
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in points {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    // Step 1 reaches under 4 voxels from the surface, the exterior band 1.
    let margin = 5.0;
    let mut glo = [0i32; 3];
    let mut n = [0usize; 3];
    let mut total: u64 = 1;
    for a in 0..3 {
        let l = (lo[a] - margin).floor();
        let h = (hi[a] + margin).ceil();
        if !(l > -1e9 && h < 1e9) {
            return Err("the mesh spans more voxels than a grid may hold".into());
        }
        let l = (l as i64).div_euclid(8) * 8;
        let h = ((h as i64).div_euclid(8) + 1) * 8;
        glo[a] = l as i32;
        n[a] = (h - l) as usize;
        total = total.saturating_mul(n[a] as u64);
    }
    if total > MAX_VOXELS {
        return Err(format!(
            "the mesh spans {total} voxels at this voxel size, more than the limit of one grid ({MAX_VOXELS})"
        ));
    }
    let g = Grid { lo: glo, n };
    let len = g.len();
    let tri_pts: Vec<[P3; 3]> = tris.iter().map(|t| t.map(|i| points[i as usize])).collect();

    // Step 1: voxelize.
    let mut sq = vec![f32::MAX; len];
    let mut prim = vec![-1i32; len];
    let mut stamp = vec![0u32; len];
    let mut subs = Vec::new();
    let mut stack = Vec::new();
    let mut n_sub = 0u32;
    for (ti, t) in tri_pts.iter().enumerate() {
        subs.clear();
        sub_triangles(*t, tris.len(), &mut subs);
        for s in &subs {
            n_sub += 1;
            let update = |c: [i32; 3], sq: &mut [f32], prim: &mut [i32]| -> Option<bool> {
                let i = g.at(c)?;
                let d = dist_sq(s, c) as f32;
                if d.is_nan() {
                    return Some(false);
                }
                if d < sq[i] {
                    sq[i] = d;
                    prim[i] = ti as i32;
                } else if d == sq[i] {
                    prim[i] = prim[i].min(ti as i32);
                }
                Some(!(d > 0.75))
            };
            let seed = s[0].map(|x| x.floor() as i32);
            update(seed, &mut sq, &mut prim).ok_or("voxelization left its box")?;
            stamp[g.at(seed).unwrap()] = n_sub;
            stack.clear();
            stack.push(seed);
            while let Some(c) = stack.pop() {
                for o in neighbours26() {
                    let nc = [c[0] + o[0], c[1] + o[1], c[2] + o[2]];
                    let ni = g.at(nc).ok_or("voxelization left its box")?;
                    if stamp[ni] != n_sub {
                        stamp[ni] = n_sub;
                        if update(nc, &mut sq, &mut prim).unwrap() {
                            stack.push(nc);
                        }
                    }
                }
            }
        }
    }
    let mut active: Vec<bool> = prim.iter().map(|p| *p >= 0).collect();
    let mut leaf = vec![false; g.leaf_count()];
    for (i, a) in active.iter().enumerate() {
        if *a {
            leaf[g.leaf(g.coord(i))] = true;
        }
    }
    let in_leaf = |c: [i32; 3], leaf: &[bool]| g.at(c).is_some() && leaf[g.leaf(c)];

    // Step 2: signs (OpenVDB's convention here: exterior negative).
    let inside = inside_flags(&g, points, tris);
    let mut v = sq.clone();
    for i in 0..len {
        if v[i] > 0.75 && !inside[i] && leaf[g.leaf(g.coord(i))] {
            v[i] = -v[i];
        }
    }
    // Values as a tree accessor reads them: off the leaves, the background (f32::MAX).
    let read = |v: &[f32], leaf: &[bool], c: [i32; 3]| -> f32 {
        if in_leaf(c, leaf) {
            v[g.at(c).unwrap()]
        } else {
            f32::MAX
        }
    };
    let closest = |c: [i32; 3], p: i32| -> P3 {
        let t = &tri_pts[p as usize];
        closest_on_triangle(t[0], t[2], t[1], to_p3(c))
    };
    let mut flips = Vec::new();
    for i in 0..len {
        let d = v[i];
        if !active[i] || !(0.0..=0.75).contains(&d) {
            continue;
        }
        let c = g.coord(i);
        let xyz = to_p3(c);
        let mut flip = false;
        for o in neighbours26() {
            let nc = [c[0] + o[0], c[1] + o[1], c[2] + o[2]];
            let Some(ni) = g.at(nc) else { continue };
            if !active[ni] || !(read(&v, &leaf, nc) < -0.75) {
                continue;
            }
            let cp = closest(nc, prim[ni]);
            let dir1 = normalized(sub(xyz, cp));
            let dir2 = normalized(sub(to_p3(nc), cp));
            // OpenVDB tests the neighbours in the voxel's leaf first, then those across
            // it, with the same product: the order does not change the outcome.
            if dot(dir2, dir1) > 0.0 {
                flip = true;
                break;
            }
        }
        if flip {
            flips.push(i);
        }
    }
    for i in flips {
        v[i] = -v[i];
    }
    // `ValidateIntersectingVoxels`.
    let mut pushed = Vec::new();
    for i in 0..len {
        let d = v[i];
        if !active[i] || !(0.0..=0.75).contains(&d) {
            continue;
        }
        let c = g.coord(i);
        let negative =
            neighbours26().any(|o| read(&v, &leaf, [c[0] + o[0], c[1] + o[1], c[2] + o[2]]) < 0.0);
        if !negative {
            pushed.push(i);
        }
    }
    for i in pushed {
        v[i] = 0.75f32 + 1e-7f32;
    }
    // `RemoveSelfIntersectingSurface`.
    let mut off = Vec::new();
    for i in 0..len {
        if !active[i] || !(v[i] > 0.75) {
            continue;
        }
        let c = g.coord(i);
        let boundary = neighbours26()
            .any(|o| !(read(&v, &leaf, [c[0] + o[0], c[1] + o[1], c[2] + o[2]]) > 0.75));
        if !boundary {
            off.push(i);
        }
    }
    for i in off {
        active[i] = false;
    }
    if !active.iter().any(|a| *a) {
        return Ok(([0; 3], [0; 3], Vec::new(), Vec::new()));
    }

    // Step 3: world distances, band widths off the band.
    let ew = vs;
    let iw = interior * vs;
    for i in 0..len {
        if active[i] {
            let w = if v[i] < 0.0 { vs } else { -vs };
            v[i] = w * v[i].abs().sqrt();
        } else {
            let c = g.coord(i);
            let exterior = if leaf[g.leaf(c)] {
                v[i] < 0.0
            } else {
                !inside[i]
            };
            v[i] = if exterior { ew } else { -iw };
        }
    }

    // Step 4: expand the band.
    if iw > vs * 2.0 || ew > vs * 2.0 {
        expand(&g, &tri_pts, &mut v, &mut active, &mut prim, ew, iw, vs);
    }

    // Step 5: renormalize, trim.
    let offset = (0.8 * vs as f64) as f32;
    let mut w = v.clone();
    for i in 0..len {
        if active[i] {
            w[i] += -offset;
        }
    }
    let at_w = |c: [i32; 3]| g.at(c).map(|i| w[i]).unwrap_or(ew);
    let inv_dx = 1.0f32 / vs;
    for i in 0..len {
        if !active[i] {
            continue;
        }
        let c = g.coord(i);
        let phi0 = w[i];
        let mut norm = 0.0f32;
        for a in 0..3 {
            let mut p = c;
            p[a] += 1;
            let up = at_w(p) - phi0;
            p[a] -= 2;
            let down = phi0 - at_w(p);
            let axis = if phi0 > 0.0 {
                (down.max(0.0).powi(2)).max(up.min(0.0).powi(2))
            } else {
                (down.min(0.0).powi(2)).max(up.max(0.0).powi(2))
            };
            norm = if a == 0 { axis } else { norm + axis };
        }
        let diff = norm.sqrt() * inv_dx - 1.0;
        let s = phi0 / (phi0 * phi0 + norm).sqrt();
        let renorm = phi0 - vs * s * diff;
        v[i] = phi0.min(renorm) + (offset - 1e-7f32);
    }
    for i in 0..len {
        if !active[i] {
            continue;
        }
        if v[i] < 0.0 && !(v[i] > -iw) {
            v[i] = -iw;
            active[i] = false;
        } else if !(v[i] < 0.0) && !(v[i] < ew) {
            v[i] = ew;
            active[i] = false;
        }
    }

    // Step 6: fog.
    let cutoff = v.iter().cloned().fold(f32::MAX, f32::min);
    let weight = 1.0f32 / cutoff;
    let mut fog = vec![0.0f32; len];
    let mut on = vec![false; len];
    for i in 0..len {
        let x = if v[i] > 0.0 { 0.0 } else { v[i] * weight };
        if x > 0.0 {
            fog[i] = if density != 1.0 { x * density } else { x };
            on[i] = true;
        }
    }
    Ok((g.lo, g.n, fog, on))
}

/// Step 4, `ExpandNarrowband` pass by pass: the voxels face-adjacent to the band that are
/// within it, measured to the triangles of band voxels near them, by leaf.
// Long because it keeps OpenVDB's pass in one piece: its leaf order decides which
// triangle a voxel is measured to first, and splitting it would scatter that state.
#[allow(clippy::too_many_arguments)]
fn expand(
    g: &Grid,
    tri_pts: &[[P3; 3]],
    v: &mut [f32],
    active: &mut [bool],
    prim: &mut [i32],
    ew: f32,
    iw: f32,
    vs: f32,
) {
    let min_band = vs * 2.0;
    let estimated = 2.0 * (((iw.max(ew) - min_band) / vs).ceil() as f64);
    let max_iter = if estimated < u32::MAX as f64 {
        estimated as u32
    } else {
        u32::MAX
    };
    // `ConstructVoxelMask`.
    let mut mask: Vec<[i32; 3]> = Vec::new();
    for i in 0..g.len() {
        if active[i] {
            let c = g.coord(i);
            for o in FACE6 {
                let nc = [c[0] + o[0], c[1] + o[1], c[2] + o[2]];
                if g.at(nc).is_some_and(|j| !active[j]) {
                    mask.push(nc);
                }
            }
        }
    }
    let mut count = 0u32;
    let mut in_mask = vec![false; g.len()];
    let mut layer1 = vec![false; g.len()];
    loop {
        // Unique, outside the band, by leaf.
        let mut by_leaf: HashMap<usize, Vec<[i32; 3]>> = HashMap::new();
        for c in mask.drain(..) {
            let Some(i) = g.at(c) else { continue };
            if active[i] || in_mask[i] {
                continue;
            }
            in_mask[i] = true;
            by_leaf.entry(g.leaf(c)).or_default().push(c);
        }
        if by_leaf.is_empty() {
            break;
        }
        let mut leaves: Vec<usize> = by_leaf.keys().copied().collect();
        leaves.sort_unstable();
        let mut new_mask = Vec::new();
        let mut activated = Vec::new();
        for l in leaves {
            let voxels = &by_leaf[&l];
            for c in voxels {
                in_mask[g.at(*c).unwrap()] = false;
            }
            let (mut blo, mut bhi) = ([i32::MAX; 3], [i32::MIN; 3]);
            for c in voxels {
                for a in 0..3 {
                    blo[a] = blo[a].min(c[a] - 1);
                    bhi[a] = bhi[a].max(c[a] + 1);
                }
            }
            // Fragments: band voxels (as at the pass start) in the box, by triangle.
            let mut frags: Vec<(i32, [i32; 3])> = Vec::new();
            for z in blo[2]..=bhi[2] {
                for y in blo[1]..=bhi[1] {
                    for x in blo[0]..=bhi[0] {
                        if let Some(i) = g.at([x, y, z]) {
                            if active[i] {
                                frags.push((prim[i], [x, y, z]));
                            }
                        }
                    }
                }
            }
            frags.sort_by_key(|f| f.0);
            let leaf_lo = {
                let c = voxels[0];
                [0, 1, 2].map(|a| c[a] - (c[a] - g.lo[a]).rem_euclid(8))
            };
            let in_leaf = |c: [i32; 3]| (0..3).all(|a| c[a] >= leaf_lo[a] && c[a] < leaf_lo[a] + 8);
            let update =
                |c: [i32; 3], limit: i32, v: &mut [f32], prim: &mut [i32]| -> (bool, bool) {
                    let p = to_p3(c);
                    let mut best = f64::MAX;
                    let mut best_prim = 0;
                    let mut last = -1;
                    for (idx, fc) in &frags {
                        if *idx == last {
                            continue;
                        }
                        let m = (fc[0] - c[0]).abs() + (fc[1] - c[1]).abs() + (fc[2] - c[2]).abs();
                        if m > limit {
                            continue;
                        }
                        last = *idx;
                        let t = &tri_pts[*idx as usize];
                        let q = closest_on_triangle(t[0], t[2], t[1], p);
                        let d = sub(p, q);
                        let d = dot(d, d);
                        if d < best {
                            best = d;
                            best_prim = *idx;
                        }
                    }
                    let dist = best.sqrt() as f32 * vs;
                    let i = g.at(c).unwrap();
                    let inside = v[i] < 0.0;
                    if !inside && dist < ew {
                        v[i] = dist;
                        prim[i] = best_prim;
                        (true, dist + vs < ew)
                    } else if inside && dist < iw {
                        v[i] = -dist;
                        prim[i] = best_prim;
                        (true, dist + vs < iw)
                    } else {
                        (false, false)
                    }
                };
            let mut second: Vec<[i32; 3]> = Vec::new();
            let mut any = false;
            for c in voxels {
                let (updated, grow) = update(*c, 5, v, prim);
                if updated {
                    any = true;
                    layer1[g.at(*c).unwrap()] = true;
                    activated.push(*c);
                }
                if grow {
                    for o in neighbours26() {
                        let nc = [c[0] + o[0], c[1] + o[1], c[2] + o[2]];
                        if in_leaf(nc) {
                            second.push(nc);
                        } else if o.iter().map(|x| x.abs()).sum::<i32>() == 1 {
                            new_mask.push(nc);
                        }
                    }
                }
            }
            if any {
                second.sort_unstable();
                second.dedup();
                for c in second {
                    let Some(i) = g.at(c) else { continue };
                    if active[i] || layer1[i] {
                        continue;
                    }
                    let (updated, grow) = update(c, 6, v, prim);
                    if updated {
                        activated.push(c);
                    }
                    if grow {
                        for o in FACE6 {
                            new_mask.push([c[0] + o[0], c[1] + o[1], c[2] + o[2]]);
                        }
                    }
                }
            }
            for c in voxels {
                layer1[g.at(*c).unwrap()] = false;
            }
        }
        for c in activated {
            active[g.at(c).unwrap()] = true;
        }
        mask = new_mask;
        count += 1;
        if count >= max_iter {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_point_regions() {
        let t = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        assert_eq!(
            closest_on_triangle(t[0], t[1], t[2], [0.5, 0.5, 3.0]),
            [0.5, 0.5, 0.0]
        );
        assert_eq!(
            closest_on_triangle(t[0], t[1], t[2], [-1.0, -1.0, 0.0]),
            [0.0, 0.0, 0.0]
        );
        assert_eq!(
            closest_on_triangle(t[0], t[1], t[2], [3.0, 3.0, 0.0]),
            [1.0, 1.0, 0.0]
        );
    }

    #[test]
    fn open_meshes_are_found() {
        assert!(check_closed(&[[0, 1, 2]]).is_err());
        // A tetrahedron is closed.
        assert!(check_closed(&[[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]]).is_ok());
    }
}
