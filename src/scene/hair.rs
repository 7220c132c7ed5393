//! Hair strands from the export (`evaluated[i].hair`): the keys Cycles syncs for an
//! object's Path hair particle systems (its blender/curves.cpp), object space, with the
//! per-key radius already shaped between root and tip.

use super::{quote, HairRef, Scene, SceneError};

/// Hair attributes by name: per key (true) or per curve, and their values.
pub type HairAttributes = Vec<(String, bool, crate::scene::mesh::AttributeData)>;

/// An object's point clouds: x, y, z, radius per point (object space), and each point's
/// index into its evaluated entry's materials.
pub type PointsData = (Vec<[f32; 4]>, Vec<u32>);

/// One object's strands, all systems in order.
#[derive(Debug, Clone, Default)]
pub struct HairData {
    /// x, y, z (object space) and radius per key.
    pub keys: Vec<[f32; 4]>,
    /// Per curve: its first key and key count.
    pub curves: Vec<(u32, u32)>,
    /// Per curve: the object's material slot.
    pub curve_slot: Vec<u32>,
    /// Attributes by name: per key (true) or per curve, and their values.
    pub attributes: HairAttributes,
    /// The attribute read as the hair's UV.
    pub uv: Option<String>,
    /// Per key: a Curves object's normals (object space); empty without.
    pub normals: Vec<[f32; 3]>,
    /// Whether the export carries the normals (`normals_file`): particle hair has none
    /// (Cycles gives it none either); a Curves object exported before they were, lacks them.
    pub has_normals: bool,
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
        let mut data = parse_hair(h, &bytes).map_err(|(loc, m)| {
            SceneError::new(
                &self.json_path(),
                format!("{at}{loc}"),
                format!("{m} (object {}, file {})", quote(&e.object), path.display()),
            )
        })?;
        if let Some(f) = &h.attributes_file {
            let apath = self.resolve(f, &format!("{at}.attributes_file"))?;
            let bytes = super::file::read_regular(&apath, super::limits::MAX_GLB_BYTES)
                .map_err(|m| SceneError::new(&apath, "", m))?;
            data.attributes = parse_hair_attributes(h, &data, &bytes).map_err(|(loc, m)| {
                SceneError::new(
                    &self.json_path(),
                    format!("{at}{loc}"),
                    format!(
                        "{m} (object {}, file {})",
                        quote(&e.object),
                        apath.display()
                    ),
                )
            })?;
        }
        data.uv = h.uv.clone();
        if let Some(f) = &h.normals_file {
            let npath = self.resolve(f, &format!("{at}.normals_file"))?;
            let bytes = super::file::read_regular(&npath, super::limits::MAX_GLB_BYTES)
                .map_err(|m| SceneError::new(&npath, "", m))?;
            data.normals = parse_hair_normals(data.keys.len(), &bytes).map_err(|m| {
                SceneError::new(
                    &self.json_path(),
                    format!("{at}.normals_file"),
                    format!(
                        "{m} (object {}, file {})",
                        quote(&e.object),
                        npath.display()
                    ),
                )
            })?;
            data.has_normals = true;
        }
        Ok(Some(data))
    }
}

impl Scene {
    /// Reads `evaluated[index].points`' file: per point x, y, z, radius (object space)
    /// and its index into the entry's materials.
    pub fn load_points(&self, index: usize) -> Result<Option<PointsData>, SceneError> {
        let e = &self.file.evaluated[index];
        let Some(p) = &e.points else {
            return Ok(None);
        };
        let at = format!("evaluated[{index}].points");
        let path = self.resolve(&p.file, &format!("{at}.file"))?;
        let bytes = super::file::read_regular(&path, super::limits::MAX_GLB_BYTES)
            .map_err(|m| SceneError::new(&path, "", m))?;
        let fail = |m: String| {
            SceneError::new(
                &self.json_path(),
                format!("{at}.file"),
                format!("{m} (object {}, file {})", quote(&e.object), path.display()),
            )
        };
        if Some(bytes.len()) != p.count.checked_mul(20) {
            return Err(fail(format!(
                "holds {} bytes, not the 20 per point of its {} points",
                bytes.len(),
                p.count
            )));
        }
        let f = |o: usize| f32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
        let keys: Vec<[f32; 4]> = (0..p.count)
            .map(|i| [f(16 * i), f(16 * i + 4), f(16 * i + 8), f(16 * i + 12)])
            .collect();
        let base = 16 * p.count;
        let slots: Vec<u32> = (0..p.count)
            .map(|i| {
                let o = base + 4 * i;
                u32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]])
            })
            .collect();
        if let Some(k) = keys
            .iter()
            .position(|k| !k.iter().all(|x| x.is_finite()) || k[3] < 0.0)
        {
            return Err(fail(format!(
                "point {k} is {:?}: positions must be finite, radii finite and >= 0",
                keys[k]
            )));
        }
        if let Some(i) = slots
            .iter()
            .position(|&s| s as usize >= e.materials.len().max(1))
        {
            return Err(fail(format!(
                "point {i} has material index {}, the entry has {} materials",
                slots[i],
                e.materials.len()
            )));
        }
        Ok(Some((keys, slots)))
    }
}

/// `keys` normals (x, y, z little-endian f32 each) from a normals file's bytes.
fn parse_hair_normals(keys: usize, bytes: &[u8]) -> Result<Vec<[f32; 3]>, String> {
    if Some(bytes.len()) != keys.checked_mul(12) {
        return Err(format!(
            "holds {} bytes, not the 12 per key of its {keys} keys",
            bytes.len()
        ));
    }
    let v: Vec<[f32; 3]> = bytes
        .chunks_exact(12)
        .map(|c| {
            std::array::from_fn(|i| {
                f32::from_le_bytes([c[4 * i], c[4 * i + 1], c[4 * i + 2], c[4 * i + 3]])
            })
        })
        .collect();
    if let Some(k) = v.iter().position(|n| !n.iter().all(|x| x.is_finite())) {
        return Err(format!("normal {k} is {:?}: normals must be finite", v[k]));
    }
    Ok(v)
}

/// The attributes `h` declares, from their file's bytes, for the curves and keys of `d`.
pub fn parse_hair_attributes(
    h: &HairRef,
    d: &HairData,
    bytes: &[u8],
) -> Result<HairAttributes, (String, String)> {
    use crate::scene::mesh::AttributeData as A;
    let mut at = 0usize;
    let mut out = Vec::with_capacity(h.attributes.len());
    for (i, a) in h.attributes.iter().enumerate() {
        let loc = |f: &str| format!(".attributes[{i}].{f}");
        let per_key = match a.domain.as_str() {
            "POINT" => true,
            "CURVE" => false,
            other => {
                return Err((
                    loc("domain"),
                    format!("is {other:?}: hair attributes are on POINT or CURVE"),
                ))
            }
        };
        let width = match a.data_type.as_str() {
            "FLOAT" => 1,
            "FLOAT2" => 2,
            "FLOAT_VECTOR" => 3,
            "FLOAT_COLOR" => 4,
            other => {
                return Err((
                    loc("data_type"),
                    format!("is {other:?}: FLOAT, FLOAT2, FLOAT_VECTOR or FLOAT_COLOR"),
                ))
            }
        };
        let n = if per_key {
            d.keys.len()
        } else {
            d.curves.len()
        };
        let size = n * width * 4;
        let Some(chunk) = bytes.get(at..at + size) else {
            return Err((
                ".attributes_file".into(),
                format!(
                    "holds {} bytes, fewer than the attributes declare",
                    bytes.len()
                ),
            ));
        };
        at += size;
        let v: Vec<f32> = chunk
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        if v.iter().any(|x| !x.is_finite()) {
            return Err((
                loc("name"),
                format!("{:?} holds a value that is not finite", a.name),
            ));
        }
        let data = match width {
            1 => A::Float(v),
            2 => A::Float2(v.chunks_exact(2).map(|c| [c[0], c[1]]).collect()),
            3 => A::Float3(v.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()),
            _ => A::Color(
                v.chunks_exact(4)
                    .map(|c| [c[0], c[1], c[2], c[3]])
                    .collect(),
            ),
        };
        out.push((a.name.clone(), per_key, data));
    }
    if at != bytes.len() {
        return Err((
            ".attributes_file".into(),
            format!("holds {} bytes, the attributes declare {at}", bytes.len()),
        ));
    }
    Ok(out)
}

/// The strands of `h` from its file's bytes; errors carry a location under `hair`.
pub fn parse_hair(h: &HairRef, bytes: &[u8]) -> Result<HairData, (String, String)> {
    // Per system: its keys and, for a Curves object's, the key count of each curve.
    let mut total = 0usize;
    let mut size = 0usize;
    for (i, s) in h.systems.iter().enumerate() {
        let at = |f: &str| format!(".systems[{i}].{f}");
        let keys = match s.key_count {
            Some(n) => {
                if s.keys_per_curve != 0 {
                    return Err((
                        at("keys_per_curve"),
                        format!(
                            "is {} with a key_count: a Curves system has keys_per_curve 0",
                            s.keys_per_curve
                        ),
                    ));
                }
                if n < s.curve_count {
                    return Err((
                        at("key_count"),
                        format!("is {n}, fewer than the {} curves", s.curve_count),
                    ));
                }
                n
            }
            None => {
                if !(2..=MAX_KEYS_PER_CURVE).contains(&s.keys_per_curve) {
                    return Err((
                        at("keys_per_curve"),
                        format!(
                            "is {}; a strand has 2 to {MAX_KEYS_PER_CURVE} keys",
                            s.keys_per_curve
                        ),
                    ));
                }
                super::limits::mul_add(s.curve_count, s.keys_per_curve, 0)
                    .ok_or_else(|| (at("curve_count"), "too many keys".to_string()))?
            }
        };
        total = total
            .checked_add(keys)
            .filter(|&t| t <= u32::MAX as usize)
            .ok_or_else(|| (at("curve_count"), "too many keys".to_string()))?;
        let counts = if s.key_count.is_some() {
            s.curve_count
        } else {
            0
        };
        size = super::limits::mul_add(keys, 16, size)
            .and_then(|z| super::limits::mul_add(counts, 4, z))
            .ok_or_else(|| (at("curve_count"), "too many keys".to_string()))?;
    }
    if bytes.len() != size {
        return Err((
            ".file".into(),
            format!(
                "holds {} bytes, the systems declare {total} keys ({size} bytes)",
                bytes.len()
            ),
        ));
    }
    let f32_at =
        |o: usize| f32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    let mut data = HairData::default();
    data.keys.reserve(total);
    let mut at = 0usize;
    for (i, s) in h.systems.iter().enumerate() {
        let first_key = data.keys.len();
        let n = s.key_count.unwrap_or(s.curve_count * s.keys_per_curve);
        for k in 0..n {
            let o = at + 16 * k;
            let key = [f32_at(o), f32_at(o + 4), f32_at(o + 8), f32_at(o + 12)];
            if !key.iter().all(|x| x.is_finite()) || key[3] < 0.0 {
                return Err((
                    ".file".into(),
                    format!(
                        "key {} is {key:?}: positions must be finite, radii finite and >= 0",
                        first_key + k
                    ),
                ));
            }
            data.keys.push(key);
        }
        at += 16 * n;
        let mut first = first_key as u32;
        for c in 0..s.curve_count {
            let count = match s.key_count {
                Some(_) => {
                    let o = at + 4 * c;
                    u32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]])
                }
                None => s.keys_per_curve as u32,
            };
            if count == 0 || first as usize + count as usize > first_key + n {
                return Err((
                    format!(".systems[{i}]"),
                    format!("curve {c} has {count} keys: each curve has at least one, and all fit in key_count {n}"),
                ));
            }
            data.curves.push((first, count));
            data.curve_slot.push(s.material_slot as u32);
            first += count;
        }
        if s.key_count.is_some() {
            if first as usize != first_key + n {
                return Err((
                    format!(".systems[{i}].key_count"),
                    format!(
                        "is {n}, the curves' key counts add up to {}",
                        first as usize - first_key
                    ),
                ));
            }
            at += 4 * s.curve_count;
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
            attributes_file: None,
            attributes: Vec::new(),
            uv: None,
            normals_file: None,
            systems: vec![HairSystem {
                name: "Hair".into(),
                material_slot: 1,
                curve_count: curves,
                keys_per_curve: keys,
                key_count: None,
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

    fn curves_system(curves: usize, keys: usize) -> HairRef {
        let mut h = hair(curves, 0);
        h.systems[0].key_count = Some(keys);
        h
    }

    #[test]
    fn reads_a_curves_objects_curves_of_different_lengths() {
        let mut b = bytes(&[0.5; 5 * 4]);
        b.extend([2u32, 3].iter().flat_map(|c| c.to_le_bytes()));
        let d = parse_hair(&curves_system(2, 5), &b).unwrap();
        assert_eq!(d.curves, vec![(0, 2), (2, 3)]);
        // Counts that do not add up to the keys, a zero count, a wrong size.
        let mut bad = bytes(&[0.5; 5 * 4]);
        bad.extend([2u32, 2].iter().flat_map(|c| c.to_le_bytes()));
        assert!(parse_hair(&curves_system(2, 5), &bad)
            .unwrap_err()
            .1
            .contains("add up"));
        let mut zero = bytes(&[0.5; 5 * 4]);
        zero.extend([0u32, 5].iter().flat_map(|c| c.to_le_bytes()));
        assert!(parse_hair(&curves_system(2, 5), &zero)
            .unwrap_err()
            .1
            .contains("at least one"));
        assert!(parse_hair(&curves_system(2, 5), &b[..b.len() - 4])
            .unwrap_err()
            .1
            .contains("bytes"));
        let mut both = curves_system(2, 5);
        both.systems[0].keys_per_curve = 3;
        assert!(parse_hair(&both, &b)
            .unwrap_err()
            .0
            .contains("keys_per_curve"));
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
