//! Bake (`node_geo_bake`). Without baked data, Blender 4.5 passes the items through as a
//! bake would hold them (`pass_through`: `move_socket_values_to_bake_items` and back):
//! each field item is captured on the last geometry item before it, on the item's
//! domain, and read back as that attribute; single values pass as they are; anonymous
//! attributes of the geometries are removed (what `simulation_zone::to_state` does for a
//! Simulation zone's state). A Bake node with baked data (packed or on disk) gives the
//! bake instead, which blendsynth does not read: such an object is Blender's evaluated
//! mesh where that is valid, else an error naming the node (`baked_reason`), as for a
//! baked Simulation zone.

use super::super::error::GeometryError;
use super::super::eval::{NodeCtx, Outputs};
use super::super::zones::item_ids;
use super::simulation_zone::{bake_of, baked_verdict, convert_item, item_types, to_state};
use crate::scene::{Object, Scene};

pub fn bake(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let flat = ctx.flat();
    let tree = (!flat.path.contains(" > ")).then_some(ctx.ev.tree.name.as_str());
    if bake_of(ctx.ev.modifier, &flat.node.name, tree).is_some_and(|b| b.baked != Some(false)) {
        return Err(ctx.err(
            "holds baked data (or the export cannot tell) that Blender reads instead of \
             its inputs; blendsynth does not read bakes",
        ));
    }
    let ids = item_ids(&ctx.node().outputs, "Item_");
    let items = item_types(ctx, &ids, "bake_items")?;
    let mut values = Vec::with_capacity(ids.len());
    for (id, (kind, _)) in ids.iter().zip(&items) {
        values.push(convert_item(ctx.input(id)?, kind).map_err(|e| ctx.err(e))?);
    }
    let values = to_state(values, &items).map_err(|e| ctx.err(e))?;
    Ok(ids.into_iter().zip(values).collect())
}

/// Why blendsynth cannot evaluate `o`'s Bake nodes: one holds baked data, which Blender
/// reads instead of its inputs, or the export does not say whether it does. None when
/// every Bake node passes its inputs through.
pub fn baked_reason(scene: &Scene, o: &Object) -> Option<String> {
    for m in o
        .modifiers
        .iter()
        .filter(|m| m.show_render && m.kind == "NODES")
    {
        let Some(group) = m.node_group.as_deref() else {
            continue;
        };
        for (tree, n) in scene.group_nodes(group) {
            if n.bl_idname != "GeometryNodeBake" {
                continue;
            }
            let node = n.name.as_str();
            if m.bake_states.is_none() {
                return Some(format!(
                    "Bake node {node:?} (modifier {:?}): the export does not say whether it \
                     holds baked data (convert the .blend again with this version)",
                    m.name
                ));
            }
            if let Some(why) = baked_verdict(m, node, tree.name.as_str(), "Bake node", "its inputs")
            {
                return Some(why);
            }
        }
    }
    None
}
