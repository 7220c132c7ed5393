//! Reading a file a scene names: regular files only (a FIFO or device would block or
//! never end), at most a stated size, and errors that never quote the file's content.

use std::io::Read;
use std::path::Path;

/// Reads `path` whole if it is a regular file of at most `max_bytes`; the error says why
/// not, without the file's content.
pub fn read_regular(path: &Path, max_bytes: u64) -> Result<Vec<u8>, String> {
    check_regular(path)?;
    let file = std::fs::File::open(path).map_err(|e| format!("cannot read: {e}"))?;
    // Checked again on the open handle: the path could have been swapped in between.
    let meta = file.metadata().map_err(|e| format!("cannot read: {e}"))?;
    if !meta.is_file() {
        return Err(not_regular(&meta));
    }
    if meta.len() > max_bytes {
        return Err(format!(
            "is {} bytes, more than the limit of {max_bytes}",
            meta.len()
        ));
    }
    let mut out = Vec::with_capacity(meta.len() as usize);
    // `take` bounds a file that grows while it is read.
    file.take(max_bytes + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("cannot read: {e}"))?;
    if out.len() as u64 > max_bytes {
        return Err(format!("is more than the limit of {max_bytes} bytes"));
    }
    Ok(out)
}

/// Errors unless `path` (following symlinks) is a regular file.
pub fn check_regular(path: &Path) -> Result<(), String> {
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot read: {e}"))?;
    if meta.is_file() {
        Ok(())
    } else {
        Err(not_regular(&meta))
    }
}

fn not_regular(meta: &std::fs::Metadata) -> String {
    let what = if meta.is_dir() {
        "a folder"
    } else {
        "a FIFO, socket or device"
    };
    format!("is {what}, not a regular file")
}
