//! Mesh topology fields (`node_geo_input_mesh_*` and `node_geo_mesh_topology_*`): Edge,
//! Face and Vertex Neighbors, Edge Vertices, Edge Angle, Mesh Island, Face is Planar, and
//! the index lookups (Corners of Face / Vertex / Edge, Edges of Vertex / Corner, Face / Vertex of
//! Corner, Offset Corner in Face). Each is computed on its own domain and moved to the
//! one asked for, as Blender's `adapt_domain` does; on other components they are zero.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, FieldContext, FieldInput, IndexInput};
use super::super::mesh::Mesh;
use super::super::types::{Array, DataType, Domain};
use super::super::value::SocketValue;
use crate::nodes::graph::Source;

/// The values of one topology quantity on its own domain.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Topo {
    /// Edge: faces using the edge.
    EdgeFaceCount,
    /// Face: corners of the face.
    FaceVertexCount,
    /// Face: faces sharing an edge, counted once per shared edge.
    FaceFaceCount,
    /// Point: edges using the vertex.
    VertexEdgeCount,
    /// Point: corners using the vertex.
    VertexCornerCount,
    /// Edge: the first / second vertex (index or position).
    EdgeVertex(usize),
    EdgePosition(usize),
    EdgeAngle {
        signed: bool,
    },
    /// Point: island index in order of first vertex, and the island count.
    IslandIndex,
    IslandCount,
}

impl Topo {
    fn domain(self) -> Domain {
        match self {
            Topo::EdgeFaceCount
            | Topo::EdgeVertex(_)
            | Topo::EdgePosition(_)
            | Topo::EdgeAngle { .. } => Domain::Edge,
            Topo::FaceVertexCount | Topo::FaceFaceCount => Domain::Face,
            Topo::VertexEdgeCount
            | Topo::VertexCornerCount
            | Topo::IslandIndex
            | Topo::IslandCount => Domain::Point,
        }
    }
    fn data_type(self) -> DataType {
        match self {
            Topo::EdgePosition(_) => DataType::Vector,
            Topo::EdgeAngle { .. } => DataType::Float,
            _ => DataType::Int,
        }
    }

    fn compute(self, m: &Mesh) -> Array {
        match self {
            Topo::EdgeFaceCount => Array::Int(edge_face_counts(m)),
            Topo::FaceVertexCount => {
                Array::Int((0..m.face_count()).map(|f| m.face_size(f) as i32).collect())
            }
            Topo::FaceFaceCount => {
                let per_edge = edge_face_counts(m);
                Array::Int(
                    (0..m.face_count())
                        .map(|f| {
                            m.face(f)
                                .map(|c| per_edge[m.corner_edges[c] as usize] - 1)
                                .sum()
                        })
                        .collect(),
                )
            }
            Topo::VertexEdgeCount => {
                let mut n = vec![0i32; m.vertex_count()];
                for e in &m.edges {
                    n[e[0] as usize] += 1;
                    n[e[1] as usize] += 1;
                }
                Array::Int(n)
            }
            Topo::VertexCornerCount => {
                let mut n = vec![0i32; m.vertex_count()];
                for &v in &m.corner_verts {
                    n[v as usize] += 1;
                }
                Array::Int(n)
            }
            Topo::EdgeVertex(k) => Array::Int(m.edges.iter().map(|e| e[k] as i32).collect()),
            Topo::EdgePosition(k) => {
                Array::Vector(m.edges.iter().map(|e| m.positions[e[k] as usize]).collect())
            }
            Topo::EdgeAngle { signed } => Array::Float(edge_angles(m, signed)),
            Topo::IslandIndex => Array::Int(islands(m).0),
            Topo::IslandCount => {
                let (_, count) = islands(m);
                Array::Int(vec![count; m.vertex_count()])
            }
        }
    }
}

fn edge_face_counts(m: &Mesh) -> Vec<i32> {
    let mut n = vec![0i32; m.edge_count()];
    for &e in &m.corner_edges {
        n[e as usize] += 1;
    }
    n
}

/// Angles between the two faces of each edge with exactly two (`angle_normalized_v3v3` of
/// the face normals); signed negative where face 2's centre lies in front of face 1
/// (convex), as Blender's Edge Angle; zero elsewhere.
fn edge_angles(m: &Mesh, signed: bool) -> Vec<f32> {
    let mut first = vec![(0u32, 0usize, 0usize); m.edge_count()];
    for f in 0..m.face_count() {
        for c in m.face(f) {
            let e = &mut first[m.corner_edges[c] as usize];
            match e.0 {
                0 => e.1 = f,
                1 => e.2 = f,
                _ => {}
            }
            e.0 += 1;
        }
    }
    let normals = m.face_normals();
    let sub = |a: [f32; 3], b: [f32; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f32; 3], b: [f32; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    first
        .iter()
        .enumerate()
        .map(|(i, &(count, f1, f2))| {
            if count != 2 {
                return 0.0;
            }
            let (n1, n2) = (normals[f1], normals[f2]);
            let angle = super::rotation::angle_normalized(n1, n2);
            if !signed {
                return angle;
            }
            let e = m.edges[i];
            let (a, b) = (m.positions[e[0] as usize], m.positions[e[1] as usize]);
            let mid = [
                (a[0] + b[0]) * 0.5,
                (a[1] + b[1]) * 0.5,
                (a[2] + b[2]) * 0.5,
            ];
            let r = m.face(f2);
            let k = r.len() as f32;
            let mut centre = [0.0f32; 3];
            for c in r {
                let p = m.positions[m.corner_verts[c] as usize];
                for j in 0..3 {
                    centre[j] += p[j];
                }
            }
            let centre = centre.map(|x| x / k);
            let tangent = super::super::math::normalize(sub(centre, mid));
            let concavity = dot(n1, tangent);
            if angle == 0.0 || angle == 2.0 * std::f32::consts::PI || concavity < 0.0 {
                angle
            } else {
                -angle
            }
        })
        .collect()
}

/// Vertex islands joined along edges: each vertex's island numbered in order of its
/// first vertex (`AtomicDisjointSet::calc_reduced_ids`), and the number of islands.
pub fn islands(m: &Mesh) -> (Vec<i32>, i32) {
    let n = m.vertex_count();
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for e in &m.edges {
        let (a, b) = (
            find(&mut parent, e[0] as usize),
            find(&mut parent, e[1] as usize),
        );
        if a != b {
            parent[a.max(b)] = a.min(b);
        }
    }
    let mut id_of_root = vec![-1i32; n];
    let mut next = 0;
    let ids = (0..n)
        .map(|v| {
            let r = find(&mut parent, v);
            if id_of_root[r] < 0 {
                id_of_root[r] = next;
                next += 1;
            }
            id_of_root[r]
        })
        .collect();
    (ids, next)
}

#[derive(Debug)]
struct TopoInput(Topo);

impl FieldInput for TopoInput {
    fn data_type(&self) -> DataType {
        self.0.data_type()
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let ComponentRef::Mesh(m) = ctx.component else {
            return Ok(Array::zeros(
                self.data_type(),
                ctx.component.domain_size(domain),
            ));
        };
        Ok(ctx
            .component
            .adapt(&self.0.compute(m), self.0.domain(), domain))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(self.0.domain())
    }
}

fn topo(t: Topo) -> SocketValue {
    SocketValue::Field(Field::input(TopoInput(t)))
}

pub fn edge_neighbors(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([("Face Count", topo(Topo::EdgeFaceCount))]))
}

pub fn face_neighbors(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([
        ("Vertex Count", topo(Topo::FaceVertexCount)),
        ("Face Count", topo(Topo::FaceFaceCount)),
    ]))
}

pub fn vertex_neighbors(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([
        ("Vertex Count", topo(Topo::VertexEdgeCount)),
        ("Face Count", topo(Topo::VertexCornerCount)),
    ]))
}

pub fn edge_vertices(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([
        ("Vertex Index 1", topo(Topo::EdgeVertex(0))),
        ("Vertex Index 2", topo(Topo::EdgeVertex(1))),
        ("Position 1", topo(Topo::EdgePosition(0))),
        ("Position 2", topo(Topo::EdgePosition(1))),
    ]))
}

pub fn edge_angle(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([
        ("Unsigned Angle", topo(Topo::EdgeAngle { signed: false })),
        ("Signed Angle", topo(Topo::EdgeAngle { signed: true })),
    ]))
}

pub fn mesh_island(_: &NodeCtx) -> Result<Outputs, GeometryError> {
    Ok(outputs([
        ("Island Index", topo(Topo::IslandIndex)),
        ("Island Count", topo(Topo::IslandCount)),
    ]))
}

/// Face is Planar: a face with more than three corners is planar when its vertices'
/// distances along its normal span less than half the threshold (evaluated per face).
#[derive(Debug)]
struct Planar {
    threshold: Field,
}

impl FieldInput for Planar {
    fn data_type(&self) -> DataType {
        DataType::Bool
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let ComponentRef::Mesh(m) = ctx.component else {
            return Ok(Array::zeros(
                DataType::Bool,
                ctx.component.domain_size(domain),
            ));
        };
        let t = ctx.eval(&self.threshold, Domain::Face, DataType::Float)?;
        let t = t.as_float();
        let normals = m.face_normals();
        let planar = (0..m.face_count())
            .map(|f| {
                if m.face_size(f) <= 3 {
                    return true;
                }
                let n = normals[f];
                let (mut lo, mut hi) = (f32::MAX, -f32::MAX);
                for c in m.face(f) {
                    let p = m.positions[m.corner_verts[c] as usize];
                    let d = n[0] * p[0] + n[1] * p[1] + n[2] * p[2];
                    lo = lo.min(d);
                    hi = hi.max(d);
                }
                hi - lo < t[f] / 2.0
            })
            .collect();
        Ok(ctx
            .component
            .adapt(&Array::Bool(planar), Domain::Face, domain))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(Domain::Face)
    }
}

pub fn face_is_planar(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let threshold = ctx.field("Threshold", DataType::Float)?;
    Ok(outputs([(
        "Planar",
        SocketValue::Field(Field::input(Planar { threshold })),
    )]))
}

// --- Index lookups ---------------------------------------------------------------------

/// An index input that is the context's index when unlinked (`implicit_field(index)`).
fn index_input(ctx: &NodeCtx, id: &str) -> Result<Field, GeometryError> {
    let unlinked = ctx.flat().input(id).is_some_and(|i| {
        i.sources
            .iter()
            .all(|s| matches!(s, Source::Default(_) | Source::Nothing))
    });
    if unlinked {
        return Ok(Field::input(IndexInput));
    }
    ctx.field(id, DataType::Int)
}

/// What a lookup reads for an element of its source domain.
#[derive(Debug, Clone, Copy)]
enum Lookup {
    /// The sorted corners of a face / corners or edges of a vertex (with the weights'
    /// domain).
    CornersOfFace,
    CornersOfVertex,
    EdgesOfVertex,
    CornersOfEdge,
    /// Per corner: the edge after / before it, its face, its index in the face, its
    /// vertex.
    NextEdge,
    PreviousEdge,
    FaceOfCorner,
    IndexInFace,
    VertexOfCorner,
    /// Per face / vertex: how many corners or edges the lookup chooses from.
    FaceCornerCount,
    VertexCornerCount,
    VertexEdgeCount,
    EdgeCornerCount,
}

impl Lookup {
    fn source_domain(self) -> Domain {
        match self {
            Lookup::CornersOfFace | Lookup::FaceCornerCount => Domain::Face,
            Lookup::CornersOfVertex
            | Lookup::EdgesOfVertex
            | Lookup::VertexCornerCount
            | Lookup::VertexEdgeCount => Domain::Point,
            Lookup::CornersOfEdge | Lookup::EdgeCornerCount => Domain::Edge,
            _ => Domain::Corner,
        }
    }
    fn weight_domain(self) -> Domain {
        match self {
            Lookup::EdgesOfVertex => Domain::Edge,
            _ => Domain::Corner,
        }
    }
}

/// A lookup: `index` (evaluated on the context domain) picks an element of the source
/// domain (out of range gives 0); grouped lookups pick the `sort`-th of its group (wrapped),
/// ordered by `weights` (a stable sort) when they are a field, else by index.
#[derive(Debug)]
struct IndexLookup {
    kind: Lookup,
    index: Field,
    sort: Field,
    weights: Field,
}

fn groups(kind: Lookup, m: &Mesh) -> Vec<Vec<u32>> {
    match kind {
        Lookup::CornersOfFace => (0..m.face_count())
            .map(|f| m.face(f).map(|c| c as u32).collect())
            .collect(),
        Lookup::CornersOfVertex => m.vert_to_corner(),
        // Each edge's corners in corner order (`build_edge_to_corner_map`).
        Lookup::CornersOfEdge => {
            let mut out = vec![Vec::new(); m.edge_count()];
            for (c, &e) in m.corner_edges.iter().enumerate() {
                out[e as usize].push(c as u32);
            }
            out
        }
        _ => {
            let mut out = vec![Vec::new(); m.vertex_count()];
            for (i, e) in m.edges.iter().enumerate() {
                out[e[0] as usize].push(i as u32);
                out[e[1] as usize].push(i as u32);
            }
            out
        }
    }
}

impl FieldInput for IndexLookup {
    fn data_type(&self) -> DataType {
        DataType::Int
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        let ComponentRef::Mesh(m) = ctx.component else {
            return Ok(Array::zeros(DataType::Int, n));
        };
        let index = ctx.eval(&self.index, domain, DataType::Int)?;
        let index = index.as_int();
        let source_len = m.domain_size(self.kind.source_domain()) as i64;
        let in_range = |i: i32| (i as i64) >= 0 && (i as i64) < source_len;
        let out: Vec<i32> = match self.kind {
            Lookup::CornersOfFace
            | Lookup::CornersOfVertex
            | Lookup::EdgesOfVertex
            | Lookup::CornersOfEdge => {
                let groups = groups(self.kind, m);
                let sort = ctx.eval(&self.sort, domain, DataType::Int)?;
                let sort = sort.as_int();
                let weights = match &self.weights {
                    Field::Constant(_) => None,
                    w => Some(w.evaluate(ctx, self.kind.weight_domain())?),
                };
                let weights = weights.as_ref().map(|w| w.convert(DataType::Float));
                let weights = weights.as_ref().map(|w| w.as_float());
                (0..n)
                    .map(|i| {
                        if !in_range(index[i]) {
                            return 0;
                        }
                        let g = &groups[index[i] as usize];
                        if g.is_empty() {
                            return 0;
                        }
                        let k = sort[i].rem_euclid(g.len() as i32) as usize;
                        match &weights {
                            None => g[k] as i32,
                            Some(w) => {
                                let mut order: Vec<usize> = (0..g.len()).collect();
                                order.sort_by(|&a, &b| {
                                    w[g[a] as usize]
                                        .partial_cmp(&w[g[b] as usize])
                                        .unwrap_or(std::cmp::Ordering::Equal)
                                });
                                g[order[k]] as i32
                            }
                        }
                    })
                    .collect()
            }
            kind => {
                let corner_faces = m.corner_faces();
                let counts = match kind {
                    Lookup::VertexCornerCount => Topo::VertexCornerCount.compute(m),
                    Lookup::VertexEdgeCount => Topo::VertexEdgeCount.compute(m),
                    Lookup::EdgeCornerCount => {
                        let mut counts = vec![0; m.edge_count()];
                        for &e in &m.corner_edges {
                            counts[e as usize] += 1;
                        }
                        Array::Int(counts)
                    }
                    _ => Array::Int(Vec::new()),
                };
                let counts = counts.as_int();
                (0..n)
                    .map(|i| {
                        if !in_range(index[i]) {
                            return 0;
                        }
                        let s = index[i] as usize;
                        match kind {
                            Lookup::NextEdge => m.corner_edges[s] as i32,
                            Lookup::PreviousEdge => {
                                let f = corner_faces[s] as usize;
                                m.corner_edges[m.prev_corner(f, s)] as i32
                            }
                            Lookup::FaceOfCorner => corner_faces[s] as i32,
                            Lookup::IndexInFace => {
                                (s - m.face(corner_faces[s] as usize).start) as i32
                            }
                            Lookup::VertexOfCorner => m.corner_verts[s] as i32,
                            Lookup::FaceCornerCount => m.face_size(s) as i32,
                            _ => counts[s],
                        }
                    })
                    .collect()
            }
        };
        Ok(Array::Int(out))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(self.kind.source_domain())
    }
}

fn lookup(kind: Lookup, index: &Field, sort: &Field, weights: &Field) -> SocketValue {
    SocketValue::Field(Field::input(IndexLookup {
        kind,
        index: index.clone(),
        sort: sort.clone(),
        weights: weights.clone(),
    }))
}

fn sorted_lookup(
    ctx: &NodeCtx,
    index_id: &str,
    kind: Lookup,
    count: Lookup,
    output: &str,
) -> Result<Outputs, GeometryError> {
    let index = index_input(ctx, index_id)?;
    let sort = ctx.field("Sort Index", DataType::Int)?;
    let weights = ctx.field("Weights", DataType::Float)?;
    let none = Field::Constant(super::super::types::Value::Int(0));
    Ok(outputs([
        (output, lookup(kind, &index, &sort, &weights)),
        ("Total", lookup(count, &index, &none, &none)),
    ]))
}

pub fn corners_of_face(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    sorted_lookup(
        ctx,
        "Face Index",
        Lookup::CornersOfFace,
        Lookup::FaceCornerCount,
        "Corner Index",
    )
}

pub fn corners_of_vertex(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    sorted_lookup(
        ctx,
        "Vertex Index",
        Lookup::CornersOfVertex,
        Lookup::VertexCornerCount,
        "Corner Index",
    )
}

/// Corners of Edge (`node_geo_mesh_topology_corners_of_edge`).
pub fn corners_of_edge(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    sorted_lookup(
        ctx,
        "Edge Index",
        Lookup::CornersOfEdge,
        Lookup::EdgeCornerCount,
        "Corner Index",
    )
}

pub fn edges_of_vertex(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    sorted_lookup(
        ctx,
        "Vertex Index",
        Lookup::EdgesOfVertex,
        Lookup::VertexEdgeCount,
        "Edge Index",
    )
}

fn corner_lookups(ctx: &NodeCtx, outs: &[(&str, Lookup)]) -> Result<Outputs, GeometryError> {
    let index = index_input(ctx, "Corner Index")?;
    let none = Field::Constant(super::super::types::Value::Int(0));
    Ok(outs
        .iter()
        .map(|(name, kind)| (name.to_string(), lookup(*kind, &index, &none, &none)))
        .collect())
}

pub fn edges_of_corner(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    corner_lookups(
        ctx,
        &[
            ("Next Edge Index", Lookup::NextEdge),
            ("Previous Edge Index", Lookup::PreviousEdge),
        ],
    )
}

pub fn face_of_corner(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    corner_lookups(
        ctx,
        &[
            ("Face Index", Lookup::FaceOfCorner),
            ("Index in Face", Lookup::IndexInFace),
        ],
    )
}

pub fn vertex_of_corner(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    corner_lookups(ctx, &[("Vertex Index", Lookup::VertexOfCorner)])
}

/// Offset Corner in Face: the corner `offset` steps around the face of `corner` (wrapped);
/// 0 for a corner out of range.
#[derive(Debug)]
struct OffsetCorner {
    corner: Field,
    offset: Field,
}

impl FieldInput for OffsetCorner {
    fn data_type(&self) -> DataType {
        DataType::Int
    }
    fn evaluate(&self, ctx: &FieldContext, domain: Domain) -> Result<Array, String> {
        let n = ctx.component.domain_size(domain);
        let ComponentRef::Mesh(m) = ctx.component else {
            return Ok(Array::zeros(DataType::Int, n));
        };
        let corner = ctx.eval(&self.corner, domain, DataType::Int)?;
        let offset = ctx.eval(&self.offset, domain, DataType::Int)?;
        let (corner, offset) = (corner.as_int(), offset.as_int());
        let corner_faces = m.corner_faces();
        Ok(Array::Int(
            (0..n)
                .map(|i| {
                    let c = corner[i];
                    if c < 0 || c as usize >= m.corner_count() {
                        return 0;
                    }
                    let r = m.face(corner_faces[c as usize] as usize);
                    let len = r.len() as i64;
                    let k = (c as i64 - r.start as i64 + offset[i] as i64).rem_euclid(len);
                    (r.start as i64 + k) as i32
                })
                .collect(),
        ))
    }
    fn preferred_domain(&self, _ctx: &FieldContext) -> Option<Domain> {
        Some(Domain::Corner)
    }
}

pub fn offset_corner_in_face(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let corner = index_input(ctx, "Corner Index")?;
    let offset = ctx.field("Offset", DataType::Int)?;
    Ok(outputs([(
        "Corner Index",
        SocketValue::Field(Field::input(OffsetCorner { corner, offset })),
    )]))
}
