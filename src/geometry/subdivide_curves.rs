//! Curve subdivision as Blender's `geometry::subdivide_curves`: each segment gets `cuts`
//! new points (the segment's first point's value), attributes interpolated linearly; Bezier
//! segments are split by De Casteljau so the shape stays (aligned handles on the new
//! points, vector segments kept straight); NURBS curves are treated as poly curves;
//! Catmull-Rom curves place the new points (and every point attribute) on their cubic.

use super::bezier_handles::calculate_auto_handles;
use super::curve_eval::{catmull_rom_array_segments, lerp_gather};
use super::curves::{
    Curves, CURVE_TYPE_BEZIER, CURVE_TYPE_CATMULL_ROM, HANDLE_ALIGN, HANDLE_AUTO, HANDLE_FREE,
    HANDLE_VECTOR,
};
use super::math::V3;
use super::types::{Array, Domain};

fn mix(a: V3, b: V3, t: f32) -> V3 {
    [
        a[0] * (1.0 - t) + b[0] * t,
        a[1] * (1.0 - t) + b[1] * t,
        a[2] * (1.0 - t) + b[2] * t,
    ]
}

/// One De Casteljau split of a Bezier segment at `t` (`bezier::insert`): the shortened
/// outer handles, the new point's handles and the new point.
fn insert(p0: V3, h0: V3, h1: V3, p1: V3, t: f32) -> (V3, V3, V3, V3, V3) {
    let centre = mix(h0, h1, t);
    let handle_prev = mix(p0, h0, t);
    let handle_next = mix(h1, p1, t);
    let left = mix(handle_prev, centre, t);
    let right = mix(centre, handle_next, t);
    (handle_prev, handle_next, left, right, mix(left, right, t))
}

/// A segment end's handle type after the split (`aligned_or_free_handle_type`).
fn aligned_or_free(t: i8) -> i8 {
    match t {
        HANDLE_AUTO | HANDLE_ALIGN => HANDLE_ALIGN,
        _ => HANDLE_FREE,
    }
}

/// Subdivides every curve; `cuts` is per point (the segment starting there).
pub fn subdivide_curves(c: &Curves, cuts: &[i32]) -> Result<Curves, String> {
    let types = c.ints("curve_type", Domain::Curve, 0);
    let cyclic = c.cyclic();
    // Per source point: its segment's first point in the result (within the curve), and
    // the result's curve offsets.
    let mut seg_start = vec![0usize; c.point_count()];
    let mut seg_len = vec![0usize; c.point_count()];
    let mut offsets = vec![0u32];
    for i in 0..c.curve_count() {
        let r = c.points(i);
        let mut acc = 0usize;
        for p in r.clone() {
            let count = if r.len() == 1 || (p + 1 == r.end && !cyclic[i]) {
                1
            } else {
                cuts[p].max(0) as usize + 1
            };
            seg_start[p] = acc;
            seg_len[p] = count;
            acc += count;
        }
        offsets.push(offsets[i] + acc as u32);
    }
    let total = *offsets.last().unwrap() as usize;
    // Linear interpolation of every point value: per result point, the two source points
    // and the factor.
    let (mut ia, mut ib, mut fac) = (
        Vec::with_capacity(total),
        Vec::with_capacity(total),
        Vec::with_capacity(total),
    );
    for i in 0..c.curve_count() {
        let r = c.points(i);
        for p in r.clone() {
            let next = if p + 1 == r.end { r.start } else { p + 1 };
            let step = 1.0 / seg_len[p] as f32;
            for k in 0..seg_len[p] {
                ia.push(p);
                ib.push(next);
                fac.push(k as f32 * step);
            }
        }
    }
    let mut out = Curves {
        positions: Vec::new(),
        curve_offsets: offsets,
        attributes: Default::default(),
        materials: c.materials.clone(),
    };
    out.positions = lerp_gather(&Array::Vector(c.positions.clone()), &ia, &ib, &fac)
        .as_vector()
        .into_owned();
    let catmull_rom = types.iter().any(|t| *t as i8 == CURVE_TYPE_CATMULL_ROM);
    if catmull_rom {
        let pos = Array::Vector(c.positions.clone());
        out.positions = catmull_rom_points(c, &types, &cyclic, &seg_start, &seg_len, &out, &pos)?
            .as_vector()
            .into_owned();
    }
    for a in c.attributes.iter() {
        let data = match a.domain {
            Domain::Curve => a.data.clone(),
            Domain::Point if catmull_rom => {
                catmull_rom_points(c, &types, &cyclic, &seg_start, &seg_len, &out, &a.data)?
            }
            Domain::Point => lerp_gather(&a.data, &ia, &ib, &fac),
            _ => continue,
        };
        out.attributes.set(a.id.clone(), a.domain, data);
    }
    if let (Some(hl), Some(hr)) = (
        c.point_vectors("handle_left"),
        c.point_vectors("handle_right"),
    ) {
        subdivide_bezier(c, &types, &cyclic, &seg_start, &hl, &hr, &mut out);
    }
    Ok(out)
}

/// A point attribute of the subdivided curves: Catmull-Rom curves' new points on their
/// cubic (`subdivide_attribute_catmull_rom`), the others' mixed linearly.
fn catmull_rom_points(
    c: &Curves,
    types: &[i32],
    cyclic: &[bool],
    seg_start: &[usize],
    seg_len: &[usize],
    out: &Curves,
    data: &Array,
) -> Result<Array, String> {
    let mut result = Array::zeros(data.data_type(), 0);
    for i in 0..c.curve_count() {
        let r = c.points(i);
        let count = out.points(i).len();
        let src = data.gather(&r.clone().collect::<Vec<_>>());
        let piece = if types[i] as i8 == CURVE_TYPE_CATMULL_ROM {
            let range =
                |s: usize| seg_start[r.start + s]..seg_start[r.start + s] + seg_len[r.start + s];
            catmull_rom_array_segments(&src, cyclic[i], count, &range).ok_or_else(|| {
                format!(
                    "curve {i}: a {:?} attribute cannot be subdivided along a Catmull-Rom curve",
                    data.data_type()
                )
            })?
        } else {
            let (mut ia, mut ib, mut fac) = (Vec::new(), Vec::new(), Vec::new());
            for p in 0..r.len() {
                let next = if p + 1 == r.len() { 0 } else { p + 1 };
                let step = 1.0 / seg_len[r.start + p] as f32;
                for k in 0..seg_len[r.start + p] {
                    ia.push(p);
                    ib.push(next);
                    fac.push(k as f32 * step);
                }
            }
            lerp_gather(&src, &ia, &ib, &fac)
        };
        result.extend(&piece);
    }
    Ok(result)
}

/// Positions, handles and handle types of the Bezier curves
/// (`subdivide_bezier_positions`), then Blender's derived handles.
fn subdivide_bezier(
    c: &Curves,
    types: &[i32],
    cyclic: &[bool],
    seg_start: &[usize],
    hl: &[V3],
    hr: &[V3],
    out: &mut Curves,
) {
    let tl = c.ints("handle_type_left", Domain::Point, 0);
    let tr = c.ints("handle_type_right", Domain::Point, 0);
    let mut dpos = out.positions.clone();
    let mut dhl = out.point_vectors("handle_left").unwrap_or_default();
    let mut dhr = out.point_vectors("handle_right").unwrap_or_default();
    let mut dtl: Vec<i8> = out
        .ints("handle_type_left", Domain::Point, 0)
        .iter()
        .map(|v| *v as i8)
        .collect();
    let mut dtr: Vec<i8> = out
        .ints("handle_type_right", Domain::Point, 0)
        .iter()
        .map(|v| *v as i8)
        .collect();
    for i in 0..c.curve_count() {
        if types[i] as i8 != CURVE_TYPE_BEZIER {
            continue;
        }
        let r = c.points(i);
        let d0 = out.points(i).start;
        let dn = out.points(i).len();
        let n = r.len();
        let segments = if cyclic[i] { n } else { n - 1 };
        for s in 0..segments {
            let (a, b) = (r.start + s, r.start + (s + 1) % n);
            let last_cyclic = s + 1 == n;
            let start = d0 + seg_start[a];
            let len = if s + 1 < n {
                seg_start[b] - seg_start[a]
            } else {
                dn - seg_start[a]
            };
            let after = if last_cyclic { d0 } else { start + len };
            let vector = tr[a] as i8 == HANDLE_VECTOR && tl[b] as i8 == HANDLE_VECTOR;
            if vector {
                // Positions are already linear; every handle of the segment is a vector one.
                dtr[start] = HANDLE_VECTOR;
                dtl[after] = HANDLE_VECTOR;
                for k in start + 1..start + len {
                    dtl[k] = HANDLE_VECTOR;
                    dtr[k] = HANDLE_VECTOR;
                }
                continue;
            }
            dpos[start] = c.positions[a];
            let (mut p0, mut h0, mut h1) = (c.positions[a], hr[a], hl[b]);
            let p1 = c.positions[b];
            for k in 0..len - 1 {
                let t = 1.0 / (len - k) as f32;
                let (hp, hn, left, right, pos) = insert(p0, h0, h1, p1, t);
                dhr[start + k] = hp;
                dhl[start + k + 1] = left;
                dpos[start + k + 1] = pos;
                p0 = pos;
                h0 = right;
                h1 = hn;
            }
            dhr[start + len - 1] = h0;
            dhl[after] = h1;
            // The segment's ends stay aligned where they can; new points are aligned.
            dtr[start] = aligned_or_free(tr[a] as i8);
            dtl[after] = aligned_or_free(tl[b] as i8);
            for k in start + 1..start + len {
                dtl[k] = HANDLE_ALIGN;
                dtr[k] = HANDLE_ALIGN;
            }
        }
        let (f, l) = (d0, d0 + dn - 1);
        if !cyclic[i] {
            dpos[l] = c.positions[r.end - 1];
            dtl[f] = tl[r.start] as i8;
            dtr[l] = tr[r.end - 1] as i8;
            dhl[f] = hl[r.start];
            dhr[l] = hr[r.end - 1];
        }
    }
    out.positions = dpos;
    out.attributes.set(
        super::attribute::AttrId::named("handle_left"),
        Domain::Point,
        Array::Vector(dhl),
    );
    out.attributes.set(
        super::attribute::AttrId::named("handle_right"),
        Domain::Point,
        Array::Vector(dhr),
    );
    out.set_i8("handle_type_left", Domain::Point, dtl);
    out.set_i8("handle_type_right", Domain::Point, dtr);
    calculate_auto_handles(out);
}
