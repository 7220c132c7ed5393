//! Blackbody node, with Cycles semantics (`kernel/svm/blackbody.h`,
//! `svm_math_blackbody_color_rec709`): a piecewise fit of the Planckian locus in Rec.709,
//! valid 800 K to 12000 K and held constant outside.

// The fit coefficients are kept digit for digit as Cycles lists them.
#![allow(clippy::excessive_precision)]

use super::math::{max_c, V3};

// Fit coefficients per temperature band (Cycles `kernel/tables.h`): R and G are
// a / t + b * t + c, B is ((a * t + b) * t + c) * t + d.
const TABLE_R: [[f32; 3]; 7] = [
    [1.61919106e+03, -2.05010916e-03, 5.02995757e+00],
    [2.48845471e+03, -1.11330907e-03, 3.22621544e+00],
    [3.34143193e+03, -4.86551192e-04, 1.76486769e+00],
    [4.09461742e+03, -1.27446582e-04, 7.25731635e-01],
    [4.67028036e+03, 2.91258199e-05, 1.26703442e-01],
    [4.59509185e+03, 2.87495649e-05, 1.50345020e-01],
    [3.78717450e+03, 9.35907826e-06, 3.99075871e-01],
];
const TABLE_G: [[f32; 3]; 7] = [
    [-4.88999748e+02, 6.04330754e-04, -7.55807526e-02],
    [-7.55994277e+02, 3.16730098e-04, 4.78306139e-01],
    [-1.02363977e+03, 1.20223470e-04, 9.36662319e-01],
    [-1.26571316e+03, 4.87340896e-06, 1.27054498e+00],
    [-1.42529332e+03, -4.01150431e-05, 1.43972784e+00],
    [-1.17554822e+03, -2.16378048e-05, 1.30408023e+00],
    [-5.00799571e+02, -4.59832026e-06, 1.09098763e+00],
];
const TABLE_B: [[f32; 4]; 7] = [
    [
        5.96945309e-11,
        -4.85742887e-08,
        -9.70622247e-05,
        -4.07936148e-03,
    ],
    [
        2.40430366e-11,
        5.55021075e-08,
        -1.98503712e-04,
        2.89312858e-02,
    ],
    [
        -1.40949732e-11,
        1.89878968e-07,
        -3.56632824e-04,
        9.10767778e-02,
    ],
    [
        -3.61460868e-11,
        2.84822009e-07,
        -4.93211319e-04,
        1.56723440e-01,
    ],
    [
        -1.97075738e-11,
        1.75359352e-07,
        -2.50542825e-04,
        -2.22783266e-02,
    ],
    [
        -1.61997957e-13,
        -1.64216008e-08,
        3.86216271e-04,
        -7.38077418e-01,
    ],
    [
        6.72650283e-13,
        -2.73078809e-08,
        4.24098264e-04,
        -7.52335691e-01,
    ],
];

/// Blackbody colour in linear Rec.709, unclamped (can be negative outside the gamut).
pub fn blackbody_rec709(t: f32) -> V3 {
    if t >= 12000.0 {
        return [0.8262954810464208, 0.9945080501520986, 1.566307710274283];
    }
    if t < 800.0 {
        // Arbitrary lower limit where the light is very dim (matches OSL).
        return [5.413294490189271, -0.20319390035873933, -0.0822535242887164];
    }
    let i = if t >= 6365.0 {
        6
    } else if t >= 3315.0 {
        5
    } else if t >= 1902.0 {
        4
    } else if t >= 1449.0 {
        3
    } else if t >= 1167.0 {
        2
    } else if t >= 965.0 {
        1
    } else {
        0
    };
    let (r, g, b) = (TABLE_R[i], TABLE_G[i], TABLE_B[i]);
    let t_inv = 1.0 / t;
    [
        r[0] * t_inv + r[1] * t + r[2],
        g[0] * t_inv + g[1] * t + g[2],
        ((b[0] * t + b[1]) * t + b[2]) * t + b[3],
    ]
}

/// The Blackbody node for a Rec.709 scene-linear space: negative channels clamped to 0.
/// (Cycles converts Rec.709 to the scene space first when that is not Rec.709.)
pub fn blackbody(temperature: f32) -> V3 {
    blackbody_rec709(temperature).map(|c| max_c(c, 0.0))
}
