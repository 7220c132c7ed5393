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
    let write = kill_point::next_write();
    kill_point::at(write, kill_point::When::BeforeRename);
    tmp.persist(path)
        .map_err(|e| format!("{}: cannot rename into place: {}", path.display(), e.error))?;
    kill_point::at(write, kill_point::When::AfterRename);
    Ok(())
}

/// A kill at a chosen write, for the crash tests (`tests/dataset_robust.rs`,
/// `fixtures/dataset/kill_resume.sh`): a kill timed from outside rarely lands inside a
/// step that takes microseconds, such as the last files a dataset run writes. With
/// `BLENDSYNTH_KILL_AT_WRITE=N` (or `N:before-rename`) the process sends itself SIGKILL
/// just after the Nth atomic write of the process is renamed into place (or with its
/// temporary file complete and not yet renamed): exactly what a kill at that moment
/// leaves. Unset, it costs one relaxed atomic increment per file.
mod kill_point {
    use std::sync::atomic::{AtomicU64, Ordering};
    use std::sync::OnceLock;

    #[derive(Clone, Copy, PartialEq, Eq, Debug)]
    pub enum When {
        BeforeRename,
        AfterRename,
    }

    static WRITES: AtomicU64 = AtomicU64::new(0);

    fn target() -> Option<(u64, When)> {
        static T: OnceLock<Option<(u64, When)>> = OnceLock::new();
        *T.get_or_init(|| {
            let v = std::env::var("BLENDSYNTH_KILL_AT_WRITE").ok()?;
            let (n, when) = match v.split_once(':') {
                Some((n, "before-rename")) => (n, When::BeforeRename),
                Some(_) => return None,
                None => (v.as_str(), When::AfterRename),
            };
            Some((n.trim().parse().ok()?, when))
        })
    }

    /// The 1-based number of this atomic write in the process.
    pub fn next_write() -> u64 {
        WRITES.fetch_add(1, Ordering::Relaxed) + 1
    }

    pub fn at(write: u64, when: When) {
        if target() == Some((write, when)) {
            #[cfg(unix)]
            {
                use rustix::process::{getpid, kill_process, Signal};
                let _ = kill_process(getpid(), Signal::KILL);
            }
            std::process::abort();
        }
    }
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
