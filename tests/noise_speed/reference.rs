//! The procedural textures as they were before the speed work (commit 7934fd9), kept
//! verbatim apart from imports as the bit-exact reference for tests/noise_speed.rs.
#![allow(dead_code, clippy::all)]

pub mod random {
    //! Blender's hash-based random values: Bob Jenkins' lookup3 hash as `BLI_noise.hh`
    //! (`noise::hash`, `hash_to_float`, `hash_float_to_float`, ...) defines it, used by the
    //! Random Value node, by noise textures' seeds and by point distribution; and
    //! `RandomNumberGenerator` (`BLI_rand.hh`, a 48-bit linear congruential generator), used
    //! by Distribute Points on Faces.

    #[inline]
    fn rot(x: u32, k: u32) -> u32 {
        x.rotate_left(k)
    }

    #[inline]
    fn mix(a: &mut u32, b: &mut u32, c: &mut u32) {
        *a = a.wrapping_sub(*c);
        *a ^= rot(*c, 4);
        *c = c.wrapping_add(*b);
        *b = b.wrapping_sub(*a);
        *b ^= rot(*a, 6);
        *a = a.wrapping_add(*c);
        *c = c.wrapping_sub(*b);
        *c ^= rot(*b, 8);
        *b = b.wrapping_add(*a);
        *a = a.wrapping_sub(*c);
        *a ^= rot(*c, 16);
        *c = c.wrapping_add(*b);
        *b = b.wrapping_sub(*a);
        *b ^= rot(*a, 19);
        *a = a.wrapping_add(*c);
        *c = c.wrapping_sub(*b);
        *c ^= rot(*b, 4);
        *b = b.wrapping_add(*a);
    }

    #[inline]
    fn finalize(a: &mut u32, b: &mut u32, c: &mut u32) {
        *c ^= *b;
        *c = c.wrapping_sub(rot(*b, 14));
        *a ^= *c;
        *a = a.wrapping_sub(rot(*c, 11));
        *b ^= *a;
        *b = b.wrapping_sub(rot(*a, 25));
        *c ^= *b;
        *c = c.wrapping_sub(rot(*b, 16));
        *a ^= *c;
        *a = a.wrapping_sub(rot(*c, 4));
        *b ^= *a;
        *b = b.wrapping_sub(rot(*a, 14));
        *c ^= *b;
        *c = c.wrapping_sub(rot(*b, 24));
    }

    const SEED: u32 = 0xdeadbeef;

    pub fn hash1(kx: u32) -> u32 {
        let mut a = SEED.wrapping_add(1 << 2).wrapping_add(13);
        let (mut b, mut c) = (a, a);
        a = a.wrapping_add(kx);
        finalize(&mut a, &mut b, &mut c);
        c
    }

    pub fn hash2(kx: u32, ky: u32) -> u32 {
        let mut a = SEED.wrapping_add(2 << 2).wrapping_add(13);
        let (mut b, mut c) = (a, a);
        b = b.wrapping_add(ky);
        a = a.wrapping_add(kx);
        finalize(&mut a, &mut b, &mut c);
        c
    }

    pub fn hash3(kx: u32, ky: u32, kz: u32) -> u32 {
        let mut a = SEED.wrapping_add(3 << 2).wrapping_add(13);
        let (mut b, mut c) = (a, a);
        c = c.wrapping_add(kz);
        b = b.wrapping_add(ky);
        a = a.wrapping_add(kx);
        finalize(&mut a, &mut b, &mut c);
        c
    }

    pub fn hash4(kx: u32, ky: u32, kz: u32, kw: u32) -> u32 {
        let mut a = SEED.wrapping_add(4 << 2).wrapping_add(13);
        let (mut b, mut c) = (a, a);
        a = a.wrapping_add(kx);
        b = b.wrapping_add(ky);
        c = c.wrapping_add(kz);
        mix(&mut a, &mut b, &mut c);
        a = a.wrapping_add(kw);
        finalize(&mut a, &mut b, &mut c);
        c
    }

    /// `uint_to_float_01`: `float(k) / float(0xFFFFFFFF)` in single precision.
    #[inline]
    pub fn uint_to_float_01(k: u32) -> f32 {
        k as f32 / u32::MAX as f32
    }

    pub fn hash_to_float1(kx: u32) -> f32 {
        uint_to_float_01(hash1(kx))
    }
    pub fn hash_to_float2(kx: u32, ky: u32) -> f32 {
        uint_to_float_01(hash2(kx, ky))
    }
    pub fn hash_to_float3(kx: u32, ky: u32, kz: u32) -> f32 {
        uint_to_float_01(hash3(kx, ky, kz))
    }
    pub fn hash_to_float4(kx: u32, ky: u32, kz: u32, kw: u32) -> f32 {
        uint_to_float_01(hash4(kx, ky, kz, kw))
    }

    /// Hashes of floats hash their bit patterns.
    pub fn hash_float_to_float1(k: f32) -> f32 {
        uint_to_float_01(hash1(k.to_bits()))
    }
    pub fn hash_float_to_float2(k: [f32; 2]) -> f32 {
        uint_to_float_01(hash2(k[0].to_bits(), k[1].to_bits()))
    }
    pub fn hash_float_to_float3(k: [f32; 3]) -> f32 {
        uint_to_float_01(hash3(k[0].to_bits(), k[1].to_bits(), k[2].to_bits()))
    }
    pub fn hash_float_to_float4(k: [f32; 4]) -> f32 {
        uint_to_float_01(hash4(
            k[0].to_bits(),
            k[1].to_bits(),
            k[2].to_bits(),
            k[3].to_bits(),
        ))
    }
}

pub mod white_noise {
    type Vec3 = [f32; 3];
    use super::random::{
        hash_float_to_float1 as h1, hash_float_to_float2 as h2, hash_float_to_float3 as h3,
        hash_float_to_float4 as h4,
    };

    pub fn hash_f1_to_f3(k: f32) -> Vec3 {
        [h1(k), h2([k, 1.0]), h2([k, 2.0])]
    }
    pub fn hash_f2_to_f2(k: [f32; 2]) -> [f32; 2] {
        [h2(k), h3([k[0], k[1], 1.0])]
    }
    pub fn hash_f2_to_f3(k: [f32; 2]) -> Vec3 {
        [h2(k), h3([k[0], k[1], 1.0]), h3([k[0], k[1], 2.0])]
    }
    pub fn hash_f3_to_f3(k: Vec3) -> Vec3 {
        [
            h3(k),
            h4([k[0], k[1], k[2], 1.0]),
            h4([k[0], k[1], k[2], 2.0]),
        ]
    }
    pub fn hash_f4_to_f4(k: [f32; 4]) -> [f32; 4] {
        [
            h4(k),
            h4([k[3], k[0], k[1], k[2]]),
            h4([k[2], k[3], k[0], k[1]]),
            h4([k[1], k[2], k[3], k[0]]),
        ]
    }
    pub fn hash_f4_to_f3(k: [f32; 4]) -> Vec3 {
        [
            h4(k),
            h4([k[2], k[0], k[3], k[1]]),
            h4([k[3], k[2], k[1], k[0]]),
        ]
    }

    /// The White Noise Texture node: (Value, Color) for `dimensions` 1-4 (`vector` for 2-4,
    /// `w` for 1 and 4).
    pub fn white_noise(dimensions: u8, vector: Vec3, w: f32) -> (f32, Vec3) {
        let [x, y, z] = vector;
        match dimensions {
            1 => (h1(w), hash_f1_to_f3(w)),
            2 => (h2([x, y]), hash_f2_to_f3([x, y])),
            4 => (h4([x, y, z, w]), hash_f4_to_f3([x, y, z, w])),
            _ => (h3(vector), hash_f3_to_f3(vector)),
        }
    }
}

pub mod voronoi {
    type Vec3 = [f32; 3];
    use super::random::hash_float_to_float1;
    use super::white_noise::{
        hash_f1_to_f3, hash_f2_to_f2, hash_f2_to_f3, hash_f3_to_f3, hash_f4_to_f3, hash_f4_to_f4,
    };
    pub use blendsynth::nodes::voronoi::{VoronoiFeature, VoronoiMetric};

    #[derive(Debug, Clone, Copy)]
    pub struct VoronoiParams {
        pub feature: VoronoiFeature,
        pub metric: VoronoiMetric,
        pub normalize: bool,
        pub scale: f32,
        pub detail: f32,
        pub roughness: f32,
        pub lacunarity: f32,
        pub smoothness: f32,
        pub exponent: f32,
        pub randomness: f32,
        max_distance: f32,
    }

    /// The node's outputs.
    #[derive(Debug, Clone, Copy, Default, PartialEq)]
    pub struct VoronoiOutput {
        pub distance: f32,
        pub color: Vec3,
        pub position: Vec3,
        pub w: f32,
        pub radius: f32,
    }

    trait Cell<const N: usize> {
        fn jitter(cell: [f32; N]) -> [f32; N];
        fn color(cell: [f32; N]) -> Vec3;
        /// The cell's colour given its jitter hash (in 3D both are the same hash).
        fn color_with(cell: [f32; N], _jitter: [f32; N]) -> Vec3 {
            Self::color(cell)
        }
        /// Cycles' `voronoi_position`: where the N components land in (x, y, z, w).
        fn position(p: [f32; N]) -> [f32; 4];
    }
    struct D;
    impl Cell<1> for D {
        fn jitter(c: [f32; 1]) -> [f32; 1] {
            [hash_float_to_float1(c[0])]
        }
        fn color(c: [f32; 1]) -> Vec3 {
            hash_f1_to_f3(c[0])
        }
        fn position(p: [f32; 1]) -> [f32; 4] {
            [0.0, 0.0, 0.0, p[0]]
        }
    }
    impl Cell<2> for D {
        fn jitter(c: [f32; 2]) -> [f32; 2] {
            hash_f2_to_f2(c)
        }
        fn color(c: [f32; 2]) -> Vec3 {
            hash_f2_to_f3(c)
        }
        fn position(p: [f32; 2]) -> [f32; 4] {
            [p[0], p[1], 0.0, 0.0]
        }
    }
    impl Cell<3> for D {
        fn jitter(c: [f32; 3]) -> [f32; 3] {
            hash_f3_to_f3(c)
        }
        fn color(c: [f32; 3]) -> Vec3 {
            hash_f3_to_f3(c)
        }
        fn color_with(_: [f32; 3], jitter: [f32; 3]) -> Vec3 {
            jitter
        }
        fn position(p: [f32; 3]) -> [f32; 4] {
            [p[0], p[1], p[2], 0.0]
        }
    }
    impl Cell<4> for D {
        fn jitter(c: [f32; 4]) -> [f32; 4] {
            hash_f4_to_f4(c)
        }
        fn color(c: [f32; 4]) -> Vec3 {
            hash_f4_to_f3(c)
        }
        fn position(p: [f32; 4]) -> [f32; 4] {
            p
        }
    }

    #[inline]
    fn add<const N: usize>(a: [f32; N], b: [f32; N]) -> [f32; N] {
        std::array::from_fn(|i| a[i] + b[i])
    }
    #[inline]
    fn sub<const N: usize>(a: [f32; N], b: [f32; N]) -> [f32; N] {
        std::array::from_fn(|i| a[i] - b[i])
    }
    #[inline]
    fn scale<const N: usize>(a: [f32; N], s: f32) -> [f32; N] {
        a.map(|x| x * s)
    }
    #[inline]
    fn dot<const N: usize>(a: [f32; N], b: [f32; N]) -> f32 {
        (0..N).fold(0.0, |s, i| s + a[i] * b[i])
    }
    #[inline]
    fn mix1(a: f32, b: f32, t: f32) -> f32 {
        a + t * (b - a)
    }
    #[inline]
    fn mixn<const N: usize>(a: [f32; N], b: [f32; N], t: f32) -> [f32; N] {
        std::array::from_fn(|i| mix1(a[i], b[i], t))
    }
    fn euclidean<const N: usize>(a: [f32; N], b: [f32; N]) -> f32 {
        let d = sub(a, b);
        dot(d, d).sqrt()
    }

    fn metric_distance<const N: usize>(a: [f32; N], b: [f32; N], p: &VoronoiParams) -> f32 {
        if N == 1 {
            return (b[0] - a[0]).abs();
        }
        let d = sub(a, b).map(f32::abs);
        match p.metric {
            VoronoiMetric::Euclidean => euclidean(a, b),
            VoronoiMetric::Manhattan => reduce_add(d),
            VoronoiMetric::Chebychev => d.iter().fold(d[0], |m, &x| m.max(x)),
            VoronoiMetric::Minkowski => {
                reduce_add(d.map(|x| x.powf(p.exponent))).powf(1.0 / p.exponent)
            }
        }
    }

    /// Cycles' `reduce_add`: float4 sums pairwise in its SSE kernels, (x + y) + (z + w);
    /// the order decides exact distance ties between lattice points (randomness 0).
    #[inline]
    fn reduce_add<const N: usize>(v: [f32; N]) -> f32 {
        if N == 4 {
            (v[0] + v[1]) + (v[2] + v[3])
        } else {
            v.iter().sum()
        }
    }

    /// Calls `f` with every cell offset in [-r, r]^N, x fastest (Cycles' loop nesting).
    #[inline]
    fn for_cells<const N: usize>(r: i32, mut f: impl FnMut([f32; N])) {
        let side = 2 * r + 1;
        let total = side.pow(N as u32);
        for t in 0..total {
            let mut k = t;
            let off = std::array::from_fn(|_| {
                let v = (k % side - r) as f32;
                k /= side;
                v
            });
            f(off);
        }
    }

    struct Octave {
        distance: f32,
        color: Vec3,
        position: [f32; 4],
    }

    fn split<const N: usize>(coord: [f32; N]) -> ([f32; N], [f32; N]) {
        let cell = coord.map(f32::floor);
        (cell, sub(coord, cell))
    }

    fn f1<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> Octave
    where
        D: Cell<N>,
    {
        let (cell, local) = split(coord);
        let mut min_d = f32::MAX;
        let (mut target_off, mut target_pos) = ([0.0; N], [0.0; N]);
        for_cells(1, |off: [f32; N]| {
            let point = add(off, scale(D::jitter(add(cell, off)), p.randomness));
            let d = metric_distance(point, local, p);
            if d < min_d {
                target_off = off;
                min_d = d;
                target_pos = point;
            }
        });
        Octave {
            distance: min_d,
            color: D::color(add(cell, target_off)),
            position: D::position(add(target_pos, cell)),
        }
    }

    fn smooth_f1<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> Octave
    where
        D: Cell<N>,
    {
        let (cell, local) = split(coord);
        let mut sd = 0.0f32;
        let mut sc = [0.0f32; 3];
        let mut sp = [0.0f32; N];
        let mut h = -1.0f32;
        for_cells(2, |off: [f32; N]| {
            let jitter = D::jitter(add(cell, off));
            let point = add(off, scale(jitter, p.randomness));
            let d = metric_distance(point, local, p);
            h = if h == -1.0 {
                1.0
            } else {
                smoothstep(0.5 + 0.5 * (sd - d) / p.smoothness)
            };
            let mut corr = p.smoothness * h * (1.0 - h);
            sd = mix1(sd, d, h) - corr;
            corr /= 1.0 + 3.0 * p.smoothness;
            let c = D::color_with(add(cell, off), jitter);
            sc = mixn(sc, c, h).map(|x| x - corr);
            sp = mixn(sp, point, h).map(|x| x - corr);
        });
        Octave {
            distance: sd,
            color: sc,
            position: D::position(add(cell, sp)),
        }
    }

    fn smoothstep(x: f32) -> f32 {
        if x < 0.0 {
            0.0
        } else if x >= 1.0 {
            1.0
        } else {
            x * x * (3.0 - 2.0 * x)
        }
    }

    fn f2<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> Octave
    where
        D: Cell<N>,
    {
        let (cell, local) = split(coord);
        let (mut d1, mut d2) = (f32::MAX, f32::MAX);
        let (mut off1, mut pos1, mut off2, mut pos2) = ([0.0; N], [0.0; N], [0.0; N], [0.0; N]);
        for_cells(1, |off: [f32; N]| {
            let point = add(off, scale(D::jitter(add(cell, off)), p.randomness));
            let d = metric_distance(point, local, p);
            if d < d1 {
                d2 = d1;
                d1 = d;
                off2 = off1;
                off1 = off;
                pos2 = pos1;
                pos1 = point;
            } else if d < d2 {
                d2 = d;
                off2 = off;
                pos2 = point;
            }
        });
        Octave {
            distance: d2,
            color: D::color(add(cell, off2)),
            position: D::position(add(pos2, cell)),
        }
    }

    fn distance_to_edge<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> f32
    where
        D: Cell<N>,
    {
        let (cell, local) = split(coord);
        if N == 1 {
            let r = p.randomness;
            let mid = hash_float_to_float1(cell[0]) * r;
            let left = -1.0 + hash_float_to_float1(cell[0] - 1.0) * r;
            let right = 1.0 + hash_float_to_float1(cell[0] + 1.0) * r;
            let dl = ((mid + left) / 2.0 - local[0]).abs();
            let dr = ((mid + right) / 2.0 - local[0]).abs();
            return dl.min(dr);
        }
        let to_point = |off: [f32; N]| {
            sub(
                add(off, scale(D::jitter(add(cell, off)), p.randomness)),
                local,
            )
        };
        let mut min_d = f32::MAX;
        let mut closest = [0.0; N];
        for_cells(1, |off: [f32; N]| {
            let v = to_point(off);
            let d = dot(v, v);
            if d < min_d {
                min_d = d;
                closest = v;
            }
        });
        min_d = f32::MAX;
        for_cells(1, |off: [f32; N]| {
            let v = to_point(off);
            let perp = sub(v, closest);
            if dot(perp, perp) > 0.0001 {
                let len = dot(perp, perp).sqrt();
                let n = perp.map(|x| x / len);
                let d = dot(add(closest, v).map(|x| x / 2.0), n);
                min_d = min_d.min(d);
            }
        });
        min_d
    }

    fn n_sphere_radius<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> f32
    where
        D: Cell<N>,
    {
        let (cell, local) = split(coord);
        let mut closest = [0.0; N];
        let mut closest_off = [0.0; N];
        let mut min_d = f32::MAX;
        for_cells(1, |off: [f32; N]| {
            let point = add(off, scale(D::jitter(add(cell, off)), p.randomness));
            let d = euclidean(point, local);
            if d < min_d {
                min_d = d;
                closest = point;
                closest_off = off;
            }
        });
        min_d = f32::MAX;
        let mut next = [0.0; N];
        for_cells(1, |o: [f32; N]| {
            if o.iter().all(|&x| x == 0.0) {
                return;
            }
            let off = add(o, closest_off);
            let point = add(off, scale(D::jitter(add(cell, off)), p.randomness));
            let d = euclidean(closest, point);
            if d < min_d {
                min_d = d;
                next = point;
            }
        });
        euclidean(next, closest) / 2.0
    }

    fn fractal_x_fx<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> Octave
    where
        D: Cell<N>,
    {
        let mut amplitude = 1.0f32;
        let mut max_amplitude = 0.0f32;
        let mut sc = 1.0f32;
        let mut out = Octave {
            distance: 0.0,
            color: [0.0; 3],
            position: [0.0; 4],
        };
        let zero_input = p.detail == 0.0 || p.roughness == 0.0;
        let mut i = 0;
        while i as f32 <= p.detail.ceil() {
            let c = scale(coord, sc);
            let octave = match p.feature {
                VoronoiFeature::F2 => f2(p, c),
                VoronoiFeature::SmoothF1 if p.smoothness != 0.0 => smooth_f1(p, c),
                _ => f1(p, c),
            };
            if zero_input {
                max_amplitude = 1.0;
                out = octave;
                break;
            }
            if i as f32 <= p.detail {
                max_amplitude += amplitude;
                out.distance += octave.distance * amplitude;
                out.color = std::array::from_fn(|k| out.color[k] + octave.color[k] * amplitude);
                out.position = mixn(out.position, octave.position.map(|x| x / sc), amplitude);
                sc *= p.lacunarity;
                amplitude *= p.roughness;
            } else {
                let rem = p.detail - p.detail.floor();
                if rem != 0.0 {
                    max_amplitude = mix1(max_amplitude, max_amplitude + amplitude, rem);
                    out.distance = mix1(
                        out.distance,
                        out.distance + octave.distance * amplitude,
                        rem,
                    );
                    out.color = std::array::from_fn(|k| {
                        mix1(
                            out.color[k],
                            out.color[k] + octave.color[k] * amplitude,
                            rem,
                        )
                    });
                    let inner = mixn(out.position, octave.position.map(|x| x / sc), amplitude);
                    out.position = mixn(out.position, inner, rem);
                }
            }
            i += 1;
        }
        if p.normalize {
            out.distance /= max_amplitude * p.max_distance;
            out.color = out.color.map(|x| x / max_amplitude);
        }
        out.position = out
            .position
            .map(|x| if p.scale != 0.0 { x / p.scale } else { 0.0 });
        out
    }

    fn fractal_distance_to_edge<const N: usize>(p: &VoronoiParams, coord: [f32; N]) -> f32
    where
        D: Cell<N>,
    {
        let mut amplitude = 1.0f32;
        let mut max_amplitude = p.max_distance;
        let mut sc = 1.0f32;
        let mut distance = 8.0f32;
        let zero_input = p.detail == 0.0 || p.roughness == 0.0;
        let mut i = 0;
        while i as f32 <= p.detail.ceil() {
            let od = distance_to_edge(p, scale(coord, sc));
            if zero_input {
                distance = od;
                break;
            }
            if i as f32 <= p.detail {
                max_amplitude = mix1(max_amplitude, p.max_distance / sc, amplitude);
                distance = mix1(distance, distance.min(od / sc), amplitude);
                sc *= p.lacunarity;
                amplitude *= p.roughness;
            } else {
                let rem = p.detail - p.detail.floor();
                if rem != 0.0 {
                    let la = mix1(max_amplitude, p.max_distance / sc, amplitude);
                    max_amplitude = mix1(max_amplitude, la, rem);
                    let ld = mix1(distance, distance.min(od / sc), amplitude);
                    distance = mix1(distance, distance.min(ld), rem);
                }
            }
            i += 1;
        }
        if p.normalize {
            distance /= max_amplitude;
        }
        distance
    }

    impl VoronoiParams {
        /// Node settings as the sockets give them; clamped here as Cycles clamps them.
        #[allow(clippy::too_many_arguments)]
        pub fn new(
            feature: VoronoiFeature,
            metric: VoronoiMetric,
            normalize: bool,
            scale: f32,
            detail: f32,
            roughness: f32,
            lacunarity: f32,
            smoothness: f32,
            exponent: f32,
            randomness: f32,
        ) -> Self {
            VoronoiParams {
                feature,
                metric,
                normalize,
                scale,
                detail: detail.clamp(0.0, 15.0),
                roughness: roughness.clamp(0.0, 1.0),
                lacunarity,
                smoothness: (smoothness / 2.0).clamp(0.0, 0.5),
                exponent,
                randomness: randomness.clamp(0.0, 1.0),
                max_distance: 0.0,
            }
        }
    }

    fn run<const N: usize>(mut p: VoronoiParams, coord: [f32; N]) -> VoronoiOutput
    where
        D: Cell<N>,
    {
        match p.feature {
            VoronoiFeature::DistanceToEdge => {
                p.max_distance = 0.5 + 0.5 * p.randomness;
                VoronoiOutput {
                    distance: fractal_distance_to_edge(&p, coord),
                    ..Default::default()
                }
            }
            VoronoiFeature::NSphereRadius => VoronoiOutput {
                radius: n_sphere_radius(&p, coord),
                ..Default::default()
            },
            _ => {
                let f2_factor = if p.feature == VoronoiFeature::F2 {
                    2.0
                } else {
                    1.0
                };
                let half = 0.5 + 0.5 * p.randomness;
                p.max_distance = metric_distance([0.0; N], [half; N], &p) * f2_factor;
                let o = fractal_x_fx(&p, coord);
                VoronoiOutput {
                    distance: o.distance,
                    color: o.color,
                    position: [o.position[0], o.position[1], o.position[2]],
                    w: o.position[3],
                    radius: 0.0,
                }
            }
        }
    }

    /// The Voronoi Texture node on one point: `dimensions` 1-4 (`vector` for 2-4, `w` for 1
    /// and 4).
    pub fn voronoi_texture(
        dimensions: u8,
        vector: Vec3,
        w: f32,
        p: VoronoiParams,
    ) -> VoronoiOutput {
        let v = vector.map(|x| x * p.scale);
        let w = w * p.scale;
        match dimensions {
            1 => run(p, [w]),
            2 => run(p, [v[0], v[1]]),
            4 => run(p, [v[0], v[1], v[2], w]),
            _ => run(p, v),
        }
    }
}

pub mod noise {
    use super::random::{hash1, hash2, hash3, hash4, hash_float_to_float1, hash_float_to_float2};

    #[inline]
    fn fade(t: f32) -> f32 {
        ((t * t * t) as f64 * (t as f64 * (t as f64 * 6.0 - 15.0) + 10.0)) as f32
    }

    #[inline]
    fn negate_if(v: f32, cond: u32) -> f32 {
        if cond != 0 {
            -v
        } else {
            v
        }
    }

    #[inline]
    fn grad1(hash: u32, x: f32) -> f32 {
        let h = hash & 15;
        let g = (1 + (h & 7)) as f32;
        negate_if(g, h & 8) * x
    }

    #[inline]
    fn grad2(hash: u32, x: f32, y: f32) -> f32 {
        let h = hash & 7;
        let u = if h < 4 { x } else { y };
        let v = 2.0 * if h < 4 { y } else { x };
        negate_if(u, h & 1) + negate_if(v, h & 2)
    }

    #[inline]
    fn grad3(hash: u32, x: f32, y: f32, z: f32) -> f32 {
        let h = hash & 15;
        let u = if h < 8 { x } else { y };
        let vt = if h == 12 || h == 14 { x } else { z };
        let v = if h < 4 { y } else { vt };
        negate_if(u, h & 1) + negate_if(v, h & 2)
    }

    #[inline]
    fn grad4(hash: u32, x: f32, y: f32, z: f32, w: f32) -> f32 {
        let h = hash & 31;
        let u = if h < 24 { x } else { y };
        let v = if h < 16 { y } else { z };
        let s = if h < 8 { z } else { w };
        negate_if(u, h & 1) + negate_if(v, h & 2) + negate_if(s, h & 4)
    }

    #[inline]
    fn lerp(v0: f32, v1: f32, x: f32) -> f32 {
        (1.0 - x) * v0 + x * v1
    }

    #[inline]
    fn bi_mix(v0: f32, v1: f32, v2: f32, v3: f32, x: f32, y: f32) -> f32 {
        let x1 = (1.0 - x as f64) as f32;
        ((1.0 - y as f64) * (v0 * x1 + v1 * x) as f64 + (y * (v2 * x1 + v3 * x)) as f64) as f32
    }

    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn tri_mix(v: [f32; 8], x: f32, y: f32, z: f32) -> f32 {
        let x1 = (1.0 - x as f64) as f32;
        let y1 = (1.0 - y as f64) as f32;
        let z1 = (1.0 - z as f64) as f32;
        z1 * (y1 * (v[0] * x1 + v[1] * x) + y * (v[2] * x1 + v[3] * x))
            + z * (y1 * (v[4] * x1 + v[5] * x) + y * (v[6] * x1 + v[7] * x))
    }

    #[inline]
    fn floor_fraction(x: f32) -> (i32, f32) {
        let f = x.floor();
        (f as i32, x - f)
    }

    fn perlin_noise1(p: f32) -> f32 {
        let (x, fx) = floor_fraction(p);
        let u = fade(fx);
        lerp(
            grad1(hash1(x as u32), fx),
            grad1(hash1(x.wrapping_add(1) as u32), fx - 1.0),
            u,
        )
    }

    fn perlin_noise2(p: [f32; 2]) -> f32 {
        let (x, fx) = floor_fraction(p[0]);
        let (y, fy) = floor_fraction(p[1]);
        let (u, v) = (fade(fx), fade(fy));
        let h = |dx: i32, dy: i32| hash2(x.wrapping_add(dx) as u32, y.wrapping_add(dy) as u32);
        bi_mix(
            grad2(h(0, 0), fx, fy),
            grad2(h(1, 0), fx - 1.0, fy),
            grad2(h(0, 1), fx, fy - 1.0),
            grad2(h(1, 1), fx - 1.0, fy - 1.0),
            u,
            v,
        )
    }

    fn perlin_noise3(p: [f32; 3]) -> f32 {
        let (x, fx) = floor_fraction(p[0]);
        let (y, fy) = floor_fraction(p[1]);
        let (z, fz) = floor_fraction(p[2]);
        let (u, v, w) = (fade(fx), fade(fy), fade(fz));
        let g = |dx: i32, dy: i32, dz: i32| {
            grad3(
                hash3(
                    x.wrapping_add(dx) as u32,
                    y.wrapping_add(dy) as u32,
                    z.wrapping_add(dz) as u32,
                ),
                fx - dx as f32,
                fy - dy as f32,
                fz - dz as f32,
            )
        };
        tri_mix(
            [
                g(0, 0, 0),
                g(1, 0, 0),
                g(0, 1, 0),
                g(1, 1, 0),
                g(0, 0, 1),
                g(1, 0, 1),
                g(0, 1, 1),
                g(1, 1, 1),
            ],
            u,
            v,
            w,
        )
    }

    fn perlin_noise4(p: [f32; 4]) -> f32 {
        let (x, fx) = floor_fraction(p[0]);
        let (y, fy) = floor_fraction(p[1]);
        let (z, fz) = floor_fraction(p[2]);
        let (w, fw) = floor_fraction(p[3]);
        let (u, v, t, s) = (fade(fx), fade(fy), fade(fz), fade(fw));
        let g = |dx: i32, dy: i32, dz: i32, dw: i32| {
            grad4(
                hash4(
                    x.wrapping_add(dx) as u32,
                    y.wrapping_add(dy) as u32,
                    z.wrapping_add(dz) as u32,
                    w.wrapping_add(dw) as u32,
                ),
                fx - dx as f32,
                fy - dy as f32,
                fz - dz as f32,
                fw - dw as f32,
            )
        };
        let a = tri_mix(
            [
                g(0, 0, 0, 0),
                g(1, 0, 0, 0),
                g(0, 1, 0, 0),
                g(1, 1, 0, 0),
                g(0, 0, 1, 0),
                g(1, 0, 1, 0),
                g(0, 1, 1, 0),
                g(1, 1, 1, 0),
            ],
            u,
            v,
            t,
        );
        let b = tri_mix(
            [
                g(0, 0, 0, 1),
                g(1, 0, 0, 1),
                g(0, 1, 0, 1),
                g(1, 1, 0, 1),
                g(0, 0, 1, 1),
                g(1, 0, 1, 1),
                g(0, 1, 1, 1),
                g(1, 1, 1, 1),
            ],
            u,
            v,
            t,
        );
        lerp(a, b, s)
    }

    /// A point of 1 to 4 dimensions, so the fractal functions are written once.
    pub trait NoisePoint: Copy {
        fn perlin_signed(self) -> f32;
        fn scaled(self, s: f32) -> Self;
        fn plus(self, o: Self) -> Self;
        /// `random_floatN_offset(seed)`.
        fn offset(seed: f32) -> Self;
        /// `perlin_distortion(p, strength)`.
        fn distortion(self, strength: f32) -> Self;
        /// `p + distortion(p, strength)`.
        fn distorted(self, strength: f32) -> Self {
            self.plus(self.distortion(strength))
        }
        /// Whether `a * b + c` is one fused operation, as in Cycles' FMA-built CPU kernels
        /// (GCC contracts them); Blender's own CPU code is built without FMA.
        const FUSED: bool = false;
    }

    #[inline]
    fn madd<P: NoisePoint>(a: f32, b: f32, c: f32) -> f32 {
        if P::FUSED {
            a.mul_add(b, c)
        } else {
            a * b + c
        }
    }

    /// Linear blend: Cycles' `a + t * (b - a)` (fused) or Blender's `interpf`.
    #[inline]
    fn blend<P: NoisePoint>(a: f32, b: f32, t: f32) -> f32 {
        if P::FUSED {
            t.mul_add(b - a, a)
        } else {
            lerp(a, b, t)
        }
    }

    fn correction(v: f32) -> f32 {
        0.5 * (v.abs() >= 1_000_000.0) as u8 as f32
    }

    impl NoisePoint for f32 {
        fn perlin_signed(self) -> f32 {
            let p = self % 100000.0 + correction(self);
            perlin_noise1(p) * 0.25
        }
        fn scaled(self, s: f32) -> Self {
            s * self
        }
        fn plus(self, o: Self) -> Self {
            self + o
        }
        fn offset(seed: f32) -> Self {
            100.0 + hash_float_to_float1(seed) * 100.0
        }
        fn distortion(self, strength: f32) -> Self {
            (self + Self::offset(0.0)).perlin_signed() * strength
        }
    }

    fn offset_component(seed: f32, k: f32) -> f32 {
        100.0 + hash_float_to_float2([seed, k]) * 100.0
    }

    impl NoisePoint for [f32; 2] {
        fn perlin_signed(self) -> f32 {
            let p = [
                self[0] % 100000.0 + correction(self[0]),
                self[1] % 100000.0 + correction(self[1]),
            ];
            perlin_noise2(p) * 0.6616
        }
        fn scaled(self, s: f32) -> Self {
            [s * self[0], s * self[1]]
        }
        fn plus(self, o: Self) -> Self {
            [self[0] + o[0], self[1] + o[1]]
        }
        fn offset(seed: f32) -> Self {
            [offset_component(seed, 0.0), offset_component(seed, 1.0)]
        }
        fn distortion(self, strength: f32) -> Self {
            [
                self.plus(Self::offset(0.0)).perlin_signed() * strength,
                self.plus(Self::offset(1.0)).perlin_signed() * strength,
            ]
        }
    }

    impl NoisePoint for [f32; 3] {
        fn perlin_signed(self) -> f32 {
            let p = [
                self[0] % 100000.0 + correction(self[0]),
                self[1] % 100000.0 + correction(self[1]),
                self[2] % 100000.0 + correction(self[2]),
            ];
            perlin_noise3(p) * 0.9820
        }
        fn scaled(self, s: f32) -> Self {
            [s * self[0], s * self[1], s * self[2]]
        }
        fn plus(self, o: Self) -> Self {
            [self[0] + o[0], self[1] + o[1], self[2] + o[2]]
        }
        fn offset(seed: f32) -> Self {
            [
                offset_component(seed, 0.0),
                offset_component(seed, 1.0),
                offset_component(seed, 2.0),
            ]
        }
        fn distortion(self, strength: f32) -> Self {
            [
                self.plus(Self::offset(0.0)).perlin_signed() * strength,
                self.plus(Self::offset(1.0)).perlin_signed() * strength,
                self.plus(Self::offset(2.0)).perlin_signed() * strength,
            ]
        }
    }

    impl NoisePoint for [f32; 4] {
        fn perlin_signed(self) -> f32 {
            let mut p = [0.0; 4];
            for i in 0..4 {
                p[i] = self[i] % 100000.0 + correction(self[i]);
            }
            perlin_noise4(p) * 0.8344
        }
        fn scaled(self, s: f32) -> Self {
            [s * self[0], s * self[1], s * self[2], s * self[3]]
        }
        fn plus(self, o: Self) -> Self {
            [
                self[0] + o[0],
                self[1] + o[1],
                self[2] + o[2],
                self[3] + o[3],
            ]
        }
        fn offset(seed: f32) -> Self {
            [
                offset_component(seed, 0.0),
                offset_component(seed, 1.0),
                offset_component(seed, 2.0),
                offset_component(seed, 3.0),
            ]
        }
        fn distortion(self, strength: f32) -> Self {
            [
                self.plus(Self::offset(0.0)).perlin_signed() * strength,
                self.plus(Self::offset(1.0)).perlin_signed() * strength,
                self.plus(Self::offset(2.0)).perlin_signed() * strength,
                self.plus(Self::offset(3.0)).perlin_signed() * strength,
            ]
        }
    }

    /// Perlin noise in [0, 1].
    pub fn perlin<P: NoisePoint>(p: P) -> f32 {
        p.perlin_signed() / 2.0 + 0.5
    }

    pub fn fbm<P: NoisePoint>(
        p: P,
        detail: f32,
        roughness: f32,
        lacunarity: f32,
        normalize: bool,
    ) -> f32 {
        let mut fscale = 1.0f32;
        let mut amp = 1.0f32;
        let mut maxamp = 0.0f32;
        let mut sum = 0.0f32;
        for _ in 0..=(detail as i32) {
            let t = p.scaled(fscale).perlin_signed();
            sum = madd::<P>(t, amp, sum);
            maxamp += amp;
            amp *= roughness;
            fscale *= lacunarity;
        }
        let rmd = detail - detail.floor();
        if rmd != 0.0 {
            let t = p.scaled(fscale).perlin_signed();
            let sum2 = madd::<P>(t, amp, sum);
            return if normalize {
                blend::<P>(
                    0.5 * sum / maxamp + 0.5,
                    0.5 * sum2 / (maxamp + amp) + 0.5,
                    rmd,
                )
            } else {
                blend::<P>(sum, sum2, rmd)
            };
        }
        if normalize {
            0.5 * sum / maxamp + 0.5
        } else {
            sum
        }
    }

    pub fn multi_fractal<P: NoisePoint>(
        mut p: P,
        detail: f32,
        roughness: f32,
        lacunarity: f32,
    ) -> f32 {
        let mut value = 1.0f32;
        let mut pwr = 1.0f32;
        for _ in 0..=(detail as i32) {
            value *= madd::<P>(pwr, p.perlin_signed(), 1.0);
            pwr *= roughness;
            p = p.scaled(lacunarity);
        }
        let rmd = detail - detail.floor();
        if rmd != 0.0 {
            value *= madd::<P>(rmd * pwr, p.perlin_signed(), 1.0);
        }
        value
    }

    pub fn hetero_terrain<P: NoisePoint>(
        mut p: P,
        detail: f32,
        roughness: f32,
        lacunarity: f32,
        offset: f32,
    ) -> f32 {
        let mut pwr = roughness;
        let mut value = offset + p.perlin_signed();
        p = p.scaled(lacunarity);
        for _ in 1..=(detail as i32) {
            value = madd::<P>((p.perlin_signed() + offset) * pwr, value, value);
            pwr *= roughness;
            p = p.scaled(lacunarity);
        }
        let rmd = detail - detail.floor();
        if rmd != 0.0 {
            let increment = (p.perlin_signed() + offset) * pwr * value;
            value = madd::<P>(rmd, increment, value);
        }
        value
    }

    pub fn hybrid_multi_fractal<P: NoisePoint>(
        mut p: P,
        detail: f32,
        roughness: f32,
        lacunarity: f32,
        offset: f32,
        gain: f32,
    ) -> f32 {
        let mut pwr = 1.0f32;
        let mut value = 0.0f32;
        let mut weight = 1.0f32;
        let mut i = 0;
        while weight > 0.001 && i <= detail as i32 {
            if weight > 1.0 {
                weight = 1.0;
            }
            let signal = (p.perlin_signed() + offset) * pwr;
            pwr *= roughness;
            value = madd::<P>(weight, signal, value);
            weight *= gain * signal;
            p = p.scaled(lacunarity);
            i += 1;
        }
        let rmd = detail - detail.floor();
        if rmd != 0.0 && weight > 0.001 {
            if weight > 1.0 {
                weight = 1.0;
            }
            let signal = (p.perlin_signed() + offset) * pwr;
            value = madd::<P>(rmd * weight, signal, value);
        }
        value
    }

    pub fn ridged_multi_fractal<P: NoisePoint>(
        mut p: P,
        detail: f32,
        roughness: f32,
        lacunarity: f32,
        offset: f32,
        gain: f32,
    ) -> f32 {
        let mut pwr = roughness;
        let mut signal = offset - p.perlin_signed().abs();
        signal *= signal;
        let mut value = signal;
        for _ in 1..=(detail as i32) {
            p = p.scaled(lacunarity);
            let weight = (signal * gain).clamp(0.0, 1.0);
            signal = offset - p.perlin_signed().abs();
            signal *= signal;
            signal *= weight;
            value = madd::<P>(signal, pwr, value);
            pwr *= roughness;
        }
        value
    }

    pub use blendsynth::nodes::noise::{NoiseParams, NoiseType};

    fn select<P: NoisePoint>(p: P, n: &NoiseParams) -> f32 {
        match n.kind {
            NoiseType::MultiFractal => multi_fractal(p, n.detail, n.roughness, n.lacunarity),
            NoiseType::Fbm => fbm(p, n.detail, n.roughness, n.lacunarity, n.normalize),
            NoiseType::HybridMultiFractal => {
                hybrid_multi_fractal(p, n.detail, n.roughness, n.lacunarity, n.offset, n.gain)
            }
            NoiseType::RidgedMultiFractal => {
                ridged_multi_fractal(p, n.detail, n.roughness, n.lacunarity, n.offset, n.gain)
            }
            NoiseType::HeteroTerrain => {
                hetero_terrain(p, n.detail, n.roughness, n.lacunarity, n.offset)
            }
        }
    }

    /// `perlin_fractal_distorted`: the Fac output.
    pub fn fractal_distorted<P: NoisePoint>(p: P, n: &NoiseParams) -> f32 {
        let p = p.distorted(n.distortion);
        select(p, n)
    }

    /// `perlin_float3_fractal_distorted`: the Color output (its first channel is Fac). The
    /// seeds of the two extra channels depend on the dimension, as in Blender.
    pub fn fractal_distorted_color<P: NoisePoint>(
        p: P,
        n: &NoiseParams,
        seeds: [f32; 2],
    ) -> [f32; 3] {
        let p = p.distorted(n.distortion);
        [
            select(p, n),
            select(p.plus(P::offset(seeds[0])), n),
            select(p.plus(P::offset(seeds[1])), n),
        ]
    }

    /// The Noise Texture node on one point: `dimensions` 1-4 (`vector` used for 2-4, `w` for
    /// 1 and 4). Returns (Fac, Color).
    #[allow(clippy::too_many_arguments)]
    pub fn noise_texture(
        dimensions: u8,
        vector: [f32; 3],
        w: f32,
        scale: f32,
        params: NoiseParams,
        want_color: bool,
    ) -> (f32, [f32; 4]) {
        let mut n = params;
        n.detail = n.detail.clamp(0.0, 15.0);
        n.roughness = n.roughness.max(0.0);
        let v = [vector[0] * scale, vector[1] * scale, vector[2] * scale];
        let ws = w * scale;
        let c = if want_color {
            match dimensions {
                1 => fractal_distorted_color(ws, &n, [1.0, 2.0]),
                2 => fractal_distorted_color([v[0], v[1]], &n, [2.0, 3.0]),
                4 => fractal_distorted_color([v[0], v[1], v[2], ws], &n, [4.0, 5.0]),
                _ => fractal_distorted_color(v, &n, [3.0, 4.0]),
            }
        } else {
            let f = match dimensions {
                1 => fractal_distorted(ws, &n),
                2 => fractal_distorted([v[0], v[1]], &n),
                4 => fractal_distorted([v[0], v[1], v[2], ws], &n),
                _ => fractal_distorted(v, &n),
            };
            [f, 0.0, 0.0]
        };
        (c[0], [c[0], c[1], c[2], 1.0])
    }

    // --- Cycles' kernel flavour -------------------------------------------------------------
    //
    // Cycles (`kernel/svm/noise.h`) computes the same Perlin noise with its own arithmetic:
    // `fade` in single precision, linear blends as `a + t * (b - a)`, and, in its SSE/AVX
    // CPU kernels, the blends in a fixed axis order (2D and 3D: x, then y, then z; 4D: w
    // first, then x, y, z). At fine scales times many octaves the coordinates are large and
    // these rounding differences grow past 1e-4, so shaders use this flavour; Geometry
    // Nodes keep Blender's CPU version above.

    #[inline]
    fn cy_mix(a: f32, b: f32, t: f32) -> f32 {
        t.mul_add(b - a, a)
    }

    #[inline]
    fn cy_fade(t: f32) -> f32 {
        let a = t.mul_add(6.0, -15.0);
        let b = t.mul_add(a, 10.0);
        (t * t) * (t * b)
    }

    fn cy_perlin1(p: f32) -> f32 {
        let (x, fx) = floor_fraction(p);
        let u = t_fade1(fx);
        cy_mix(
            grad1(hash1(x as u32), fx),
            grad1(hash1(x.wrapping_add(1) as u32), fx - 1.0),
            u,
        )
    }

    /// The scalar 1D kernel's fade: `t * t * t * (t * (t * 6 - 15) + 10)`.
    #[inline]
    fn t_fade1(t: f32) -> f32 {
        t * t * t * t.mul_add(t.mul_add(6.0, -15.0), 10.0)
    }

    fn cy_perlin2(p: [f32; 2]) -> f32 {
        let (x, fx) = floor_fraction(p[0]);
        let (y, fy) = floor_fraction(p[1]);
        let (u, v) = (cy_fade(fx), cy_fade(fy));
        let h = |dx: i32, dy: i32| hash2(x.wrapping_add(dx) as u32, y.wrapping_add(dy) as u32);
        let g0 = cy_mix(grad2(h(0, 0), fx, fy), grad2(h(1, 0), fx - 1.0, fy), u);
        let g1 = cy_mix(
            grad2(h(0, 1), fx, fy - 1.0),
            grad2(h(1, 1), fx - 1.0, fy - 1.0),
            u,
        );
        cy_mix(g0, g1, v)
    }

    /// Gradients at the 8 corners (index bit 0: x, bit 1: y, bit 2: z) blended x, y, z.
    #[inline]
    fn cy_tri(g: impl Fn(i32, i32, i32) -> f32, u: f32, v: f32, w: f32) -> f32 {
        let x00 = cy_mix(g(0, 0, 0), g(1, 0, 0), u);
        let x10 = cy_mix(g(0, 1, 0), g(1, 1, 0), u);
        let x01 = cy_mix(g(0, 0, 1), g(1, 0, 1), u);
        let x11 = cy_mix(g(0, 1, 1), g(1, 1, 1), u);
        cy_mix(cy_mix(x00, x10, v), cy_mix(x01, x11, v), w)
    }

    fn cy_perlin3(p: [f32; 3]) -> f32 {
        let (x, fx) = floor_fraction(p[0]);
        let (y, fy) = floor_fraction(p[1]);
        let (z, fz) = floor_fraction(p[2]);
        let g = |dx: i32, dy: i32, dz: i32| {
            grad3(
                hash3(
                    x.wrapping_add(dx) as u32,
                    y.wrapping_add(dy) as u32,
                    z.wrapping_add(dz) as u32,
                ),
                fx - dx as f32,
                fy - dy as f32,
                fz - dz as f32,
            )
        };
        cy_tri(g, cy_fade(fx), cy_fade(fy), cy_fade(fz))
    }

    fn cy_perlin4(p: [f32; 4]) -> f32 {
        let (x, fx) = floor_fraction(p[0]);
        let (y, fy) = floor_fraction(p[1]);
        let (z, fz) = floor_fraction(p[2]);
        let (w, fw) = floor_fraction(p[3]);
        let s = cy_fade(fw);
        let g = |dx: i32, dy: i32, dz: i32| {
            let at = |dw: i32| {
                grad4(
                    hash4(
                        x.wrapping_add(dx) as u32,
                        y.wrapping_add(dy) as u32,
                        z.wrapping_add(dz) as u32,
                        w.wrapping_add(dw) as u32,
                    ),
                    fx - dx as f32,
                    fy - dy as f32,
                    fz - dz as f32,
                    fw - dw as f32,
                )
            };
            cy_mix(at(0), at(1), s)
        };
        cy_tri(g, cy_fade(fx), cy_fade(fy), cy_fade(fz))
    }

    /// A point evaluated with Cycles' kernel arithmetic (see above).
    #[derive(Debug, Clone, Copy)]
    pub struct Cycles<P>(pub P);

    macro_rules! cycles_point {
        ($t:ty, $perlin:ident, $scale:expr) => {
            impl NoisePoint for Cycles<$t> {
                fn perlin_signed(self) -> f32 {
                    // Repeats every 100000 with Blender's half-cell shift beyond 1e6.
                    let p = cycles_fmod(self.0);
                    $perlin(p) * $scale
                }
                fn scaled(self, s: f32) -> Self {
                    Cycles(self.0.scaled(s))
                }
                fn plus(self, o: Self) -> Self {
                    Cycles(self.0.plus(o.0))
                }
                fn offset(seed: f32) -> Self {
                    Cycles(<$t>::offset(seed))
                }
                fn distortion(self, strength: f32) -> Self {
                    let mut out = self.0;
                    let n = std::mem::size_of::<$t>() / 4;
                    for i in 0..n {
                        let o = Cycles(<$t>::offset(i as f32));
                        set(&mut out, i, self.plus(o).perlin_signed() * strength);
                    }
                    Cycles(out)
                }
                fn distorted(self, strength: f32) -> Self {
                    if std::mem::size_of::<$t>() == 4 {
                        // The scalar kernel contracts `p += snoise(..) * distortion`.
                        let mut out = self.0;
                        let d = self.plus(Cycles(<$t>::offset(0.0))).perlin_signed();
                        set(&mut out, 0, d.mul_add(strength, get(self.0)));
                        Cycles(out)
                    } else {
                        self.plus(self.distortion(strength))
                    }
                }
                const FUSED: bool = true;
            }
        };
    }

    trait Comps: Copy {
        fn map_c(self, f: impl Fn(f32) -> f32) -> Self;
        fn set_c(&mut self, i: usize, v: f32);
        fn first_c(self) -> f32;
    }
    impl Comps for f32 {
        fn map_c(self, f: impl Fn(f32) -> f32) -> Self {
            f(self)
        }
        fn set_c(&mut self, _: usize, v: f32) {
            *self = v;
        }
        fn first_c(self) -> f32 {
            self
        }
    }
    impl<const N: usize> Comps for [f32; N] {
        fn map_c(self, f: impl Fn(f32) -> f32) -> Self {
            self.map(f)
        }
        fn set_c(&mut self, i: usize, v: f32) {
            self[i] = v;
        }
        fn first_c(self) -> f32 {
            self[0]
        }
    }
    fn cycles_fmod<T: Comps>(p: T) -> T {
        p.map_c(|x| x % 100000.0 + correction(x))
    }
    fn get<T: Comps>(p: T) -> f32 {
        p.first_c()
    }
    fn set<T: Comps>(p: &mut T, i: usize, v: f32) {
        p.set_c(i, v)
    }

    cycles_point!(f32, cy_perlin1, 0.25);
    cycles_point!([f32; 2], cy_perlin2, 0.6616);
    cycles_point!([f32; 3], cy_perlin3, 0.9820);
    cycles_point!([f32; 4], cy_perlin4, 0.8344);

    /// The Noise Texture node as Cycles' shader kernel evaluates it: (Fac, Color).
    #[allow(clippy::too_many_arguments)]
    pub fn noise_texture_cycles(
        dimensions: u8,
        vector: [f32; 3],
        w: f32,
        scale: f32,
        params: NoiseParams,
    ) -> (f32, [f32; 3]) {
        let mut n = params;
        n.detail = n.detail.clamp(0.0, 15.0);
        n.roughness = n.roughness.max(0.0);
        let v = [vector[0] * scale, vector[1] * scale, vector[2] * scale];
        let ws = w * scale;
        let c = match dimensions {
            1 => fractal_distorted_color(Cycles(ws), &n, [1.0, 2.0]),
            2 => fractal_distorted_color(Cycles([v[0], v[1]]), &n, [2.0, 3.0]),
            4 => fractal_distorted_color(Cycles([v[0], v[1], v[2], ws]), &n, [4.0, 5.0]),
            _ => fractal_distorted_color(Cycles(v), &n, [3.0, 4.0]),
        };
        (c[0], c)
    }
}

pub mod wave {
    type Vec3 = [f32; 3];
    use super::noise::{fbm, Cycles};
    pub use blendsynth::nodes::wave::{
        BandsDirection, RingsDirection, WaveProfile, WaveSettings, WaveType,
    };

    /// Fac of the Wave Texture at `vector` (Color is Fac in all three channels).
    #[allow(clippy::too_many_arguments)]
    pub fn wave(
        s: WaveSettings,
        vector: Vec3,
        scale: f32,
        distortion: f32,
        detail: f32,
        detail_scale: f32,
        detail_roughness: f32,
        phase: f32,
    ) -> f32 {
        // The nudge avoids precision trouble on unit coordinates, as Cycles does.
        let p = vector.map(|v| (v * scale + 0.000001) * 0.999999);
        let mut n = match s.kind {
            WaveType::Bands => match s.bands {
                BandsDirection::X => p[0] * 20.0,
                BandsDirection::Y => p[1] * 20.0,
                BandsDirection::Z => p[2] * 20.0,
                BandsDirection::Diagonal => (p[0] + p[1] + p[2]) * 10.0,
            },
            WaveType::Rings => {
                let mut r = p;
                match s.rings {
                    RingsDirection::X => r[0] = 0.0,
                    RingsDirection::Y => r[1] = 0.0,
                    RingsDirection::Z => r[2] = 0.0,
                    RingsDirection::Spherical => {}
                }
                (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt() * 20.0
            }
        };
        n += phase;
        if distortion != 0.0 {
            let q = p.map(|v| v * detail_scale);
            n += distortion * (fbm(Cycles(q), detail, detail_roughness, 2.0, true) * 2.0 - 1.0);
        }
        let tau = 2.0 * std::f32::consts::PI;
        match s.profile {
            WaveProfile::Sin => 0.5 + 0.5 * (n - std::f32::consts::FRAC_PI_2).sin(),
            WaveProfile::Saw => {
                let n = n / tau;
                n - n.floor()
            }
            WaveProfile::Tri => {
                let n = n / tau;
                (n - (n + 0.5).floor()).abs() * 2.0
            }
        }
    }
}
