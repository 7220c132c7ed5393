//! Nearest-element search as Blender's `BLI_bvhtree_find_nearest` callbacks do it: the
//! closest point on a triangle (`closest_on_tri_to_point_v3`) or segment
//! (`closest_to_line_segment_v3`) in single precision, and a bounding-box tree over the
//! elements that finds the one with the smallest squared distance.
//!
//! Blender keeps the first element its BVH visits among exactly equal distances, so its
//! choice at a tie depends on its tree's layout; here the lowest element index wins, which
//! is deterministic (the parity fixtures keep their sample points away from ties).

use crate::foundation::math::{dot, madd, sub};

use super::math::V3;

/// `len_squared_v3v3`.
#[inline]
pub fn dist_sq(a: V3, b: V3) -> f32 {
    let d = sub(a, b);
    dot(d, d)
}

/// `closest_to_line_segment_v3`: a zero-length segment gives its first point.
pub fn closest_on_segment(p: V3, a: V3, b: V3) -> V3 {
    let d = sub(b, a);
    let t = dot(d, sub(p, a)) / dot(d, d);
    if !(t > 0.0) {
        a
    } else if !(t < 1.0) {
        b
    } else {
        madd(a, d, t)
    }
}

/// `closest_on_tri_to_point_v3` (the Voronoi-region walk of Ericson's book).
pub fn closest_on_triangle(p: V3, a: V3, b: V3, c: V3) -> V3 {
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

/// `normal_tri_v3`: the unit normal of triangle (a, b, c), zero when degenerate.
pub fn normal_tri(a: V3, b: V3, c: V3) -> V3 {
    let n1 = sub(a, b);
    let n2 = sub(b, c);
    let n = [
        n1[1] * n2[2] - n1[2] * n2[1],
        n1[2] * n2[0] - n1[0] * n2[2],
        n1[0] * n2[1] - n1[1] * n2[0],
    ];
    super::math::normalize_v3(n).0
}

/// `interp_weights_tri_v3`: barycentric weights of `p` in triangle (a, b, c), from signed
/// areas in the plane of the normal's two smaller axes; a third each when degenerate.
pub fn interp_weights_tri(a: V3, b: V3, c: V3, p: V3) -> V3 {
    let n = normal_tri(a, b, c);
    let (xn, yn, zn) = (n[0].abs(), n[1].abs(), n[2].abs());
    let (i, j) = if zn >= xn && zn >= yn {
        (0, 1)
    } else if yn >= xn && yn >= zn {
        (0, 2)
    } else {
        (1, 2)
    };
    let area = |v1: V3, v2: V3, v3: V3| {
        0.5 * ((v1[i] - v2[i]) * (v2[j] - v3[j]) + (v1[j] - v2[j]) * (v3[i] - v2[i]))
    };
    let w = [area(b, c, p), area(c, a, p), area(a, b, p)];
    let total = w[0] + w[1] + w[2];
    let inv = 1.0 / total;
    let w = [w[0] * inv, w[1] * inv, w[2] * inv];
    if w.iter().all(|x| x.is_finite()) {
        w
    } else {
        [1.0 / 3.0; 3]
    }
}

#[derive(Clone, Copy)]
struct Node {
    min: V3,
    max: V3,
    /// Leaf: first entry in `order`; inner: index of the left child (right = left + 1).
    start: u32,
    /// Element count; 0 for inner nodes.
    count: u32,
}

/// A bounding-box tree over elements for nearest queries.
pub struct NearestTree {
    nodes: Vec<Node>,
    /// Element indices in leaf order.
    order: Vec<u32>,
}

const LEAF: usize = 4;

impl NearestTree {
    /// A tree over elements with these bounds (`(min, max)` per element).
    pub fn build(bounds: &[(V3, V3)]) -> NearestTree {
        let n = bounds.len();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = vec![Node {
            min: [0.0; 3],
            max: [0.0; 3],
            start: 0,
            count: n as u32,
        }];
        let mut stack = vec![0usize];
        let centre = |i: u32, a: usize| bounds[i as usize].0[a] + bounds[i as usize].1[a];
        while let Some(ni) = stack.pop() {
            let (start, count) = (nodes[ni].start as usize, nodes[ni].count as usize);
            let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            let (mut clo, mut chi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
            for &i in &order[start..start + count] {
                let (a, b) = bounds[i as usize];
                for k in 0..3 {
                    lo[k] = lo[k].min(a[k]);
                    hi[k] = hi[k].max(b[k]);
                    clo[k] = clo[k].min(centre(i, k));
                    chi[k] = chi[k].max(centre(i, k));
                }
            }
            nodes[ni].min = lo;
            nodes[ni].max = hi;
            if count <= LEAF {
                continue;
            }
            // Median split along the widest spread of element centres.
            let axis = (0..3)
                .max_by(|&a, &b| (chi[a] - clo[a]).total_cmp(&(chi[b] - clo[b])))
                .unwrap();
            let mid = count / 2;
            order[start..start + count].select_nth_unstable_by(mid, |&x, &y| {
                centre(x, axis).total_cmp(&centre(y, axis)).then(x.cmp(&y))
            });
            let left = nodes.len();
            nodes.push(Node {
                min: lo,
                max: hi,
                start: start as u32,
                count: mid as u32,
            });
            nodes.push(Node {
                min: lo,
                max: hi,
                start: (start + mid) as u32,
                count: (count - mid) as u32,
            });
            nodes[ni].start = left as u32;
            nodes[ni].count = 0;
            stack.push(left);
            stack.push(left + 1);
        }
        NearestTree { nodes, order }
    }

    /// The element with the smallest `dist(element)` (a squared distance from `q`, with any
    /// payload it computed along), the lowest index among equal ones; None when there are
    /// no elements or no distance is a number.
    pub fn nearest<T>(
        &self,
        q: V3,
        mut dist: impl FnMut(u32) -> (f32, T),
    ) -> Option<(u32, f32, T)> {
        if self.order.is_empty() {
            return None;
        }
        let mut best: Option<(u32, f32, T)> = None;
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(ni) = stack.pop() {
            let node = &self.nodes[ni as usize];
            // Box distances are rounded differently from element distances: prune only
            // boxes clearly beyond the best, so equal elements still meet the tie rule.
            if let Some((_, d, _)) = &best {
                if box_dist_sq(node, q) > *d * (1.0 + 1e-5) {
                    continue;
                }
            }
            if node.count > 0 {
                for &i in &self.order[node.start as usize..(node.start + node.count) as usize] {
                    let (d, payload) = dist(i);
                    let better = match &best {
                        None => !d.is_nan(),
                        Some((bi, bd, _)) => d < *bd || (d == *bd && i < *bi),
                    };
                    if better {
                        best = Some((i, d, payload));
                    }
                }
            } else {
                let (l, r) = (node.start, node.start + 1);
                let (dl, dr) = (
                    box_dist_sq(&self.nodes[l as usize], q),
                    box_dist_sq(&self.nodes[r as usize], q),
                );
                // The nearer child is searched first (pushed last).
                if dl <= dr {
                    stack.push(r);
                    stack.push(l);
                } else {
                    stack.push(l);
                    stack.push(r);
                }
            }
        }
        best
    }
}

fn box_dist_sq(n: &Node, q: V3) -> f32 {
    let mut d = 0.0f32;
    for k in 0..3 {
        let g = if q[k] < n.min[k] {
            n.min[k] - q[k]
        } else if q[k] > n.max[k] {
            q[k] - n.max[k]
        } else {
            0.0
        };
        d += g * g;
    }
    d
}

/// Bounds of a triangle or segment's corners.
pub fn bounds_of(points: &[V3]) -> (V3, V3) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tree_finds_what_a_scan_finds_and_lowest_index_on_ties() {
        // A pseudo-random cloud with duplicated points (exact ties).
        let mut s = 12345u32;
        let mut r = || {
            s = s.wrapping_mul(1664525).wrapping_add(1013904223);
            (s >> 8) as f32 / (1u32 << 24) as f32 - 0.5
        };
        let mut pts: Vec<V3> = (0..300).map(|_| [r(), r(), r()]).collect();
        pts.extend_from_slice(&pts.clone()[..50]);
        let tree = NearestTree::build(&pts.iter().map(|p| (*p, *p)).collect::<Vec<_>>());
        for _ in 0..200 {
            let q = [r() * 1.5, r() * 1.5, r() * 1.5];
            let (i, d, _) = tree
                .nearest(q, |i| (dist_sq(pts[i as usize], q), ()))
                .unwrap();
            let mut best = (0u32, f32::INFINITY);
            for (k, p) in pts.iter().enumerate() {
                let dk = dist_sq(*p, q);
                if dk < best.1 {
                    best = (k as u32, dk);
                }
            }
            assert_eq!((i, d), best);
        }
    }

    #[test]
    fn barycentric_weights_reproduce_the_point() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [2.0, 0.0, 0.5], [0.0, 1.0, 1.0]);
        let p = [0.5, 0.25, 0.375];
        let w = interp_weights_tri(a, b, c, p);
        for k in 0..3 {
            assert!((a[k] * w[0] + b[k] * w[1] + c[k] * w[2] - p[k]).abs() < 1e-6);
        }
        assert_eq!(interp_weights_tri(a, a, a, p), [1.0 / 3.0; 3]);
    }
}
