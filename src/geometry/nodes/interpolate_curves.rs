//! Interpolate Curves (`node_geo_interpolate_curves`): one new Catmull-Rom curve per
//! point of Points (a point cloud, else a mesh's vertices), rooted there and shaped as the
//! weighted mix of its nearest guide curves of the same group, each guide's shape taken
//! relative to its root and turned from Guide Up to Point Up.
//!
//! As Blender: guides are grouped by Guide Group ID (a balanced `BLI_kdtree_3d` of roots
//! per group, `geometry::kdtree`, whose walk decides among equal distances); a point finds
//! Max Neighbors guides, plus one more when its group has more guides than that, which
//! then sets the distance where weights reach zero (`(max - d) / d`, else `1 / d`), and
//! the weights are normalized. When every guide of the group has the same number of
//! points, control points are mixed index for index; otherwise the child gets the
//! weighted mean of its guides' counts, rounded, and each guide is sampled at even steps
//! of its control polygon's length (a single-point guide adds its root itself, as
//! Blender's code does). A point with no guides gives a single-point curve.
//!
//! Guide attributes other than the built-ins (radius, tilt and resolution excepted) are
//! mixed onto the same domain with Blender's default mixers (a child without guides gets
//! zero); Points' attributes the guides lack are copied to the curves. Closest Index and
//! Closest Weight are the guide with the largest weight (the first of equals).

use std::collections::HashMap;
use std::sync::Arc;

use super::super::attribute::{AttrId, Attributes};
use super::super::curves::{Curves, CURVE_TYPE_CATMULL_ROM};
use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::field::{AttributeInput, ComponentRef, Field};
use super::super::kdtree::KdTree;
use super::super::math::{mat3_mul_v3, normalize, rotation_between_vecs_to_mat3, Mat3f, V3};
use super::super::set::GeometrySet;
use super::super::types::{Array, DataType, Domain, Value};
use super::super::value::SocketValue;
use super::geometry_ops::eval_fields;

/// Built-in curve attributes (`CurvesGeometry`'s providers) and their domains.
const CURVE_BUILTINS: &[(&str, Domain)] = &[
    ("position", Domain::Point),
    ("radius", Domain::Point),
    ("tilt", Domain::Point),
    ("id", Domain::Point),
    ("handle_left", Domain::Point),
    ("handle_right", Domain::Point),
    ("handle_type_left", Domain::Point),
    ("handle_type_right", Domain::Point),
    ("nurbs_weight", Domain::Point),
    ("custom_normal", Domain::Point),
    ("curve_type", Domain::Curve),
    ("cyclic", Domain::Curve),
    ("resolution", Domain::Curve),
    ("normal_mode", Domain::Curve),
    ("nurbs_order", Domain::Curve),
    ("knots_mode", Domain::Curve),
];

fn curve_builtin(name: Option<&str>) -> Option<Domain> {
    let name = name?;
    CURVE_BUILTINS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, d)| *d)
}

/// Built-in mesh attributes that are no curve built-in (Blender skips them).
fn mesh_builtin(name: Option<&str>) -> bool {
    matches!(
        name,
        Some(
            "position"
                | "material_index"
                | "sharp_face"
                | "sharp_edge"
                | "id"
                | "custom_normal"
                | ".edge_verts"
                | ".corner_vert"
                | ".corner_edge"
        )
    )
}

/// The guides each child mixes: up to `max` (index, weight) per child, flattened.
struct Neighbors {
    max: usize,
    index: Vec<usize>,
    weight: Vec<f32>,
    count: Vec<usize>,
}

impl Neighbors {
    fn of(&self, child: usize) -> impl Iterator<Item = (usize, f32)> + '_ {
        let s = child * self.max;
        (s..s + self.count[child]).map(move |k| (self.index[k], self.weight[k]))
    }
}

/// `find_neighbor_guides`.
fn find_neighbors(
    roots: &[V3],
    positions: &[V3],
    point_groups: &[i32],
    trees: &HashMap<i32, (KdTree, usize)>,
    max: usize,
) -> Neighbors {
    let n = positions.len();
    let mut nb = Neighbors {
        max,
        index: vec![0; n * max],
        weight: vec![0.0; n * max],
        count: vec![0; n],
    };
    let (mut nearest, mut stack) = (Vec::new(), Vec::new());
    for child in 0..n {
        let Some((tree, group_size)) = trees.get(&point_groups[child]) else {
            continue;
        };
        // An extra neighbour, given weight zero, keeps nearby children that pick
        // different guides alike.
        let extra = *group_size > max;
        tree.nearest_n(
            roots,
            positions[child],
            max + extra as usize,
            &mut nearest,
            &mut stack,
        );
        if nearest.is_empty() {
            continue;
        }
        let s = child * max;
        let mut total = 0.0f32;
        let mut k = 0;
        if extra {
            let max_distance = nearest.iter().map(|e| e.1).fold(f32::MIN, f32::max);
            if max_distance == 0.0 {
                nb.count[child] = 1;
                nb.index[s] = nearest[0].0;
                nb.weight[s] = 1.0;
                continue;
            }
            for &(i, d) in &nearest {
                let w = (max_distance - d) / d.max(0.000001);
                if w > 0.0 {
                    total += w;
                    nb.index[s + k] = i;
                    nb.weight[s + k] = w;
                    k += 1;
                }
            }
        } else {
            for &(i, d) in &nearest {
                let w = 1.0 / d.max(0.000001);
                if w > 0.0 {
                    total += w;
                    nb.index[s + k] = i;
                    nb.weight[s + k] = w;
                    k += 1;
                }
            }
        }
        nb.count[child] = k;
        if total > 0.0 {
            let f = 1.0 / total;
            for w in &mut nb.weight[s..s + k] {
                *w *= f;
            }
        }
    }
    nb
}

/// `length_parameterize::sample_at_lengths`: segment and factor per sample, with
/// Blender's hint (the last segment is tried first, so a zero-length segment, whose
/// factor is always 0, keeps every later sample).
fn sample_at_lengths(lengths: &[f32], samples: &[f32], seg: &mut Vec<usize>, fac: &mut Vec<f32>) {
    seg.clear();
    fac.clear();
    let total = lengths[lengths.len() - 1];
    let mut hint: Option<(usize, f32, f32)> = None;
    for &len in samples {
        if let Some((i, start, inv)) = hint {
            let f = (len - start) * inv;
            if (0.0..1.0).contains(&f) {
                seg.push(i);
                fac.push(f);
                continue;
            }
        }
        if len >= total {
            seg.push(lengths.len() - 1);
            fac.push(1.0);
            continue;
        }
        let i = lengths.partition_point(|&l| l <= len);
        let start = if i == 0 { 0.0 } else { lengths[i - 1] };
        let l = lengths[i] - start;
        let inv = if l == 0.0 { 0.0 } else { 1.0 / l };
        seg.push(i);
        fac.push((len - start) * inv);
        hint = Some((i, start, inv));
    }
}

/// Per guide: accumulated control-polygon lengths (`accumulate_lengths`, open).
fn guide_lengths(g: &Curves) -> Vec<Vec<f32>> {
    (0..g.curve_count())
        .map(|c| {
            let p = &g.positions[g.points(c)];
            let mut out = Vec::with_capacity(p.len().saturating_sub(1));
            let mut len = 0.0f32;
            for w in p.windows(2) {
                let d = [w[1][0] - w[0][0], w[1][1] - w[0][1], w[1][2] - w[0][2]];
                len += (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                out.push(len);
            }
            out
        })
        .collect()
}

/// Where each child point samples a guide that it does not mix index for index: segment
/// and factor along the guide's control polygon at `i / (n - 1)` of its length.
fn samples_on(
    lengths: &[f32],
    n: usize,
    seg: &mut Vec<usize>,
    fac: &mut Vec<f32>,
    buf: &mut Vec<f32>,
) {
    let total = lengths[lengths.len() - 1];
    let step = if n > 1 { total / (n - 1) as f32 } else { 0.0 };
    buf.clear();
    buf.extend((0..n).map(|i| i as f32 * step));
    sample_at_lengths(lengths, buf, seg, fac);
}

/// One attribute mixed from guides (Blender's `DefaultMixer`): sums of value * weight
/// and of weights, then scaled by the inverse total weight (zero without weight).
enum Mixer {
    /// Float, float2, float3 and colour lanes, summed in single precision.
    Lanes(usize, Vec<f32>, Vec<f32>),
    /// Integers, summed in double precision and rounded.
    Int(Vec<f64>, Vec<f32>),
    /// 8-bit integers, summed in single precision and rounded.
    Int8(Vec<f32>, Vec<f32>),
    /// Booleans: true when the weighted mean reaches one half.
    Bool(Vec<f32>, Vec<f32>),
}

/// An attribute's values as f32 lanes (`None`: a type the mixers here do not take).
fn lanes(a: &Array) -> Option<(usize, Vec<f32>)> {
    Some(match a {
        Array::Float(v) => (1, v.clone()),
        Array::Float2(v) => (2, v.iter().flatten().copied().collect()),
        Array::Vector(v) => (3, v.iter().flatten().copied().collect()),
        Array::Color(v) => (4, v.iter().flatten().copied().collect()),
        Array::Int(v) => (1, v.iter().map(|x| *x as f32).collect()),
        Array::Int8(v) => (1, v.iter().map(|x| *x as f32).collect()),
        Array::Bool(v) => (1, v.iter().map(|x| *x as u8 as f32).collect()),
        _ => return None,
    })
}

impl Mixer {
    fn new(kind: &Array, n: usize) -> Mixer {
        match kind {
            Array::Int(_) => Mixer::Int(vec![0.0; n], vec![0.0; n]),
            Array::Int8(_) => Mixer::Int8(vec![0.0; n], vec![0.0; n]),
            Array::Bool(_) => Mixer::Bool(vec![0.0; n], vec![0.0; n]),
            other => {
                let k = lanes(other).map_or(1, |l| l.0);
                Mixer::Lanes(k, vec![0.0; n * k], vec![0.0; n])
            }
        }
    }
    /// Mixes in `value` (lanes, already converted as the type converts) at `i`.
    fn mix_in(&mut self, i: usize, value: &[f32], w: f32) {
        match self {
            Mixer::Lanes(k, sum, tw) => {
                for (j, v) in value.iter().enumerate().take(*k) {
                    sum[i * *k + j] += v * w;
                }
                tw[i] += w;
            }
            Mixer::Int(sum, tw) => {
                sum[i] += value[0] as f64 * w as f64;
                tw[i] += w;
            }
            Mixer::Int8(sum, tw) | Mixer::Bool(sum, tw) => {
                sum[i] += value[0] * w;
                tw[i] += w;
            }
        }
    }
    fn finish(self, like: &Array) -> Array {
        match self {
            Mixer::Lanes(k, mut sum, tw) => {
                for (i, t) in tw.iter().enumerate() {
                    let inv = 1.0 / t;
                    for x in &mut sum[i * k..(i + 1) * k] {
                        *x = if *t > 0.0 { *x * inv } else { 0.0 };
                    }
                }
                match like {
                    Array::Float(_) => Array::Float(sum),
                    Array::Float2(_) => {
                        Array::Float2(sum.chunks(2).map(|c| [c[0], c[1]]).collect())
                    }
                    Array::Vector(_) => {
                        Array::Vector(sum.chunks(3).map(|c| [c[0], c[1], c[2]]).collect())
                    }
                    _ => Array::Color(sum.chunks(4).map(|c| [c[0], c[1], c[2], c[3]]).collect()),
                }
            }
            Mixer::Int(sum, tw) => Array::Int(
                sum.iter()
                    .zip(&tw)
                    .map(|(s, t)| {
                        if *t > 0.0 {
                            (s * (1.0 / t) as f64).round() as i32
                        } else {
                            0
                        }
                    })
                    .collect(),
            ),
            Mixer::Int8(sum, tw) => Array::Int8(
                sum.iter()
                    .zip(&tw)
                    .map(|(s, t)| {
                        if *t > 0.0 {
                            (s * (1.0 / t)).round() as i8
                        } else {
                            0
                        }
                    })
                    .collect(),
            ),
            Mixer::Bool(sum, tw) => Array::Bool(
                sum.iter()
                    .zip(&tw)
                    .map(|(s, t)| *t > 0.0 && s * (1.0 / t) >= 0.5)
                    .collect(),
            ),
        }
    }
}

/// `math::interpolate(a, b, t)` as the attribute's type computes it: `a * (1 - t) + b * t`
/// in floats, rounded for integer types (booleans: true unless it rounds to zero).
fn interpolate_value(like: &Array, k: usize, a: &[f32], b: &[f32], t: f32, out: &mut [f32]) {
    for j in 0..k {
        let v = a[j] * (1.0 - t) + b[j] * t;
        out[j] = match like {
            Array::Int(_) | Array::Int8(_) => v.round(),
            Array::Bool(_) => (v.round() != 0.0) as u8 as f32,
            _ => v,
        };
    }
}

/// The Points input's component: a point cloud, else a mesh's vertices.
enum PointsRef<'a> {
    Cloud(&'a super::super::pointcloud::PointCloud),
    Mesh(&'a super::super::mesh::Mesh),
}

impl PointsRef<'_> {
    fn component(&self) -> ComponentRef<'_> {
        match self {
            PointsRef::Cloud(p) => ComponentRef::Points(p),
            PointsRef::Mesh(m) => ComponentRef::Mesh(m),
        }
    }
    fn positions(&self) -> &[V3] {
        match self {
            PointsRef::Cloud(p) => &p.positions,
            PointsRef::Mesh(m) => &m.positions,
        }
    }
    fn attributes(&self) -> &Attributes {
        match self {
            PointsRef::Cloud(p) => &p.attributes,
            PointsRef::Mesh(m) => &m.attributes,
        }
    }
}

struct Inputs<'a> {
    guides: &'a Curves,
    points: PointsRef<'a>,
    guide_up: Vec<V3>,
    point_up: Vec<V3>,
    guide_group: Vec<i32>,
    point_group: Vec<i32>,
    max: usize,
}

/// `generate_interpolated_curves`.
// Long because it follows Blender's generate_interpolated_curves step by step: groups,
// neighbours, positions per child, then every attribute, in Blender's order.
fn interpolate(inp: &Inputs, ids: (&Option<AttrId>, &Option<AttrId>)) -> Result<Curves, String> {
    let g = inp.guides;
    let positions = inp.points.positions();
    let n = positions.len();
    let max = inp.max;
    // Guides per group in index order, groups in order of first appearance.
    let mut groups: Vec<(i32, Vec<usize>)> = Vec::new();
    let mut slot: HashMap<i32, usize> = HashMap::new();
    for (c, id) in inp.guide_group.iter().enumerate() {
        let k = *slot.entry(*id).or_insert_with(|| {
            groups.push((*id, Vec::new()));
            groups.len() - 1
        });
        groups[k].1.push(c);
    }
    let sizes: Vec<usize> = (0..g.curve_count()).map(|c| g.points(c).len()).collect();
    if let Some(c) = sizes.iter().position(|s| *s == 0) {
        return Err(format!("guide curve {c} has no points"));
    }
    // A group whose guides all have the same number of points mixes them directly.
    let uniform: HashMap<i32, usize> = groups
        .iter()
        .filter(|(_, m)| m.iter().all(|&c| sizes[c] == sizes[m[0]]))
        .map(|(id, m)| (*id, sizes[m[0]]))
        .collect();
    let roots: Vec<V3> = (0..g.curve_count())
        .map(|c| g.positions[g.curve_offsets[c] as usize])
        .collect();
    let trees: HashMap<i32, (KdTree, usize)> = groups
        .iter()
        .map(|(id, m)| (*id, (KdTree::new(&roots, m.clone()), m.len())))
        .collect();
    let nb = find_neighbors(&roots, positions, &inp.point_group, &trees, max);

    // Point counts (`compute_point_counts_per_child`).
    let mut direct = vec![false; n];
    let mut offsets = Vec::with_capacity(n + 1);
    offsets.push(0u32);
    for child in 0..n {
        let count = if nb.count[child] == 0 {
            1
        } else if let Some(&u) = uniform.get(&inp.point_group[child]) {
            direct[child] = true;
            u
        } else {
            let mut sum = 0.0f32;
            for (i, w) in nb.of(child) {
                sum += w * sizes[i] as f32;
            }
            (sum.round() as i64).max(1) as usize
        };
        super::super::limits::check(
            Some(offsets[child] as u64 + count as u64),
            "the interpolated curves' points",
        )?;
        offsets.push(offsets[child] + count as u32);
    }
    let total = offsets[n] as usize;
    let lengths = guide_lengths(g);

    // Shapes (`interpolate_curve_shapes`).
    let mut out_pos = vec![[0.0f32; 3]; total];
    let (mut seg, mut fac, mut buf) = (Vec::new(), Vec::new(), Vec::new());
    for child in 0..n {
        let pts = offsets[child] as usize..offsets[child + 1] as usize;
        let dst = &mut out_pos[pts.clone()];
        dst.fill(positions[child]);
        let child_up = inp.point_up[child];
        for (i, w) in nb.of(child) {
            let gp = &g.positions[g.points(i)];
            let root = gp[0];
            let up = inp.guide_up[i];
            let rot: Option<Mat3f> =
                (up != child_up).then(|| rotation_between_vecs_to_mat3(up, child_up));
            let turn = |v: V3| rot.as_ref().map_or(v, |m| mat3_mul_v3(m, v));
            let add = |p: &mut V3, rel: V3| {
                let r = turn(rel);
                for k in 0..3 {
                    p[k] += w * r[k];
                }
            };
            if direct[child] {
                for (p, q) in dst.iter_mut().zip(gp) {
                    add(p, [q[0] - root[0], q[1] - root[1], q[2] - root[2]]);
                }
            } else if gp.len() == 1 {
                // Blender adds the single-point guide's root itself (not relative to it).
                let r = turn(root);
                let gpos = [r[0] * w, r[1] * w, r[2] * w];
                for p in dst.iter_mut() {
                    for k in 0..3 {
                        p[k] += gpos[k];
                    }
                }
            } else {
                samples_on(&lengths[i], dst.len(), &mut seg, &mut fac, &mut buf);
                for (j, p) in dst.iter_mut().enumerate() {
                    let (a, b, t) = (gp[seg[j]], gp[seg[j] + 1], fac[j]);
                    let s = [0, 1, 2].map(|k| a[k] * (1.0 - t) + b[k] * t);
                    add(p, [s[0] - root[0], s[1] - root[1], s[2] - root[2]]);
                }
            }
        }
    }

    let mut out = Curves {
        positions: out_pos,
        curve_offsets: offsets.clone(),
        attributes: Attributes::default(),
        materials: g.materials.clone(),
    };

    // Guide attributes (`interpolate_curve_attributes`), on their own domain.
    for a in g.attributes.iter() {
        if curve_builtin(a.id.name())
            .is_some_and(|_| !matches!(a.id.name(), Some("radius" | "tilt" | "resolution")))
        {
            continue;
        }
        let Some((k, src)) = lanes(&a.data) else {
            return Err(format!(
                "guide attribute {:?}: mixing {} values is not supported",
                a.id.label(),
                a.data.data_type().name()
            ));
        };
        let data = match a.domain {
            Domain::Curve => {
                let mut m = Mixer::new(&a.data, n);
                for child in 0..n {
                    for (i, w) in nb.of(child) {
                        m.mix_in(child, &src[i * k..(i + 1) * k], w);
                    }
                }
                m.finish(&a.data)
            }
            Domain::Point => {
                let mut m = Mixer::new(&a.data, total);
                let mut v = [0.0f32; 4];
                for child in 0..n {
                    let pts = offsets[child] as usize..offsets[child + 1] as usize;
                    for (i, w) in nb.of(child) {
                        let gpts = g.points(i);
                        let at = |p: usize| &src[(gpts.start + p) * k..(gpts.start + p + 1) * k];
                        if direct[child] {
                            for (j, p) in pts.clone().enumerate() {
                                m.mix_in(p, at(j), w);
                            }
                        } else if gpts.len() == 1 {
                            for p in pts.clone() {
                                m.mix_in(p, at(0), w);
                            }
                        } else {
                            samples_on(&lengths[i], pts.len(), &mut seg, &mut fac, &mut buf);
                            for (j, p) in pts.clone().enumerate() {
                                interpolate_value(
                                    &a.data,
                                    k,
                                    at(seg[j]),
                                    at(seg[j] + 1),
                                    fac[j],
                                    &mut v,
                                );
                                m.mix_in(p, &v[..k], w);
                            }
                        }
                    }
                }
                m.finish(&a.data)
            }
            _ => continue,
        };
        out.attributes.set(a.id.clone(), a.domain, data);
    }

    // Points' attributes become curve attributes, one per child.
    for a in inp.points.attributes().iter() {
        let name = a.id.name();
        let is_mesh = matches!(inp.points, PointsRef::Mesh(_));
        if (is_mesh && mesh_builtin(name) && curve_builtin(name).is_none())
            || name == Some("position")
            || g.attributes.contains(&a.id)
        {
            continue;
        }
        if a.domain != Domain::Point {
            return Err(format!(
                "the Points mesh's {} attribute {:?}: Blender copies it onto the curves by index",
                a.domain.name(),
                a.id.label()
            ));
        }
        // A built-in of the curves is only made on its own domain (none of the point
        // built-ins is on the curve domain).
        if let Some(d) = curve_builtin(name) {
            let ty_ok = matches!(
                (name, &a.data),
                (Some("resolution"), Array::Int(_))
                    | (Some("cyclic"), Array::Bool(_))
                    | (
                        Some("curve_type" | "normal_mode" | "nurbs_order" | "knots_mode"),
                        Array::Int8(_)
                    )
            );
            if d != Domain::Curve || !ty_ok {
                continue;
            }
        }
        out.attributes
            .set(a.id.clone(), Domain::Curve, a.data.clone());
    }

    // Closest Index and Closest Weight (`store_output_attributes`).
    let (index_id, weight_id) = ids;
    if index_id.is_some() || weight_id.is_some() {
        let mut ci = vec![0i32; n];
        let mut cw = vec![0.0f32; n];
        for child in 0..n {
            let mut best: Option<(usize, f32)> = None;
            for (i, w) in nb.of(child) {
                if best.is_none_or(|b| w > b.1) {
                    best = Some((i, w));
                }
            }
            if let Some((i, w)) = best {
                ci[child] = i as i32;
                cw[child] = w;
            }
        }
        if let Some(id) = weight_id {
            out.attributes
                .set(id.clone(), Domain::Curve, Array::Float(cw));
        }
        if let Some(id) = index_id {
            out.attributes
                .set(id.clone(), Domain::Curve, Array::Int(ci));
        }
    }
    out.set_i8("curve_type", Domain::Curve, vec![CURVE_TYPE_CATMULL_ROM; n]);
    Ok(out)
}

fn normalized(v: &Array) -> Vec<V3> {
    v.as_vector().iter().map(|u| normalize(*u)).collect()
}

pub fn interpolate_curves(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let guides_geo = ctx.geometry("Guide Curves")?;
    let points_geo = ctx.geometry("Points")?;
    let guide_up = ctx.field("Guide Up", DataType::Vector)?;
    let guide_group = ctx.field("Guide Group ID", DataType::Int)?;
    let point_up = ctx.field("Point Up", DataType::Vector)?;
    let point_group = ctx.field("Point Group ID", DataType::Int)?;
    let max = ctx.int("Max Neighbors")?.max(1) as usize;
    let index_id = ctx
        .output_used("Closest Index")
        .then(|| AttrId::anonymous("Closest Index"));
    let weight_id = ctx
        .output_used("Closest Weight")
        .then(|| AttrId::anonymous("Closest Weight"));
    let mut out = Outputs::new();
    let field_out = |id: &Option<AttrId>, ty: DataType| match id {
        Some(id) => SocketValue::Field(Field::input(AttributeInput { id: id.clone(), ty })),
        None => SocketValue::Field(Field::Constant(Value::zero(ty))),
    };
    out.insert("Closest Index".into(), field_out(&index_id, DataType::Int));
    out.insert(
        "Closest Weight".into(),
        field_out(&weight_id, DataType::Float),
    );
    let points = match (&points_geo.points, &points_geo.mesh) {
        (Some(p), _) => Some(PointsRef::Cloud(p)),
        (None, Some(m)) => Some(PointsRef::Mesh(m)),
        _ => None,
    };
    let (Some(guides), Some(points)) = (guides_geo.curves.as_deref(), points) else {
        out.insert(
            "Curves".into(),
            SocketValue::Geometry(GeometrySet::default()),
        );
        return Ok(out);
    };
    if guides.curve_count() == 0 {
        out.insert(
            "Curves".into(),
            SocketValue::Geometry(GeometrySet::default()),
        );
        return Ok(out);
    }
    let r = eval_fields(
        ComponentRef::Curves(guides),
        Domain::Curve,
        &[(&guide_up, DataType::Vector), (&guide_group, DataType::Int)],
    )
    .map_err(|e| ctx.err(e))?;
    let p = eval_fields(
        points.component(),
        Domain::Point,
        &[(&point_up, DataType::Vector), (&point_group, DataType::Int)],
    )
    .map_err(|e| ctx.err(e))?;
    let inp = Inputs {
        guides,
        guide_up: normalized(&r[0]),
        guide_group: r[1].as_int().into_owned(),
        point_up: normalized(&p[0]),
        point_group: p[1].as_int().into_owned(),
        points,
        max,
    };
    let curves = interpolate(&inp, (&index_id, &weight_id)).map_err(|e| ctx.err(e))?;
    let mut set = GeometrySet::default();
    if curves.curve_count() > 0 {
        set.curves = Some(Arc::new(curves));
    }
    out.insert("Curves".into(), SocketValue::Geometry(set));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::mesh::Mesh;
    use crate::geometry::pointcloud::PointCloud;

    fn guides() -> Curves {
        let mut g = Curves {
            positions: vec![[0.0; 3], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0]],
            curve_offsets: vec![0, 2, 4],
            ..Default::default()
        };
        g.attributes.set(
            AttrId::named("turn"),
            Domain::Point,
            Array::Quaternion(vec![[1.0, 0.0, 0.0, 0.0]; 4]),
        );
        g
    }

    fn run(g: &Curves, points: PointsRef) -> Result<Curves, String> {
        let n = points.positions().len();
        let inp = Inputs {
            guides: g,
            points,
            guide_up: vec![[0.0; 3]; 2],
            point_up: vec![[0.0; 3]; n],
            guide_group: vec![0; 2],
            point_group: vec![0; n],
            max: 4,
        };
        interpolate(&inp, (&None, &None))
    }

    /// A guide attribute of a type Blender mixes in ways not modelled here, and a mesh's
    /// non-point attribute Blender would copy by index, are errors naming them.
    #[test]
    fn unmodelled_attributes_are_refused_by_name() {
        let cloud = PointCloud {
            positions: vec![[0.5, 0.0, 0.0]],
            ..Default::default()
        };
        let e = run(&guides(), PointsRef::Cloud(&cloud)).unwrap_err();
        assert!(e.contains("turn") && e.contains("QUATERNION"), "{e}");
        let mut g = guides();
        g.attributes.remove(&AttrId::named("turn"));
        let c = run(&g, PointsRef::Cloud(&cloud)).unwrap();
        // Equidistant guides: the child is their mean shape, rooted at its point.
        assert_eq!(c.positions, vec![[0.5, 0.0, 0.0], [0.5, 0.0, 1.0]]);
        let mut m = Mesh::new();
        m.positions = vec![[0.5, 0.0, 0.0]];
        m.attributes.set(
            AttrId::named("face_value"),
            Domain::Face,
            Array::Float(vec![]),
        );
        let e = run(&g, PointsRef::Mesh(&m)).unwrap_err();
        assert!(e.contains("face_value") && e.contains("FACE"), "{e}");
    }
}
