//! Owen-scrambled Sobol sequences (Burley 2020, "Practical Hash-based Owen Scrambling"):
//! 4D Sobol points, index shuffled and each dimension nested-uniform scrambled with
//! hashes of (pixel, seed, dimension set). The random numbers of a sample depend only on
//! the pixel, the sample index and the seed, so any thread count gives the same bits.

/// Sobol direction numbers for the first four dimensions (Joe and Kuo), generated once.
const fn directions() -> [[u32; 32]; 4] {
    let mut v = [[0u32; 32]; 4];
    let mut k = 0;
    while k < 32 {
        v[0][k] = 1u32 << (31 - k);
        k += 1;
    }
    // (degree s, coefficients a, initial m) for dimensions 2..4.
    let params: [(usize, u32, [u32; 3]); 3] =
        [(1, 0, [1, 0, 0]), (2, 1, [1, 3, 0]), (3, 1, [1, 3, 1])];
    let mut d = 0;
    while d < 3 {
        let (s, a, m) = params[d];
        let mut k = 0;
        while k < 32 {
            if k < s {
                v[d + 1][k] = m[k] << (31 - k);
            } else {
                let mut x = v[d + 1][k - s] ^ (v[d + 1][k - s] >> s);
                let mut j = 1;
                while j < s {
                    if (a >> (s - 1 - j)) & 1 == 1 {
                        x ^= v[d + 1][k - j];
                    }
                    j += 1;
                }
                v[d + 1][k] = x;
            }
            k += 1;
        }
        d += 1;
    }
    v
}

/// Per dimension and byte, the XOR of the direction numbers a byte's set bits select, laid
/// out for `get4`'s nested uniform scramble: indexed by the bytes of the scrambled index
/// *before* its final bit reversal, and holding the Sobol point bit-reversed (reversal
/// commutes with XOR), so neither reversal around the lookup is computed (`get4` did ten
/// 32-bit reversals per call, now five). Four lookups per dimension instead of a loop
/// over 32 bits; the same bits (`tests::tables_match_bitwise_sobol`).
const fn byte_tables() -> [[[u32; 256]; 4]; 4] {
    let dirs = directions();
    let mut t = [[[0u32; 256]; 4]; 4];
    let mut d = 0;
    while d < 4 {
        let mut byte = 0;
        while byte < 4 {
            let mut v = 0;
            while v < 256 {
                // Byte `byte` of y is byte 3 - byte of reverse(y), bit-reversed.
                let rv = (v as u8).reverse_bits() as usize;
                let mut r = 0u32;
                let mut b = 0;
                while b < 8 {
                    if (rv >> b) & 1 == 1 {
                        r ^= dirs[d][(3 - byte) * 8 + b];
                    }
                    b += 1;
                }
                t[d][byte][v] = r.reverse_bits();
                v += 1;
            }
            byte += 1;
        }
        d += 1;
    }
    t
}

static SOBOL_BYTES: [[[u32; 256]; 4]; 4] = byte_tables();

/// `sobol(y.reverse_bits(), dim).reverse_bits()`, where `sobol(i, d)` is the Sobol point
/// of index `i` in dimension `d` (the XOR of the direction numbers of `i`'s set bits).
#[inline]
fn sobol_reversed(y: u32, dim: usize) -> u32 {
    let t = &SOBOL_BYTES[dim];
    t[0][(y & 255) as usize]
        ^ t[1][((y >> 8) & 255) as usize]
        ^ t[2][((y >> 16) & 255) as usize]
        ^ t[3][(y >> 24) as usize]
}

#[inline]
pub fn hash_u32(mut x: u32) -> u32 {
    // A good 32-bit integer hash (Wellons' lowbias32).
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846ca68b);
    x ^= x >> 16;
    x
}

#[inline]
pub fn hash_combine(a: u32, b: u32) -> u32 {
    hash_u32(
        a ^ b
            .wrapping_mul(0x9e3779b9)
            .wrapping_add(0x632be5ab)
            .wrapping_add(a << 6)
            .wrapping_add(a >> 2),
    )
}

#[inline]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50b47c);
    x ^= x.wrapping_mul(0xb82f1e52);
    x ^= x.wrapping_mul(0xc7afe638);
    x ^= x.wrapping_mul(0x8d22f6e6);
    x
}

#[cfg(test)]
fn nested_uniform_scramble(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

#[inline]
fn to_unit(x: u32) -> f32 {
    // 24 bits so the result is strictly below 1.
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// The random sequence of one pixel.
#[derive(Debug, Clone, Copy)]
pub struct PixelSampler {
    seed: u32,
}

impl PixelSampler {
    pub fn new(x: u32, y: u32, seed: u32) -> PixelSampler {
        PixelSampler {
            seed: hash_combine(hash_combine(hash_u32(x), y), seed),
        }
    }

    /// Four dimensions of sample `index` from dimension set `set` (each set is its own
    /// shuffled 4D Sobol sequence, so sets are decorrelated).
    #[inline]
    pub fn get4(&self, index: u32, set: u32) -> [f32; 4] {
        self.first_dims(index, set)
    }

    /// The first two of `get4`'s dimensions, the same bits, for callers that use only
    /// those (the subsurface walk's second set of each bounce).
    #[inline]
    pub fn get2(&self, index: u32, set: u32) -> [f32; 2] {
        self.first_dims(index, set)
    }

    #[inline(always)]
    fn first_dims<const N: usize>(&self, index: u32, set: u32) -> [f32; N] {
        // Dimension d is nested_uniform_scramble(sobol(i, d), seed_d) with the shuffled
        // index i = nested_uniform_scramble(index, s) = y.reverse_bits(); the reversals
        // next to the Sobol lookup are folded into its table (`sobol_reversed`).
        let s = hash_combine(self.seed, set);
        let y = laine_karras(index.reverse_bits(), s);
        let mut out = [0.0; N];
        for (d, o) in out.iter_mut().enumerate() {
            let x = laine_karras(sobol_reversed(y, d), hash_combine(s, d as u32 + 1));
            *o = to_unit(x.reverse_bits());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Sobol point of index `i` in dimension `d`, bit by bit.
    fn sobol_bitwise(i: u32, d: usize) -> u32 {
        let dirs = directions();
        (0..32)
            .filter(|b| (i >> b) & 1 == 1)
            .fold(0u32, |r, b| r ^ dirs[d][b])
    }

    /// The tables give the bit-reversed Sobol points of the bit-reversed index, and
    /// `get4` the values of the formula it folds (nested uniform scrambles around the
    /// Sobol point), bit for bit.
    #[test]
    fn tables_match_bitwise_sobol() {
        let mut x = 0x1234_5678u32;
        for _ in 0..10_000 {
            x = hash_u32(x);
            for d in 0..4 {
                assert_eq!(
                    sobol_reversed(x, d),
                    sobol_bitwise(x.reverse_bits(), d).reverse_bits()
                );
            }
        }
        let sampler = PixelSampler::new(5, 9, 3);
        for index in (0..2000).chain([u32::MAX - 1, u32::MAX]) {
            for set in [0, 1, 7, 1000] {
                let s = hash_combine(sampler.seed, set);
                let i = nested_uniform_scramble(index, s);
                let want: Vec<u32> = (0..4)
                    .map(|d| {
                        let v = nested_uniform_scramble(
                            sobol_bitwise(i, d),
                            hash_combine(s, d as u32 + 1),
                        );
                        to_unit(v).to_bits()
                    })
                    .collect();
                let got: Vec<u32> = sampler.get4(index, set).map(f32::to_bits).to_vec();
                assert_eq!(got, want, "index {index} set {set}");
            }
        }
    }

    #[test]
    fn stratified_in_2d() {
        // 16 points of an Owen-scrambled Sobol sequence fall one per 4x4 cell.
        let s = PixelSampler::new(3, 7, 1);
        let mut cells = [0; 16];
        for i in 0..16 {
            let p = s.get4(i, 0);
            cells[(p[0] * 4.0) as usize * 4 + (p[1] * 4.0) as usize] += 1;
        }
        assert!(cells.iter().all(|&c| c == 1), "{cells:?}");
    }
}
