//! Geometry Proximity: distance to and position of the nearest target element: POINTS
//! (mesh vertices and point cloud points), EDGES (mesh edges as segments) or FACES (mesh
//! faces as Blender's corner triangles), searched with a bounding-box tree (`nearest`), the
//! lowest index winning exact ties.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::math::V3;
use super::super::nearest::{
    bounds_of, closest_on_segment, closest_on_triangle, dist_sq, nearest_tree,
};
use super::super::realize::realize_instances;
use super::super::types::{Array, DataType};
use super::super::value::SocketValue;
use crate::foundation::box_tree::BoxTree;

/// Target points sorted by x, so a query scans outwards from its own x and stops once
/// the x gap alone exceeds the best distance found.
struct SortedPoints {
    p: Vec<V3>,
}

impl SortedPoints {
    fn new(mut p: Vec<V3>) -> Self {
        p.sort_by(|a, b| {
            a[0].total_cmp(&b[0])
                .then(a[1].total_cmp(&b[1]))
                .then(a[2].total_cmp(&b[2]))
        });
        SortedPoints { p }
    }
    fn nearest(&self, q: V3) -> Option<(V3, f32)> {
        if self.p.is_empty() {
            return None;
        }
        let d2 = |a: &V3| {
            (a[0] - q[0]) * (a[0] - q[0])
                + (a[1] - q[1]) * (a[1] - q[1])
                + (a[2] - q[2]) * (a[2] - q[2])
        };
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
        if ctx.has_input(id)
            && ctx
                .field(id, DataType::Int)?
                .as_constant()
                .is_none_or(|v| v.as_int() != 0)
        {
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
            let segs = target.mesh.as_ref().map_or(Vec::new(), |m| {
                m.edges
                    .iter()
                    .map(|e| [m.positions[e[0] as usize], m.positions[e[1] as usize]])
                    .collect()
            });
            Target::edges(segs)
        }
        "FACES" => {
            let tris = match &target.mesh {
                Some(m) => {
                    let (tris, _) = super::distribute::corner_tris(m).map_err(|e| ctx.err(e))?;
                    tris.iter()
                        .map(|t| t.map(|c| m.positions[m.corner_verts[c as usize] as usize]))
                        .collect()
                }
                None => Vec::new(),
            };
            Target::faces(tris)
        }
        other => return Err(ctx.err(format!("target element {other} is not supported"))),
    };
    let tree = std::sync::Arc::new(target);
    let src = ctx.field("Source Position", DataType::Vector)?;
    let fields = Field::op(
        "Geometry Proximity",
        vec![src],
        vec![DataType::Vector, DataType::Float, DataType::Bool],
        move |n, a| {
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
            Ok(vec![
                Array::Vector(pos),
                Array::Float(dist),
                Array::Bool(valid),
            ])
        },
    )
    .map_err(|e| ctx.err(e))?;
    let mut it = fields.into_iter();
    let (p, d, v) = (it.next().unwrap(), it.next().unwrap(), it.next().unwrap());
    Ok(outputs([
        ("Position", SocketValue::Field(p)),
        ("Distance", SocketValue::Field(d)),
        ("Is Valid", SocketValue::Field(v)),
    ]))
}

enum Target {
    Points(SortedPoints),
    Edges(Vec<[V3; 2]>, BoxTree),
    Faces(Vec<[V3; 3]>, BoxTree),
}

impl Target {
    fn edges(segs: Vec<[V3; 2]>) -> Target {
        let tree = nearest_tree(&segs.iter().map(|s| bounds_of(s)).collect::<Vec<_>>());
        Target::Edges(segs, tree)
    }
    fn faces(tris: Vec<[V3; 3]>) -> Target {
        let tree = nearest_tree(&tris.iter().map(|t| bounds_of(t)).collect::<Vec<_>>());
        Target::Faces(tris, tree)
    }
    fn nearest(&self, q: V3) -> Option<(V3, f32)> {
        let found = match self {
            Target::Points(p) => return p.nearest(q),
            Target::Edges(s, tree) => tree.nearest(q, |i| {
                let [a, b] = s[i as usize];
                let p = closest_on_segment(q, a, b);
                (dist_sq(p, q), p)
            }),
            Target::Faces(t, tree) => tree.nearest(q, |i| {
                let [a, b, c] = t[i as usize];
                let p = closest_on_triangle(q, a, b, c);
                (dist_sq(p, q), p)
            }),
        };
        found.map(|(_, d, p)| (p, d.sqrt()))
    }
}
