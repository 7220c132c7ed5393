//! The Weld modifier (`MOD_weld.cc`): Blender's merge by distance, "All" (vertices within
//! the distance of an earlier one) or "Connected" (along edges shorter than it), as the
//! Merge by Distance node does it (`geometry::weld`). Vertex groups are not exported and
//! Connected's Only Loose Edges is not evaluated: `unsupported` names them.

use std::sync::Arc;

use super::super::set::GeometrySet;
use super::super::weld;
use super::{flag, float, text, Props};

pub fn unsupported(p: &Props) -> Option<String> {
    let mut out = Vec::new();
    let group = text(p, "vertex_group").unwrap_or("");
    if !group.is_empty() {
        out.push(format!(
            "Vertex Group {group:?} (vertex groups are not exported)"
        ));
    }
    match text(p, "mode") {
        Ok("ALL") => {}
        Ok("CONNECTED") => {
            if flag(p, "loose_edges") {
                out.push("Only Loose Edges (loose_edges)".into());
            }
        }
        other => out.push(format!("mode {:?}", other.ok())),
    }
    (!out.is_empty()).then(|| out.join(", "))
}

pub fn apply(p: &Props, mut g: GeometrySet) -> Result<GeometrySet, String> {
    let Some(m) = g.mesh.clone() else {
        return Ok(g);
    };
    let distance = float(p, "merge_threshold")?;
    let selection = vec![true; m.vertex_count()];
    let (dest, killed) = if text(p, "mode")? == "ALL" {
        weld::duplicates_all(&m.positions, &selection, distance)
    } else {
        weld::duplicates_connected(&m, &selection, distance)
    };
    if killed > 0 {
        g.mesh = Some(Arc::new(weld::merge(&m, &dest)?));
    }
    Ok(g)
}
