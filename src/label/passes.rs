//! A render's label passes as image files (`blendsynth render --passes DIR`): depth (Z
//! along the camera's view axis) and distance (along the ray), object / instance /
//! material indices, the semantic class (`classes`: custom property or a mapping),
//! normal, albedo and UV, each from the primary ray through the pixel centre, as float
//! EXRs or as PNGs. Every file is written atomically; `classes.json` names the ids.

use std::path::{Path, PathBuf};

use crate::foundation::exr::rgb_bytes as exr_rgb_bytes;
use crate::foundation::files::write_atomic;
use crate::foundation::png::{png16_bytes, png_bytes};
use crate::label::ClassMap;

/// How the passes are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PassFormat {
    /// 32-bit float EXR, values as they are (ids as floats, depth in scene units,
    /// background depth 1e10).
    Exr,
    /// PNG: ids as 16-bit grey, depth and distance as 16-bit millimetres (0 for the
    /// background and beyond 65.535 m), normal and albedo as 8-bit RGB (normal mapped
    /// from [-1, 1]), UV as 16-bit grey U and V files.
    Png,
}

/// The passes to write, as plain per-pixel data (the renderer's `Passes`).
pub struct PassImages<'a> {
    pub width: u32,
    pub height: u32,
    pub depth: &'a [f32],
    pub distance: &'a [f32],
    pub object_index: &'a [u32],
    pub instance_id: &'a [u32],
    pub material_index: &'a [u32],
    pub normal: &'a [[f32; 3]],
    pub albedo: &'a [[f32; 3]],
    pub uv: &'a [[f32; 2]],
    /// Object name of each instance id - 1.
    pub instance_objects: &'a [String],
    /// The view layer's shader AOV passes (written to `aovs.exr`), and the view layer's
    /// name their channels start with.
    pub aovs: Vec<AovPlane<'a>>,
    pub view_layer: &'a str,
}

/// One shader AOV pass: its name, and `channels` floats per pixel (1 for a Value AOV,
/// RGBA for a Color AOV).
pub struct AovPlane<'a> {
    pub name: &'a str,
    pub channels: usize,
    pub data: &'a [f32],
}

impl<'a> AovPlane<'a> {
    /// A render's AOV pass as a plane.
    pub fn of(a: &'a crate::render::film::aov::AovImage) -> AovPlane<'a> {
        AovPlane {
            name: &a.name,
            channels: if a.color { 4 } else { 1 },
            data: &a.data,
        }
    }
}

impl<'a> PassImages<'a> {
    /// Only the AOV passes of a render (the other passes empty), for `aov_channels`.
    pub fn aovs_only(
        width: u32,
        height: u32,
        aovs: &'a [crate::render::film::aov::AovImage],
        view_layer: &'a str,
    ) -> PassImages<'a> {
        PassImages {
            width,
            height,
            depth: &[],
            distance: &[],
            object_index: &[],
            instance_id: &[],
            material_index: &[],
            normal: &[],
            albedo: &[],
            uv: &[],
            instance_objects: &[],
            aovs: aovs.iter().map(AovPlane::of).collect(),
            view_layer,
        }
    }
}

/// The channels of the AOV passes as Blender names them in a multilayer EXR:
/// "<view layer>.<AOV>.X" for a Value AOV, ".R", ".G", ".B", ".A" for a Color AOV.
pub fn aov_channels(p: &PassImages) -> Result<Vec<(String, Vec<f32>)>, String> {
    let n = (p.width * p.height) as usize;
    let mut out = Vec::new();
    for a in &p.aovs {
        let names: &[&str] = match a.channels {
            1 => &["X"],
            4 => &["R", "G", "B", "A"],
            c => return Err(format!("AOV {:?}: {c} channels (1 or 4 expected)", a.name)),
        };
        if a.data.len() != n * a.channels {
            return Err(format!(
                "AOV {:?}: {} values, {}x{} needs {}",
                a.name,
                a.data.len(),
                p.width,
                p.height,
                n * a.channels
            ));
        }
        for (k, c) in names.iter().enumerate() {
            out.push((
                format!("{}.{}.{c}", p.view_layer, a.name),
                a.data.iter().skip(k).step_by(a.channels).copied().collect(),
            ));
        }
    }
    Ok(out)
}

/// A depth in scene units to 16-bit millimetres: 0 for the background and for what
/// lies beyond the 16-bit range (65.535 m), so 0 always means "no depth".
pub fn depth_mm(z: f32, mm_per_unit: f64) -> u16 {
    depth_png16(z, mm_per_unit, 65535.0)
}

/// A depth in scene units to a 16-bit value with full scale `max_mm`: round(mm /
/// max_mm * 65535); 0 for the background and for what lies beyond `max_mm`.
pub fn depth_png16(z: f32, mm_per_unit: f64, max_mm: f64) -> u16 {
    let q = (z as f64 * mm_per_unit / max_mm * 65535.0).round();
    if z.is_finite() && (0.0..=65535.0).contains(&q) {
        q as u16
    } else {
        0
    }
}

/// World-space normals turned into OpenCV camera axes by the rotation rows of a
/// world-to-camera matrix (`CameraInfo::world_to_camera_opencv`).
pub fn normals_to_camera(normals: &[[f32; 3]], world_to_camera: &[[f64; 4]; 4]) -> Vec<[f32; 3]> {
    let r = world_to_camera;
    normals
        .iter()
        .map(|n| {
            std::array::from_fn(|i| {
                (r[i][0] * n[0] as f64 + r[i][1] * n[1] as f64 + r[i][2] * n[2] as f64) as f32
            })
        })
        .collect()
}

/// The semantic class pass: 0 background or unlabelled, else class index + 1.
pub fn semantic(p: &PassImages, classes: &ClassMap) -> Vec<u32> {
    let of_instance: Vec<u32> = p
        .instance_objects
        .iter()
        .map(|o| classes.class_of(o).map_or(0, |c| c as u32 + 1))
        .collect();
    p.instance_id
        .iter()
        .map(|&i| {
            if i == 0 {
                0
            } else {
                of_instance.get(i as usize - 1).copied().unwrap_or(0)
            }
        })
        .collect()
}

/// Writes every pass into `dir` (created if needed); returns the files written.
pub fn write_passes(
    dir: &Path,
    p: &PassImages,
    classes: &ClassMap,
    format: PassFormat,
    mm_per_unit: f64,
) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let (w, h) = (p.width, p.height);
    let n = (w * h) as usize;
    for (name, len) in [
        ("depth", p.depth.len()),
        ("distance", p.distance.len()),
        ("object_index", p.object_index.len()),
        ("instance_id", p.instance_id.len()),
        ("material_index", p.material_index.len()),
        ("normal", p.normal.len()),
        ("albedo", p.albedo.len()),
        ("uv", p.uv.len()),
    ] {
        if len != n {
            return Err(format!("{name} pass has {len} pixels, {w}x{h} needs {n}"));
        }
    }
    let sem = semantic(p, classes);
    let mut written = Vec::new();
    let mut put = |name: String, bytes: Vec<u8>| -> Result<(), String> {
        let path = dir.join(name);
        write_atomic(&path, &bytes)?;
        written.push(path);
        Ok(())
    };
    let ids: [(&str, &[u32]); 4] = [
        ("object_index", p.object_index),
        ("instance_id", p.instance_id),
        ("material_index", p.material_index),
        ("semantic", &sem),
    ];
    match format {
        PassFormat::Exr => {
            let grey = |v: &mut dyn Iterator<Item = f32>| v.map(|x| [x; 3]).collect::<Vec<_>>();
            let far = |d: &f32| if d.is_finite() { *d } else { 1e10 };
            put(
                "depth.exr".into(),
                exr_rgb_bytes(w, h, &grey(&mut p.depth.iter().map(far)))?,
            )?;
            put(
                "distance.exr".into(),
                exr_rgb_bytes(w, h, &grey(&mut p.distance.iter().map(far)))?,
            )?;
            for (name, v) in ids {
                put(
                    format!("{name}.exr"),
                    exr_rgb_bytes(w, h, &grey(&mut v.iter().map(|&x| x as f32)))?,
                )?;
            }
            put("normal.exr".into(), exr_rgb_bytes(w, h, p.normal)?)?;
            put("albedo.exr".into(), exr_rgb_bytes(w, h, p.albedo)?)?;
            put(
                "uv.exr".into(),
                exr_rgb_bytes(
                    w,
                    h,
                    &p.uv.iter().map(|u| [u[0], u[1], 0.0]).collect::<Vec<_>>(),
                )?,
            )?;
        }
        PassFormat::Png => {
            let mm = |v: &[f32]| {
                v.iter()
                    .map(|&z| depth_mm(z, mm_per_unit))
                    .collect::<Vec<u16>>()
            };
            put("depth.png".into(), png16_bytes(w, h, &mm(p.depth))?)?;
            put("distance.png".into(), png16_bytes(w, h, &mm(p.distance))?)?;
            for (name, v) in ids {
                let v16: Vec<u16> = v
                    .iter()
                    .map(|&x| {
                        u16::try_from(x).map_err(|_| {
                            format!("{name} pass: id {x} does not fit a 16-bit PNG; use EXR passes")
                        })
                    })
                    .collect::<Result<_, _>>()?;
                put(format!("{name}.png"), png16_bytes(w, h, &v16)?)?;
            }
            let q8 = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
            let normal: Vec<u8> = p
                .normal
                .iter()
                .flat_map(|n| n.map(|c| q8(c * 0.5 + 0.5)))
                .collect();
            put("normal.png".into(), png_bytes(w, h, 3, &normal)?)?;
            let albedo: Vec<u8> = p.albedo.iter().flat_map(|a| a.map(q8)).collect();
            put("albedo.png".into(), png_bytes(w, h, 3, &albedo)?)?;
            let q16 = |x: f32| (x.clamp(0.0, 1.0) * 65535.0 + 0.5) as u16;
            put(
                "uv_u.png".into(),
                png16_bytes(w, h, &p.uv.iter().map(|u| q16(u[0])).collect::<Vec<_>>())?,
            )?;
            put(
                "uv_v.png".into(),
                png16_bytes(w, h, &p.uv.iter().map(|u| q16(u[1])).collect::<Vec<_>>())?,
            )?;
        }
    }
    // Shader AOVs are float data in either format: one EXR, channels named as Blender's
    // multilayer EXR names them.
    if !p.aovs.is_empty() {
        let channels = aov_channels(p)?;
        let list: Vec<(&str, Vec<f32>)> = channels
            .iter()
            .map(|(n, v)| (n.as_str(), v.clone()))
            .collect();
        put(
            "aovs.exr".into(),
            crate::foundation::exr::channels_bytes(w, h, &list)?,
        )?;
    }
    let names: serde_json::Map<String, serde_json::Value> =
        std::iter::once(("0".to_string(), serde_json::Value::from("background")))
            .chain(
                classes
                    .names
                    .iter()
                    .enumerate()
                    .map(|(i, n)| ((i + 1).to_string(), serde_json::Value::from(n.as_str()))),
            )
            .collect();
    let objects: serde_json::Map<String, serde_json::Value> = p
        .instance_objects
        .iter()
        .enumerate()
        .map(|(i, o)| ((i + 1).to_string(), serde_json::Value::from(o.as_str())))
        .collect();
    let meta = serde_json::json!({ "semantic": names, "instance_id": objects, "depth_unit": if format == PassFormat::Png { "mm" } else { "scene units" }, "mm_per_unit": mm_per_unit });
    put(
        "classes.json".into(),
        serde_json::to_vec_pretty(&meta).map_err(|e| e.to_string())?,
    )?;
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::{depth_mm, depth_png16};

    #[test]
    fn depth_in_millimetres_with_zero_for_none() {
        assert_eq!(depth_mm(1.2345, 1000.0), 1235);
        assert_eq!(depth_mm(f32::INFINITY, 1000.0), 0);
        assert_eq!(depth_mm(70.0, 1000.0), 0);
        assert_eq!(depth_mm(65.535, 1000.0), 65535);
    }

    /// SimCol3D's convention: 20 cm full scale; decoding value * 200 / 65535 mm is within
    /// half a step of the depth, and 0 stays "no depth".
    #[test]
    fn depth_png_scale_round_trips_within_half_a_step() {
        let step = 200.0 / 65535.0;
        for i in 0..20000 {
            let z = 0.2 * i as f64 / 19999.0 + 1e-7 * (i % 7) as f64;
            let v = depth_png16(z as f32, 1000.0, 200.0);
            let back = v as f64 * step;
            let mm = z as f32 as f64 * 1000.0;
            if mm <= 200.0 {
                assert!(
                    (back - mm).abs() <= step / 2.0 + 1e-9,
                    "{mm} mm -> {v} -> {back}"
                );
            }
        }
        assert_eq!(depth_png16(0.2001, 1000.0, 200.0), 0);
        assert_eq!(depth_png16(f32::INFINITY, 1000.0, 200.0), 0);
        assert_eq!(depth_png16(0.2, 1000.0, 200.0), 65535);
    }
}
