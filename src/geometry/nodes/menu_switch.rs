//! Menu Switch (`node_geo_menu_switch`): passes on the input of the menu item the Menu
//! input names. The items are the node's `enum_items`, in order; the input of item `k` is
//! the `k`-th value input after Menu.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::value::SocketValue;

pub fn menu_switch(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let node = ctx.node();
    let items: Vec<&str> = ctx
        .prop("enum_items")
        .and_then(|v| v.as_array())
        .ok_or_else(|| ctx.err("property \"enum_items\" missing"))?
        .iter()
        .map(|i| i.get("name").and_then(|n| n.as_str()).unwrap_or_default())
        .collect();
    let inputs: Vec<&str> = node
        .inputs
        .iter()
        .skip(1)
        .filter(|s| s.identifier != "__extend__")
        .map(|s| s.identifier.as_str())
        .collect();
    let picked = match ctx.input("Menu")? {
        SocketValue::Menu(s) | SocketValue::String(s) => s,
        other => {
            return Err(ctx.err(format!(
                "input \"Menu\" is a {}, expected a menu item (a field menu is not supported)",
                other.kind()
            )))
        }
    };
    // An empty value is what the exporter reads for a menu socket whose stored item
    // Blender cannot resolve (no items reach it, as on a group node of Molecular Nodes'
    // Style Preset 3): Blender's Menu Switch then matches no item and outputs its
    // defaults (`set_default_remaining_node_outputs`; checked in bpy, the preset's
    // spheres give neither points nor instances).
    if picked.is_empty() {
        let kind = node.outputs.first().map(|s| s.kind.as_str()).unwrap_or("");
        return Ok(outputs([("Output", SocketValue::zero(kind))]));
    }
    // Any other value that names no item (a modifier menu stored as a number, or a
    // renamed item) is refused: Blender's own fallback depends on item identifiers the
    // export does not carry.
    let k = items.iter().position(|i| *i == picked).ok_or_else(|| {
        ctx.err(format!(
            "menu value {picked:?} is none of the items {items:?}"
        ))
    })?;
    let id = inputs
        .get(k)
        .ok_or_else(|| ctx.err(format!("menu item {picked:?} has no input socket")))?;
    Ok(outputs([("Output", ctx.input(id)?)]))
}
