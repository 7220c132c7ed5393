//! Scale Elements (`node_geo_scale_elements`): selected faces (or edges) joined by shared
//! vertices form islands, numbered by their first vertex; each island's vertices scale
//! about the mean of its elements' Center by the mean Scale, uniformly or along the mean
//! Axis.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field, PositionInput};
use super::super::math::{mat4_mul, normalize, transform_point, Mat4f, MAT4_IDENTITY, V3};
use super::super::mesh::Mesh;
use super::super::set::GeometrySet;
use super::super::types::{DataType, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::{eval_fields, modify_geometry_sets};

fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `create_single_axis_transform`: scale by `scale` along `axis` about `center`.
fn single_axis_transform(center: V3, axis: V3, scale: f32) -> Mat4f {
    let x = normalize(axis);
    let mut y = cross(x, [0.0, 0.0, 1.0]);
    if y == [0.0; 3] {
        y = cross(x, [0.0, 1.0, 0.0]);
    }
    let y = normalize(y);
    let z = cross(x, y);
    let mut t = MAT4_IDENTITY;
    for k in 0..3 {
        t[3][k] -= center[k];
    }
    let mut base = MAT4_IDENTITY;
    base[0][..3].copy_from_slice(&x);
    base[1][..3].copy_from_slice(&y);
    base[2][..3].copy_from_slice(&z);
    let mut inv = MAT4_IDENTITY;
    for c in 0..4 {
        for r in 0..4 {
            inv[c][r] = base[r][c];
        }
    }
    let mut s = MAT4_IDENTITY;
    s[0][0] = scale;
    let mut m = mat4_mul(&mat4_mul(&mat4_mul(&base, &s), &inv), &t);
    for k in 0..3 {
        m[3][k] += center[k];
    }
    m
}

/// Islands of the selected elements: (elements, vertices) per island, both ascending.
fn islands(m: &Mesh, elems: &[usize], face: bool) -> Vec<(Vec<usize>, Vec<usize>)> {
    let verts_of = |e: usize| -> Vec<usize> {
        if face {
            m.face(e).map(|c| m.corner_verts[c] as usize).collect()
        } else {
            m.edges[e].iter().map(|&v| v as usize).collect()
        }
    };
    let n = m.vertex_count();
    let mut used = vec![false; n];
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for &e in elems {
        let vs = verts_of(e);
        for &v in &vs {
            used[v] = true;
        }
        for &v in &vs[1..] {
            let (a, b) = (find(&mut parent, vs[0]), find(&mut parent, v));
            if a != b {
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    // Island ids in order of each island's first selected vertex.
    let mut id_of_root = vec![usize::MAX; n];
    let mut out: Vec<(Vec<usize>, Vec<usize>)> = Vec::new();
    let mut island_of = vec![usize::MAX; n];
    for v in (0..n).filter(|&v| used[v]) {
        let r = find(&mut parent, v);
        if id_of_root[r] == usize::MAX {
            id_of_root[r] = out.len();
            out.push((Vec::new(), Vec::new()));
        }
        island_of[v] = id_of_root[r];
        out[id_of_root[r]].1.push(v);
    }
    for &e in elems {
        out[island_of[verts_of(e)[0]]].0.push(e);
    }
    out
}

/// `gather_mean`: the values summed in element order, divided by their count.
fn mean3(v: &[V3], idx: &[usize]) -> V3 {
    let mut s = [0.0f32; 3];
    for &i in idx {
        for k in 0..3 {
            s[k] += v[i][k];
        }
    }
    s.map(|x| x / idx.len() as f32)
}

pub fn scale_elements(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let domain = match ctx.prop_str("domain")? {
        "FACE" => Domain::Face,
        "EDGE" => Domain::Edge,
        d => return Err(ctx.err(format!("domain {d} is not supported"))),
    };
    let single_axis = match ctx.prop_str("scale_mode")? {
        "UNIFORM" => false,
        "SINGLE_AXIS" => true,
        mode => return Err(ctx.err(format!("scale mode {mode} is not supported"))),
    };
    let sel = ctx.field("Selection", DataType::Bool)?;
    let scale = ctx.field("Scale", DataType::Float)?;
    let unlinked = ctx.flat().input("Center").is_some_and(|i| {
        i.sources.iter().all(|s| {
            matches!(
                s,
                crate::nodes::graph::Source::Default(_) | crate::nodes::graph::Source::Nothing
            )
        })
    });
    let center = if unlinked {
        Field::input(PositionInput)
    } else {
        ctx.field("Center", DataType::Vector)?
    };
    let axis = if ctx.has_input("Axis") {
        ctx.field("Axis", DataType::Vector)?
    } else {
        Field::Constant(super::super::types::Value::Vector([1.0, 0.0, 0.0]))
    };
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let Some(m) = s.mesh.clone() else {
            return Ok(());
        };
        let r = eval_fields(
            ComponentRef::Mesh(&m),
            domain,
            &[
                (&sel, DataType::Bool),
                (&scale, DataType::Float),
                (&center, DataType::Vector),
                (&axis, DataType::Vector),
            ],
        )?;
        let selected = r[0].as_bool();
        let elems: Vec<usize> = (0..selected.len()).filter(|&i| selected[i]).collect();
        if elems.is_empty() {
            return Ok(());
        }
        let (scales, centers, axes) = (r[1].as_float(), r[2].as_vector(), r[3].as_vector());
        let mesh = s.mesh_mut().unwrap();
        for (es, vs) in islands(&m, &elems, domain == Domain::Face) {
            let sc = es.iter().map(|&e| scales[e]).sum::<f32>() / es.len() as f32;
            let c = mean3(&centers, &es);
            if single_axis {
                let a = mean3(&axes, &es);
                let a = if a == [0.0; 3] { [1.0, 0.0, 0.0] } else { a };
                let t = single_axis_transform(c, a, sc);
                for v in vs {
                    mesh.positions[v] = transform_point(&t, mesh.positions[v]);
                }
            } else {
                for v in vs {
                    let p = mesh.positions[v];
                    mesh.positions[v] = [0, 1, 2].map(|k| c[k] + sc * (p[k] - c[k]));
                }
            }
        }
        mesh.custom_vert_normals = None;
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Geometry", SocketValue::Geometry(g))]))
}
