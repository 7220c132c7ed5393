//! RGB Curves, Vector Curves and Float Curve: Blender's CurveMapping as Cycles sees it.
//!
//! Cycles never evaluates the Bézier curves itself. At sync time Blender rebuilds each
//! curve's own 257-entry table (`curvemap_make_table`: auto/vector handles, Bézier
//! segments forward-differenced at 32 steps, resampled at equal x), then Cycles samples
//! `BKE_curvemap_evaluateF` at 257 equal steps of the range spanned by the curves' end
//! points into its lookup table (for RGB Curves the combined C curve first, then R/G/B).
//! The kernel maps the input into that range, interpolates linearly, and extrapolates
//! from the first/last two entries when the mapping's extend mode is EXTRAPOLATED.
//! Clipping of the output and the black/white levels are not part of Cycles' path.

/// Blender's per-curve table resolution (`CM_TABLE`), and Bézier steps per segment
/// (`CM_RESOL`).
const CM_TABLE: usize = 256;
const CM_RESOL: usize = 32;
/// Cycles' lookup table size (`RAMP_TABLE_SIZE + 1`).
pub const CURVE_TABLE_SIZE: usize = 257;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HandleType {
    Auto,
    /// `AUTO_CLAMPED`: auto handles kept horizontal at extremes.
    AutoClamped,
    Vector,
}

impl HandleType {
    pub fn from_blender(id: &str) -> Option<Self> {
        match id {
            "AUTO" => Some(HandleType::Auto),
            "AUTO_CLAMPED" => Some(HandleType::AutoClamped),
            "VECTOR" => Some(HandleType::Vector),
            _ => None,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint {
    pub x: f32,
    pub y: f32,
    pub handle: HandleType,
    pub select: bool,
}

/// A CurveMapping's settings that shape its tables.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveMapping {
    /// `extend == "EXTRAPOLATED"`.
    pub extrapolate: bool,
    pub use_clip: bool,
    /// Clip rectangle: xmin, xmax, ymin, ymax.
    pub clip: [f32; 4],
    pub curves: Vec<Vec<CurvePoint>>,
}

/// One curve's Blender-side table (`CurveMap` after `curvemap_make_table`).
struct CurveMapTable {
    mintable: f32,
    /// 1 / (table step).
    range: f32,
    /// (x, y) of CM_TABLE + 1 entries.
    table: [[f32; 2]; CM_TABLE + 1],
    ext_in: [f32; 2],
    ext_out: [f32; 2],
}

#[derive(Clone, Copy, Default)]
struct Bez {
    /// Left handle, point, right handle.
    vec: [[f32; 2]; 3],
    h: u8,
}

const HD_AUTO: u8 = 1;
const HD_VECT: u8 = 2;
const HD_AUTO_ANIM: u8 = 4;

fn len2(v: [f32; 2]) -> f32 {
    (v[0] * v[0] + v[1] * v[1]).sqrt()
}

/// Blender's `calchandle_curvemap` (the same handle type on both sides).
fn calc_handle(b: &mut Bez, prev: Option<Bez>, next: Option<Bez>) {
    let p2 = b.vec[1];
    let p1 = match prev {
        Some(p) => p.vec[1],
        None => {
            let p3 = next.unwrap().vec[1];
            [2.0 * p2[0] - p3[0], 2.0 * p2[1] - p3[1]]
        }
    };
    let p3 = match next {
        Some(n) => n.vec[1],
        None => {
            let p1 = prev.unwrap().vec[1];
            [2.0 * p2[0] - p1[0], 2.0 * p2[1] - p1[1]]
        }
    };
    let dvec_a = [p2[0] - p1[0], p2[1] - p1[1]];
    let dvec_b = [p3[0] - p2[0], p3[1] - p2[1]];
    let mut len_a = len2(dvec_a);
    let mut len_b = len2(dvec_b);
    if len_a == 0.0 {
        len_a = 1.0;
    }
    if len_b == 0.0 {
        len_b = 1.0;
    }
    if b.h == HD_AUTO || b.h == HD_AUTO_ANIM {
        let tvec = [
            dvec_b[0] / len_b + dvec_a[0] / len_a,
            dvec_b[1] / len_b + dvec_a[1] / len_a,
        ];
        let len = len2(tvec) * 2.5614;
        if len != 0.0 {
            let la = len_a / len;
            b.vec[0] = [p2[0] + tvec[0] * -la, p2[1] + tvec[1] * -la];
            if let (true, Some(pv), Some(nx)) = (b.h == HD_AUTO_ANIM, prev, next) {
                let yd1 = pv.vec[1][1] - b.vec[1][1];
                let yd2 = nx.vec[1][1] - b.vec[1][1];
                if (yd1 <= 0.0 && yd2 <= 0.0) || (yd1 >= 0.0 && yd2 >= 0.0) {
                    b.vec[0][1] = b.vec[1][1];
                } else if yd1 <= 0.0 {
                    b.vec[0][1] = pv.vec[1][1].max(b.vec[0][1]);
                } else {
                    b.vec[0][1] = pv.vec[1][1].min(b.vec[0][1]);
                }
            }
            let lb = len_b / len;
            b.vec[2] = [p2[0] + tvec[0] * lb, p2[1] + tvec[1] * lb];
            if let (true, Some(pv), Some(nx)) = (b.h == HD_AUTO_ANIM, prev, next) {
                let yd1 = pv.vec[1][1] - b.vec[1][1];
                let yd2 = nx.vec[1][1] - b.vec[1][1];
                if (yd1 <= 0.0 && yd2 <= 0.0) || (yd1 >= 0.0 && yd2 >= 0.0) {
                    b.vec[2][1] = b.vec[1][1];
                } else if yd1 <= 0.0 {
                    b.vec[2][1] = nx.vec[1][1].min(b.vec[2][1]);
                } else {
                    b.vec[2][1] = nx.vec[1][1].max(b.vec[2][1]);
                }
            }
        }
    }
    if b.h == HD_VECT {
        let t = -1.0f32 / 3.0;
        b.vec[0] = [p2[0] + dvec_a[0] * t, p2[1] + dvec_a[1] * t];
        let t = 1.0f32 / 3.0;
        b.vec[2] = [p2[0] + dvec_b[0] * t, p2[1] + dvec_b[1] * t];
    }
}

/// `BKE_curve_correct_bezpart`: shortens both handles so the segment cannot loop in x.
fn correct_bezpart(v1: [f32; 2], v2: &mut [f32; 2], v3: &mut [f32; 2], v4: [f32; 2]) {
    let h1 = [v1[0] - v2[0], v1[1] - v2[1]];
    let h2 = [v4[0] - v3[0], v4[1] - v3[1]];
    let len = v4[0] - v1[0];
    let (len1, len2) = (h1[0].abs(), h2[0].abs());
    if len1 + len2 == 0.0 {
        return;
    }
    if len1 + len2 > len {
        let fac = len / (len1 + len2);
        *v2 = [v1[0] - fac * h1[0], v1[1] - fac * h1[1]];
        *v3 = [v4[0] - fac * h2[0], v4[1] - fac * h2[1]];
    }
}

/// `BKE_curve_forward_diff_bezier` with `it` steps, writing it + 1 values.
fn forward_diff(q0: f32, q1: f32, q2: f32, q3: f32, out: &mut [[f32; 2]], axis: usize) {
    let it = out.len() - 1;
    let mut f = it as f32;
    let rt0 = q0;
    let rt1 = 3.0 * (q1 - q0) / f;
    f *= f;
    let rt2 = 3.0 * (q0 - 2.0 * q1 + q2) / f;
    f *= it as f32;
    let rt3 = (q3 - q0 + 3.0 * (q1 - q2)) / f;
    let (mut a, mut b, mut c, d) = (rt0, rt1 + rt2 + rt3, 2.0 * rt2 + 6.0 * rt3, 6.0 * rt3);
    for p in out.iter_mut() {
        p[axis] = a;
        a += b;
        b += c;
        c += d;
    }
}

/// `curvemap_calc_extend`: beyond the first/last point, flat or along the end handle.
fn calc_extend(
    extrapolate: bool,
    t: &CurveMapTable,
    x: f32,
    first: [f32; 2],
    last: [f32; 2],
) -> f32 {
    if x <= first[0] {
        if !extrapolate {
            return first[1];
        }
        if t.ext_in[0] == 0.0 {
            return first[1] + t.ext_in[1] * 10000.0;
        }
        return first[1] + t.ext_in[1] * (x - first[0]) / t.ext_in[0];
    }
    if x >= last[0] {
        if !extrapolate {
            return last[1];
        }
        if t.ext_out[0] == 0.0 {
            return last[1] - t.ext_out[1] * 10000.0;
        }
        return last[1] + t.ext_out[1] * (x - last[0]) / t.ext_out[0];
    }
    0.0
}

impl CurveMapping {
    /// `BKE_curvemapping_changed` without edits: clip selected points into the clip
    /// rectangle (one shared shift, as Blender moves a selection), stable-sort by x.
    fn prepared(&self, points: &[CurvePoint]) -> Vec<CurvePoint> {
        let mut pts = points.to_vec();
        let [xmin, xmax, ymin, ymax] = self.clip;
        if self.use_clip {
            let (mut dx, mut dy) = (0.0f32, 0.0f32);
            for p in pts.iter().filter(|p| p.select) {
                if p.x < xmin {
                    dx = dx.min(p.x - xmin);
                } else if p.x > xmax {
                    dx = dx.max(p.x - xmax);
                }
                if p.y < ymin {
                    dy = dy.min(p.y - ymin);
                } else if p.y > ymax {
                    dy = dy.max(p.y - ymax);
                }
            }
            for p in pts.iter_mut().filter(|p| p.select) {
                p.x -= dx;
                p.y -= dy;
            }
        }
        pts.sort_by(|a, b| a.x.partial_cmp(&b.x).unwrap_or(std::cmp::Ordering::Equal));
        pts
    }

    /// `curvemap_make_table` (no wrapping: shader curve mappings never wrap).
    fn make_table(&self, points: &[CurvePoint]) -> CurveMapTable {
        let mut mintable = self.clip[0];
        let mut maxtable = self.clip[1];
        let n = points.len().max(2);
        let mut bezt = vec![Bez::default(); n];
        if points.len() >= 2 {
            for (b, p) in bezt.iter_mut().zip(points) {
                mintable = mintable.min(p.x);
                maxtable = maxtable.max(p.x);
                b.vec[1] = [p.x, p.y];
                b.h = match p.handle {
                    HandleType::Vector => HD_VECT,
                    HandleType::AutoClamped => HD_AUTO_ANIM,
                    HandleType::Auto => HD_AUTO,
                };
            }
        } else {
            mintable = 0.0;
            maxtable = 0.0;
            bezt[0].h = HD_AUTO;
            bezt[1].h = HD_AUTO;
        }
        let mut prev: Option<Bez> = None;
        for a in 0..n {
            let next = if a + 1 < n { Some(bezt[a + 1]) } else { None };
            let mut b = bezt[a];
            calc_handle(&mut b, prev, next);
            bezt[a] = b;
            prev = Some(b);
        }
        // End handles point at the neighbour's handle instead of its centre.
        if n > 2 {
            let fix = |b: &mut Bez, toward: [f32; 2], left: bool| {
                let hlen = if left {
                    len2(sub(b.vec[1], b.vec[2]))
                } else {
                    len2(sub(b.vec[1], b.vec[0]))
                };
                let mut v = toward;
                v[0] = if left {
                    v[0].max(b.vec[1][0])
                } else {
                    v[0].min(b.vec[1][0])
                };
                let v = sub(v, b.vec[1]);
                let nlen = len2(v);
                if nlen > f32::EPSILON {
                    let v = [v[0] * (hlen / nlen), v[1] * (hlen / nlen)];
                    if left {
                        b.vec[2] = [v[0] + b.vec[1][0], v[1] + b.vec[1][1]];
                        b.vec[0] = [b.vec[1][0] - v[0], b.vec[1][1] - v[1]];
                    } else {
                        b.vec[0] = [v[0] + b.vec[1][0], v[1] + b.vec[1][1]];
                        b.vec[2] = [b.vec[1][0] - v[0], b.vec[1][1] - v[1]];
                    }
                }
            };
            if bezt[0].h == HD_AUTO {
                let toward = bezt[1].vec[0];
                fix(&mut bezt[0], toward, true);
            }
            if bezt[n - 1].h == HD_AUTO {
                let toward = bezt[n - 2].vec[2];
                fix(&mut bezt[n - 1], toward, false);
            }
        }
        let mut all = vec![[0.0f32; 2]; (n - 1) * CM_RESOL];
        for a in 0..n - 1 {
            let (s, e) = (bezt[a], bezt[a + 1]);
            let (mut h1, mut h2) = (s.vec[2], e.vec[0]);
            correct_bezpart(s.vec[1], &mut h1, &mut h2, e.vec[1]);
            let seg = &mut all[a * CM_RESOL..(a + 1) * CM_RESOL];
            forward_diff(s.vec[1][0], h1[0], h2[0], e.vec[1][0], seg, 0);
            forward_diff(s.vec[1][1], h1[1], h2[1], e.vec[1][1], seg, 1);
        }
        let unit = |v: [f32; 2]| {
            let l = (v[0] * v[0] + v[1] * v[1]).sqrt();
            [v[0] / l, v[1] / l]
        };
        let ext_in = unit(sub(bezt[0].vec[0], bezt[0].vec[1]));
        let ext_out = unit(sub(bezt[n - 1].vec[1], bezt[n - 1].vec[2]));
        let step = (1.0 / CM_TABLE as f32) * (maxtable - mintable);
        let mut t = CurveMapTable {
            mintable,
            range: 1.0 / step,
            table: [[0.0; 2]; CM_TABLE + 1],
            ext_in,
            ext_out,
        };
        let (first, last) = (all[0], all[all.len() - 1]);
        let mut k = 0usize;
        let lastk = all.len() - 1;
        for a in 0..=CM_TABLE {
            let cur_x = mintable + step * a as f32;
            while cur_x >= all[k][0] && k != lastk {
                k += 1;
            }
            let y = if k == 0 || (k == lastk && cur_x >= all[k][0]) {
                if (cur_x - all[k][0]).abs() <= 1e-6 {
                    all[k][1]
                } else {
                    calc_extend(self.extrapolate, &t, cur_x, first, last)
                }
            } else {
                let mut fac1 = all[k][0] - all[k - 1][0];
                let fac2 = all[k][0] - cur_x;
                fac1 = if fac1 > f32::EPSILON {
                    fac2 / fac1
                } else {
                    0.0
                };
                fac1 * all[k - 1][1] + (1.0 - fac1) * all[k][1]
            };
            t.table[a] = [cur_x, y];
        }
        t
    }

    /// The range Cycles maps inputs into: first/last point x over the first `count`
    /// curves (`curvemapping_minmax`, on the points as stored).
    fn min_max(&self, count: usize) -> (f32, f32) {
        let (mut lo, mut hi) = (f32::MAX, -f32::MAX);
        for c in self.curves.iter().take(count) {
            if let (Some(f), Some(l)) = (c.first(), c.last()) {
                lo = lo.min(f.x);
                hi = hi.max(l.x);
            }
        }
        (lo, hi)
    }
}

fn sub(a: [f32; 2], b: [f32; 2]) -> [f32; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// `BKE_curvemap_evaluateF` on a Blender-side table.
fn evaluate(extrapolate: bool, t: &CurveMapTable, value: f32) -> f32 {
    let fi = (value - t.mintable) * t.range;
    if fi < 0.0 || fi > CM_TABLE as f32 {
        return calc_extend(extrapolate, t, value, t.table[0], t.table[CM_TABLE]);
    }
    let i = fi as i32;
    if i < 0 {
        return t.table[0][1];
    }
    if i as usize >= CM_TABLE {
        return t.table[CM_TABLE][1];
    }
    let i = i as usize;
    let f = fi - i as f32;
    (1.0 - f) * t.table[i][1] + f * t.table[i + 1][1]
}

/// Which node a curve table is for: decides the curves used and their composition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CurveKind {
    /// R, G, B after the combined C curve.
    Rgb,
    /// X, Y, Z.
    Vector,
    /// One curve.
    Float,
}

/// Cycles' per-node lookup table: 257 entries of up to three channels over
/// [min_x, max_x].
#[derive(Debug, Clone)]
pub struct CurveTable {
    pub min_x: f32,
    pub max_x: f32,
    pub extrapolate: bool,
    pub table: Vec<[f32; 3]>,
}

/// An error naming what is wrong with a curve mapping.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveError(pub String);

impl CurveTable {
    /// Bakes the table Cycles' Blender sync builds for this node kind.
    pub fn new(m: &CurveMapping, kind: CurveKind) -> Result<Self, CurveError> {
        let count = match kind {
            CurveKind::Rgb => 4,
            CurveKind::Vector => 3,
            CurveKind::Float => 1,
        };
        if m.curves.len() < count {
            return Err(CurveError(format!(
                "mapping has {} curves, {count} needed",
                m.curves.len()
            )));
        }
        if m.curves.iter().take(count).any(|c| c.is_empty()) {
            return Err(CurveError("a curve has no points".into()));
        }
        let (min_x, max_x) = m.min_max(count);
        let range = max_x - min_x;
        let tables: Vec<CurveMapTable> = m
            .curves
            .iter()
            .take(count)
            .map(|c| m.make_table(&m.prepared(c)))
            .collect();
        let ev = |c: usize, x: f32| evaluate(m.extrapolate, &tables[c], x);
        let size = CURVE_TABLE_SIZE - 1;
        let table = (0..=size)
            .map(|i| {
                let t = min_x + i as f32 / size as f32 * range;
                match kind {
                    CurveKind::Rgb => {
                        let c = ev(3, t);
                        [ev(0, c), ev(1, c), ev(2, c)]
                    }
                    CurveKind::Vector => [ev(0, t), ev(1, t), ev(2, t)],
                    CurveKind::Float => [ev(0, t), 0.0, 0.0],
                }
            })
            .collect();
        Ok(CurveTable {
            min_x,
            max_x,
            extrapolate: m.extrapolate,
            table,
        })
    }

    /// Cycles' `rgb_ramp_lookup` (interpolating) of channel `ch` at relative position f.
    fn lookup(&self, f: f32, ch: usize) -> f32 {
        let n = self.table.len();
        if !(0.0..=1.0).contains(&f) && self.extrapolate {
            let (t0, t1, f) = if f < 0.0 {
                (self.table[0][ch], self.table[1][ch], -f)
            } else {
                (self.table[n - 1][ch], self.table[n - 2][ch], f - 1.0)
            };
            return t0 + (t0 - t1) * f * (n - 1) as f32;
        }
        let f = f.clamp(0.0, 1.0) * (n - 1) as f32;
        // NaN becomes index 0, as the kernel's clamped int conversion does.
        let i = (f as i32).clamp(0, n as i32 - 1) as usize;
        let t = f - i as f32;
        let a = self.table[i][ch];
        if t > 0.0 {
            (1.0 - t) * a + t * self.table[i + 1][ch]
        } else {
            a
        }
    }

    /// RGB Curves / Vector Curves (`svm_node_curves`).
    pub fn eval3(&self, fac: f32, v: [f32; 3]) -> [f32; 3] {
        let range = self.max_x - self.min_x;
        let mut out = [0.0; 3];
        for ch in 0..3 {
            let r = self.lookup((v[ch] - self.min_x) / range, ch);
            out[ch] = (1.0 - fac) * v[ch] + fac * r;
        }
        out
    }

    /// Float Curve (`svm_node_curve`).
    pub fn eval1(&self, fac: f32, v: f32) -> f32 {
        let range = self.max_x - self.min_x;
        let r = self.lookup((v - self.min_x) / range, 0);
        (1.0 - fac) * v + fac * r
    }
}

/// Reads a CurveMapping as the exporter writes it (RNA names: `extend`, `use_clip`,
/// `clip_min_x`.., `curves[i].points[j].{location, handle_type, select}`).
pub fn mapping_from_json(v: &serde_json::Value) -> Result<CurveMapping, CurveError> {
    let bad = |m: String| CurveError(m);
    let num = |k: &str| {
        v.get(k)
            .and_then(serde_json::Value::as_f64)
            .map(|x| x as f32)
            .ok_or_else(|| bad(format!("mapping has no number {k}")))
    };
    let extrapolate = match v.get("extend").and_then(serde_json::Value::as_str) {
        Some("EXTRAPOLATED") => true,
        Some("HORIZONTAL") => false,
        other => return Err(bad(format!("mapping extend {other:?} is not supported"))),
    };
    let use_clip = v
        .get("use_clip")
        .and_then(serde_json::Value::as_bool)
        .unwrap_or(false);
    let clip = [
        num("clip_min_x")?,
        num("clip_max_x")?,
        num("clip_min_y")?,
        num("clip_max_y")?,
    ];
    let curves = v
        .get("curves")
        .and_then(serde_json::Value::as_array)
        .ok_or_else(|| bad("mapping has no curves".into()))?
        .iter()
        .enumerate()
        .map(|(ci, c)| {
            c.get("points")
                .and_then(serde_json::Value::as_array)
                .ok_or_else(|| bad(format!("curve {ci} has no points")))?
                .iter()
                .enumerate()
                .map(|(pi, p)| {
                    let loc = p.get("location").and_then(serde_json::Value::as_array);
                    let xy = loc
                        .filter(|l| l.len() >= 2)
                        .and_then(|l| Some([l[0].as_f64()? as f32, l[1].as_f64()? as f32]))
                        .ok_or_else(|| bad(format!("curve {ci} point {pi}: bad location")))?;
                    let ht = p
                        .get("handle_type")
                        .and_then(serde_json::Value::as_str)
                        .unwrap_or("AUTO");
                    let handle = HandleType::from_blender(ht).ok_or_else(|| {
                        bad(format!(
                            "curve {ci} point {pi}: handle type {ht:?} is not supported"
                        ))
                    })?;
                    let select = p
                        .get("select")
                        .and_then(serde_json::Value::as_bool)
                        .unwrap_or(false);
                    Ok(CurvePoint {
                        x: xy[0],
                        y: xy[1],
                        handle,
                        select,
                    })
                })
                .collect::<Result<Vec<_>, _>>()
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(CurveMapping {
        extrapolate,
        use_clip,
        clip,
        curves,
    })
}

/// One curve of a mapping as Blender itself evaluates it (`BKE_curvemapping_evaluateF`,
/// what Geometry Nodes' Float Curve uses): the curve's own table, then the clip range on
/// the output when clipping is on.
pub struct BlenderCurve {
    table: CurveMapTable,
    extrapolate: bool,
    clip_y: Option<[f32; 2]>,
}

impl BlenderCurve {
    pub fn new(m: &CurveMapping, index: usize) -> Result<Self, CurveError> {
        let c = m
            .curves
            .get(index)
            .filter(|c| !c.is_empty())
            .ok_or_else(|| CurveError(format!("mapping has no curve {index} with points")))?;
        let table = m.make_table(&m.prepared(c));
        Ok(BlenderCurve {
            table,
            extrapolate: m.extrapolate,
            clip_y: m.use_clip.then_some([m.clip[2], m.clip[3]]),
        })
    }
    /// `BKE_curvemap_evaluateF`: the curve alone, without the mapping's clipping (what
    /// Geometry Nodes' RGB and Vector Curves use per channel).
    pub fn eval_unclipped(&self, x: f32) -> f32 {
        evaluate(self.extrapolate, &self.table, x)
    }
    pub fn eval(&self, x: f32) -> f32 {
        let v = evaluate(self.extrapolate, &self.table, x);
        match self.clip_y {
            Some([lo, hi]) => v.clamp(lo, hi),
            None => v,
        }
    }
}
