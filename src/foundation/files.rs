//! The one atomic file writer: every output goes to a temporary file beside its target,
//! is synced, and is renamed over it, so a reader (or a run resumed after a kill) sees
//! either the whole old file, the whole new one, or none: never half a file.

use std::io::Write;
use std::path::Path;

/// The mode a temporary output file is created with: an output is a file the user asked
/// for, so it gets the mode any program's new file gets (0666 less the umask), not a
/// temporary file's private 0600.
pub fn user_file_permissions() -> std::fs::Permissions {
    use std::os::unix::fs::PermissionsExt;
    std::fs::Permissions::from_mode(0o666)
}

/// Writes `bytes` to `path` atomically. The temporary file is `.NAME.XXXXXX.partial` in
/// the target's folder (which must exist): the dataset writer deletes such leftovers of
/// a killed run when it resumes.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), String> {
    write_atomic_with(path, |w| {
        w.write_all(bytes)
            .map_err(|e| format!("{}: cannot write: {e}", path.display()))
    })
}

/// `write_atomic` with the contents written by `f` into a buffered writer.
pub fn write_atomic_with(
    path: &Path,
    f: impl FnOnce(&mut dyn Write) -> Result<(), String>,
) -> Result<(), String> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| format!("{}: no file name", path.display()))?
        .to_string_lossy();
    let mut tmp = tempfile::Builder::new()
        .prefix(&format!(".{name}."))
        .suffix(".partial")
        .permissions(user_file_permissions())
        .tempfile_in(dir)
        .map_err(|e| {
            format!(
                "{}: cannot create a temporary file in {}: {e}",
                path.display(),
                dir.display()
            )
        })?;
    {
        let mut w = std::io::BufWriter::new(tmp.as_file_mut());
        f(&mut w)?;
        w.flush()
            .map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    }
    tmp.as_file()
        .sync_all()
        .map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    tmp.persist(path)
        .map_err(|e| format!("{}: cannot rename into place: {}", path.display(), e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_whole_files_and_leaves_no_temporary_behind() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("a.bin");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two!").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two!");
        let failed = write_atomic_with(&p, |w| {
            w.write_all(b"half").unwrap();
            Err("stopped".into())
        });
        assert_eq!(failed, Err("stopped".into()));
        assert_eq!(std::fs::read(&p).unwrap(), b"two!");
        let names: Vec<_> = std::fs::read_dir(d.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "{names:?}");
        assert!(write_atomic(&d.path().join("missing/a.bin"), b"x").is_err());
    }
}
