//! Curve nodes: Resample Curve, Set Curve Radius, Set Curve Tilt, Curve to Mesh
//! (`geometry::resample_curves`, `bke::curve_to_mesh_sweep`).

use std::sync::Arc;

use super::super::attribute::AttrId;
use super::super::curve_eval::{accumulated_lengths, Evaluated};
use super::super::curves::{Curves, CURVE_TYPE_POLY};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::ComponentRef;
use super::super::math::{add, cross, normalize, scale, V3};
use super::super::mesh::Mesh;
use super::super::types::{Array, DataType, Domain};
use super::geometry_ops::{eval_fields, geo, modify_geometry_sets};

/// Segment index and factor of a sample at `len` along accumulated segment `lengths`
/// (`length_parameterize::sample_at_length`).
pub fn sample_at_length(lengths: &[f32], len: f32) -> (usize, f32) {
    let total = lengths[lengths.len() - 1];
    if len >= total {
        return (lengths.len() - 1, 1.0);
    }
    let idx = lengths.partition_point(|&l| l <= len);
    let start = if idx == 0 { 0.0 } else { lengths[idx - 1] };
    let seg = lengths[idx] - start;
    // Blender multiplies by the inverse (bit for bit, that is not a division).
    let inv = if seg == 0.0 { 0.0 } else { 1.0 / seg };
    (idx, (len - start) * inv)
}

/// `count` uniform samples along accumulated `lengths` (`length_parameterize::sample_uniform`).
fn sample_uniform(
    lengths: &[f32],
    include_last: bool,
    count: usize,
    idx: &mut Vec<usize>,
    fac: &mut Vec<f32>,
) {
    if count == 1 {
        idx.push(0);
        fac.push(0.0);
        return;
    }
    let total = *lengths.last().unwrap();
    let step = total / (count - include_last as usize) as f32;
    for i in 0..count {
        let (s, f) = sample_at_length(lengths, total.min(i as f32 * step));
        idx.push(s);
        fac.push(f);
    }
}

pub enum ResampleMode {
    Count(Vec<i32>),
    Length(Vec<f32>),
    Evaluated,
}

/// Resamples every curve to poly curves (all curves selected).
fn resample(c: &Curves, mode: ResampleMode) -> Result<Curves, String> {
    Ok(resample_indexed(c, mode)?.0)
}

/// Samples of a resampling: for each new point, the two evaluated points it lies between
/// and the factor.
pub struct Samples {
    pub a: Vec<usize>,
    pub b: Vec<usize>,
    pub factor: Vec<f32>,
}

/// `resample` with where each new point came from (for tangents and normals).
pub fn resample_indexed(
    c: &Curves,
    mode: ResampleMode,
) -> Result<(Curves, Samples, Evaluated), String> {
    let ev = Evaluated::new(c)?;
    let eval_pos = ev.positions(c);
    let mut out = Curves {
        curve_offsets: vec![0],
        ..Default::default()
    };
    // Per output point: the evaluated points it lies between, and the factor.
    let (mut ia, mut ib, mut fac) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..c.curve_count() {
        let r = ev.range(i);
        let cyclic = ev.cyclic[i];
        let p = &eval_pos[r.clone()];
        let lengths = accumulated_lengths(p, cyclic);
        let count = match &mode {
            ResampleMode::Count(n) => n[i].max(1) as usize,
            ResampleMode::Length(l) => {
                let total = lengths.last().copied().unwrap_or(0.0);
                ((total / l[i]) as i32 + 1).max(1) as usize
            }
            ResampleMode::Evaluated => p.len(),
        };
        let (mut idx, mut f) = (Vec::with_capacity(count), Vec::with_capacity(count));
        if matches!(mode, ResampleMode::Evaluated) {
            idx.extend(0..p.len());
            f.resize(p.len(), 0.0);
        } else if lengths.is_empty() {
            idx.resize(count, 0);
            f.resize(count, 0.0);
        } else {
            sample_uniform(&lengths, !cyclic, count, &mut idx, &mut f);
        }
        for (s, t) in idx.iter().zip(&f) {
            let next = if s + 1 == p.len() { 0 } else { s + 1 };
            ia.push(r.start + s);
            ib.push(r.start + next);
            fac.push(*t);
        }
        out.curve_offsets.push(ia.len() as u32);
    }
    out.positions = (0..ia.len())
        .map(|k| lerp3(eval_pos[ia[k]], eval_pos[ib[k]], fac[k]))
        .collect();
    for a in c.attributes.iter() {
        match a.domain {
            Domain::Curve => {
                let data = if a.id.name() == Some("curve_type") {
                    Array::Int8(vec![CURVE_TYPE_POLY; c.curve_count()])
                } else {
                    a.data.clone()
                };
                out.attributes.set(a.id.clone(), Domain::Curve, data);
            }
            Domain::Point => {
                if a.id.name().is_some_and(|n| {
                    matches!(
                        n,
                        "handle_type_left"
                            | "handle_type_right"
                            | "handle_left"
                            | "handle_right"
                            | "nurbs_weight"
                    )
                }) {
                    continue;
                }
                let evaluated = ev.interpolate(c, &a.data)?;
                out.attributes.set(
                    a.id.clone(),
                    Domain::Point,
                    super::super::curve_eval::lerp_gather(&evaluated, &ia, &ib, &fac),
                );
            }
            _ => {}
        }
    }
    if out.attributes.named("curve_type").is_none() {
        out.attributes.set(
            AttrId::named("curve_type"),
            Domain::Curve,
            Array::Int8(vec![CURVE_TYPE_POLY; c.curve_count()]),
        );
    }
    out.materials = c.materials.clone();
    Ok((
        out,
        Samples {
            a: ia,
            b: ib,
            factor: fac,
        },
        ev,
    ))
}

fn lerp3(a: V3, b: V3, t: f32) -> V3 {
    [
        a[0] * (1.0 - t) + b[0] * t,
        a[1] * (1.0 - t) + b[1] * t,
        a[2] * (1.0 - t) + b[2] * t,
    ]
}

pub fn resample_curve(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Curve")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let mode = ctx.prop_str("mode")?.to_string();
    let value = |id: &str, ty: DataType| -> Result<super::super::field::Field, GeometryError> {
        if ctx.has_input(id) {
            ctx.field(id, ty)
        } else {
            Ok(super::super::field::Field::Constant(
                super::super::types::Value::zero(ty),
            ))
        }
    };
    let count = if mode == "COUNT" {
        value("Count", DataType::Int)?
    } else {
        value("", DataType::Int)?
    };
    let length = if mode == "LENGTH" {
        value("Length", DataType::Float)?
    } else {
        value("", DataType::Float)?
    };
    modify_geometry_sets(&mut g, &mut |s| {
        let Some(c) = s.curves.clone() else {
            return Ok(());
        };
        let r = eval_fields(
            ComponentRef::Curves(&c),
            Domain::Curve,
            &[
                (&sel, DataType::Bool),
                (&count, DataType::Int),
                (&length, DataType::Float),
            ],
        )?;
        if r[0].as_bool().iter().any(|x| !x) {
            return Err("resampling only some curves (a Selection) is not supported yet".into());
        }
        let m = match mode.as_str() {
            "COUNT" => ResampleMode::Count(r[1].as_int().into_owned()),
            "LENGTH" => {
                ResampleMode::Length(r[2].as_float().iter().map(|l| l.max(0.0001)).collect())
            }
            "EVALUATED" => ResampleMode::Evaluated,
            other => return Err(format!("mode {other} is not supported")),
        };
        s.curves = Some(Arc::new(resample(&c, m)?));
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Curve", geo(g))]))
}

/// Set Curve Radius / Set Curve Tilt: a float point attribute from a field, selected points.
fn set_point_float(
    ctx: &NodeCtx,
    input: &str,
    attr: &str,
    default: f32,
) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Curve")?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    let value = ctx.field(input, DataType::Float)?;
    modify_geometry_sets(&mut g, &mut |s| {
        let Some(c) = s.curves.clone() else {
            return Ok(());
        };
        let r = eval_fields(
            ComponentRef::Curves(&c),
            Domain::Point,
            &[(&sel, DataType::Bool), (&value, DataType::Float)],
        )?;
        let (sel, v) = (r[0].as_bool(), r[1].as_float());
        let mut cur = match c.attributes.named(attr) {
            Some(a) => ComponentRef::Curves(&c)
                .adapt(&a.data, a.domain, Domain::Point)
                .as_float()
                .into_owned(),
            None => vec![default; c.point_count()],
        };
        for i in 0..cur.len() {
            if sel[i] {
                cur[i] = v[i];
            }
        }
        s.curves_mut().unwrap().attributes.set(
            AttrId::named(attr),
            Domain::Point,
            Array::Float(cur),
        );
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Curve", geo(g))]))
}

pub fn set_curve_radius(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    set_point_float(ctx, "Radius", "radius", 1.0)
}

pub fn set_curve_tilt(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    set_point_float(ctx, "Tilt", "tilt", 0.0)
}

fn is_builtin_curve_attribute(n: &str) -> bool {
    matches!(
        n,
        "position"
            | "radius"
            | "tilt"
            | "handle_left"
            | "handle_right"
            | "handle_type_left"
            | "handle_type_right"
            | "nurbs_weight"
            | "normal_mode"
            | "curve_type"
            | "cyclic"
            | "resolution"
            | "nurbs_order"
            | "knots_mode"
            | "custom_normal"
    )
}

/// `bke::curves::segments_num`: a one-point curve has no segment, cyclic or not.
fn segments(n: usize, cyclic: bool) -> usize {
    if cyclic && n > 1 {
        n
    } else {
        n.saturating_sub(1)
    }
}

/// Sweeps every profile curve along every main curve (main curves outer, profiles inner),
/// with Blender's vertex, edge, face and corner order (`bke::curve_to_mesh_sweep`).
// Long because it follows Blender's curve-to-mesh sweep step by step.
fn sweep(
    main: &Curves,
    scale_field: &[f32],
    profile: Option<&Curves>,
    fill_caps: bool,
) -> Result<Mesh, String> {
    let mev = Evaluated::new(main)?;
    let mpos = mev.positions(main);
    let mtan = mev.tangents(main, &mpos);
    let mnorm = mev.normals(main, &mtan)?;
    let mscale = mev
        .interpolate(main, &Array::Float(scale_field.to_vec()))?
        .as_float()
        .into_owned();
    // Without a profile Blender sweeps a single point at the origin.
    let default_profile;
    let profile = match profile {
        Some(p) => p,
        None => {
            default_profile = Curves {
                positions: vec![[0.0; 3]],
                curve_offsets: vec![0, 1],
                attributes: {
                    let mut a = super::super::attribute::Attributes::default();
                    a.set(
                        AttrId::named("curve_type"),
                        Domain::Curve,
                        Array::Int8(vec![CURVE_TYPE_POLY]),
                    );
                    a
                },
                materials: Vec::new(),
            };
            &default_profile
        }
    };
    let pev = Evaluated::new(profile)?;
    let ppos = pev.positions(profile);
    let mut m = Mesh::new();
    // Caps are flat-shaded n-gons with sharp rims (edge and face indices).
    let mut sharp_edges: Vec<u32> = Vec::new();
    let mut sharp_faces: Vec<u32> = Vec::new();
    for im in 0..main.curve_count() {
        let mr = mev.range(im);
        let mcyc = mev.cyclic[im];
        let mn = mr.len();
        let mseg = segments(mn, mcyc);
        for ip in 0..profile.curve_count() {
            let pr = pev.range(ip);
            let pcyc = pev.cyclic[ip];
            let pn = pr.len();
            let pseg = segments(pn, pcyc);
            let vert0 = m.positions.len() as u32;
            let edge0 = m.edges.len() as u32;
            for i in mr.clone() {
                // Blender 4.5's point matrix: the normal, the normalized cross product of
                // tangent and normal, the tangent, each scaled; a Free normal that is not
                // orthogonal to the tangent stays as it is (measured: Curve to Mesh of
                // gn_curve_normal_free's curves).
                let s = mscale[i];
                let t = scale(mtan[i], s);
                let n = scale(mnorm[i], s);
                let b = scale(normalize(cross(mtan[i], mnorm[i])), s);
                for j in pr.clone() {
                    let p = ppos[j];
                    // `transform_point`: the 3x3 part times the point, then the location.
                    let v = add(
                        add(add(scale(n, p[0]), scale(b, p[1])), scale(t, p[2])),
                        mpos[i],
                    );
                    m.positions.push(v);
                }
            }
            if pn == 1 {
                for i in 0..mseg {
                    let next = if i + 1 == mn { 0 } else { i + 1 };
                    m.edges.push([vert0 + i as u32, vert0 + next as u32]);
                }
                continue;
            }
            // Edges along the curve, one run per profile point; then the rings.
            for jp in 0..pn {
                for i in 0..mseg {
                    let next = if i + 1 == mn { 0 } else { i + 1 };
                    m.edges.push([
                        vert0 + (pn * i + jp) as u32,
                        vert0 + (pn * next + jp) as u32,
                    ]);
                }
            }
            let ring_edges = edge0 + (pn * mseg) as u32;
            for i in 0..mn {
                for jp in 0..pseg {
                    let nj = if jp + 1 == pn { 0 } else { jp + 1 };
                    m.edges
                        .push([vert0 + (pn * i + jp) as u32, vert0 + (pn * i + nj) as u32]);
                }
            }
            for i in 0..mseg {
                let ni = if i + 1 == mn { 0 } else { i + 1 };
                let ring_v = vert0 + (pn * i) as u32;
                let next_ring_v = vert0 + (pn * ni) as u32;
                let ring_e = ring_edges + (pseg * i) as u32;
                let next_ring_e = ring_edges + (pseg * ni) as u32;
                for jp in 0..pseg {
                    let nj = if jp + 1 == pn { 0 } else { jp + 1 };
                    let main_e = edge0 + (mseg * jp) as u32;
                    let next_main_e = edge0 + (mseg * nj) as u32;
                    m.corner_verts.extend([
                        ring_v + jp as u32,
                        ring_v + nj as u32,
                        next_ring_v + nj as u32,
                        next_ring_v + jp as u32,
                    ]);
                    m.corner_edges.extend([
                        ring_e + jp as u32,
                        next_main_e + i as u32,
                        next_ring_e + jp as u32,
                        main_e + i as u32,
                    ]);
                    m.face_offsets.push(m.corner_verts.len() as u32);
                }
            }
            if fill_caps && !mcyc && pcyc {
                let last_ring_v = vert0 + (pn * (mn - 1)) as u32;
                let last_ring_e = ring_edges + (pseg * (mn - 1)) as u32;
                sharp_edges.extend(ring_edges..ring_edges + pseg as u32);
                sharp_edges.extend(last_ring_e..last_ring_e + pseg as u32);
                let f0 = m.face_count() as u32;
                sharp_faces.extend([f0, f0 + 1]);
                for k in 0..pseg {
                    let inv = pseg - k - 1;
                    m.corner_verts.push(vert0 + inv as u32);
                    m.corner_edges
                        .push(ring_edges + if k == pseg - 1 { pseg - 1 } else { inv - 1 } as u32);
                }
                m.face_offsets.push(m.corner_verts.len() as u32);
                for k in 0..pseg {
                    m.corner_verts.push(last_ring_v + k as u32);
                    m.corner_edges.push(last_ring_e + k as u32);
                }
                m.face_offsets.push(m.corner_verts.len() as u32);
            }
        }
    }
    // Main curves' own point attributes on the vertices of each ring (built-in curve
    // attributes are not mesh attributes and stay behind, as in Blender).
    for a in main.attributes.iter() {
        if a.domain != Domain::Point || a.id.name().is_some_and(is_builtin_curve_attribute) {
            continue;
        }
        let evaluated = mev.interpolate(main, &a.data)?;
        let mut idx = Vec::with_capacity(m.vertex_count());
        for im in 0..main.curve_count() {
            for ip in 0..profile.curve_count() {
                let pn = pev.range(ip).len();
                for i in mev.range(im) {
                    idx.extend(std::iter::repeat_n(i, pn));
                }
            }
        }
        m.attributes
            .set(a.id.clone(), Domain::Point, evaluated.gather(&idx));
    }
    // Main curves' own curve attributes on every vertex of the curve's rings (Blender puts
    // generic attributes on the mesh's point domain).
    for a in main.attributes.iter() {
        if a.domain != Domain::Curve || a.id.name().is_some_and(is_builtin_curve_attribute) {
            continue;
        }
        let mut idx = Vec::with_capacity(m.vertex_count());
        for im in 0..main.curve_count() {
            for ip in 0..profile.curve_count() {
                let n = pev.range(ip).len() * mev.range(im).len();
                idx.extend(std::iter::repeat_n(im, n));
            }
        }
        m.attributes
            .set(a.id.clone(), Domain::Point, a.data.gather(&idx));
    }
    if !sharp_faces.is_empty() {
        let mut e = vec![false; m.edge_count()];
        for i in sharp_edges {
            e[i as usize] = true;
        }
        let mut f = vec![false; m.face_count()];
        for i in sharp_faces {
            f[i as usize] = true;
        }
        m.attributes
            .set(AttrId::named("sharp_edge"), Domain::Edge, Array::Bool(e));
        m.attributes
            .set(AttrId::named("sharp_face"), Domain::Face, Array::Bool(f));
    }
    m.materials = main.materials.clone();
    Ok(m)
}

/// Blender's mesh of curves alone (`curve_to_wire_mesh`, what `Object.to_mesh` gives for a
/// curve object without bevel or extrusion): the evaluated points as vertices, the
/// segments as edges, no faces.
pub fn curves_to_wire_mesh(c: &Curves) -> Result<Mesh, String> {
    sweep(c, &vec![1.0; c.point_count()], None, false)
}

pub fn curve_to_mesh(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Curve")?;
    let profile_set = ctx.geometry("Profile Curve")?;
    let fill_caps = ctx.bool("Fill Caps")?;
    let scale_f = if ctx.has_input("Scale") {
        Some(ctx.field("Scale", DataType::Float)?)
    } else {
        None
    };
    if profile_set.instances.is_some() {
        return Err(ctx
            .err("a Profile Curve with instances is not supported (Blender realizes them first)"));
    }
    let profile = profile_set.curves.clone();
    modify_geometry_sets(&mut g, &mut |s| {
        // Blender replaces the mesh with the swept curves (none without curves) and keeps
        // only meshes (and instances) in each geometry.
        let mesh = match s.curves.clone() {
            Some(c) => {
                let sc = match &scale_f {
                    Some(f) => eval_fields(
                        ComponentRef::Curves(&c),
                        Domain::Point,
                        &[(f, DataType::Float)],
                    )?
                    .remove(0)
                    .as_float()
                    .into_owned(),
                    None => vec![1.0; c.point_count()],
                };
                Some(Arc::new(sweep(&c, &sc, profile.as_deref(), fill_caps)?))
            }
            None => None,
        };
        s.curves = None;
        s.points = None;
        s.mesh = mesh;
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Mesh", geo(g))]))
}
