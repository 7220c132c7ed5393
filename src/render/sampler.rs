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

/// Per dimension and byte of the index, the XOR of the direction numbers that byte's set
/// bits select: a Sobol point is then four lookups per dimension instead of a loop over
/// 32 bits (the scrambled index uses all of them). The same bits as the loop.
const fn byte_tables() -> [[[u32; 256]; 4]; 4] {
    let dirs = directions();
    let mut t = [[[0u32; 256]; 4]; 4];
    let mut d = 0;
    while d < 4 {
        let mut byte = 0;
        while byte < 4 {
            let mut v = 0;
            while v < 256 {
                let mut r = 0u32;
                let mut b = 0;
                while b < 8 {
                    if (v >> b) & 1 == 1 {
                        r ^= dirs[d][byte * 8 + b];
                    }
                    b += 1;
                }
                t[d][byte][v] = r;
                v += 1;
            }
            byte += 1;
        }
        d += 1;
    }
    t
}

static SOBOL_BYTES: [[[u32; 256]; 4]; 4] = byte_tables();

#[inline]
fn sobol(index: u32, dim: usize) -> u32 {
    let t = &SOBOL_BYTES[dim];
    t[0][(index & 255) as usize]
        ^ t[1][((index >> 8) & 255) as usize]
        ^ t[2][((index >> 16) & 255) as usize]
        ^ t[3][(index >> 24) as usize]
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

#[inline]
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
        let s = hash_combine(self.seed, set);
        let i = nested_uniform_scramble(index, s);
        let mut out = [0.0; 4];
        for (d, o) in out.iter_mut().enumerate() {
            *o = to_unit(nested_uniform_scramble(
                sobol(i, d),
                hash_combine(s, d as u32 + 1),
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The byte tables give the Sobol points of the direction numbers bit by bit.
    #[test]
    fn byte_tables_match_bitwise_sobol() {
        let dirs = directions();
        let mut x = 0x1234_5678u32;
        for _ in 0..10_000 {
            x = hash_u32(x);
            for (d, dir) in dirs.iter().enumerate() {
                let want = (0..32)
                    .filter(|b| (x >> b) & 1 == 1)
                    .fold(0u32, |r, b| r ^ dir[b]);
                assert_eq!(sobol(x, d), want);
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
