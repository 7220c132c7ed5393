//! The pixel filter by importance sampling (Cycles' approach): a Blackman-Harris window
//! over twice the filter width, tabulated as an inverted CDF; each camera ray's offset
//! is drawn from it, so every sample has weight one.

const TABLE: usize = 1024;

pub struct FilterTable {
    inv_cdf: Vec<f32>,
}

fn blackman_harris(v: f32, width: f32) -> f32 {
    let v = 2.0 * std::f32::consts::PI * (v / width + 0.5);
    0.35875 - 0.48829 * v.cos() + 0.14128 * (2.0 * v).cos() - 0.01168 * (3.0 * v).cos()
}

impl FilterTable {
    /// `width` is the scene's filter width in pixels (Blender's `filter_width`).
    pub fn blackman_harris(width: f32) -> FilterTable {
        let width = width.max(0.01) * 2.0;
        let half = width * 0.5;
        // CDF over [0, half] on a fine grid, then inverted onto TABLE entries.
        let n = 4096;
        let mut cdf = vec![0.0f64; n + 1];
        for i in 0..n {
            let x = (i as f32 + 0.5) / n as f32 * half;
            cdf[i + 1] = cdf[i] + blackman_harris(x, width).max(0.0) as f64;
        }
        let total = cdf[n].max(1e-30);
        let mut inv = vec![0.0f32; TABLE];
        let mut j = 0;
        for (i, o) in inv.iter_mut().enumerate() {
            let u = i as f64 / (TABLE - 1) as f64 * total;
            while j < n && cdf[j + 1] < u {
                j += 1;
            }
            let seg = (cdf[j + 1] - cdf[j]).max(1e-30);
            let t = ((u - cdf[j]) / seg).clamp(0.0, 1.0);
            *o = ((j as f64 + t) / n as f64 * half as f64) as f32;
        }
        FilterTable { inv_cdf: inv }
    }

    /// An offset from the pixel centre in [-width, width] for a uniform sample `u`.
    #[inline]
    pub fn sample(&self, u: f32) -> f32 {
        // Symmetric: the sign from which half u falls in.
        let (s, v) = if u < 0.5 {
            (-1.0, 1.0 - 2.0 * u)
        } else {
            (1.0, 2.0 * u - 1.0)
        };
        let x = v * (TABLE - 1) as f32;
        let i = (x as usize).min(TABLE - 2);
        let t = x - i as f32;
        s * (self.inv_cdf[i] * (1.0 - t) + self.inv_cdf[i + 1] * t)
    }
}
