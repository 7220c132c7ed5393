//! Moving attribute values between domains as Blender does (`adapt_mesh_domain_*`,
//! `adapt_curve_domain_*`): averages with Blender's mixer (floats summed in single
//! precision and scaled by `1 / count`, integers averaged in double and rounded), copies
//! where one element maps to one, and Blender's own rules for booleans (a face is
//! selected when all its corners are, a vertex when any of its edges is, ...).

use super::curves::Curves;
use super::mesh::Mesh;
use super::types::{Array, Domain};

/// Averages `data[src]` into `n_out` outputs for each `(out, src)` pair, in pair order.
fn mix(data: &Array, n_out: usize, pairs: &[(u32, u32)]) -> Array {
    let mut count = vec![0.0f32; n_out];
    for &(o, _) in pairs {
        count[o as usize] += 1.0;
    }
    fn lanes<const K: usize>(
        v: &[[f32; K]],
        n_out: usize,
        pairs: &[(u32, u32)],
        count: &[f32],
    ) -> Vec<[f32; K]> {
        let mut sum = vec![[0.0f32; K]; n_out];
        for &(o, s) in pairs {
            for k in 0..K {
                sum[o as usize][k] += v[s as usize][k];
            }
        }
        for (i, x) in sum.iter_mut().enumerate() {
            if count[i] > 0.0 {
                let w = 1.0 / count[i];
                for c in x.iter_mut() {
                    *c *= w;
                }
            }
        }
        sum
    }
    fn ints<const K: usize>(
        v: &[[i32; K]],
        n_out: usize,
        pairs: &[(u32, u32)],
        count: &[f32],
    ) -> Vec<[i32; K]> {
        let mut sum = vec![[0.0f64; K]; n_out];
        for &(o, s) in pairs {
            for k in 0..K {
                sum[o as usize][k] += v[s as usize][k] as f64;
            }
        }
        sum.iter()
            .enumerate()
            .map(|(i, x)| {
                let mut r = [0i32; K];
                if count[i] > 0.0 {
                    for k in 0..K {
                        r[k] = (x[k] / count[i] as f64).round() as i32;
                    }
                }
                r
            })
            .collect()
    }
    match data {
        Array::Float(v) => {
            let w: Vec<[f32; 1]> = v.iter().map(|x| [*x]).collect();
            Array::Float(
                lanes(&w, n_out, pairs, &count)
                    .into_iter()
                    .map(|x| x[0])
                    .collect(),
            )
        }
        Array::Float2(v) => Array::Float2(lanes(v, n_out, pairs, &count)),
        Array::Vector(v) => Array::Vector(lanes(v, n_out, pairs, &count)),
        Array::Color(v) => Array::Color(lanes(v, n_out, pairs, &count)),
        Array::ByteColor(v) => Array::ByteColor(lanes(v, n_out, pairs, &count)),
        Array::Quaternion(v) => {
            let r = lanes(v, n_out, pairs, &count);
            Array::Quaternion(r.into_iter().map(super::math::normalize_quat).collect())
        }
        Array::Matrix(v) => {
            let flat: Vec<[f32; 16]> = v.iter().map(super::math::flatten).collect();
            let r = lanes(&flat, n_out, pairs, &count);
            Array::Matrix(
                r.iter()
                    .map(|f| {
                        let mut m = [[0.0f32; 4]; 4];
                        for (k, x) in f.iter().enumerate() {
                            m[k / 4][k % 4] = *x;
                        }
                        m
                    })
                    .collect(),
            )
        }
        Array::Int(v) => {
            let w: Vec<[i32; 1]> = v.iter().map(|x| [*x]).collect();
            Array::Int(
                ints(&w, n_out, pairs, &count)
                    .into_iter()
                    .map(|x| x[0])
                    .collect(),
            )
        }
        Array::Int8(v) => {
            let w: Vec<[i32; 1]> = v.iter().map(|x| [*x as i32]).collect();
            Array::Int8(
                ints(&w, n_out, pairs, &count)
                    .into_iter()
                    .map(|x| x[0].clamp(-128, 127) as i8)
                    .collect(),
            )
        }
        Array::Int2(v) => Array::Int2(ints(v, n_out, pairs, &count)),
        Array::Bool(v) => {
            // The generic boolean mixer: true when at least half the inputs are.
            let f: Vec<[f32; 1]> = v.iter().map(|x| [if *x { 1.0 } else { 0.0 }]).collect();
            Array::Bool(
                lanes(&f, n_out, pairs, &count)
                    .into_iter()
                    .map(|x| x[0] >= 0.5)
                    .collect(),
            )
        }
    }
}

/// Boolean rule: an output is true when all (`all`) or any of its inputs are; outputs
/// without inputs are false.
fn bool_rule(v: &[bool], n_out: usize, pairs: &[(u32, u32)], all: bool) -> Array {
    let mut any_in = vec![false; n_out];
    let mut out = vec![all; n_out];
    for &(o, s) in pairs {
        any_in[o as usize] = true;
        if all {
            out[o as usize] &= v[s as usize];
        } else {
            out[o as usize] |= v[s as usize];
        }
    }
    for (o, has) in out.iter_mut().zip(&any_in) {
        if !has {
            *o = false;
        }
    }
    Array::Bool(out)
}

/// Averages (booleans: all or any) `data[src]` into outputs for each `(out, src)` pair.
pub fn combine(data: &Array, n_out: usize, pairs: &[(u32, u32)], bool_all: bool) -> Array {
    match data {
        Array::Bool(v) => bool_rule(v, n_out, pairs, bool_all),
        _ => mix(data, n_out, pairs),
    }
}

/// Moves mesh values from domain `from` to `to`.
pub fn adapt_mesh(mesh: &Mesh, data: &Array, from: Domain, to: Domain) -> Array {
    use Domain::*;
    if from == to {
        return data.clone();
    }
    let n_out = mesh.domain_size(to);
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    let faces = mesh.face_count();
    match (from, to) {
        // One to one: copies.
        (Point, Corner) => {
            return data.gather(
                &mesh
                    .corner_verts
                    .iter()
                    .map(|&v| v as usize)
                    .collect::<Vec<_>>(),
            )
        }
        (Face, Corner) => {
            return data.gather(
                &mesh
                    .corner_faces()
                    .iter()
                    .map(|&f| f as usize)
                    .collect::<Vec<_>>(),
            )
        }
        (Corner, Point) => {
            for (c, &v) in mesh.corner_verts.iter().enumerate() {
                pairs.push((v, c as u32));
            }
            return combine(data, n_out, &pairs, true);
        }
        (Point, Face) | (Corner, Face) | (Edge, Face) => {
            for f in 0..faces {
                for c in mesh.face(f) {
                    let s = match from {
                        Point => mesh.corner_verts[c],
                        Corner => c as u32,
                        _ => mesh.corner_edges[c],
                    };
                    pairs.push((f as u32, s));
                }
            }
            return combine(data, n_out, &pairs, true);
        }
        (Face, Point) | (Face, Edge) => {
            for f in 0..faces {
                for c in mesh.face(f) {
                    let o = if to == Point {
                        mesh.corner_verts[c]
                    } else {
                        mesh.corner_edges[c]
                    };
                    pairs.push((o, f as u32));
                }
            }
            return combine(data, n_out, &pairs, false);
        }
        (Point, Edge) => {
            for (e, ev) in mesh.edges.iter().enumerate() {
                pairs.push((e as u32, ev[0]));
                pairs.push((e as u32, ev[1]));
            }
            return combine(data, n_out, &pairs, true);
        }
        (Edge, Point) => {
            for (e, ev) in mesh.edges.iter().enumerate() {
                pairs.push((ev[0], e as u32));
                pairs.push((ev[1], e as u32));
            }
            return combine(data, n_out, &pairs, false);
        }
        (Corner, Edge) => {
            for f in 0..faces {
                for c in mesh.face(f) {
                    let e = mesh.corner_edges[c];
                    pairs.push((e, c as u32));
                    pairs.push((e, mesh.next_corner(f, c) as u32));
                }
            }
            return combine(data, n_out, &pairs, true);
        }
        (Edge, Corner) => {
            for f in 0..faces {
                for c in mesh.face(f) {
                    pairs.push((c as u32, mesh.corner_edges[c]));
                    pairs.push((c as u32, mesh.corner_edges[mesh.prev_corner(f, c)]));
                }
            }
            return combine(data, n_out, &pairs, true);
        }
        _ => {}
    }
    Array::zeros(data.data_type(), n_out)
}

/// Moves curve values between the POINT and CURVE domains.
pub fn adapt_curves(curves: &Curves, data: &Array, from: Domain, to: Domain) -> Array {
    if from == to {
        return data.clone();
    }
    match (from, to) {
        (Domain::Curve, Domain::Point) => {
            let mut idx = Vec::with_capacity(curves.point_count());
            for c in 0..curves.curve_count() {
                idx.extend(curves.points(c).map(|_| c));
            }
            data.gather(&idx)
        }
        (Domain::Point, Domain::Curve) => {
            let mut pairs = Vec::new();
            for c in 0..curves.curve_count() {
                for p in curves.points(c) {
                    pairs.push((c as u32, p as u32));
                }
            }
            combine(data, curves.curve_count(), &pairs, true)
        }
        _ => Array::zeros(data.data_type(), curves.domain_size(to)),
    }
}
