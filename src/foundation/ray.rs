//! Cycles' path flags (`PATH_RAY_*`): what kind of ray a path is on. The Light Path node
//! reads them, and objects' ray visibility filters BVH hits by them.

pub const CAMERA: u32 = 1 << 0;
pub const REFLECT: u32 = 1 << 1;
pub const TRANSMIT: u32 = 1 << 2;
pub const DIFFUSE: u32 = 1 << 3;
pub const GLOSSY: u32 = 1 << 4;
pub const SINGULAR: u32 = 1 << 5;
pub const TRANSPARENT: u32 = 1 << 6;
pub const SHADOW: u32 = 1 << 7;
/// Emission evaluated for a light sample (Cycles counts it one bounce further).
pub const EMISSION: u32 = 1 << 8;
/// A ray leaving a volume scatter point (render/volume.rs), as Is Volume Scatter Ray
/// reads it.
pub const VOLUME_SCATTER: u32 = 1 << 9;
