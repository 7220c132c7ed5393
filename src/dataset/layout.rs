//! The dataset folder and atomic writes.
//!
//! ```text
//! OUT/manifest.json                     what made it (spec, seed, frames, split, shard)
//! OUT/images/SPLIT/NNNNNNNNN.png        8-bit RGB image
//! OUT/masks/SPLIT/NNNNNNNNN.png         semantic mask (0 background, else class id;
//!                                       8-bit up to 254 classes, else 16-bit)
//! OUT/labels/SPLIT/NNNNNNNNN.txt        YOLO boxes
//! OUT/depth/SPLIT/NNNNNNNNN.png         optional: depth in mm, 16-bit (0: none/far)
//! OUT/depth/SPLIT/NNNNNNNNN.exr|npy     optional: metric depth, float32 (0: none)
//! OUT/normals/SPLIT/NNNNNNNNN.exr       optional: world-space normals, float RGB
//! OUT/normals_camera/SPLIT/NNNNNNNNN.exr optional: normals in OpenCV camera axes
//! OUT/aovs/SPLIT/NNNNNNNNN.exr          optional: the view layer's shader AOVs, float
//!                                       channels named as Blender names them
//! OUT/flow_fw|flow_bw/SPLIT/NNNNNNNNN.exr optional: optical flow to the next / previous
//!                                       frame of the step, float R (x) G (y), pixels;
//!                                       NaN where invalid (also .flo with flow_flo)
//! OUT/occlusion_fw|occlusion_bw/SPLIT/NNNNNNNNN.png optional: 255 occluded, 0 visible
//! OUT/meshes/SPLIT/NNNNNNNNN.glb        optional: the evaluated scene, world space
//! OUT/sequences/SSSSSSSSS/             with [sequence]: trajectory.txt (TUM), COLMAP's
//!                                       cameras.txt, images.txt, points3D.txt
//! OUT/frames/NNNNNNNNN.json             per-frame record; written last: its presence
//!                                       marks the frame finished
//! OUT/annotations/instances_SPLIT.json  COCO (written when all frames are done)
//! OUT/frames.jsonl                      every record, one per line, in frame order
//! OUT/data.yaml                         Ultralytics dataset file
//! ```
//! Every file is written to `.NAME.XXXXXX.partial` beside it and renamed into place, so a
//! killed run leaves whole files or `.partial` leftovers that a resumed run deletes.
//! A writer holds an exclusive flock on OUT itself (no lock file), so two writers
//! never share a folder.

use std::path::{Path, PathBuf};

pub use crate::foundation::exr::channels_bytes as exr_channels_bytes;
pub use crate::foundation::exr::rgb_bytes as exr_rgb_bytes;
pub use crate::foundation::png::{png16_bytes, png_bytes};

/// A split name becomes a folder name: letters, digits, '_' and '-' only, so a name
/// read from a manifest or a frame record can never lead outside the dataset.
pub fn check_split_name(name: &str) -> Result<(), String> {
    if name.is_empty()
        || name.len() > 64
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        return Err(format!(
            "split name {name:?} must be 1 to 64 letters, digits, '_' or '-'"
        ));
    }
    Ok(())
}

/// The image path a frame record must name (relative to the dataset folder).
pub fn image_rel(split: &str, index: u64) -> String {
    format!("images/{split}/{}.png", frame_name(index))
}

pub fn frame_name(index: u64) -> String {
    format!("{index:09}")
}
pub fn image_path(out: &Path, split: &str, index: u64) -> PathBuf {
    out.join("images")
        .join(split)
        .join(format!("{}.png", frame_name(index)))
}
pub fn mask_path(out: &Path, split: &str, index: u64) -> PathBuf {
    out.join("masks")
        .join(split)
        .join(format!("{}.png", frame_name(index)))
}
pub fn label_path(out: &Path, split: &str, index: u64) -> PathBuf {
    out.join("labels")
        .join(split)
        .join(format!("{}.txt", frame_name(index)))
}
pub fn depth_path(out: &Path, split: &str, index: u64) -> PathBuf {
    out.join("depth")
        .join(split)
        .join(format!("{}.png", frame_name(index)))
}
pub fn normal_path(out: &Path, split: &str, index: u64) -> PathBuf {
    out.join("normals")
        .join(split)
        .join(format!("{}.exr", frame_name(index)))
}
pub fn depth_float_path(out: &Path, split: &str, index: u64, ext: &str) -> PathBuf {
    out.join("depth")
        .join(split)
        .join(format!("{}.{ext}", frame_name(index)))
}
pub fn aov_path(out: &Path, split: &str, index: u64) -> PathBuf {
    out.join("aovs")
        .join(split)
        .join(format!("{}.exr", frame_name(index)))
}
pub fn normal_camera_path(out: &Path, split: &str, index: u64) -> PathBuf {
    out.join("normals_camera")
        .join(split)
        .join(format!("{}.exr", frame_name(index)))
}
/// Optical flow (`kind` "flow_fw" or "flow_bw"; `ext` "exr" or "flo") or an occlusion
/// mask ("occlusion_fw", "occlusion_bw"; "png").
pub fn motion_path(out: &Path, kind: &str, split: &str, index: u64, ext: &str) -> PathBuf {
    out.join(kind)
        .join(split)
        .join(format!("{}.{ext}", frame_name(index)))
}
/// A frame's optional files (written when the spec asks for them).
pub fn optional_frame_files(out: &Path, split: &str, index: u64) -> Vec<PathBuf> {
    let mut v = vec![
        depth_path(out, split, index),
        depth_float_path(out, split, index, "exr"),
        depth_float_path(out, split, index, "npy"),
        normal_path(out, split, index),
        normal_camera_path(out, split, index),
        aov_path(out, split, index),
    ];
    for (kind, ext) in [
        ("flow_fw", "exr"),
        ("flow_bw", "exr"),
        ("flow_fw", "flo"),
        ("flow_bw", "flo"),
        ("occlusion_fw", "png"),
        ("occlusion_bw", "png"),
        ("meshes", "glb"),
    ] {
        v.push(motion_path(out, kind, split, index, ext));
    }
    v
}
/// A sequence's folder: trajectory.txt (TUM) and COLMAP's cameras.txt, images.txt,
/// points3D.txt.
pub fn sequence_dir(out: &Path, sequence: u64) -> PathBuf {
    out.join("sequences").join(frame_name(sequence))
}
pub fn record_path(out: &Path, index: u64) -> PathBuf {
    out.join("frames")
        .join(format!("{}.json", frame_name(index)))
}

/// Writes `bytes` to `path` atomically (temp file beside it, fsync, rename). A failed
/// write (a full disk) removes its temp file, so it leaves nothing half-written.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let dir = path
        .parent()
        .ok_or_else(|| format!("{}: no parent folder", path.display()))?;
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create: {e}", dir.display()))?;
    crate::foundation::files::write_atomic(path, bytes)
}

/// An exclusive advisory lock (flock) on a dataset folder, held while the value lives.
/// The kernel releases it when the process exits however it ends, so a lock left by a
/// killed run is never stale, and no lock file is added to the dataset.
#[derive(Debug)]
pub struct FolderLock(#[allow(dead_code)] Option<std::fs::File>);

/// Locks the folder `dir` (which must exist); a second writer gets an error at once.
#[cfg(unix)]
pub fn lock(dir: &Path) -> Result<FolderLock, String> {
    use rustix::fs::{flock, FlockOperation};
    let f = std::fs::File::open(dir)
        .map_err(|e| format!("{}: cannot open to lock: {e}", dir.display()))?;
    match flock(&f, FlockOperation::NonBlockingLockExclusive) {
        Ok(()) => Ok(FolderLock(Some(f))),
        Err(rustix::io::Errno::WOULDBLOCK) => Err(format!(
            "{} is in use by another blendsynth process (generate or merge); wait for it to finish, or stop it and rerun with --resume",
            dir.display()
        )),
        Err(e) => Err(format!("{}: cannot lock: {e}", dir.display())),
    }
}

/// Without flock (not unix) folders are not locked.
#[cfg(not(unix))]
pub fn lock(_dir: &Path) -> Result<FolderLock, String> {
    Ok(FolderLock(None))
}

/// Deletes `.partial` leftovers of a killed run.
pub fn remove_partials(dir: &Path) -> std::io::Result<usize> {
    let mut n = 0;
    if !dir.is_dir() {
        return Ok(0);
    }
    for e in std::fs::read_dir(dir)? {
        let e = e?;
        let p = e.path();
        if e.file_type()?.is_dir() {
            n += remove_partials(&p)?;
        } else if p
            .file_name()
            .is_some_and(|f| f.to_string_lossy().ends_with(".partial"))
        {
            std::fs::remove_file(&p)?;
            n += 1;
        }
    }
    Ok(n)
}

/// The most classes an 8-bit mask holds: values 1..=254, leaving 255 free (the usual
/// "ignore" label of segmentation tools); with more classes masks are 16-bit.
pub const MAX_CLASSES_8BIT: usize = 254;
/// The most classes a 16-bit mask holds (values 1..=65535).
pub const MAX_CLASSES: usize = 65535;

/// PNG bytes of a semantic mask: 8-bit grey while the dataset has at most
/// `MAX_CLASSES_8BIT` classes, else 16-bit grey (the same values, never clamped).
pub fn mask_png_bytes(
    width: u32,
    height: u32,
    classes: usize,
    mask: &[u16],
) -> Result<Vec<u8>, String> {
    if classes > MAX_CLASSES {
        return Err(format!(
            "{classes} classes do not fit a 16-bit mask (at most {MAX_CLASSES})"
        ));
    }
    if classes <= MAX_CLASSES_8BIT {
        let m: Vec<u8> = mask.iter().map(|&v| v as u8).collect();
        png_bytes(width, height, 1, &m)
    } else {
        png16_bytes(width, height, mask)
    }
}

pub use crate::foundation::exr::grey_bytes as exr_grey_bytes;

/// NumPy `.npy` (format 1.0): little-endian float32, C order, shape (height, width).
pub fn npy_f32_bytes(width: u32, height: u32, data: &[f32]) -> Result<Vec<u8>, String> {
    if data.len() != width as usize * height as usize {
        return Err(format!(
            "npy encode: {} values for {width}x{height}",
            data.len()
        ));
    }
    let mut header =
        format!("{{'descr': '<f4', 'fortran_order': False, 'shape': ({height}, {width}), }}");
    // Magic (6) + version (2) + length (2) + header, padded with spaces to a multiple of
    // 64 and ended by a newline, as numpy writes it.
    let total = (10 + header.len() + 1).div_ceil(64) * 64;
    header.push_str(&" ".repeat(total - 10 - header.len() - 1));
    header.push('\n');
    let mut out = Vec::with_capacity(total + data.len() * 4);
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for v in data {
        out.extend_from_slice(&v.to_le_bytes());
    }
    Ok(out)
}

/// Display-referred [0, 1] RGBA to 8-bit RGB, rounded.
pub fn to_rgb8(color: &[[f32; 4]]) -> Vec<u8> {
    let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    color
        .iter()
        .flat_map(|c| [q(c[0]), q(c[1]), q(c[2])])
        .collect()
}
