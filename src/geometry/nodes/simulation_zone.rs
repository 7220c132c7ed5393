//! The Simulation zone (`GeometryNodeSimulationInput` / `GeometryNodeSimulationOutput`)
//! at its start frame only. There Blender 4.5 runs the body once on the input state with
//! a Delta Time of 0 (Skip passes the input state through); every later frame continues
//! from the previous frame's state, which lives in Blender's simulation cache or bake,
//! so blendsynth refuses those frames by name rather than evaluate a stale state.

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::value::SocketValue;
use super::super::zones::{item_ids, Zone};

/// The input node is only evaluated through its zone (see `repeat_zone::repeat_input`).
pub fn simulation_input(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    Err(ctx.err("is read outside its Simulation zone"))
}

pub fn simulation_output(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let zone = Zone::of(ctx, "GeometryNodeSimulationInput")?;
    let session = ctx.session();
    let start = session
        .scene
        .file
        .scene
        .simulation_frame_start
        .ok_or_else(|| {
            ctx.err(
                "the export does not say where simulations start (simulation_frame_start): \
                 convert the .blend again with this version",
            )
        })?;
    if session.frame != f64::from(start) {
        return Err(ctx.err(format!(
            "a Simulation zone at frame {} continues Blender's simulation state from the \
             frames before, which only Blender's cache or bake holds; blendsynth evaluates \
             it only at its start frame {start}",
            session.frame
        )));
    }
    let input = zone.input_ctx(ctx);
    let ids = item_ids(&ctx.node().outputs, "Item_");
    let mut state = Vec::with_capacity(ids.len());
    for id in &ids {
        state.push(input.input(id)?);
    }
    zone.spend(ctx, 1, "the simulation step")?;
    let mut values: Outputs = ids.iter().cloned().zip(state.iter().cloned()).collect();
    values.insert("Delta Time".into(), SocketValue::float(0.0));
    // Skip may be computed inside the zone, so it is evaluated with the body.
    let mut wanted = ids.clone();
    wanted.push("Skip".into());
    let mut stepped = zone.run(ctx, values, &wanted)?;
    let skip = match stepped.pop() {
        Some(SocketValue::Field(f)) => f.as_constant().map(|v| v.as_bool()).ok_or_else(|| {
            ctx.err("input \"Skip\" takes a single value but a field is connected")
        })?,
        _ => false,
    };
    let out = if skip { state } else { stepped };
    Ok(ids.into_iter().zip(out).collect())
}
