//! Size limits on what a scene's files may declare, checked before anything is
//! allocated or indexed from an input number (docs/limits.md lists them all).

/// Elements in one mesh domain (vertices, edges, faces, corners, triangles) and values
/// in one attribute. Blender stores these counts as `int`, so no Blender mesh holds more.
pub const MAX_MESH_ELEMENTS: usize = i32::MAX as usize;

/// Bytes of one scene.json. The largest export in the study corpus is a few MB.
pub const MAX_SCENE_JSON_BYTES: u64 = 1 << 30;

/// Bytes of one glb: the format's own limit (its length field is 32-bit).
pub const MAX_GLB_BYTES: u64 = u32::MAX as u64;

/// Bytes of one colour-management config or LUT file.
pub const MAX_COLOR_FILE_BYTES: u64 = 1 << 30;

/// `a * b + c` for sizes computed from input numbers, or None when it overflows.
pub fn mul_add(a: usize, b: usize, c: usize) -> Option<usize> {
    a.checked_mul(b)?.checked_add(c)
}

/// Largest Point Density grid side read (the exporter writes at most 256).
pub const MAX_POINT_DENSITY_RESOLUTION: u32 = 256;
