//! The mesh component: Blender's layout (positions, edges, faces as corner ranges, each
//! corner naming a vertex and an edge) plus generic attributes on the four domains.

use super::attribute::{AttrId, Attribute, Attributes};
use super::math::{add, cross, dot, normalize, normalize_v3, scale, sub, V3};
use super::types::{Array, DataType, Domain};
use crate::scene::{self, AttributeData, MeshData};

/// Positions at which Import PLY set the mesh's custom normals (`Mesh::relative_normals_moved`);
/// internal, as Blender's dot-prefixed attributes are.
pub const RELATIVE_NORMALS_REST: &str = ".relative_normals_rest";

#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<V3>,
    pub edges: Vec<[u32; 2]>,
    /// `face_count + 1` entries, starting at 0.
    pub face_offsets: Vec<u32>,
    pub corner_verts: Vec<u32>,
    pub corner_edges: Vec<u32>,
    pub attributes: Attributes,
    /// Material slots of the mesh data (`material_index` indexes these).
    pub materials: Vec<Option<String>>,
    /// Vertex normals a primitive assigned directly (Blender's UV sphere does); dropped
    /// whenever positions change.
    pub custom_vert_normals: Option<Vec<V3>>,
}

impl Mesh {
    pub fn new() -> Mesh {
        Mesh {
            face_offsets: vec![0],
            ..Default::default()
        }
    }
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }
    pub fn face_count(&self) -> usize {
        self.face_offsets.len().saturating_sub(1)
    }
    pub fn corner_count(&self) -> usize {
        self.corner_verts.len()
    }
    pub fn domain_size(&self, d: Domain) -> usize {
        match d {
            Domain::Point => self.vertex_count(),
            Domain::Edge => self.edge_count(),
            Domain::Face => self.face_count(),
            Domain::Corner => self.corner_count(),
            _ => 0,
        }
    }
    pub fn face(&self, f: usize) -> std::ops::Range<usize> {
        self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize
    }
    pub fn face_size(&self, f: usize) -> usize {
        (self.face_offsets[f + 1] - self.face_offsets[f]) as usize
    }
    /// The corner after `c` in its face `f`.
    pub fn next_corner(&self, f: usize, c: usize) -> usize {
        let r = self.face(f);
        if c + 1 == r.end {
            r.start
        } else {
            c + 1
        }
    }
    pub fn prev_corner(&self, f: usize, c: usize) -> usize {
        let r = self.face(f);
        if c == r.start {
            r.end - 1
        } else {
            c - 1
        }
    }
    /// The face of every corner.
    pub fn corner_faces(&self) -> Vec<u32> {
        let mut out = vec![0u32; self.corner_count()];
        for f in 0..self.face_count() {
            for c in self.face(f) {
                out[c] = f as u32;
            }
        }
        out
    }

    /// Checks sizes and indices (a node producing a broken mesh is a bug).
    pub fn validate(&self) -> Result<(), String> {
        let nv = self.vertex_count() as u32;
        if self.face_offsets.first() != Some(&0)
            || *self.face_offsets.last().unwrap() as usize != self.corner_count()
        {
            return Err("face offsets do not span the corners".into());
        }
        if self.corner_edges.len() != self.corner_count() {
            return Err("corner_edges has the wrong size".into());
        }
        if self.edges.iter().any(|e| e[0] >= nv || e[1] >= nv)
            || self.corner_verts.iter().any(|&v| v >= nv)
        {
            return Err("vertex index out of range".into());
        }
        let ne = self.edge_count() as u32;
        if self.corner_edges.iter().any(|&e| e >= ne) {
            return Err("edge index out of range".into());
        }
        for a in self.attributes.iter() {
            if a.data.len() != self.domain_size(a.domain) {
                return Err(format!(
                    "attribute {} has {} values for {} {}",
                    a.id.label(),
                    a.data.len(),
                    self.domain_size(a.domain),
                    a.domain.name()
                ));
            }
        }
        Ok(())
    }

    /// Reads a mesh as the exporter wrote it.
    pub fn from_scene(m: &MeshData, materials: &[Option<String>]) -> Mesh {
        let mut out = Mesh {
            positions: m.positions.clone(),
            edges: m.edges.clone(),
            face_offsets: if m.face_offsets.is_empty() {
                vec![0]
            } else {
                m.face_offsets.clone()
            },
            corner_verts: m.corner_verts.clone(),
            corner_edges: m.corner_edges.clone(),
            attributes: Attributes::default(),
            materials: materials.to_vec(),
            custom_vert_normals: None,
        };
        if out.corner_edges.len() != out.corner_verts.len() {
            out.corner_edges = vec![0; out.corner_verts.len()];
        }
        for a in &m.attributes {
            let domain = match a.domain {
                scene::Domain::Point => Domain::Point,
                scene::Domain::Edge => Domain::Edge,
                scene::Domain::Face => Domain::Face,
                scene::Domain::Corner => Domain::Corner,
            };
            let dt = DataType::parse(&a.data_type).unwrap_or(DataType::Float);
            let data = match (&a.data, dt) {
                (AttributeData::Float(v), _) => Array::Float(v.clone()),
                (AttributeData::Float2(v), _) => Array::Float2(v.clone()),
                (AttributeData::Float3(v), _) => Array::Vector(v.clone()),
                (AttributeData::Color(v), DataType::ByteColor) => Array::ByteColor(v.clone()),
                (AttributeData::Color(v), _) => Array::Color(v.clone()),
                (AttributeData::Quaternion(v), _) => Array::Quaternion(v.clone()),
                (AttributeData::Float4x4(v), _) => Array::Matrix(
                    v.iter()
                        .map(|c| {
                            let mut m = [[0.0f32; 4]; 4];
                            for (k, x) in c.iter().enumerate() {
                                m[k / 4][k % 4] = *x;
                            }
                            m
                        })
                        .collect(),
                ),
                (AttributeData::Int(v), _) => Array::Int(v.clone()),
                (AttributeData::Int2(v), _) => Array::Int2(v.clone()),
                (AttributeData::Int8(v), _) => Array::Int8(v.clone()),
                (AttributeData::Bool(v), _) => Array::Bool(v.clone()),
            };
            out.attributes
                .set(AttrId::Named(a.name.clone()), domain, data);
        }
        out
    }

    /// Converts to the exchange format's mesh (named attributes only; loop triangles as
    /// Blender makes them for triangles and quads, fans for n-gons; corner normals).
    pub fn to_scene(&self, name: &str) -> MeshData {
        let mut m = MeshData {
            name: name.to_string(),
            positions: self.positions.clone(),
            edges: self.edges.clone(),
            face_offsets: self.face_offsets.clone(),
            corner_verts: self.corner_verts.clone(),
            corner_edges: self.corner_edges.clone(),
            ..Default::default()
        };
        for f in 0..self.face_count() {
            let r = self.face(f);
            for k in 1..r.len().saturating_sub(1) {
                m.triangles.push([
                    r.start as u32,
                    (r.start + k) as u32,
                    (r.start + k + 1) as u32,
                ]);
                m.triangle_faces.push(f as u32);
            }
        }
        if self.face_count() > 0 {
            m.corner_normals = self.shading_corner_normals();
        }
        for a in self.attributes.iter() {
            let Some(name) = a.id.name() else { continue };
            let domain = match a.domain {
                Domain::Point => scene::Domain::Point,
                Domain::Edge => scene::Domain::Edge,
                Domain::Face => scene::Domain::Face,
                Domain::Corner => scene::Domain::Corner,
                _ => continue,
            };
            let data = scene_data(&a.data);
            m.attributes.push(scene::Attribute {
                name: name.to_string(),
                domain,
                data_type: a.data_type().name().to_string(),
                data,
            });
        }
        m
    }

    /// Face normals as Blender computes them (`face_normal_calc`): triangles and quads by
    /// a cross product of edge / diagonal vectors, n-gons by Newell's method.
    pub fn face_normals(&self) -> Vec<V3> {
        (0..self.face_count())
            .map(|f| self.face_normal(f))
            .collect()
    }

    pub fn face_normal(&self, f: usize) -> V3 {
        let r = self.face(f);
        let p = |c: usize| self.positions[self.corner_verts[c] as usize];
        let n = match r.len() {
            3 => cross(
                sub(p(r.start), p(r.start + 1)),
                sub(p(r.start + 1), p(r.start + 2)),
            ),
            4 => cross(
                sub(p(r.start), p(r.start + 2)),
                sub(p(r.start + 1), p(r.start + 3)),
            ),
            _ => {
                let mut n = [0.0f32; 3];
                let mut prev = p(r.end - 1);
                for c in r.clone() {
                    let cur = p(c);
                    n[0] += (prev[1] - cur[1]) * (prev[2] + cur[2]);
                    n[1] += (prev[2] - cur[2]) * (prev[0] + cur[0]);
                    n[2] += (prev[0] - cur[0]) * (prev[1] + cur[1]);
                    prev = cur;
                }
                n
            }
        };
        let (n, len) = normalize_v3(n);
        if len == 0.0 {
            [0.0, 0.0, 1.0]
        } else {
            n
        }
    }

    /// Vertex normals: face normals weighted by the corner angle, normalized; a vertex
    /// with none takes its normalized position (Blender's fallback).
    pub fn vertex_normals(&self) -> Vec<V3> {
        if let Some(n) = &self.custom_vert_normals {
            if n.len() == self.vertex_count() {
                return n.clone();
            }
        }
        self.vertex_normals_from(&self.face_normals())
    }

    /// `normals_calc_verts` from the given face normals.
    pub fn vertex_normals_from(&self, fnorm: &[V3]) -> Vec<V3> {
        let mut acc = vec![[0.0f32; 3]; self.vertex_count()];
        let mut used = vec![false; self.vertex_count()];
        // Blender sums per vertex over its faces in face order (vert_to_face_map), each
        // face weighted by its corner angle (`safe_acos_approx`).
        for f in 0..self.face_count() {
            let r = self.face(f);
            for c in r.clone() {
                let v = self.corner_verts[c] as usize;
                let prev = self.corner_verts[self.prev_corner(f, c)] as usize;
                let next = self.corner_verts[self.next_corner(f, c)] as usize;
                let d1 = normalize(sub(self.positions[prev], self.positions[v]));
                let d2 = normalize(sub(self.positions[next], self.positions[v]));
                let angle = safe_acos_approx(dot(d1, d2));
                acc[v] = add(acc[v], scale(fnorm[f], angle));
                used[v] = true;
            }
        }
        acc.iter()
            .enumerate()
            .map(|(v, n)| {
                if used[v] {
                    normalize(*n)
                } else {
                    normalize(self.positions[v])
                }
            })
            .collect()
    }

    /// Faces marked flat (`sharp_face`); absent means all smooth.
    pub fn sharp_faces(&self) -> Vec<bool> {
        match self.attributes.named("sharp_face") {
            Some(a) if a.domain == Domain::Face => a.data.as_bool().into_owned(),
            _ => vec![false; self.face_count()],
        }
    }

    /// Free custom normals: Blender 4.5's `custom_normal` attribute as a float vector on
    /// points, faces or corners (Set Mesh Normal's Free mode). Blender uses the stored
    /// vectors as they are, unnormalized, as the normals of that domain.
    pub fn free_custom_normals(&self) -> Option<(Domain, &[V3])> {
        match self.attributes.named("custom_normal") {
            Some(Attribute {
                domain: d @ (Domain::Point | Domain::Face | Domain::Corner),
                data: Array::Vector(v),
                ..
            }) => Some((*d, v.as_slice())),
            _ => None,
        }
    }

    /// Why the custom normals are not Blender's: Import PLY's come with the positions they
    /// were set at (`RELATIVE_NORMALS_REST`), because Blender stores them relative to each
    /// corner's fan and they follow any later deformation, which blendsynth does not
    /// evaluate. None while every vertex with a custom normal is where it was.
    pub fn relative_normals_moved(&self) -> Option<String> {
        let rest = self.attributes.named(RELATIVE_NORMALS_REST)?;
        let (Domain::Point, Some((Domain::Point, n)), Array::Vector(rest)) =
            (rest.domain, self.free_custom_normals(), &rest.data)
        else {
            return None;
        };
        let moved = rest.len() != self.vertex_count()
            || (0..n.len()).any(|v| n[v] != [0.0; 3] && rest[v] != self.positions[v]);
        moved.then(|| {
            "its custom normals come from Import PLY (the file's vertex normals, which Blender \
             stores relative to each corner's fan) and the mesh was deformed after the import: \
             Blender's normals follow the deformation, which blendsynth does not evaluate"
                .to_string()
        })
    }

    /// The Normal input on `domain` where free custom normals replace Blender's
    /// (`Mesh::vert_normals`, `face_normals`, `corner_normals`): None without them. Points
    /// from face or corner custom normals and edges from face or corner ones (Blender's
    /// angle-weighted mixes) are errors.
    pub fn custom_normals_on(&self, domain: Domain) -> Option<Result<Vec<V3>, String>> {
        let (d, n) = self.free_custom_normals()?;
        if let Some(why) = self.relative_normals_moved() {
            return Some(Err(why));
        }
        let sum_norm = |it: &mut dyn Iterator<Item = V3>| normalize(it.fold([0.0f32; 3], add));
        Some(match (domain, d) {
            (Domain::Corner, _) => Ok(self.corner_normals()),
            (x, y) if x == y => Ok(n.to_vec()),
            // `mix_normals_vert_to_face` / `mix_normals_corner_to_face`: normalized sums.
            (Domain::Face, Domain::Point) => Ok((0..self.face_count())
                .map(|f| {
                    sum_norm(&mut self.face(f).map(|c| n[self.corner_verts[c] as usize]))
                })
                .collect()),
            (Domain::Face, Domain::Corner) => Ok((0..self.face_count())
                .map(|f| sum_norm(&mut self.face(f).map(|c| n[c])))
                .collect()),
            (Domain::Edge, Domain::Point) => Ok(self
                .edges
                .iter()
                .map(|e| {
                    let (a, b) = (n[e[0] as usize], n[e[1] as usize]);
                    normalize([
                        a[0] * 0.5 + b[0] * 0.5,
                        a[1] * 0.5 + b[1] * 0.5,
                        a[2] * 0.5 + b[2] * 0.5,
                    ])
                })
                .collect()),
            (x, _) if !matches!(x, Domain::Point | Domain::Edge) => {
                Ok(vec![[0.0; 3]; self.domain_size(x)])
            }
            (x, y) => Err(format!(
                "the Normal input on the {} domain of a mesh with free custom normals on the {} domain is not supported",
                x.name(),
                y.name()
            )),
        })
    }

    /// The corner normals Cycles shades the mesh with (`blender/mesh.cpp` `create_mesh`):
    /// Blender's corner normals, except with free custom normals on points or faces, which
    /// Cycles reads as vertex normals on smooth faces: point ones as they are; face ones
    /// mixed to the vertices (`Mesh::vert_normals`: angle-weighted, normalized), and only
    /// where the mesh has a `sharp_face` attribute (without one every face is flat). Flat
    /// faces take the true face normal.
    pub fn shading_corner_normals(&self) -> Vec<V3> {
        let Some((d, n)) = self
            .free_custom_normals()
            .filter(|(d, _)| *d != Domain::Corner)
        else {
            return self.corner_normals();
        };
        let sharp = match self.attributes.named("sharp_face") {
            Some(a) if a.domain == Domain::Face => Some(a.data.as_bool().into_owned()),
            _ => None,
        };
        let vn: Vec<V3> = if d == Domain::Point {
            n.to_vec()
        } else {
            self.vertex_normals_from(n)
        };
        let smooth = |f: usize| match (&sharp, d) {
            (Some(s), _) => !s[f],
            (None, Domain::Point) => true,
            (None, _) => false,
        };
        let mut out = Vec::with_capacity(self.corner_count());
        for f in 0..self.face_count() {
            let flat = (!smooth(f)).then(|| self.face_normal(f));
            for c in self.face(f) {
                out.push(flat.unwrap_or(vn[self.corner_verts[c] as usize]));
            }
        }
        out
    }

    /// Corner normals as Blender 4.1+ defines them: free custom normals where the mesh has
    /// them, else face normals on flat faces, vertex normals where nothing is sharp, and
    /// fans split at sharp edges otherwise.
    pub fn corner_normals(&self) -> Vec<V3> {
        if let Some((d, n)) = self.free_custom_normals() {
            return match d {
                Domain::Point => self.corner_verts.iter().map(|&v| n[v as usize]).collect(),
                Domain::Face => self.corner_faces().iter().map(|&f| n[f as usize]).collect(),
                _ => n.to_vec(),
            };
        }
        let sharp_face = self.sharp_faces();
        let sharp_edge = match self.attributes.named("sharp_edge") {
            Some(a) if a.domain == Domain::Edge => a.data.as_bool().into_owned(),
            _ => vec![false; self.edge_count()],
        };
        let fnorm = self.face_normals();
        let corner_face = self.corner_faces();
        if sharp_face.iter().all(|&s| s) {
            return corner_face.iter().map(|&f| fnorm[f as usize]).collect();
        }
        if !sharp_face.iter().any(|&s| s) && !sharp_edge.iter().any(|&s| s) {
            let vn = self.vertex_normals();
            return self.corner_verts.iter().map(|&v| vn[v as usize]).collect();
        }
        // Fans: an edge splits if it is sharp, borders a flat face, or is not manifold.
        let mut edge_faces = vec![0u32; self.edge_count()];
        for &e in &self.corner_edges {
            edge_faces[e as usize] += 1;
        }
        let mut edge_sharp = sharp_edge.clone();
        for (c, &e) in self.corner_edges.iter().enumerate() {
            if sharp_face[corner_face[c] as usize] || edge_faces[e as usize] != 2 {
                edge_sharp[e as usize] = true;
            }
        }
        // Union corners around a vertex that share a smooth edge.
        let mut parent: Vec<usize> = (0..self.corner_count()).collect();
        fn find(p: &mut [usize], x: usize) -> usize {
            let mut r = x;
            while p[r] != r {
                r = p[r];
            }
            let mut y = x;
            while p[y] != r {
                let n = p[y];
                p[y] = r;
                y = n;
            }
            r
        }
        // For each edge, the first two corners using it (both directions), in corner
        // order: only edges with exactly two join fans. Two flat arrays rather than a list
        // per edge (a million small allocations on the colon).
        let mut first = vec![usize::MAX; self.edge_count()];
        let mut second = vec![usize::MAX; self.edge_count()];
        for (c, &e) in self.corner_edges.iter().enumerate() {
            let e = e as usize;
            if first[e] == usize::MAX {
                first[e] = c;
            } else if second[e] == usize::MAX {
                second[e] = c;
            }
        }
        for e in 0..self.edge_count() {
            if edge_sharp[e] || edge_faces[e] != 2 {
                continue;
            }
            let (a, b) = (first[e], second[e]);
            // corner a is edge (v_a -> next); corner b is the other face's corner of it.
            let fa = corner_face[a] as usize;
            let fb = corner_face[b] as usize;
            let a_next = self.next_corner(fa, a);
            let b_next = self.next_corner(fb, b);
            // Join the corners sharing each of the edge's two vertices.
            for (x, y) in [(a, b_next), (a_next, b)] {
                if self.corner_verts[x] == self.corner_verts[y] {
                    let (rx, ry) = (find(&mut parent, x), find(&mut parent, y));
                    parent[rx] = ry;
                }
            }
        }
        let mut acc = vec![[0.0f32; 3]; self.corner_count()];
        for c in 0..self.corner_count() {
            let f = corner_face[c] as usize;
            let v = self.corner_verts[c] as usize;
            let prev = self.corner_verts[self.prev_corner(f, c)] as usize;
            let next = self.corner_verts[self.next_corner(f, c)] as usize;
            let d1 = normalize(sub(self.positions[prev], self.positions[v]));
            let d2 = normalize(sub(self.positions[next], self.positions[v]));
            let angle = safe_acos_approx(dot(d1, d2));
            let r = find(&mut parent, c);
            acc[r] = add(acc[r], scale(fnorm[f], angle));
        }
        (0..self.corner_count())
            .map(|c| {
                let r = find(&mut parent, c);
                let u = normalize(acc[r]);
                if u == [0.0; 3] {
                    fnorm[corner_face[c] as usize]
                } else {
                    u
                }
            })
            .collect()
    }

    /// Builds edges from the faces and fills `corner_edges`, as `bke::mesh_calc_edges`
    /// does: unique edges (low, high) in insertion order, each face adding its edges from
    /// (last, first) on. Meshes of 1000+ faces are hashed into several tables by the low
    /// vertex index, one per thread (a power of two up to 8), and the tables concatenated,
    /// so the order then depends on the machine's thread count, as it does in Blender.
    pub fn calc_edges(&mut self, keep_existing: bool) {
        use std::collections::HashMap;
        let maps = if self.face_count() < 1000 {
            1
        } else {
            let threads = std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1)
                .min(8);
            1usize << (usize::BITS - 1 - threads.leading_zeros())
        };
        let mask = (maps - 1) as u32;
        let mut tables: Vec<Vec<[u32; 2]>> = vec![Vec::new(); maps];
        let mut index: HashMap<(u32, u32), (usize, usize)> = HashMap::new();
        let mut add = |a: u32, b: u32, tables: &mut Vec<Vec<[u32; 2]>>| {
            let key = (a.min(b), a.max(b));
            if let std::collections::hash_map::Entry::Vacant(slot) = index.entry(key) {
                let t = (key.0 & mask) as usize;
                tables[t].push([key.0, key.1]);
                slot.insert((t, tables[t].len() - 1));
            }
        };
        if keep_existing {
            for e in self.edges.clone() {
                add(e[0], e[1], &mut tables);
            }
        }
        for f in 0..self.face_count() {
            for c in self.face(f) {
                let v = self.corner_verts[c];
                let prev = self.corner_verts[self.prev_corner(f, c)];
                if v != prev {
                    add(prev, v, &mut tables);
                }
            }
        }
        let mut offsets = vec![0usize; maps + 1];
        for t in 0..maps {
            offsets[t + 1] = offsets[t] + tables[t].len();
        }
        let mut corner_edges = vec![0u32; self.corner_count()];
        for f in 0..self.face_count() {
            for c in self.face(f) {
                let v = self.corner_verts[c];
                let next = self.corner_verts[self.next_corner(f, c)];
                if v == next {
                    continue;
                }
                let (t, i) = index[&(v.min(next), v.max(next))];
                corner_edges[c] = (offsets[t] + i) as u32;
            }
        }
        self.edges = tables.concat();
        self.corner_edges = corner_edges;
    }

    /// The corners of each vertex, in corner order.
    pub fn vert_to_corner(&self) -> Vec<Vec<u32>> {
        let mut out = vec![Vec::new(); self.vertex_count()];
        for (c, &v) in self.corner_verts.iter().enumerate() {
            out[v as usize].push(c as u32);
        }
        out
    }

    /// Marks all faces flat or smooth, as `bke::mesh_smooth_set` does (smooth removes the
    /// `sharp_face` and `sharp_edge` attributes; flat writes `sharp_face` = true).
    pub fn set_smooth(&mut self, smooth: bool) {
        self.attributes.remove(&AttrId::named("sharp_face"));
        if smooth {
            self.attributes.remove(&AttrId::named("sharp_edge"));
        } else {
            let n = self.face_count();
            self.attributes.set(
                AttrId::named("sharp_face"),
                Domain::Face,
                Array::Bool(vec![true; n]),
            );
        }
    }

    /// An attribute's values (None if absent), `position` included.
    pub fn attribute(&self, id: &AttrId) -> Option<(Domain, Array)> {
        if id.name() == Some("position") {
            return Some((Domain::Point, Array::Vector(self.positions.clone())));
        }
        self.attributes
            .get(id)
            .map(|a: &Attribute| (a.domain, a.data.clone()))
    }
}

/// `math::safe_acos_approx` (Cycles' `fast_acosf`): Blender weights face normals by this
/// approximation of the corner angle (max error 4.5e-5).
#[allow(clippy::approx_constant)] // Blender's literal coefficient, not pi / 2
pub fn safe_acos_approx(x: f32) -> f32 {
    let f = x.abs();
    let m = if f < 1.0 { 1.0 - (1.0 - f) } else { 1.0 };
    let a = (1.0 - m).sqrt()
        * (1.570_796_3 + m * (-0.213_300_99 + m * (0.077_980_48 + m * -0.021_640_95)));
    if x < 0.0 {
        std::f32::consts::PI - a
    } else {
        a
    }
}

/// `saturate_acos`: acos clamped to [-1, 1].
pub fn saturate_acos(f: f32) -> f32 {
    if f <= -1.0 {
        std::f32::consts::PI
    } else if f >= 1.0 {
        0.0
    } else {
        f.acos()
    }
}

/// An attribute's values as the exchange format's `AttributeData` (what `to_scene` and the
/// renderer's point clouds carry).
pub fn scene_data(a: &Array) -> AttributeData {
    match a {
        Array::Float(v) => AttributeData::Float(v.clone()),
        Array::Int(v) => AttributeData::Int(v.clone()),
        Array::Bool(v) => AttributeData::Bool(v.clone()),
        Array::Float2(v) => AttributeData::Float2(v.clone()),
        Array::Vector(v) => AttributeData::Float3(v.clone()),
        Array::Color(v) | Array::ByteColor(v) => AttributeData::Color(v.clone()),
        Array::Quaternion(v) => AttributeData::Quaternion(v.clone()),
        Array::Matrix(v) => AttributeData::Float4x4(v.iter().map(super::math::flatten).collect()),
        Array::Int8(v) => AttributeData::Int8(v.clone()),
        Array::Int2(v) => AttributeData::Int2(v.clone()),
    }
}
