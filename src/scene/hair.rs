//! Hair strands from the export (`evaluated[i].hair`): the keys Cycles syncs for an
//! object's Path hair particle systems (its blender/curves.cpp), object space, with the
//! per-key radius already shaped between root and tip.

use super::{quote, HairRef, Scene, SceneError};

/// One object's strands, all systems in order.
#[derive(Debug, Clone, Default)]
pub struct HairData {
    /// x, y, z (object space) and radius per key.
    pub keys: Vec<[f32; 4]>,
    /// Per curve: its first key and key count.
    pub curves: Vec<(u32, u32)>,
    /// Per curve: the object's material slot.
    pub curve_slot: Vec<u32>,
}

/// The strands in one hair file: a curve has at most this many keys (Cycles' render steps
/// are at most 2^10 + 1, plus a spiral kink's extra steps).
const MAX_KEYS_PER_CURVE: usize = 1 << 16;

impl Scene {
    /// Reads `evaluated[index].hair`'s file and checks it against its systems.
    pub fn load_hair(&self, index: usize) -> Result<Option<HairData>, SceneError> {
        let e = &self.file.evaluated[index];
        let Some(h) = &e.hair else {
            return Ok(None);
        };
        let at = format!("evaluated[{index}].hair");
        let path = self.resolve(&h.file, &format!("{at}.file"))?;
        let bytes = super::file::read_regular(&path, super::limits::MAX_GLB_BYTES)
            .map_err(|m| SceneError::new(&path, "", m))?;
        parse_hair(h, &bytes)
            .map_err(|(loc, m)| {
                SceneError::new(
                    &self.json_path(),
                    format!("{at}{loc}"),
                    format!("{m} (object {}, file {})", quote(&e.object), path.display()),
                )
            })
            .map(Some)
    }
}

/// The strands of `h` from its file's bytes; errors carry a location under `hair`.
pub fn parse_hair(h: &HairRef, bytes: &[u8]) -> Result<HairData, (String, String)> {
    let mut total = 0usize;
    for (i, s) in h.systems.iter().enumerate() {
        if !(2..=MAX_KEYS_PER_CURVE).contains(&s.keys_per_curve) {
            return Err((
                format!(".systems[{i}].keys_per_curve"),
                format!(
                    "is {}; a strand has 2 to {MAX_KEYS_PER_CURVE} keys",
                    s.keys_per_curve
                ),
            ));
        }
        total = super::limits::mul_add(s.curve_count, s.keys_per_curve, total)
            .filter(|&t| t <= u32::MAX as usize)
            .ok_or_else(|| {
                (
                    format!(".systems[{i}].curve_count"),
                    "too many keys".to_string(),
                )
            })?;
    }
    if bytes.len() != total * 16 {
        return Err((
            ".file".into(),
            format!(
                "holds {} bytes, the systems declare {total} keys of 16 bytes",
                bytes.len()
            ),
        ));
    }
    let keys: Vec<[f32; 4]> = bytes
        .chunks_exact(16)
        .map(|c| {
            [0, 1, 2, 3]
                .map(|k| f32::from_le_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]]))
        })
        .collect();
    if let Some(k) = keys
        .iter()
        .position(|k| !k.iter().all(|x| x.is_finite()) || k[3] < 0.0)
    {
        return Err((
            ".file".into(),
            format!(
                "key {k} is {:?}: positions must be finite, radii finite and >= 0",
                keys[k]
            ),
        ));
    }
    let mut data = HairData {
        keys,
        ..HairData::default()
    };
    let mut first = 0u32;
    for s in &h.systems {
        for _ in 0..s.curve_count {
            data.curves.push((first, s.keys_per_curve as u32));
            data.curve_slot.push(s.material_slot as u32);
            first += s.keys_per_curve as u32;
        }
    }
    Ok(data)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::HairSystem;

    fn hair(curves: usize, keys: usize) -> HairRef {
        HairRef {
            file: "h.bin".into(),
            systems: vec![HairSystem {
                name: "Hair".into(),
                material_slot: 1,
                curve_count: curves,
                keys_per_curve: keys,
                children: false,
            }],
        }
    }

    fn bytes(vals: &[f32]) -> Vec<u8> {
        vals.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    #[test]
    fn reads_keys_and_curves() {
        let b = bytes(&[
            0., 0., 0., 0.1, 0., 0., 1., 0.0, 1., 0., 0., 0.2, 1., 0., 1., 0.1,
        ]);
        let d = parse_hair(&hair(2, 2), &b).unwrap();
        assert_eq!(d.curves, vec![(0, 2), (2, 2)]);
        assert_eq!(d.curve_slot, vec![1, 1]);
        assert_eq!(d.keys[2], [1., 0., 0., 0.2]);
    }

    #[test]
    fn refuses_wrong_size_nan_and_negative_radius() {
        let b = bytes(&[0.; 12]);
        assert!(parse_hair(&hair(2, 2), &b)
            .unwrap_err()
            .1
            .contains("48 bytes"));
        let mut v = [0f32; 16];
        v[5] = f32::NAN;
        assert!(parse_hair(&hair(2, 2), &bytes(&v))
            .unwrap_err()
            .1
            .contains("finite"));
        v[5] = 0.0;
        v[7] = -1.0;
        assert!(parse_hair(&hair(2, 2), &bytes(&v))
            .unwrap_err()
            .1
            .contains(">= 0"));
        assert!(parse_hair(&hair(1, 1), &bytes(&[0.; 4]))
            .unwrap_err()
            .0
            .contains("keys_per_curve"));
    }
}
