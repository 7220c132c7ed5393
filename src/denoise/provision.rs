//! Open Image Denoise for machines that have none: the library is taken from a pinned
//! `pyoidn` wheel on the Python package index, fetched with `python3 -m pip download`
//! (the client every supported Linux can have), checked against its sha256, and only the
//! CPU libraries are unpacked into the user's cache folder, where later runs find it.
//!
//! Layout: `<root>/oidn-<version>/lib/libOpenImageDenoise.so.2` and its neighbours, with
//! `<root>` = `$XDG_CACHE_HOME/blendsynth` or `~/.cache/blendsynth`. The libraries keep the
//! wheel's rpath `$ORIGIN/../lib`, which is why the folder is named `lib`.
//!
//! Several shard processes on one node may start at once: an exclusive lock on
//! `<root>/oidn-<version>.lock` lets one download while the others wait, and the folder is
//! built under a temporary name and renamed into place, so it is either complete or absent
//! (a process killed half-way leaves only a temporary folder, removed on the next try).

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;

use sha2::{Digest, Sha256};

/// The pinned wheel: what is downloaded, what it must hash to, what is kept from it.
pub struct Wheel {
    /// The pip requirement.
    pub requirement: &'static str,
    /// The version of OIDN inside (the cache folder is named after it).
    pub oidn_version: &'static str,
    pub file_name: &'static str,
    pub platform: &'static str,
    pub sha256: &'static str,
    /// Download size, for the notice.
    pub megabytes: u32,
    /// Archive members kept (the CPU device and what it needs; the GPU devices and
    /// their runtimes are left out), all in one folder.
    pub members: &'static [&'static str],
    /// Shown on the notice and written next to the libraries.
    pub license_member: &'static str,
}

/// pyoidn 2.5.1.0 ships OIDN 2.5.1. Measured on tests/denoise.rs' fixture, it denoises
/// bit for bit as the OIDN 2.3.3 of bpy 4.5.4 does (see docs/denoise.md).
#[cfg(all(target_os = "linux", target_arch = "x86_64"))]
pub static PINNED: Option<Wheel> = Some(Wheel {
    requirement: "pyoidn==2.5.1.0",
    oidn_version: "2.5.1",
    file_name: "pyoidn-2.5.1.0-py3-none-manylinux2014_x86_64.whl",
    platform: "manylinux2014_x86_64",
    sha256: "32ad13368f8de1ef63001942ad05b02a00cd732d1206d97f352d3a3f606d823e",
    megabytes: 88,
    members: &[
        "pyoidn/oidn/lib/libOpenImageDenoise.so.2",
        "pyoidn/oidn/lib/libOpenImageDenoise_core.so.2.5.1",
        "pyoidn/oidn/lib/libOpenImageDenoise_device_cpu.so.2.5.1",
        "pyoidn/oidn/lib/libtbb.so.12",
    ],
    license_member: "pyoidn-2.5.1.0.dist-info/licenses/LICENSE",
});

/// No wheel is pinned for other platforms (pyoidn publishes manylinux x86_64 builds).
#[cfg(not(all(target_os = "linux", target_arch = "x86_64")))]
pub static PINNED: Option<Wheel> = None;

/// Turns automatic provisioning off when set to 0, off, no or false (`--no-oidn-download`
/// sets it too).
pub const DOWNLOAD_ENV: &str = "BLENDSYNTH_OIDN_DOWNLOAD";

#[derive(Debug, thiserror::Error)]
pub enum ProvisionError {
    #[error("no wheel of Open Image Denoise is pinned for this platform ({0})")]
    Unsupported(String),
    #[error("no cache folder: neither $XDG_CACHE_HOME nor $HOME is set")]
    NoCacheDir,
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot run `{command}`: {message}")]
    Pip { command: String, message: String },
    #[error("downloaded {file}: sha256 is {got}, expected {expected}; not used")]
    Checksum {
        file: PathBuf,
        expected: String,
        got: String,
    },
    #[error("{file}: {message}")]
    Archive { file: PathBuf, message: String },
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> ProvisionError + '_ {
    move |source| ProvisionError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Whether automatic provisioning is on ($BLENDSYNTH_OIDN_DOWNLOAD not 0/off/no/false).
pub fn enabled() -> bool {
    match std::env::var(DOWNLOAD_ENV) {
        Ok(v) => !matches!(
            v.trim().to_ascii_lowercase().as_str(),
            "0" | "off" | "no" | "false"
        ),
        Err(_) => true,
    }
}

/// `$XDG_CACHE_HOME/blendsynth`, or `~/.cache/blendsynth` (XDG: a relative
/// XDG_CACHE_HOME is ignored).
pub fn cache_root() -> Result<PathBuf, ProvisionError> {
    let abs = |k: &str| {
        std::env::var_os(k)
            .map(PathBuf::from)
            .filter(|p| p.is_absolute())
    };
    if let Some(x) = abs("XDG_CACHE_HOME") {
        return Ok(x.join("blendsynth"));
    }
    abs("HOME")
        .map(|h| h.join(".cache").join("blendsynth"))
        .ok_or(ProvisionError::NoCacheDir)
}

fn pinned() -> Result<&'static Wheel, ProvisionError> {
    PINNED.as_ref().ok_or_else(|| {
        ProvisionError::Unsupported(format!(
            "{}-{}",
            std::env::consts::OS,
            std::env::consts::ARCH
        ))
    })
}

/// The library folder provisioning makes under `root` (whether or not it exists yet).
pub fn lib_dir(root: &Path) -> Result<PathBuf, ProvisionError> {
    let w = pinned()?;
    Ok(root.join(format!("oidn-{}", w.oidn_version)).join("lib"))
}

/// The provisioned library folder under `root`, if it is there.
pub fn existing(root: &Path) -> Option<PathBuf> {
    let dir = lib_dir(root).ok()?;
    dir.join("libOpenImageDenoise.so.2")
        .is_file()
        .then_some(dir)
}

/// The pip command that fetches the pinned wheel into `dest`.
fn pip_command(w: &Wheel, dest: &Path) -> Command {
    let mut c = Command::new("python3");
    c.args(["-m", "pip", "download", "--no-deps", "--only-binary=:all:"])
        .args(["--platform", w.platform])
        .args([
            "--no-cache-dir",
            "--disable-pip-version-check",
            "--no-input",
        ])
        .args(["--progress-bar", "off", "--quiet", "--dest"])
        .arg(dest)
        .arg(w.requirement)
        .stdin(std::process::Stdio::null());
    c
}

/// The pip command as the user would type it (for messages).
pub fn pip_command_line() -> String {
    match pinned() {
        Ok(w) => format!(
            "python3 -m pip download --no-deps --only-binary=:all: --platform {} {}",
            w.platform, w.requirement
        ),
        Err(_) => "python3 -m pip download --no-deps pyoidn".into(),
    }
}

/// The lowercase hex sha256 of a file.
pub fn sha256_file(path: &Path) -> Result<String, ProvisionError> {
    let mut f = std::fs::File::open(path).map_err(io(path))?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 20];
    loop {
        let n = f.read(&mut buf).map_err(io(path))?;
        if n == 0 {
            break;
        }
        h.update(&buf[..n]);
    }
    Ok(h.finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<String>())
}

/// Writes the archive members named in `members` into `out` (each under its file name),
/// after checking that no member of the archive names a path outside it (absolute, `..`,
/// or a drive prefix): such an archive is refused whole. `license` is written as LICENSE.
pub fn extract(
    archive: &Path,
    members: &[&str],
    license: Option<&str>,
    out: &Path,
) -> Result<(), ProvisionError> {
    let bad = |message: String| ProvisionError::Archive {
        file: archive.to_path_buf(),
        message,
    };
    let f = std::fs::File::open(archive).map_err(io(archive))?;
    let mut zip = zip::ZipArchive::new(std::io::BufReader::new(f))
        .map_err(|e| bad(format!("not a readable wheel: {e}")))?;
    for i in 0..zip.len() {
        let e = zip
            .by_index_raw(i)
            .map_err(|e| bad(format!("member {i}: {e}")))?;
        if e.enclosed_name().is_none() {
            return Err(bad(format!(
                "member {:?} names a path outside the archive",
                e.name()
            )));
        }
    }
    std::fs::create_dir_all(out).map_err(io(out))?;
    let wanted = members
        .iter()
        .map(|m| (*m, None))
        .chain(license.map(|l| (l, Some("LICENSE"))));
    for (member, rename) in wanted {
        let mut e = zip
            .by_name(member)
            .map_err(|e| bad(format!("member {member:?}: {e}")))?;
        // The target name is ours (the last component of a pinned member), never the
        // archive's own path.
        let name = rename.unwrap_or_else(|| member.rsplit('/').next().unwrap_or(member));
        let to = out.join(name);
        let mut w = std::fs::File::create(&to).map_err(io(&to))?;
        // Reading to the end checks the member's CRC-32.
        std::io::copy(&mut e, &mut w).map_err(|err| bad(format!("member {member:?}: {err}")))?;
        w.sync_all().map_err(io(&to))?;
    }
    Ok(())
}

/// Makes the provisioned library folder under `root` if it is not there yet, and returns
/// it. `say` receives the one notice printed when a download starts. Blocks while another
/// process provisions the same folder.
pub fn provision(root: &Path, say: &dyn Fn(&str)) -> Result<PathBuf, ProvisionError> {
    let w = pinned()?;
    if let Some(d) = existing(root) {
        return Ok(d);
    }
    std::fs::create_dir_all(root).map_err(io(root))?;
    let lock_path = root.join(format!("oidn-{}.lock", w.oidn_version));
    let lock = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(&lock_path)
        .map_err(io(&lock_path))?;
    // fs4's flock; called by path because std's File::lock has the same name but a newer
    // minimum Rust. Released when `lock` is dropped, or by the OS if the process dies.
    fs4::FileExt::lock(&lock).map_err(io(&lock_path))?;
    if let Some(d) = existing(root) {
        return Ok(d);
    }
    // Leftovers of a process killed mid-way (we hold the lock, so none is in use).
    let prefix = format!(".oidn-{}-", w.oidn_version);
    if let Ok(rd) = std::fs::read_dir(root) {
        for e in rd.flatten() {
            if e.file_name().to_string_lossy().starts_with(&prefix) {
                let _ = std::fs::remove_dir_all(e.path());
            }
        }
    }
    let final_dir = root.join(format!("oidn-{}", w.oidn_version));
    let staging = tempfile::Builder::new()
        .prefix(&prefix)
        .tempdir_in(root)
        .map_err(io(root))?;
    say(&format!(
        "notice: Open Image Denoise not found; downloading it once ({} wheel from the Python package index, {} MB, through `python3 -m pip`) into {}",
        w.requirement,
        w.megabytes,
        final_dir.display()
    ));
    let dl = staging.path().join("download");
    let mut cmd = pip_command(w, &dl);
    let out = cmd.output().map_err(|e| ProvisionError::Pip {
        command: pip_command_line(),
        message: if e.kind() == std::io::ErrorKind::NotFound {
            "python3 is not on PATH".into()
        } else {
            e.to_string()
        },
    })?;
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        let last = err
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("")
            .trim();
        let hint = if err.contains("No module named pip") {
            "; install pip first (Debian/Ubuntu: apt-get install python3-pip)"
        } else {
            ""
        };
        return Err(ProvisionError::Pip {
            command: pip_command_line(),
            message: format!("{} ({last}){hint}", out.status),
        });
    }
    let wheel = dl.join(w.file_name);
    if !wheel.is_file() {
        return Err(ProvisionError::Pip {
            command: pip_command_line(),
            message: format!("it did not write {}", wheel.display()),
        });
    }
    let got = sha256_file(&wheel)?;
    if got != w.sha256 {
        return Err(ProvisionError::Checksum {
            file: PathBuf::from(w.file_name),
            expected: w.sha256.into(),
            got,
        });
    }
    let built = staging.path().join("oidn");
    extract(
        &wheel,
        w.members,
        Some(w.license_member),
        &built.join("lib"),
    )?;
    std::fs::write(
        built.join("SOURCE"),
        format!(
            "Open Image Denoise {} (CPU libraries only) from {} (sha256 {}), unpacked by blendsynth.\n",
            w.oidn_version, w.file_name, w.sha256
        ),
    )
    .map_err(io(&built))?;
    // Atomic: the folder appears complete or not at all.
    std::fs::rename(&built, &final_dir).map_err(io(&final_dir))?;
    drop(staging);
    drop(lock);
    existing(root).ok_or_else(|| ProvisionError::Io {
        path: final_dir,
        source: std::io::Error::other("missing after provisioning"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn zip_with(members: &[(&str, &[u8])]) -> (tempfile::TempDir, PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.whl");
        let mut z = zip::ZipWriter::new(std::fs::File::create(&p).unwrap());
        let o = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored);
        for (name, data) in members {
            z.start_file(*name, o).unwrap();
            z.write_all(data).unwrap();
        }
        z.finish().unwrap();
        (dir, p)
    }

    #[test]
    fn extracts_only_the_named_members_by_file_name() {
        let (dir, p) = zip_with(&[
            ("pkg/lib/liba.so.1", b"a"),
            ("pkg/lib/libb.so.1", b"b"),
            ("pkg.dist-info/LICENSE", b"MIT"),
        ]);
        let out = dir.path().join("out");
        extract(
            &p,
            &["pkg/lib/liba.so.1"],
            Some("pkg.dist-info/LICENSE"),
            &out,
        )
        .unwrap();
        assert_eq!(std::fs::read(out.join("liba.so.1")).unwrap(), b"a");
        assert_eq!(std::fs::read(out.join("LICENSE")).unwrap(), b"MIT");
        assert!(!out.join("libb.so.1").exists());
    }

    #[test]
    fn an_archive_with_an_escaping_member_is_refused_whole() {
        for evil in ["../../escape.so", "/etc/escape.so", "pkg/../../escape.so"] {
            let (dir, p) = zip_with(&[("pkg/lib/liba.so.1", b"a"), (evil, b"x")]);
            let out = dir.path().join("sub/out");
            let e = extract(&p, &["pkg/lib/liba.so.1"], None, &out)
                .unwrap_err()
                .to_string();
            assert!(e.contains(evil) && e.contains("outside"), "{e}");
            assert!(!out.exists(), "{evil}: wrote before refusing");
            assert!(!dir.path().join("escape.so").exists());
        }
    }

    #[test]
    fn a_missing_member_is_an_error_naming_it() {
        let (dir, p) = zip_with(&[("pkg/lib/liba.so.1", b"a")]);
        let e = extract(&p, &["pkg/lib/libz.so"], None, &dir.path().join("o"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("pkg/lib/libz.so"), "{e}");
    }

    #[test]
    fn sha256_of_a_known_input() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("abc");
        std::fs::write(&p, b"abc").unwrap();
        assert_eq!(
            sha256_file(&p).unwrap(),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
