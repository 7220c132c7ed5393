//! Bounding Box: the axis-aligned box of the real geometry (mesh and point cloud
//! positions, curves' evaluated points: `CurvesGeometry::bounds_min_max` measures those,
//! so a Bezier curve's box follows its segments, not its control points; with Use Radius
//! points and curve points are spheres of their radius) as a cube mesh,
//! per geometry its instances reference, plus Min and Max of the top level
//! (`node_geo_bounding_box.cc`).

use super::super::attribute::AttrId;
use super::super::curve_eval::Evaluated;
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::Field;
use super::super::math::V3;
use super::super::set::GeometrySet;
use super::super::types::Value;
use super::super::types::{Array, Domain};
use super::super::value::SocketValue;
use super::geometry_ops::modify_geometry_sets;
use super::primitives::{cuboid_mesh, cuboid_uvs_for};

/// Radii of points or curve points: the `radius` attribute, or Blender's default 0.01
/// for every point when there is none (a single value: the box is padded by it).
enum Radii {
    None,
    Single(f32),
    Each(Vec<f32>),
}

fn radii(attrs: &super::super::attribute::Attributes, use_radius: bool) -> Radii {
    if !use_radius {
        return Radii::None;
    }
    match attrs.named("radius") {
        Some(a) if a.domain == Domain::Point => Radii::Each(a.data.as_float().into_owned()),
        _ => Radii::Single(0.01),
    }
}

/// The box of the set's real geometry: mesh vertices, points and curves' evaluated
/// points, the latter two grown by their radii when `use_radius` (meshes have none).
fn bounds(g: &GeometrySet, use_radius: bool) -> Result<Option<(V3, V3)>, String> {
    let mut mn = [f32::INFINITY; 3];
    let mut mx = [f32::NEG_INFINITY; 3];
    let mut any = false;
    let mut add = |ps: &[V3], r: &Radii| {
        for (i, p) in ps.iter().enumerate() {
            any = true;
            let r = match r {
                Radii::None => 0.0,
                Radii::Single(r) => *r,
                Radii::Each(v) => v[i],
            };
            for k in 0..3 {
                mn[k] = mn[k].min(p[k] - r);
                mx[k] = mx[k].max(p[k] + r);
            }
        }
    };
    if let Some(m) = &g.mesh {
        add(&m.positions, &Radii::None);
    }
    if let Some(p) = &g.points {
        add(&p.positions, &radii(&p.attributes, use_radius));
    }
    if let Some(c) = &g.curves {
        if c.point_count() > 0 {
            let evaluated = Evaluated::new(c)?;
            let r = match radii(&c.attributes, use_radius) {
                // Radii are interpolated to the evaluated points as any point attribute.
                Radii::Each(v) => Radii::Each(
                    evaluated
                        .interpolate(c, &Array::Float(v))?
                        .as_float()
                        .into_owned(),
                ),
                r => r,
            };
            add(&evaluated.positions(c), &r);
        }
    }
    Ok(any.then_some((mn, mx)))
}

pub fn bounding_box(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    let use_radius = ctx.has_input("Use Radius") && ctx.bool("Use Radius")?;
    let (mn, mx) = bounds(&g, use_radius)
        .map_err(|e| ctx.err(e))?
        .unwrap_or(([0.0; 3], [0.0; 3]));
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let b = bounds(s, use_radius)?;
        let inst = s.instances.take();
        *s = GeometrySet::default();
        s.instances = inst;
        if let Some((lo, hi)) = b {
            let size = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
            let centre = [
                lo[0] + size[0] / 2.0,
                lo[1] + size[1] / 2.0,
                lo[2] + size[2] / 2.0,
            ];
            let mut m = cuboid_mesh(size, 2, 2, 2);
            // Blender names the box's UV map "uv_map".
            let uvs = cuboid_uvs_for(size);
            m.attributes
                .set(AttrId::named("uv_map"), Domain::Corner, Array::Float2(uvs));
            for p in m.positions.iter_mut() {
                for k in 0..3 {
                    p[k] += centre[k];
                }
            }
            s.mesh = Some(std::sync::Arc::new(m));
        }
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([
        ("Bounding Box", SocketValue::Geometry(g)),
        (
            "Min",
            SocketValue::Field(Field::Constant(Value::Vector(mn))),
        ),
        (
            "Max",
            SocketValue::Field(Field::Constant(Value::Vector(mx))),
        ),
    ]))
}
