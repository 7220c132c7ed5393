//! Curve > Write: Set Spline Cyclic, Set Spline Resolution, Set Handle Type, Set Handle
//! Positions and Set Curve Normal (`node_geo_set_spline_cyclic`,
//! `node_geo_set_spline_resolution`, `node_geo_curve_set_handle_type`,
//! `node_geo_set_curve_handles`, `node_geo_set_curve_normal`). Derived (auto, vector,
//! aligned) handles are recomputed where Blender recomputes them.

use std::sync::Arc;

use super::super::attribute::AttrId;
use super::super::bezier_handles::{
    calculate_auto_handles, set_handle_position, types_for_movement, write_handles,
};
use super::super::curve_eval::{NORMAL_MODE_FREE, NORMAL_MODE_MINIMUM_TWIST, NORMAL_MODE_Z_UP};
use super::super::curves::{Curves, HANDLE_FREE};
use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::field::{ComponentRef, Field};
use super::super::math::add;
use super::super::types::{Array, DataType, Domain};
use super::curve_read::{handle_positions_field, handle_sides, handle_type};
use super::geometry_ops::{eval_fields, geo, modify_geometry_sets};
use crate::nodes::graph::Source;

/// An edit of one curves component, given its evaluated fields.
pub type CurvesEdit<'f> = dyn FnMut(&mut Curves, &[Array]) -> Result<(), String> + 'f;

/// Runs `f` on every curves component of the input `socket`, with `fields` evaluated on
/// `domain` of it.
pub fn edit_curves(
    ctx: &NodeCtx,
    socket: &str,
    domain: Domain,
    fields: &[(&Field, DataType)],
    f: &mut CurvesEdit,
) -> Result<Outputs, GeometryError> {
    let mut g = ctx.geometry(socket)?;
    modify_geometry_sets(&mut g, &mut |s| {
        let Some(c) = s.curves.clone() else {
            return Ok(());
        };
        let r = eval_fields(ComponentRef::Curves(&c), domain, fields)?;
        let mut c = Arc::unwrap_or_clone(c);
        f(&mut c, &r)?;
        s.curves = Some(Arc::new(c));
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([(socket, geo(g))]))
}

pub fn set_spline_cyclic(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let sel = ctx.field("Selection", DataType::Bool)?;
    let v = ctx.field("Cyclic", DataType::Bool)?;
    edit_curves(
        ctx,
        "Geometry",
        Domain::Curve,
        &[(&sel, DataType::Bool), (&v, DataType::Bool)],
        &mut |c, r| {
            let mut cur = c.cyclic();
            let (sel, v) = (r[0].as_bool(), r[1].as_bool());
            for i in 0..cur.len() {
                if sel[i] {
                    cur[i] = v[i];
                }
            }
            c.attributes
                .set(AttrId::named("cyclic"), Domain::Curve, Array::Bool(cur));
            Ok(())
        },
    )
}

pub fn set_spline_resolution(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let sel = ctx.field("Selection", DataType::Bool)?;
    let v = ctx.field("Resolution", DataType::Int)?;
    edit_curves(
        ctx,
        "Geometry",
        Domain::Curve,
        &[(&sel, DataType::Bool), (&v, DataType::Int)],
        &mut |c, r| {
            let mut cur = c.ints("resolution", Domain::Curve, 12);
            let (sel, v) = (r[0].as_bool(), r[1].as_int());
            for i in 0..cur.len() {
                if sel[i] {
                    // The built-in's validator keeps it at 1 or more.
                    cur[i] = v[i].max(1);
                }
            }
            c.attributes
                .set(AttrId::named("resolution"), Domain::Curve, Array::Int(cur));
            Ok(())
        },
    )
}

fn has_handles(c: &Curves) -> bool {
    c.attributes.named("handle_type_left").is_some()
        && c.attributes.named("handle_type_right").is_some()
}

fn handle_types(c: &Curves) -> (Vec<i8>, Vec<i8>) {
    let f = |n| {
        c.ints(n, Domain::Point, 0)
            .iter()
            .map(|v| *v as i8)
            .collect()
    };
    (f("handle_type_left"), f("handle_type_right"))
}

pub fn set_handle_type(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let ty = handle_type(ctx)?;
    let (left, right) = handle_sides(ctx)?;
    let sel = ctx.field("Selection", DataType::Bool)?;
    edit_curves(
        ctx,
        "Curve",
        Domain::Point,
        &[(&sel, DataType::Bool)],
        &mut |c, r| {
            if !has_handles(c) {
                return Ok(());
            }
            let sel = r[0].as_bool();
            let (mut tl, mut tr) = handle_types(c);
            for i in 0..sel.len() {
                if sel[i] {
                    if left {
                        tl[i] = ty;
                    }
                    if right {
                        tr[i] = ty;
                    }
                }
            }
            c.set_i8("handle_type_left", Domain::Point, tl);
            c.set_i8("handle_type_right", Domain::Point, tr);
            if ty != HANDLE_FREE {
                calculate_auto_handles(c);
            }
            Ok(())
        },
    )
}

pub fn set_handle_positions(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let left = match ctx.prop_str("mode")? {
        "LEFT" => true,
        "RIGHT" => false,
        other => return Err(ctx.err(format!("mode {other:?} is not supported"))),
    };
    let sel = ctx.field("Selection", DataType::Bool)?;
    // Unlinked, Position is the handle being set (Blender's implicit field for this node).
    let linked = ctx.flat().input("Position").is_some_and(|i| {
        i.sources
            .iter()
            .any(|s| !matches!(s, Source::Default(_) | Source::Nothing))
    });
    let pos = if linked {
        ctx.field("Position", DataType::Vector)?
    } else {
        handle_positions_field(left)
    };
    let off = ctx.field("Offset", DataType::Vector)?;
    edit_curves(
        ctx,
        "Curve",
        Domain::Point,
        &[
            (&sel, DataType::Bool),
            (&pos, DataType::Vector),
            (&off, DataType::Vector),
        ],
        &mut |c, r| {
            let (Some(mut hl), Some(mut hr)) = (
                c.point_vectors("handle_left"),
                c.point_vectors("handle_right"),
            ) else {
                return Ok(());
            };
            let (sel, pos, off) = (r[0].as_bool(), r[1].as_vector(), r[2].as_vector());
            let (mut tl, mut tr) = handle_types(c);
            {
                let (t, t_other, h, h_other) = if left {
                    (&mut tl, &mut tr, &mut hl, &mut hr)
                } else {
                    (&mut tr, &mut tl, &mut hr, &mut hl)
                };
                for i in 0..sel.len() {
                    if sel[i] {
                        types_for_movement(&mut t[i], &mut t_other[i]);
                    }
                }
                for i in 0..sel.len() {
                    if sel[i] {
                        set_handle_position(
                            c.positions[i],
                            (t[i], t_other[i]),
                            add(pos[i], off[i]),
                            &mut h[i],
                            &mut h_other[i],
                        );
                    }
                }
            }
            write_handles(c, tl, tr, hl, hr);
            Ok(())
        },
    )
}

/// Set Curve Normal (`node_geo_set_curve_normal`): the mode on the selected curves; Free
/// also captures the Normal field (evaluated before the mode changes, so a Normal input
/// in it reads the old normals) into `custom_normal` on the selected curves' points.
pub fn set_curve_normal(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let mode = match ctx.prop_str("mode")? {
        "MINIMUM_TWIST" => NORMAL_MODE_MINIMUM_TWIST,
        "Z_UP" => NORMAL_MODE_Z_UP,
        "FREE" => NORMAL_MODE_FREE,
        other => return Err(ctx.err(format!("normal mode {other:?} is not supported"))),
    };
    let sel = ctx.field("Selection", DataType::Bool)?;
    let normal = if mode == NORMAL_MODE_FREE {
        Some(ctx.field("Normal", DataType::Vector)?)
    } else {
        None
    };
    let mut g = ctx.geometry("Curve")?;
    modify_geometry_sets(&mut g, &mut |s| {
        let Some(c) = s.curves.clone() else {
            return Ok(());
        };
        let picked = eval_fields(
            ComponentRef::Curves(&c),
            Domain::Curve,
            &[(&sel, DataType::Bool)],
        )?
        .remove(0)
        .as_bool()
        .into_owned();
        let custom = match &normal {
            Some(f) => Some(
                eval_fields(
                    ComponentRef::Curves(&c),
                    Domain::Point,
                    &[(f, DataType::Vector)],
                )?
                .remove(0)
                .as_vector()
                .into_owned(),
            ),
            None => None,
        };
        let mut c = Arc::unwrap_or_clone(c);
        if let Some(values) = custom {
            // Unselected curves keep their stored normals (zero where there were none).
            let mut stored = c
                .point_vectors("custom_normal")
                .unwrap_or_else(|| vec![[0.0; 3]; c.point_count()]);
            for (i, _) in picked.iter().enumerate().filter(|(_, p)| **p) {
                for p in c.points(i) {
                    stored[p] = values[p];
                }
            }
            c.attributes.set(
                AttrId::named("custom_normal"),
                Domain::Point,
                Array::Vector(stored),
            );
        }
        c.set_i8_selected("normal_mode", Domain::Curve, 0, &picked, mode);
        s.curves = Some(Arc::new(c));
        Ok(())
    })
    .map_err(|e| ctx.err(e))?;
    Ok(outputs([("Curve", geo(g))]))
}
