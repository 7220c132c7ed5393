//! Bump mapping as Cycles does it: ray differentials around a shading point
//! (`kernel/util/differential.h`), the points the Height subgraph is evaluated at for its
//! dx/dy copies (the bump variants of the coordinate nodes), and the Bump, Displacement,
//! Vector Displacement and Normal Map nodes (`kernel/svm/displace.h`, `tex_coord.h`).

use crate::foundation::math::{
    transform_direction, transform_direction_transposed, transform_point, Vec3, V3,
};

use super::point::ShadingPoint;

/// An object's transform as a shading point needs it: rows of the 3x4 object-to-world
/// and world-to-object matrices. The default is the identity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectTransform {
    pub to_world: [[f32; 4]; 3],
    pub to_object: [[f32; 4]; 3],
}

const IDENTITY: [[f32; 4]; 3] = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
];

impl Default for ObjectTransform {
    fn default() -> Self {
        ObjectTransform {
            to_world: IDENTITY,
            to_object: IDENTITY,
        }
    }
}

impl ObjectTransform {
    /// Cycles' object_inverse_position_transform.
    pub fn inverse_point(&self, p: V3) -> V3 {
        transform_point(&self.to_object, p)
    }
    /// object_dir_transform / object_inverse_dir_transform.
    pub fn dir(&self, d: V3) -> V3 {
        transform_direction(&self.to_world, d)
    }
    pub fn inverse_dir(&self, d: V3) -> V3 {
        transform_direction(&self.to_object, d)
    }
    /// object_normal_transform: world normal from an object-space one.
    pub fn normal(&self, n: V3) -> V3 {
        normalize(transform_direction_transposed(&self.to_object, n))
    }
    /// object_inverse_normal_transform: object-space normal from a world one.
    pub fn inverse_normal(&self, n: V3) -> V3 {
        normalize(transform_direction_transposed(&self.to_world, n))
    }
}

/// Cycles' `normalize`: each component divided by the length (NaN for a zero vector).
pub fn normalize(v: V3) -> V3 {
    normalize_div(v.into()).into()
}

fn normalize_div(v: Vec3) -> Vec3 {
    v / v.length()
}

/// Cycles' `safe_normalize`: as `normalize`, a zero vector giving zero.
pub fn safe_normalize(v: V3) -> V3 {
    safe_normalize_div(v.into()).into()
}

fn safe_normalize_div(v: Vec3) -> Vec3 {
    let l = v.length();
    if l != 0.0 {
        v / l
    } else {
        Vec3::ZERO
    }
}

fn signf(x: f32) -> f32 {
    if x < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// Two unit tangents completing `n` to an orthonormal frame (Cycles' make_orthonormals:
/// (1,1,1) x N, or (-1,1,1) x N when N is on the diagonal), which decides the directions
/// a compact differential expands to. Bump results depend on it to second order.
pub fn make_orthonormals(n: Vec3) -> (Vec3, Vec3) {
    let a = if n.x != n.y || n.x != n.z {
        Vec3::new(n.z - n.y, n.x - n.z, n.y - n.x)
    } else {
        Vec3::new(n.z - n.y, n.x + n.z, -n.y - n.x)
    };
    let a = normalize_div(a);
    (a, n.cross(a))
}

/// A compact differential (a radius) as the two vectors Cycles expands it to around `d`.
pub fn differential_from_compact(d: V3, radius: f32) -> (V3, V3) {
    let (x, y) = make_orthonormals(d.into());
    ((x * radius).into(), (y * radius).into())
}

/// Cycles' differential_make_compact: the mean length of the two differentials.
pub fn differential_make_compact(dx: V3, dy: V3) -> f32 {
    0.5 * (Vec3::from(dx).length() + Vec3::from(dy).length())
}

/// Changes of the barycentric (u, v) of a triangle along `dp` (Cycles' differential_dudv,
/// Cramer's rule after dropping the axis the normal is largest along). `dpdu`, `dpdv` are
/// p1 - p0 and p2 - p0 (the point is (1-u-v) p0 + u p1 + v p2).
pub fn differential_dudv(mut dpdu: V3, mut dpdv: V3, mut dp: [V3; 2], ng: V3) -> [[f32; 2]; 2] {
    let (xn, yn, zn) = (ng[0].abs(), ng[1].abs(), ng[2].abs());
    if zn < xn || zn < yn {
        if yn < xn || yn < zn {
            dpdu[0] = dpdu[1];
            dpdv[0] = dpdv[1];
            dp[0][0] = dp[0][1];
            dp[1][0] = dp[1][1];
        }
        dpdu[1] = dpdu[2];
        dpdv[1] = dpdv[2];
        dp[0][1] = dp[0][2];
        dp[1][1] = dp[1][2];
    }
    let mut det = dpdu[0] * dpdv[1] - dpdv[0] * dpdu[1];
    if det != 0.0 {
        det = 1.0 / det;
    }
    // [[du/dx, dv/dx], [du/dy, dv/dy]]
    std::array::from_fn(|k| {
        [
            (dp[k][0] * dpdv[1] - dp[k][1] * dpdv[0]) * det,
            (dp[k][1] * dpdu[0] - dp[k][0] * dpdu[1]) * det,
        ]
    })
}

/// The change of a triangle attribute (values at corners `f`) for barycentric changes `d`.
pub fn attribute_differential(f: [V3; 3], d: [f32; 2]) -> V3 {
    let f = f.map(Vec3::from);
    ((f[1] - f[0]) * d[0] + (f[2] - f[0]) * d[1]).into()
}

/// Which of the three Height evaluations a bump program is running.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BumpPoint {
    Center,
    Dx,
    Dy,
}

/// The shading point as the coordinate nodes of a Bump's dx/dy copy see it: position,
/// object coordinates, Generated and UV moved by `width` times the differential (Cycles'
/// svm_node_bump_P_dx and the attribute nodes' bump variants). The normal stays.
pub fn offset_point(sp: &ShadingPoint, which: BumpPoint, width: f32) -> ShadingPoint {
    let (dp, dg, duv, d) = match which {
        BumpPoint::Center => return *sp,
        BumpPoint::Dx => (sp.dp_dx, sp.generated_dx, sp.uv_dx, 0),
        BumpPoint::Dy => (sp.dp_dy, sp.generated_dy, sp.uv_dy, 1),
    };
    let mut o = *sp;
    o.position = moved(sp.position, dp, width);
    o.object_position = sp.transform.inverse_point(o.position);
    o.generated = moved(sp.generated, dg, width);
    o.uv = moved(sp.uv, duv, width);
    // Mesh attributes extrapolated along the triangle, as Cycles' attribute bump nodes do
    // (f + df * width).
    for (a, da) in o.attrs.iter_mut().zip(&sp.attrs_d) {
        for k in 0..4 {
            a[k] += da[d][k] * width;
        }
    }
    for (f, df) in o.attr_fac.iter_mut().zip(&sp.attr_fac_d) {
        *f += df[d] * width;
    }
    o
}

/// `*sp = offset_point(base, which, width)` for an `sp` that equals `base` except in the
/// fields `offset_point` sets (as the program's point always does): writes only those.
/// The point is over a kilobyte, and its copies, three per Bump, showed as memmove in
/// the profile (docs/speed.md). The same operations, so the same bits.
pub fn offset_point_into(sp: &mut ShadingPoint, base: &ShadingPoint, which: BumpPoint, width: f32) {
    let (dp, dg, duv, d) = match which {
        BumpPoint::Center => {
            sp.position = base.position;
            sp.object_position = base.object_position;
            sp.generated = base.generated;
            sp.uv = base.uv;
            sp.attrs = base.attrs;
            sp.attr_fac = base.attr_fac;
            return;
        }
        BumpPoint::Dx => (base.dp_dx, base.generated_dx, base.uv_dx, 0),
        BumpPoint::Dy => (base.dp_dy, base.generated_dy, base.uv_dy, 1),
    };
    sp.position = moved(base.position, dp, width);
    sp.object_position = base.transform.inverse_point(sp.position);
    sp.generated = moved(base.generated, dg, width);
    sp.uv = moved(base.uv, duv, width);
    for ((a, b), da) in sp.attrs.iter_mut().zip(&base.attrs).zip(&base.attrs_d) {
        for k in 0..4 {
            a[k] = b[k] + da[d][k] * width;
        }
    }
    for ((f, b), df) in sp
        .attr_fac
        .iter_mut()
        .zip(&base.attr_fac)
        .zip(&base.attr_fac_d)
    {
        *f = b + df[d] * width;
    }
}

/// `p` moved by `width` times the differential `d`.
fn moved(p: V3, d: V3, width: f32) -> V3 {
    (Vec3::from(p) + Vec3::from(d) * width).into()
}

/// The Bump node's settings that are not stack values.
#[derive(Debug, Clone, Copy)]
pub struct BumpSettings {
    pub invert: bool,
    pub object_space: bool,
    pub filter_width: f32,
}

/// Cycles' svm_node_set_bump: the normal perturbed by the finite differences of the
/// height sampled at the centre and at the dx/dy points.
#[allow(clippy::too_many_arguments)]
pub fn bump_normal(
    sp: &ShadingPoint,
    set: BumpSettings,
    normal_in: V3,
    strength: f32,
    distance: f32,
    h_c: f32,
    h_x: f32,
    h_y: f32,
) -> V3 {
    let (mut n, mut dx, mut dy) = (normal_in, sp.dp_dx, sp.dp_dy);
    if set.object_space {
        n = sp.transform.inverse_normal(n);
        dx = sp.transform.inverse_dir(dx);
        dy = sp.transform.inverse_dir(dy);
    }
    let (n, dx, dy) = (Vec3::from(n), Vec3::from(dx), Vec3::from(dy));
    let rx = dy.cross(n);
    let ry = n.cross(dx);
    let det = dx.dot(rx);
    let surfgrad = rx * (h_x - h_c) + ry * (h_y - h_c);
    let absdet = det.abs();
    let scale = if set.invert { -distance } else { distance };
    let strength = strength.max(0.0);
    let mut out =
        safe_normalize_div(n * (set.filter_width * absdet) - surfgrad * (scale * signf(det)));
    if out == Vec3::ZERO {
        out = n;
    } else {
        out = normalize_div(out * strength + n * (1.0 - strength));
    }
    if set.object_space {
        return sp.transform.normal(out.into());
    }
    out.into()
}

/// Displacement node: the offset along the normal, world or object space.
pub fn displacement(
    sp: &ShadingPoint,
    object_space: bool,
    height: f32,
    midlevel: f32,
    scale: f32,
    normal: V3,
) -> V3 {
    let k = (height - midlevel) * scale;
    if object_space {
        let n = Vec3::from(sp.transform.inverse_normal(normal));
        sp.transform.dir((n * k).into())
    } else {
        (Vec3::from(normal) * k).into()
    }
}

/// The spaces of the Vector Displacement and Normal Map nodes (Cycles' NodeNormalMapSpace).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MapSpace {
    Tangent,
    Object,
    World,
    BlenderObject,
    BlenderWorld,
}

impl MapSpace {
    pub fn from_blender(s: &str) -> Option<MapSpace> {
        Some(match s {
            "TANGENT" => MapSpace::Tangent,
            "OBJECT" => MapSpace::Object,
            "WORLD" => MapSpace::World,
            "BLENDER_OBJECT" => MapSpace::BlenderObject,
            "BLENDER_WORLD" => MapSpace::BlenderWorld,
            _ => return None,
        })
    }
}

/// Vector Displacement in object or world space (tangent space needs tangents).
pub fn vector_displacement(
    sp: &ShadingPoint,
    space: MapSpace,
    vector: V3,
    midlevel: f32,
    scale: f32,
) -> V3 {
    let d = ((Vec3::from(vector) - Vec3::splat(midlevel)) * scale).into();
    match space {
        MapSpace::World => d,
        _ => sp.transform.dir(d),
    }
}

/// Normal Map in the non-tangent spaces (Cycles' svm_node_normal_map): the colour read as
/// a normal, then blended toward the shading normal by strength.
pub fn normal_map(sp: &ShadingPoint, space: MapSpace, color: V3, strength: f32) -> V3 {
    let mut c = (Vec3::from(color) - Vec3::splat(0.5)) * 2.0;
    if matches!(space, MapSpace::BlenderObject | MapSpace::BlenderWorld) {
        c.y = -c.y;
        c.z = -c.z;
    }
    let mut n = match space {
        MapSpace::Object | MapSpace::BlenderObject => sp.transform.normal(c.into()).into(),
        _ => safe_normalize_div(c),
    };
    // Cycles 4.5 blends by strength before turning the normal to a back face's side.
    if strength != 1.0 {
        let s = strength.max(0.0);
        let normal = Vec3::from(sp.normal);
        n = safe_normalize_div(normal + (n - normal) * s);
    }
    if sp.backfacing {
        n *= -1.0;
    }
    // Only a zero normal falls back (is_zero): a NaN from normalising a zero object-space
    // vector stays, as in Cycles, and the closures given it reflect nothing.
    if n == Vec3::ZERO {
        return sp.normal;
    }
    n.into()
}

/// The normal the displacement bump gives every closure: heights are the displacement
/// projected on the unperturbed normal (Cycles' bump_from_displacement: distance 1,
/// strength 1, the Bump node's default filter width).
pub fn displacement_bump(sp: &ShadingPoint, object_space: bool, d_c: V3, d_x: V3, d_y: V3) -> V3 {
    let n = sp.normal;
    let along = |d: V3| Vec3::from(d).dot(n.into());
    let set = BumpSettings {
        invert: false,
        object_space,
        filter_width: DEFAULT_FILTER_WIDTH,
    };
    bump_normal(sp, set, n, 1.0, 1.0, along(d_c), along(d_x), along(d_y))
}

/// Cycles' BumpNode default filter width, used by the displacement bump.
pub const DEFAULT_FILTER_WIDTH: f32 = 0.1;

#[cfg(test)]
mod offset_tests {
    use super::*;

    /// The in-place move the program uses equals `offset_point` from the base point in
    /// every field, whatever point the program moved to before.
    #[test]
    fn offset_point_into_equals_offset_point() {
        let f = |k: f32| [0.3 * k + 0.1, -0.7 * k, 1.9 + k];
        let mut base = ShadingPoint {
            position: f(1.0),
            object_position: f(2.0),
            generated: f(3.0),
            uv: f(4.0),
            dp_dx: f(5.0),
            dp_dy: f(6.0),
            generated_dx: f(7.0),
            generated_dy: f(8.0),
            uv_dx: f(9.0),
            uv_dy: f(10.0),
            normal: f(11.0),
            ..ShadingPoint::default()
        };
        for i in 0..base.attrs.len() {
            let k = i as f32;
            base.attrs[i] = [k, -k, 0.5 * k, 1.0 + k];
            base.attr_fac[i] = 0.25 + k;
            base.attrs_d[i] = [[0.1 * k, 0.2, -0.3, k], [k, 0.7, -0.1 * k, 2.0]];
            base.attr_fac_d[i] = [0.01 * k + 0.5, -0.2 * k];
        }
        let mut sp = base;
        for which in [
            BumpPoint::Dx,
            BumpPoint::Dy,
            BumpPoint::Center,
            BumpPoint::Dy,
            BumpPoint::Dx,
            BumpPoint::Center,
        ] {
            offset_point_into(&mut sp, &base, which, 0.37);
            assert_eq!(sp, offset_point(&base, which, 0.37), "{which:?}");
        }
    }
}
