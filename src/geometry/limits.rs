//! Element-count limits for nodes that size a mesh from an input number (Grid's
//! vertices, Subdivide Mesh's level, ...): the count is computed with checked arithmetic
//! and compared with the limit before anything is allocated, so `--set` with a huge
//! value is an error naming the node and the input, not an out-of-memory abort.
//! docs/limits.md lists the limits.

/// Most elements a node may make in one domain (vertices, edges, faces or corners):
/// 2^26, about 67 million, a few GB of mesh. Blender itself stops at 2^31 - 1.
pub const MAX_ELEMENTS: u64 = 1 << 26;

/// Most runs of zone bodies (Repeat iterations, For Each elements) in one Geometry Nodes
/// evaluation, all zones together (nested zones multiply): 2^20. Blender has no limit, so
/// a hostile Iterations of 1e9 would run for hours; past this it is an error naming the
/// zone's node.
pub const MAX_ZONE_ITERATIONS: u64 = 1 << 20;

/// Most frames a Simulation zone is played for to reach the frame asked for (each one
/// a whole evaluation of the object): 2^16, about 45 minutes at 24 fps.
pub const MAX_SIMULATION_FRAMES: u64 = 1 << 16;

/// Deepest field carried through a Repeat zone's iterations (operations from the field's
/// output to its deepest input). Each iteration can wrap a field item in more operations
/// and evaluating a field recurses through them, so a field item that grows with the
/// iterations stops here with an error naming the zone instead of exhausting the stack.
pub const MAX_FIELD_DEPTH: usize = 2000;

/// `Ok` when `count` (None: it overflowed) is within MAX_ELEMENTS; the error names the
/// input(s) the count came from, for the caller to prefix with the node.
pub fn check(count: Option<u64>, input: &str) -> Result<(), String> {
    match count {
        Some(n) if n <= MAX_ELEMENTS => Ok(()),
        Some(n) => Err(format!(
            "{input} would make {n} elements, more than the limit of {MAX_ELEMENTS}"
        )),
        None => Err(format!(
            "{input} would make more elements than can be counted (limit {MAX_ELEMENTS})"
        )),
    }
}

/// Product of input numbers, None on overflow.
pub fn product(factors: &[u64]) -> Option<u64> {
    factors.iter().try_fold(1u64, |acc, &f| acc.checked_mul(f))
}

/// Faces (and corners / 4) after `level` rounds of subdividing a mesh with `corners`
/// face corners: the first round makes one quad per corner, each later round four per
/// quad. The largest domain of the result is its corners, four per quad.
pub fn subdivided_corners(corners: u64, level: u32) -> Option<u64> {
    // No corners stay no corners at any level; checking 4^level first would
    // refuse an empty mesh at a level whose factor alone overflows.
    if level == 0 || corners == 0 {
        return Some(corners);
    }
    let quads = corners.checked_mul(4u64.checked_pow(level - 1)?)?;
    quads.checked_mul(4)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts() {
        assert!(check(product(&[100, 100]), "x").is_ok());
        assert!(check(product(&[100_000, 100_000]), "x").is_err());
        assert!(check(product(&[u64::MAX, 2]), "x").is_err());
        // A cube (24 corners) at level 1: 24 quads, 96 corners.
        assert_eq!(subdivided_corners(24, 1), Some(96));
        assert_eq!(subdivided_corners(24, 2), Some(384));
        assert!(check(subdivided_corners(24, 11), "Level").is_err());
        assert_eq!(subdivided_corners(u64::MAX, 3), None);
    }
}
