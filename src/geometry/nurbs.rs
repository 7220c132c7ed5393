//! NURBS curve evaluation as Blender 4.5 does it (`bke::curves::nurbs`): knots from the
//! curve's knot mode, `resolution * segments` evaluated points spread evenly over the
//! knot range, each a Cox-de Boor basis combination of `order` control points (rational:
//! basis times `nurbs_weight`, normalized by the weight sum, as `DefaultMixer` mixes).
//! A curve with too few points for its order and knot mode evaluates to its control
//! points. Custom knots are refused by the caller.
//!
//! Used by Trim Curve, which trims NURBS curves on their evaluated points.

use super::math::V3;
use super::types::Array;

/// Blender's `KnotsMode` values as stored in the `knots_mode` curve attribute.
pub const KNOTS_NORMAL: i8 = 0;
pub const KNOTS_ENDPOINT: i8 = 1;
pub const KNOTS_BEZIER: i8 = 2;
pub const KNOTS_ENDPOINT_BEZIER: i8 = 3;
pub const KNOTS_CUSTOM: i8 = 4;

/// Basis weights of every evaluated point: `order` weights from `start[i]` on (control
/// point indices wrap for cyclic curves), or `None` when the curve evaluates to its
/// control points.
pub struct Basis {
    order: usize,
    weights: Vec<f32>,
    start: Vec<usize>,
}

fn valid(points: usize, order: usize, cyclic: bool, mode: i8) -> bool {
    if points < order {
        return false;
    }
    if mode == KNOTS_BEZIER || mode == KNOTS_ENDPOINT_BEZIER {
        if mode == KNOTS_BEZIER && points <= order {
            return false;
        }
        return !cyclic || points.is_multiple_of(order - 1);
    }
    true
}

fn knots(points: usize, mode: i8, order: usize, cyclic: bool) -> Vec<f32> {
    let n = if cyclic {
        points + order * 2 - 1
    } else {
        points + order
    };
    let is_bezier = mode == KNOTS_BEZIER || mode == KNOTS_ENDPOINT_BEZIER;
    let is_end_point = mode == KNOTS_ENDPOINT || mode == KNOTS_ENDPOINT_BEZIER;
    let repeat_inner = if is_bezier { order - 1 } else { 1 };
    let head = if is_end_point {
        order - cyclic as usize
    } else if is_bezier {
        repeat_inner.min(2)
    } else {
        1
    };
    let tail = if cyclic {
        2 * order - 1
    } else if is_end_point {
        order
    } else {
        0
    };
    let mut k = vec![0.0f32; n];
    let mut r = head;
    let mut current = 0.0f32;
    let offset = (is_end_point && cyclic) as usize;
    if offset == 1 {
        k[0] = current;
        current += 1.0;
    }
    for v in k.iter_mut().take(n - tail).skip(offset) {
        *v = current;
        r -= 1;
        if r == 0 {
            current += 1.0;
            r = repeat_inner;
        }
    }
    let tail_index = n - tail;
    for i in 0..tail {
        k[tail_index + i] = current + (k[i] - k[0]);
    }
    k
}

/// `calculate_basis_for_point`: Cox-de Boor for one parameter.
fn basis_for_point(t: f32, points: usize, degree: usize, knots: &[f32], out: &mut [f32]) -> usize {
    let order = degree + 1;
    let (mut start, mut end) = (0usize, 0usize);
    for i in 0..points + degree {
        if knots[i] == knots[i + 1] || t < knots[i] || t > knots[i + 1] {
            continue;
        }
        start = i.saturating_sub(degree);
        end = i;
        break;
    }
    let mut buf = [0.0f32; 2 * 16];
    buf[end - start] = 1.0;
    for i_order in 2..=degree + 1 {
        if end + i_order >= knots.len() {
            end = points + degree - i_order;
        }
        for i in 0..=end - start {
            let k = start + i;
            let mut b = 0.0f32;
            if buf[i] != 0.0 {
                b += ((t - knots[k]) * buf[i]) / (knots[k + i_order - 1] - knots[k]);
            }
            if buf[i + 1] != 0.0 {
                b += ((knots[k + i_order] - t) * buf[i + 1]) / (knots[k + i_order] - knots[k + 1]);
            }
            buf[i] = b;
        }
    }
    for v in buf.iter_mut().skip(end - start + 1) {
        *v = 0.0;
    }
    out.copy_from_slice(&buf[..order]);
    start
}

impl Basis {
    /// The basis of one curve, or `Ok(None)` when it evaluates to its control points.
    pub fn new(
        points: usize,
        order: i32,
        cyclic: bool,
        resolution: i32,
        mode: i8,
    ) -> Result<Option<Basis>, String> {
        if mode == KNOTS_CUSTOM {
            return Err("NURBS curves with custom knots are not supported".into());
        }
        if !(0..=KNOTS_ENDPOINT_BEZIER).contains(&mode) {
            return Err(format!("NURBS knot mode {mode} is not supported"));
        }
        if !(1..=16).contains(&order) {
            return Err(format!("NURBS order {order} is not supported"));
        }
        let order = order as usize;
        if points == 0 || !valid(points, order, cyclic, mode) {
            return Ok(None);
        }
        let segments = if cyclic { points } else { points - 1 };
        // Checked before allocating: a hostile resolution is an error, not an abort.
        super::limits::check(
            super::limits::product(&[resolution.max(0) as u64, segments as u64, order as u64]),
            "the NURBS curve's resolution",
        )?;
        let evaluated = resolution.max(0) as usize * segments;
        let degree = order - 1;
        let k = knots(points, mode, order, cyclic);
        let last = if cyclic { points + degree } else { points };
        let eval_segments = if cyclic {
            evaluated
        } else {
            evaluated.saturating_sub(1)
        };
        let (t0, t1) = (k[degree], k[last]);
        let step = (t1 - t0) / eval_segments as f32;
        let mut weights = vec![0.0f32; evaluated * order];
        let mut start = vec![0usize; evaluated];
        for i in 0..evaluated {
            // Clamped for floating point inaccuracy, as Blender does.
            let t = (t0 + step * i as f32).clamp(k[0], k[points + degree]);
            start[i] = basis_for_point(
                t,
                last,
                degree,
                &k,
                &mut weights[i * order..(i + 1) * order],
            );
        }
        Ok(Some(Basis {
            order,
            weights,
            start,
        }))
    }

    pub fn len(&self) -> usize {
        self.start.len()
    }

    pub fn is_empty(&self) -> bool {
        self.start.is_empty()
    }

    /// Per evaluated point: (control point, weight) pairs, the weights already multiplied
    /// by the control weights (`interpolate_to_evaluated_rational`).
    fn terms<'a>(
        &'a self,
        i: usize,
        n: usize,
        control_weights: Option<&'a [f32]>,
    ) -> impl Iterator<Item = (usize, f32)> + 'a {
        (0..self.order).map(move |j| {
            let p = (self.start[i] + j) % n;
            let w = self.weights[i * self.order + j];
            (p, control_weights.map_or(w, |cw| w * cw[p]))
        })
    }

    /// Evaluated positions (or any vectors) of one curve's control values.
    pub fn evaluate_vectors(&self, src: &[V3], control_weights: Option<&[f32]>) -> Vec<V3> {
        (0..self.len())
            .map(|i| {
                let (mut acc, mut total) = ([0.0f32; 3], 0.0f32);
                for (p, w) in self.terms(i, src.len(), control_weights) {
                    for k in 0..3 {
                        acc[k] += src[p][k] * w;
                    }
                    total += w;
                }
                if total > 0.0 {
                    let inv = 1.0 / total;
                    acc.map(|v| v * inv)
                } else {
                    [0.0; 3]
                }
            })
            .collect()
    }

    /// A point attribute of one curve (its control values) on the evaluated points, mixed
    /// as Blender's `DefaultMixer` does for the type; `None` for types it does not mix.
    pub fn evaluate(&self, src: &Array, control_weights: Option<&[f32]>) -> Option<Array> {
        let n = src.len();
        let lanes = |get: &dyn Fn(usize) -> Vec<f32>, width: usize| -> Vec<Vec<f32>> {
            (0..self.len())
                .map(|i| {
                    let mut acc = vec![0.0f32; width];
                    let mut total = 0.0f32;
                    for (p, w) in self.terms(i, n, control_weights) {
                        for (a, v) in acc.iter_mut().zip(get(p)) {
                            *a += v * w;
                        }
                        total += w;
                    }
                    if total > 0.0 {
                        let inv = 1.0 / total;
                        acc.iter_mut().for_each(|a| *a *= inv);
                    } else {
                        acc.iter_mut().for_each(|a| *a = 0.0);
                    }
                    acc
                })
                .collect()
        };
        Some(match src {
            Array::Float(v) => {
                Array::Float(lanes(&|p| vec![v[p]], 1).iter().map(|x| x[0]).collect())
            }
            Array::Float2(v) => Array::Float2(
                lanes(&|p| v[p].to_vec(), 2)
                    .iter()
                    .map(|x| [x[0], x[1]])
                    .collect(),
            ),
            Array::Vector(v) => Array::Vector(self.evaluate_vectors(v, control_weights)),
            Array::Color(v) => Array::Color(
                lanes(&|p| v[p].to_vec(), 4)
                    .iter()
                    .map(|x| [x[0], x[1], x[2], x[3]])
                    .collect(),
            ),
            // Integers and booleans accumulate as floats and round / threshold.
            Array::Int(v) => Array::Int(
                lanes(&|p| vec![v[p] as f32], 1)
                    .iter()
                    .map(|x| x[0].round() as i32)
                    .collect(),
            ),
            Array::Bool(v) => Array::Bool(
                lanes(&|p| vec![v[p] as u8 as f32], 1)
                    .iter()
                    .map(|x| x[0] >= 0.5)
                    .collect(),
            ),
            _ => return None,
        })
    }
}
