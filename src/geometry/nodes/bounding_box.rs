//! Bounding Box: the axis-aligned box of the real geometry (mesh, point cloud and curve
//! positions) as a cube mesh, per geometry its instances reference, plus Min and Max of
//! the top level (`node_geo_bounding_box.cc`).

use super::super::attribute::AttrId;
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

fn bounds(g: &GeometrySet) -> Option<(V3, V3)> {
    let mut mn = [f32::INFINITY; 3];
    let mut mx = [f32::NEG_INFINITY; 3];
    let mut any = false;
    let mut add = |ps: &[V3]| {
        for p in ps {
            any = true;
            for k in 0..3 {
                mn[k] = mn[k].min(p[k]);
                mx[k] = mx[k].max(p[k]);
            }
        }
    };
    if let Some(m) = &g.mesh {
        add(&m.positions);
    }
    if let Some(p) = &g.points {
        add(&p.positions);
    }
    if let Some(c) = &g.curves {
        add(&c.positions);
    }
    any.then_some((mn, mx))
}

pub fn bounding_box(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry("Geometry")?;
    if ctx.has_input("Use Radius")
        && ctx.bool("Use Radius")?
        && (g.points.is_some() || g.curves.is_some())
    {
        return Err(ctx.err("Use Radius with points or curves is not supported yet"));
    }
    let (mn, mx) = bounds(&g).unwrap_or(([0.0; 3], [0.0; 3]));
    modify_geometry_sets(&mut g, &mut |s: &mut GeometrySet| {
        let b = bounds(s);
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
