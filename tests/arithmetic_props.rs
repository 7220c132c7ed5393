//! Property tests (proptest) for the checked arithmetic on input numbers (issue 27):
//! the checked helpers agree with exact 128-bit arithmetic, and a glb accessor with any
//! offsets, stride and count is either read within its data or refused, never a panic.

use blendsynth::geometry::limits as glimits;
use blendsynth::scene::limits::mul_add;
use blendsynth::scene::mesh::parse_glb;
use proptest::prelude::*;
use serde_json::{json, Value};
use std::path::Path;

/// A glb whose only content is `positions` (a VEC3 float accessor) with the given
/// layout numbers, declaring `count` vertices.
fn glb(
    count: u64,
    view_offset: u64,
    acc_offset: u64,
    stride: Option<u64>,
    view_len: u64,
    bin: &[u8],
) -> Vec<u8> {
    let mut view = json!({"buffer": 0, "byteOffset": view_offset, "byteLength": view_len});
    if let Some(s) = stride {
        view["byteStride"] = Value::from(s);
    }
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [view],
        "accessors": [{"bufferView": 0, "byteOffset": acc_offset, "componentType": 5126,
                        "count": count, "type": "VEC3"}],
        "extras": {"blendsynth": {"version": 1, "name": "P", "vertex_count": count,
                   "edge_count": 0, "face_count": 0, "corner_count": 0,
                   "vertex_positions": 0}}
    });
    let mut j = serde_json::to_vec(&doc).unwrap();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&((28 + j.len() + b.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}

/// Numbers around the interesting edges: small, near powers of two, near u64::MAX.
fn edgy() -> impl Strategy<Value = u64> {
    prop_oneof![
        0u64..64,
        (0u32..64).prop_map(|k| 1u64 << k),
        (0u32..64, -3i64..4).prop_map(|(k, d)| (1u64 << k).wrapping_add(d as u64)),
        (0u64..8).prop_map(|d| u64::MAX - d),
        any::<u64>(),
    ]
}

proptest! {
    // A fixed seed: CI must not pass or fail by the luck of the draw (a random
    // seed once found `subdivided_corners(0, 33)` on CI only). Many cases make
    // up for the fixed stream; the edge values above are drawn often.
    #![proptest_config(ProptestConfig {
        cases: 20_000,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x5eed_b1e5),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn mul_add_agrees_with_u128(a in edgy(), b in edgy(), c in edgy()) {
        let (a, b, c) = (a as usize, b as usize, c as usize);
        let exact = a as u128 * b as u128 + c as u128;
        let want = (exact <= usize::MAX as u128).then_some(exact as usize);
        prop_assert_eq!(mul_add(a, b, c), want);
    }

    #[test]
    fn product_and_subdivided_corners_agree_with_u128(a in edgy(), b in edgy(), level in 0u32..40) {
        let exact = a as u128 * b as u128;
        prop_assert_eq!(glimits::product(&[a, b]), (exact <= u64::MAX as u128).then_some(exact as u64));
        let exact = if level == 0 {
            Some(a as u128)
        } else {
            4u128.checked_pow(level).and_then(|p| p.checked_mul(a as u128))
        };
        let want = exact.filter(|&n| n <= u64::MAX as u128).map(|n| n as u64);
        prop_assert_eq!(glimits::subdivided_corners(a, level), want);
        // The limit check refuses exactly what is beyond the limit.
        let ok = glimits::check(want, "x").is_ok();
        prop_assert_eq!(ok, want.is_some_and(|n| n <= glimits::MAX_ELEMENTS));
    }

    #[test]
    fn a_glb_accessor_is_read_inside_its_data_or_refused(
        count in edgy(), view_offset in edgy(), acc_offset in edgy(),
        stride in proptest::option::of(edgy()), view_len in edgy(), bin_len in 0usize..512,
    ) {
        let bin: Vec<u8> = (0..bin_len).map(|i| (i % 7) as u8).collect();
        let bytes = glb(count, view_offset, acc_offset, stride, view_len, &bin);
        let r = std::panic::catch_unwind(|| parse_glb(&bytes, Path::new("p.glb")));
        prop_assert!(r.is_ok(), "parse_glb panicked");
        let padded = bin_len.div_ceil(4) * 4;
        let elem = 12u128;
        let st = stride.map_or(elem, |s| s as u128);
        let start = view_offset as u128 + acc_offset as u128;
        let end = if count == 0 { start } else { start + st * (count as u128 - 1) + elem };
        let fits = st >= elem
            && end <= view_offset as u128 + view_len as u128
            && view_offset as u128 + view_len as u128 <= padded as u128;
        if let Ok(Ok(m)) = &r.as_ref().map(|r| r.as_ref().map(|m| m.vertex_count())) {
            prop_assert!(fits, "accepted an accessor outside its data");
            prop_assert_eq!(*m as u64, count);
        }
    }
}

/// The case a random seed found on CI: an empty mesh subdivided past the level
/// at which 4^level alone overflows u64 still has no corners.
#[test]
fn empty_mesh_subdivided_deeply_has_no_corners() {
    for level in [0, 1, 31, 32, 33, 39, 200] {
        assert_eq!(
            glimits::subdivided_corners(0, level),
            Some(0),
            "level {level}"
        );
    }
    assert_eq!(glimits::subdivided_corners(1, 32), None);
    assert_eq!(glimits::subdivided_corners(1, 31), Some(1 << 62));
}
