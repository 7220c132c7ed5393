//! Nearest-element search as Blender's `BLI_bvhtree_find_nearest` callbacks do it: the
//! closest point on a triangle (`closest_on_tri_to_point_v3`) or segment
//! (`closest_to_line_segment_v3`) in single precision, and the foundation's box tree
//! (`foundation::box_tree`) over the elements, which finds the one with the smallest
//! squared distance.
//!
//! Blender keeps the first element its BVH visits among exactly equal distances, so its
//! choice at a tie depends on its tree's layout; here the lowest element index wins, which
//! is deterministic (the parity fixtures keep their sample points away from ties).

use crate::foundation::box_tree::{BoxTree, Split};
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

/// The tree for nearest queries over elements with these bounds (`(min, max)` each), by
/// the split rule these queries' results were made with.
pub fn nearest_tree(bounds: &[(V3, V3)]) -> BoxTree {
    BoxTree::build(bounds, Split::MedianByIndex)
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
