//! The Repeat zone (`GeometryNodeRepeatInput` / `GeometryNodeRepeatOutput`), as Blender
//! 4.5 evaluates it (`geometry_nodes_repeat_zone.cc`): the items enter through the input
//! node, the body runs Iterations times, each run's output items becoming the next run's
//! input items, and the output node gives the last run's items. Iterations of zero or
//! less run nothing: the output items are the input items. Field items are carried as
//! fields (not evaluated per iteration), so a field item is evaluated where it is used,
//! on whatever geometry that is, as everywhere in Geometry Nodes.

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::value::SocketValue;
use super::super::zones::{check_carried, item_ids, Zone};

/// The input node is only evaluated through its zone (`repeat_output`), which gives it
/// its values for each iteration: a link from inside a zone to outside it is invalid in
/// Blender, so nothing else reads it.
pub fn repeat_input(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    Err(ctx.err("is read outside its Repeat zone"))
}

pub fn repeat_output(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let zone = Zone::of(ctx, "GeometryNodeRepeatInput")?;
    let input = zone.input_ctx(ctx);
    let ids = item_ids(&ctx.node().outputs, "Item_");
    // The items' initial values, converted to the items' socket types.
    let mut state = Vec::with_capacity(ids.len());
    for id in &ids {
        state.push(input.input(id)?);
    }
    let iterations = input.int("Iterations")?;
    if iterations > 0 {
        zone.spend(ctx, iterations as u64, &format!("Iterations {iterations}"))?;
    }
    for i in 0..iterations.max(0) {
        let mut values: Outputs = ids.iter().cloned().zip(state).collect();
        values.insert("Iteration".into(), SocketValue::int(i));
        state = zone.run(ctx, values, &ids)?;
        for (id, v) in ids.iter().zip(&state) {
            check_carried(ctx, id, v)?;
        }
    }
    Ok(ids.into_iter().zip(state).collect())
}
