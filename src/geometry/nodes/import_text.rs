//! Import Text (Blender 4.5, `node_geo_import_text.cc`): the file's bytes as the String
//! output, unchanged (line endings and a byte order mark kept). A file that is not
//! valid UTF-8 is Blender's node error ("File contains invalid UTF-8 characters"): an
//! error naming the node and the file here.

use super::super::error::GeometryError;
use super::super::eval::{outputs, NodeCtx, Outputs};
use super::super::value::SocketValue;
use super::import_file::read_path;

pub fn import_text(ctx: &NodeCtx) -> Result<Outputs, GeometryError> {
    let text = match read_path(ctx)? {
        None => String::new(),
        Some((path, bytes)) => String::from_utf8(bytes).map_err(|e| {
            ctx.err(format!(
                "text file {path:?} is not valid UTF-8 (byte {}; Blender: \"File contains invalid UTF-8 characters\")",
                e.utf8_error().valid_up_to()
            ))
        })?,
    };
    Ok(outputs([("String", SocketValue::String(text))]))
}
