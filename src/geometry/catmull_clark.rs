//! Catmull-Clark refinement as OpenSubdiv's Catmark scheme does it for Blender (uniform
//! creasing, Blender's crease-to-sharpness mapping, boundary edges infinitely sharp), and
//! the limit positions of the refined vertices.
//!
//! Blender's Subdivision Surface evaluates OpenSubdiv patches at ptex grid points. Without
//! "limit surface" the mesh is refined uniformly to the level and the patches are bilinear
//! quads over the refined vertices, so every grid point *is* a refined vertex. With it the
//! mesh is isolated adaptively to the same level; the grid points then fall on B-spline
//! patches (exact limit surface) or on the corners of end-cap patches (limit points), so
//! every grid point is the limit position of the refined vertex: the limit mask applied to
//! the uniformly refined mesh gives the same points. Two exceptions measured against
//! Blender: sharpness still left on the last level does not count in the limit (only
//! infinite creases do), and a boundary vertex of a single face stays where the deepest
//! isolation level puts it (the end-cap corner).
//!
//! Rules (`opensubdiv/sdc/catmarkScheme.h`, `crease.h`): an edge point is the smooth
//! average of the edge ends and face points, the midpoint when the edge stays sharp, and a
//! blend (by the sharpness) when it turns smooth on this level. A vertex's rule follows
//! its sharp edges (0-1 smooth, 2 crease, 3+ or a sharp vertex corner); a vertex whose rule
//! changes between parent and child blends both masks by the mean sharpness of what
//! turned smooth. Sharpness decays by one a level; 10 is infinite.

use super::mesh::Mesh;

/// Sharpness at or above this never decays (`Sdc::Crease::SHARPNESS_INFINITE`).
pub const INFINITE: f32 = 10.0;

/// Blender's edge and vertex crease (0..1) as OpenSubdiv sharpness.
pub fn crease_to_sharpness(crease: f32) -> f32 {
    crease * crease * 10.0
}

fn decay(s: f32) -> f32 {
    if s <= 0.0 {
        0.0
    } else if s >= INFINITE {
        INFINITE
    } else if s > 1.0 {
        s - 1.0
    } else {
        0.0
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Rule {
    Smooth,
    Dart,
    Crease,
    Corner,
}

fn rule_of(vertex_sharpness: f32, edge_sharpness: impl Iterator<Item = f32>) -> Rule {
    if vertex_sharpness > 0.0 {
        return Rule::Corner;
    }
    match edge_sharpness.filter(|s| *s > 0.0).count() {
        0 => Rule::Smooth,
        1 => Rule::Dart,
        2 => Rule::Crease,
        _ => Rule::Corner,
    }
}

/// Options matching Blender's settings.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    /// Boundary Smooth "Keep Corners": a vertex with a single face is a corner.
    pub boundary_corners: bool,
    /// Place the vertices on the limit surface.
    pub limit: bool,
}

/// One refinement level: positions, faces (corner vertices and the edge after each
/// corner), edges and their sharpness, and vertex sharpness.
struct Level {
    pos: Vec<[f64; 3]>,
    face_offsets: Vec<usize>,
    corner_verts: Vec<u32>,
    corner_edges: Vec<u32>,
    edges: Vec<[u32; 2]>,
    edge_sharp: Vec<f32>,
    vert_sharp: Vec<f32>,
}

/// Incidence of a level, compressed rows.
struct Adjacency {
    vert_edge_off: Vec<usize>,
    vert_edges: Vec<u32>,
    vert_face_off: Vec<usize>,
    vert_faces: Vec<u32>,
    edge_face_off: Vec<usize>,
    edge_faces: Vec<u32>,
}

fn rows(n: usize, pairs: impl Iterator<Item = (usize, u32)> + Clone) -> (Vec<usize>, Vec<u32>) {
    let mut off = vec![0usize; n + 1];
    for (k, _) in pairs.clone() {
        off[k + 1] += 1;
    }
    for i in 0..n {
        off[i + 1] += off[i];
    }
    let mut fill = off.clone();
    let mut data = vec![0u32; off[n]];
    for (k, v) in pairs {
        data[fill[k]] = v;
        fill[k] += 1;
    }
    (off, data)
}

impl Level {
    fn face_count(&self) -> usize {
        self.face_offsets.len() - 1
    }

    fn adjacency(&self) -> Adjacency {
        let nv = self.pos.len();
        let ne = self.edges.len();
        let (vert_edge_off, vert_edges) = rows(
            nv,
            self.edges
                .iter()
                .enumerate()
                .flat_map(|(e, v)| [(v[0] as usize, e as u32), (v[1] as usize, e as u32)]),
        );
        let faces_of_corners = (0..self.face_count()).flat_map(|f| {
            (self.face_offsets[f]..self.face_offsets[f + 1]).map(move |c| (c, f as u32))
        });
        let (vert_face_off, vert_faces) = rows(
            nv,
            faces_of_corners
                .clone()
                .map(|(c, f)| (self.corner_verts[c] as usize, f)),
        );
        let (edge_face_off, edge_faces) = rows(
            ne,
            faces_of_corners.map(|(c, f)| (self.corner_edges[c] as usize, f)),
        );
        Adjacency {
            vert_edge_off,
            vert_edges,
            vert_face_off,
            vert_faces,
            edge_face_off,
            edge_faces,
        }
    }
}

fn other_end(e: [u32; 2], v: u32) -> usize {
    (if e[0] == v { e[1] } else { e[0] }) as usize
}

fn lerp3(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    [
        a[0] + (b[0] - a[0]) * t,
        a[1] + (b[1] - a[1]) * t,
        a[2] + (b[2] - a[2]) * t,
    ]
}

/// The refined mesh seen through the coarse one: coarse vertices, coarse-edge chains and
/// ptex grids as indices into the final level's positions.
pub struct Refined {
    pub positions: Vec<[f64; 3]>,
    vertex: Vec<u32>,
    /// Grid steps of the final level per step of the requested level.
    stride: usize,
    /// Per coarse edge: its vertices from its first to its second end.
    chains: Vec<Vec<u32>>,
    /// Per ptex patch (Blender's order): grid rows (v) of columns (u).
    grids: Vec<Vec<Vec<u32>>>,
}

impl Refined {
    pub fn vertex(&self, v: usize) -> [f64; 3] {
        self.positions[self.vertex[v] as usize]
    }
    /// The `i`-th inner point of coarse edge `e`.
    pub fn edge_point(&self, e: usize, i: usize) -> [f64; 3] {
        self.positions[self.chains[e][(i + 1) * self.stride] as usize]
    }
    pub fn ptex_point(&self, ptex: usize, x: usize, y: usize) -> [f64; 3] {
        self.positions[self.grids[ptex][y * self.stride][x * self.stride] as usize]
    }
}

/// Refines `m` `level` (>= 1) times, or to `isolation` (the modifier's quality) when that
/// is deeper: the limit surface is isolated that far, which moves the corners of
/// single-face boundary vertices. `edge_sharpness` and `vert_sharpness` are OpenSubdiv
/// sharpness per coarse edge and vertex.
// Long because it follows OpenSubdiv's refinement step by step.
pub fn refine(
    m: &Mesh,
    level: u32,
    isolation: u32,
    edge_sharpness: &[f32],
    vert_sharpness: &[f32],
    opts: Options,
) -> Refined {
    let depth = if opts.limit {
        level.max(isolation)
    } else {
        level
    };
    let stride = 1usize << (depth - level);
    let mut lv = Level {
        pos: m
            .positions
            .iter()
            .map(|p| [p[0] as f64, p[1] as f64, p[2] as f64])
            .collect(),
        face_offsets: m.face_offsets.iter().map(|&o| o as usize).collect(),
        corner_verts: m.corner_verts.clone(),
        corner_edges: m.corner_edges.clone(),
        edges: m.edges.clone(),
        edge_sharp: edge_sharpness.to_vec(),
        vert_sharp: vert_sharpness.to_vec(),
    };
    // Boundary and non-manifold edges are infinitely sharp; with "Keep Corners" so is a
    // vertex with a single face.
    let adj = lv.adjacency();
    for e in 0..lv.edges.len() {
        if adj.edge_face_off[e + 1] - adj.edge_face_off[e] != 2 {
            lv.edge_sharp[e] = INFINITE;
        }
    }
    // Blender (its OpenSubdiv topology factory) adds to a vertex of exactly two edges the
    // smaller of their given sharpness, so a plane with sharp borders keeps its corners.
    for v in 0..lv.pos.len() {
        let r = adj.vert_edge_off[v]..adj.vert_edge_off[v + 1];
        if r.len() == 2 {
            let (e0, e1) = (
                adj.vert_edges[r.start] as usize,
                adj.vert_edges[r.start + 1] as usize,
            );
            let add = |s: f32| if s < 1e-6 { 0.0 } else { s };
            lv.vert_sharp[v] = (lv.vert_sharp[v]
                + add(edge_sharpness[e0]).min(add(edge_sharpness[e1])))
            .min(INFINITE);
        }
    }
    if opts.boundary_corners {
        for v in 0..lv.pos.len() {
            if adj.vert_face_off[v + 1] - adj.vert_face_off[v] == 1 {
                lv.vert_sharp[v] = INFINITE;
            }
        }
    }

    let mut vertex: Vec<u32> = (0..lv.pos.len() as u32).collect();
    let mut chains: Vec<Vec<u32>> = lv.edges.iter().map(|e| vec![e[0], e[1]]).collect();
    // Grids start at the level where the patch is a face: quads now, n-gon corners after
    // the first refinement. `face_grids` name the face of each grid cell.
    let mut grids: Vec<Vec<Vec<u32>>> = Vec::new();
    let mut face_grids: Vec<Vec<Vec<u32>>> = Vec::new();
    for f in 0..lv.face_count() {
        let r = lv.face_offsets[f]..lv.face_offsets[f + 1];
        let cv = &lv.corner_verts[r.clone()];
        if r.len() == 4 {
            grids.push(vec![vec![cv[0], cv[1]], vec![cv[3], cv[2]]]);
            face_grids.push(vec![vec![f as u32]]);
        } else {
            for _ in 0..r.len() {
                grids.push(Vec::new());
                face_grids.push(Vec::new());
            }
        }
    }

    let mut adj = adj;
    for step in 0..depth {
        let (next, map) = refine_once(&lv, &adj);
        // Follow the coarse features into the new level.
        for v in vertex.iter_mut() {
            *v = map.vert_child(*v as usize);
        }
        for (e, chain) in chains.iter_mut().enumerate() {
            let mut c = Vec::with_capacity(chain.len() * 2 - 1);
            for k in 0..chain.len() - 1 {
                let (a, b) = (chain[k], chain[k + 1]);
                let edge = if step == 0 {
                    e
                } else {
                    map.edge_between(&lv, &adj, a, b)
                };
                c.push(map.vert_child(a as usize));
                c.push(map.edge_child(edge));
            }
            c.push(map.vert_child(*chain.last().unwrap() as usize));
            *chain = c;
        }
        let mut ptex = 0;
        for f in 0..m.face_count() {
            let n = m.face_size(f);
            if n == 4 {
                let (g, fg) = refine_grid(&lv, &adj, &map, &grids[ptex], &face_grids[ptex]);
                grids[ptex] = g;
                face_grids[ptex] = fg;
                ptex += 1;
            } else {
                for c in 0..n {
                    if step == 0 {
                        // Corner c's quad: corner, next edge's point, face point, previous
                        // edge's point; the child face made for that corner.
                        let s = lv.face_offsets[f];
                        let prev = s + (c + n - 1) % n;
                        grids[ptex] = vec![
                            vec![
                                map.vert_child(lv.corner_verts[s + c] as usize),
                                map.edge_child(lv.corner_edges[s + c] as usize),
                            ],
                            vec![
                                map.edge_child(lv.corner_edges[prev] as usize),
                                map.face_child(f),
                            ],
                        ];
                        face_grids[ptex] = vec![vec![(s + c) as u32]];
                    } else {
                        let (g, fg) = refine_grid(&lv, &adj, &map, &grids[ptex], &face_grids[ptex]);
                        grids[ptex] = g;
                        face_grids[ptex] = fg;
                    }
                    ptex += 1;
                }
            }
        }
        lv = next;
        adj = lv.adjacency();
    }
    let positions = if opts.limit {
        limit_positions(&lv, &adj)
    } else {
        lv.pos.clone()
    };
    Refined {
        positions,
        vertex,
        stride,
        chains,
        grids,
    }
}

/// Index layout of a refined level: face points, then edge points, then vertex points;
/// child faces one per parent corner (in corner order); child edges: two halves per
/// parent edge, then one inner edge per parent corner.
struct ChildMap {
    nf: usize,
    ne: usize,
}

impl ChildMap {
    fn face_child(&self, f: usize) -> u32 {
        f as u32
    }
    fn edge_child(&self, e: usize) -> u32 {
        (self.nf + e) as u32
    }
    fn vert_child(&self, v: usize) -> u32 {
        (self.nf + self.ne + v) as u32
    }
    fn edge_between(&self, lv: &Level, adj: &Adjacency, a: u32, b: u32) -> usize {
        let r = adj.vert_edge_off[a as usize]..adj.vert_edge_off[a as usize + 1];
        adj.vert_edges[r]
            .iter()
            .map(|&e| e as usize)
            .find(|&e| other_end(lv.edges[e], a) == b as usize)
            .expect("grid edge exists")
    }
}

fn refine_grid(
    lv: &Level,
    adj: &Adjacency,
    map: &ChildMap,
    g: &[Vec<u32>],
    fg: &[Vec<u32>],
) -> (Vec<Vec<u32>>, Vec<Vec<u32>>) {
    let n = g.len();
    let mut out = vec![vec![0u32; 2 * n - 1]; 2 * n - 1];
    let mut fout = vec![vec![0u32; 2 * n - 2]; 2 * n - 2];
    for y in 0..n {
        for x in 0..n {
            out[2 * y][2 * x] = map.vert_child(g[y][x] as usize);
            if x + 1 < n {
                out[2 * y][2 * x + 1] =
                    map.edge_child(map.edge_between(lv, adj, g[y][x], g[y][x + 1]));
            }
            if y + 1 < n {
                out[2 * y + 1][2 * x] =
                    map.edge_child(map.edge_between(lv, adj, g[y][x], g[y + 1][x]));
            }
            if x + 1 < n && y + 1 < n {
                let f = fg[y][x] as usize;
                out[2 * y + 1][2 * x + 1] = map.face_child(f);
                // The child face at each cell corner is the one made for that corner.
                let r = lv.face_offsets[f]..lv.face_offsets[f + 1];
                for (dy, dx) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                    let v = g[y + dy][x + dx];
                    let c = r
                        .clone()
                        .find(|&c| lv.corner_verts[c] == v)
                        .expect("cell corner in face");
                    fout[2 * y + dy][2 * x + dx] = c as u32;
                }
            }
        }
    }
    (out, fout)
}

// Long because it follows OpenSubdiv's refinement step by step.
fn refine_once(lv: &Level, adj: &Adjacency) -> (Level, ChildMap) {
    let nf = lv.face_count();
    let ne = lv.edges.len();
    let nv = lv.pos.len();
    let map = ChildMap { nf, ne };
    let mut pos = vec![[0.0f64; 3]; nf + ne + nv];
    // Face points: centroids.
    for f in 0..nf {
        let r = lv.face_offsets[f]..lv.face_offsets[f + 1];
        let k = 1.0 / r.len() as f64;
        let mut p = [0.0; 3];
        for c in r {
            let q = lv.pos[lv.corner_verts[c] as usize];
            for i in 0..3 {
                p[i] += q[i] * k;
            }
        }
        pos[f] = p;
    }
    // Edge points.
    for e in 0..ne {
        let [a, b] = lv.edges[e];
        let mid = lerp3(lv.pos[a as usize], lv.pos[b as usize], 0.5);
        let faces = &adj.edge_faces[adj.edge_face_off[e]..adj.edge_face_off[e + 1]];
        let s = lv.edge_sharp[e];
        let p = if faces.len() != 2 || s > 1.0 {
            mid
        } else {
            let (pa, pb) = (lv.pos[a as usize], lv.pos[b as usize]);
            let (f0, f1) = (pos[faces[0] as usize], pos[faces[1] as usize]);
            let smooth = [0, 1, 2].map(|i| 0.25 * (pa[i] + pb[i] + f0[i] + f1[i]));
            if s > 0.0 {
                lerp3(smooth, mid, s as f64)
            } else {
                smooth
            }
        };
        pos[nf + e] = p;
    }
    // Vertex points.
    for v in 0..nv {
        let edges = &adj.vert_edges[adj.vert_edge_off[v]..adj.vert_edge_off[v + 1]];
        let faces = &adj.vert_faces[adj.vert_face_off[v]..adj.vert_face_off[v + 1]];
        let p = lv.pos[v];
        if faces.is_empty() {
            pos[nf + ne + v] = p;
            continue;
        }
        let ps = lv.vert_sharp[v];
        let pe = |i: usize| lv.edge_sharp[edges[i] as usize];
        let prule = rule_of(ps, (0..edges.len()).map(pe));
        let smooth = || {
            let n = edges.len() as f64;
            let mut q = [0.0; 3];
            for &e in edges {
                let o = lv.pos[other_end(lv.edges[e as usize], v as u32)];
                for i in 0..3 {
                    q[i] += o[i];
                }
            }
            for &f in faces {
                for i in 0..3 {
                    q[i] += pos[f as usize][i];
                }
            }
            [0, 1, 2].map(|i| p[i] * (n - 2.0) / n + q[i] / (n * n))
        };
        let crease = |sharp: &dyn Fn(usize) -> f32| {
            let mut q = [0.0; 3];
            for (i, &e) in edges.iter().enumerate() {
                if sharp(i) > 0.0 {
                    let o = lv.pos[other_end(lv.edges[e as usize], v as u32)];
                    for k in 0..3 {
                        q[k] += o[k];
                    }
                }
            }
            [0, 1, 2].map(|k| p[k] * 0.75 + q[k] * 0.125)
        };
        let mask = |rule: Rule, sharp: &dyn Fn(usize) -> f32| match rule {
            Rule::Smooth | Rule::Dart => smooth(),
            Rule::Crease => crease(sharp),
            Rule::Corner => p,
        };
        let parent = mask(prule, &pe);
        if matches!(prule, Rule::Smooth | Rule::Dart) {
            pos[nf + ne + v] = parent;
            continue;
        }
        let cs = decay(ps);
        let ce = |i: usize| decay(pe(i));
        let crule = rule_of(cs, (0..edges.len()).map(ce));
        if crule == prule {
            pos[nf + ne + v] = parent;
            continue;
        }
        let child = mask(crule, &ce);
        // The mean sharpness of what turned smooth, at most 1.
        let (mut count, mut sum) = (0usize, 0.0f32);
        if ps > 0.0 && cs <= 0.0 {
            count += 1;
            sum += ps;
        }
        for i in 0..edges.len() {
            if pe(i) > 0.0 && ce(i) <= 0.0 {
                count += 1;
                sum += pe(i);
            }
        }
        let w = if count == 0 {
            0.0
        } else {
            (sum / count as f32).min(1.0) as f64
        };
        pos[nf + ne + v] = lerp3(child, parent, w);
    }

    // Topology of the child level.
    let mut edges = Vec::with_capacity(2 * ne + lv.corner_verts.len());
    let mut edge_sharp = Vec::with_capacity(edges.capacity());
    for e in 0..ne {
        let [a, b] = lv.edges[e];
        let s = decay(lv.edge_sharp[e]);
        edges.push([map.vert_child(a as usize), map.edge_child(e)]);
        edges.push([map.edge_child(e), map.vert_child(b as usize)]);
        edge_sharp.push(s);
        edge_sharp.push(s);
    }
    for f in 0..nf {
        for c in lv.face_offsets[f]..lv.face_offsets[f + 1] {
            edges.push([
                map.edge_child(lv.corner_edges[c] as usize),
                map.face_child(f),
            ]);
            edge_sharp.push(0.0);
        }
    }
    let half =
        |e: usize, v: u32| -> u32 { (2 * e + if lv.edges[e][0] == v { 0 } else { 1 }) as u32 };
    let mut corner_verts = Vec::with_capacity(4 * lv.corner_verts.len());
    let mut corner_edges = Vec::with_capacity(4 * lv.corner_verts.len());
    for f in 0..nf {
        let r = lv.face_offsets[f]..lv.face_offsets[f + 1];
        let n = r.len();
        for k in 0..n {
            let c = r.start + k;
            let prev = r.start + (k + n - 1) % n;
            let v = lv.corner_verts[c];
            let (e_next, e_prev) = (lv.corner_edges[c] as usize, lv.corner_edges[prev] as usize);
            corner_verts.extend([
                map.vert_child(v as usize),
                map.edge_child(e_next),
                map.face_child(f),
                map.edge_child(e_prev),
            ]);
            corner_edges.extend([
                half(e_next, v),
                (2 * ne + c) as u32,
                (2 * ne + prev) as u32,
                half(e_prev, v),
            ]);
        }
    }
    let mut vert_sharp = vec![0.0f32; nf + ne + nv];
    for v in 0..nv {
        vert_sharp[nf + ne + v] = decay(lv.vert_sharp[v]);
    }
    let face_offsets = (0..=lv.corner_verts.len()).map(|i| 4 * i).collect();
    (
        Level {
            pos,
            face_offsets,
            corner_verts,
            corner_edges,
            edges,
            edge_sharp,
            vert_sharp,
        },
        map,
    )
}

/// Limit positions of a level's vertices (OpenSubdiv's Catmark limit masks).
fn limit_positions(lv: &Level, adj: &Adjacency) -> Vec<[f64; 3]> {
    (0..lv.pos.len())
        .map(|v| {
            let p = lv.pos[v];
            let edges = &adj.vert_edges[adj.vert_edge_off[v]..adj.vert_edge_off[v + 1]];
            let faces = &adj.vert_faces[adj.vert_face_off[v]..adj.vert_face_off[v + 1]];
            // A boundary vertex of a single face is the corner of an end-cap patch, which
            // OpenSubdiv places at the vertex itself (not on the boundary curve's limit).
            if faces.len() <= 1 {
                return p;
            }
            let inf = |s: f32| if s >= INFINITE { s } else { 0.0 };
            let rule = rule_of(
                inf(lv.vert_sharp[v]),
                edges.iter().map(|&e| inf(lv.edge_sharp[e as usize])),
            );
            match rule {
                Rule::Corner => p,
                Rule::Crease => {
                    let mut q = [0.0; 3];
                    for &e in edges {
                        if lv.edge_sharp[e as usize] >= INFINITE {
                            let o = lv.pos[other_end(lv.edges[e as usize], v as u32)];
                            for k in 0..3 {
                                q[k] += o[k];
                            }
                        }
                    }
                    [0, 1, 2].map(|k| (4.0 * p[k] + q[k]) / 6.0)
                }
                Rule::Smooth | Rule::Dart => {
                    let n = faces.len() as f64;
                    let mut q = [0.0; 3];
                    for &e in edges {
                        let o = lv.pos[other_end(lv.edges[e as usize], v as u32)];
                        for k in 0..3 {
                            q[k] += 4.0 * o[k];
                        }
                    }
                    // Every face is a quad here: add the corner opposite the vertex.
                    for &f in faces {
                        let s = lv.face_offsets[f as usize];
                        let i = (0..4)
                            .find(|&i| lv.corner_verts[s + i] as usize == v)
                            .unwrap();
                        let o = lv.pos[lv.corner_verts[s + (i + 2) % 4] as usize];
                        for k in 0..3 {
                            q[k] += o[k];
                        }
                    }
                    [0, 1, 2].map(|k| (n * n * p[k] + q[k]) / (n * (n + 5.0)))
                }
            }
        })
        .collect()
}
