//! Geometry Proximity: distance to and position of the nearest target element: POINTS
//! (mesh vertices and point cloud points), EDGES (mesh edges as segments) or FACES (mesh
//! faces as Blender's corner triangles). Edges and faces are searched exhaustively.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::math::V3;
use super::super::realize::realize_instances;
use super::super::types::{Array, DataType};
use super::super::value::SocketValue;

/// Target points sorted by x, so a query scans outwards from its own x and stops once
/// the x gap alone exceeds the best distance found.
struct SortedPoints {
    p: Vec<V3>,
}

impl SortedPoints {
    fn new(mut p: Vec<V3>) -> Self {
        p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])).then(a[2].total_cmp(&b[2])));
        SortedPoints { p }
    }
    fn nearest(&self, q: V3) -> Option<(V3, f32)> {
        if self.p.is_empty() {
            return None;
        }
        let d2 = |a: &V3| (a[0] - q[0]) * (a[0] - q[0]) + (a[1] - q[1]) * (a[1] - q[1]) + (a[2] - q[2]) * (a[2] - q[2]);
        let start = self.p.partition_point(|a| a[0] < q[0]);
        let mut best = f32::INFINITY;
        let mut best_p = self.p[0];
        let mut i = start;
        while i < self.p.len() {
            let dx = self.p[i][0] - q[0];
            if dx * dx > best {
                break;
            }
            let d = d2(&self.p[i]);
            if d < best {
                best = d;
                best_p = self.p[i];
            }
            i += 1;
        }
        let mut i = start;
        while i > 0 {
            i -= 1;
            let dx = q[0] - self.p[i][0];
            if dx * dx > best {
                break;
            }
            let d = d2(&self.p[i]);
            if d < best {
                best = d;
                best_p = self.p[i];
            }
        }
        Some((best_p, best.sqrt()))
    }
}

pub fn geometry_proximity(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let target = realize_instances(&ctx.geometry("Target")?);
    let element = ctx.prop_str("target_element")?;
    for id in ["Group ID", "Sample Group ID"] {
        if ctx.has_input(id) && ctx.field(id, DataType::Int)?.as_constant().map_or(true, |v| v.as_int() != 0) {
            return Err(ctx.err(format!("{id} is not supported yet")));
        }
    }
    let target = match element {
        "POINTS" => {
            let mut pts = Vec::new();
            if let Some(m) = &target.mesh {
                pts.extend_from_slice(&m.positions);
            }
            if let Some(p) = &target.points {
                pts.extend_from_slice(&p.positions);
            }
            Target::Points(SortedPoints::new(pts))
        }
        "EDGES" => {
            let segs = target.mesh.as_ref().map_or(Vec::new(), |m| m.edges.iter().map(|e| [m.positions[e[0] as usize], m.positions[e[1] as usize]]).collect());
            Target::Edges(segs)
        }
        "FACES" => {
            let tris = match &target.mesh {
                Some(m) => {
                    let (tris, _) = super::distribute::corner_tris(m).map_err(|e| ctx.err(e))?;
                    tris.iter().map(|t| t.map(|c| m.positions[m.corner_verts[c as usize] as usize])).collect()
                }
                None => Vec::new(),
            };
            Target::Faces(tris)
        }
        other => return Err(ctx.err(format!("target element {other} is not supported"))),
    };
    let tree = std::sync::Arc::new(target);
    let src = ctx.field("Source Position", DataType::Vector)?;
    let fields = Field::op("Geometry Proximity", vec![src], vec![DataType::Vector, DataType::Float, DataType::Bool], move |n, a| {
        let q = a[0].as_vector();
        let mut pos = vec![[0.0f32; 3]; n];
        let mut dist = vec![0.0f32; n];
        let mut valid = vec![false; n];
        for i in 0..n {
            if let Some((p, d)) = tree.nearest(q[i]) {
                pos[i] = p;
                dist[i] = d;
                valid[i] = true;
            }
        }
        Ok(vec![Array::Vector(pos), Array::Float(dist), Array::Bool(valid)])
    })
    .map_err(|e| ctx.err(e))?;
    let mut it = fields.into_iter();
    let (p, d, v) = (it.next().unwrap(), it.next().unwrap(), it.next().unwrap());
    Ok(outputs([("Position", SocketValue::Field(p)), ("Distance", SocketValue::Field(d)), ("Is Valid", SocketValue::Field(v))]))
}

enum Target {
    Points(SortedPoints),
    Edges(Vec<[V3; 2]>),
    Faces(Vec<[V3; 3]>),
}

impl Target {
    fn nearest(&self, q: V3) -> Option<(V3, f32)> {
        let best = |it: &mut dyn Iterator<Item = V3>| -> Option<(V3, f32)> {
            let mut out: Option<(V3, f32)> = None;
            for p in it {
                let d = dist2(p, q);
                if out.map_or(true, |(_, b)| d < b) {
                    out = Some((p, d));
                }
            }
            out.map(|(p, d)| (p, d.sqrt()))
        };
        match self {
            Target::Points(p) => p.nearest(q),
            Target::Edges(s) => best(&mut s.iter().map(|[a, b]| closest_on_segment(q, *a, *b))),
            Target::Faces(t) => best(&mut t.iter().map(|[a, b, c]| closest_on_triangle(q, *a, *b, *c))),
        }
    }
}

fn dist2(a: V3, b: V3) -> f32 {
    (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2])
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: V3, b: V3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn madd(a: V3, d: V3, t: f32) -> V3 {
    [a[0] + d[0] * t, a[1] + d[1] * t, a[2] + d[2] * t]
}

/// `closest_to_line_segment_v3`.
fn closest_on_segment(p: V3, a: V3, b: V3) -> V3 {
    let d = sub(b, a);
    let len2 = dot(d, d);
    if len2 == 0.0 {
        return a;
    }
    let t = dot(sub(p, a), d) / len2;
    if t <= 0.0 {
        a
    } else if t >= 1.0 {
        b
    } else {
        madd(a, d, t)
    }
}

/// `closest_on_tri_to_point_v3` (the Voronoi-region walk of Ericson's book).
fn closest_on_triangle(p: V3, a: V3, b: V3, c: V3) -> V3 {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
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
        return madd(a, ab, d1 / (d1 - d3));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return madd(a, ac, d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return madd(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    madd(madd(a, ab, v), ac, w)
}
