//! Cycles' adaptive sampling (integrator/adaptive_sampling.cpp, scene/integrator.cpp
//! `get_adaptive_sampling`, kernel/film/adaptive_sampling.h):
//! - settings: threshold 0 means automatic (max(0.001, 1/samples)); min samples 0 means
//!   automatic (ceil(16 / threshold^0.3), at least 4); the threshold is then scaled by 5;
//!   checks every 16 samples, the first after sample index `(min_samples+1) | 15`.
//! - error: every sample is summed, and the class-A half of the samples (odd popcount of
//!   the index's odd bits) is summed twice over in an auxiliary buffer; a pixel has
//!   converged when |I - A| (summed over RGB, per sample) / (1e-4 + sqrt(intensity), or
//!   intensity when above 1) is below the threshold.
//! - dilation: a box filter in x then in y marks the neighbours of unconverged pixels
//!   unconverged again.
//!
//! The check runs over the whole image at fixed sample counts, so the result does not
//! depend on threads or timing.

const STEP: u32 = 16;

#[derive(Debug, Clone, Copy)]
pub struct Adaptive {
    pub enabled: bool,
    /// Effective threshold (already scaled by Cycles' factor of 5).
    pub threshold: f32,
    pub min_samples: u32,
}

impl Adaptive {
    /// From the scene's Cycles settings; `override_threshold` (`--threshold`) turns
    /// adaptive sampling on with that threshold when above 0, and off when 0.
    pub fn from_settings(
        i: &crate::scene::settings::Integrator,
        samples: u32,
        override_threshold: Option<f32>,
    ) -> Adaptive {
        let (enabled, threshold) = match override_threshold {
            Some(t) => (t > 0.0 && t.is_finite(), t),
            None => (i.use_adaptive_sampling, i.adaptive_threshold as f32),
        };
        let min_setting = i.adaptive_min_samples.max(0.0) as u32;
        Adaptive::new(enabled, threshold, min_setting, samples)
    }

    pub fn new(enabled: bool, threshold_setting: f32, min_setting: u32, samples: u32) -> Adaptive {
        if !enabled {
            return Adaptive {
                enabled: false,
                threshold: 0.0,
                min_samples: 0,
            };
        }
        let clamped = samples.min(1 << 24);
        let mut threshold = threshold_setting;
        if clamped > 0 && threshold_setting == 0.0 {
            threshold = (1.0 / samples as f32).max(0.001);
        }
        let min_samples = if threshold > 0.0 && min_setting == 0 {
            ((16.0 / threshold.powf(0.3)).ceil() as u32).max(4)
        } else {
            min_setting.max(4)
        };
        Adaptive {
            enabled: true,
            threshold: threshold * 5.0,
            min_samples,
        }
    }

    /// How many of `num` samples from `start` to take before the next check.
    pub fn align_samples(&self, start: u32, num: u32) -> u32 {
        if !self.enabled {
            return num;
        }
        let first = (self.min_samples + 1) | (STEP - 1);
        if start + num <= first {
            return num;
        }
        let next = first.max(start | (STEP - 1));
        (next - start + 1).min(num)
    }

    /// Whether the check runs after 0-based sample index `sample`.
    pub fn need_filter(&self, sample: u32) -> bool {
        self.enabled && sample > self.min_samples && sample & (STEP - 1) == STEP - 1
    }
}

/// Cycles' split of samples into two classes for the error estimate.
#[inline]
pub fn sample_is_class_a(sample: u32) -> bool {
    (sample & 0xaaaa_aaaa).count_ones() & 1 == 1
}

/// One pixel's accumulators.
#[derive(Debug, Clone, Copy, Default)]
pub struct PixelAcc {
    pub sum: [f64; 3],
    pub aux: [f64; 3],
    pub count: u32,
    pub converged: bool,
    /// Summed transparency (1 - alpha) of the samples; not part of the error estimate,
    /// as in Cycles, whose convergence check reads only the colour.
    pub transparent: f64,
}

impl PixelAcc {
    /// Adds sample `index`; a NaN or infinite sample counts but adds nothing.
    #[inline]
    pub fn add(&mut self, index: u32, c: [f32; 3], transparent: f32) {
        self.count += 1;
        if transparent.is_finite() {
            self.transparent += transparent as f64;
        }
        if !c.iter().all(|v| v.is_finite()) {
            return;
        }
        let a = sample_is_class_a(index);
        for k in 0..3 {
            self.sum[k] += c[k] as f64;
            if a {
                self.aux[k] += 2.0 * c[k] as f64;
            }
        }
    }
}

pub struct Film {
    px: Vec<PixelAcc>,
}

impl Film {
    pub fn new(n: usize) -> Film {
        Film {
            px: vec![PixelAcc::default(); n],
        }
    }

    #[inline]
    pub fn pixel(&self, i: usize) -> PixelAcc {
        self.px[i]
    }

    #[inline]
    pub fn set(&mut self, i: usize, p: PixelAcc) {
        self.px[i] = p;
    }

    /// Convergence check then neighbour dilation over the whole image; returns the
    /// number of pixels still to sample.
    pub fn converge_and_dilate(
        &mut self,
        a: &Adaptive,
        exposure: f32,
        w: usize,
        h: usize,
    ) -> usize {
        for p in self.px.iter_mut() {
            if p.converged {
                continue;
            }
            let scale = exposure / p.count.max(1) as f32;
            let (i, x) = (p.sum.map(|v| v as f32), p.aux.map(|v| v as f32));
            let diff = ((i[0] - x[0]).abs() + (i[1] - x[1]).abs() + (i[2] - x[2]).abs()) * scale;
            let intensity = (i[0] + i[1] + i[2]) * scale;
            let norm = if intensity < 1.0 {
                intensity.sqrt()
            } else {
                intensity
            };
            p.converged = diff / (0.0001 + norm) < a.threshold;
        }
        // Rows, then columns: each run of unconverged pixels grows by one on both ends.
        for y in 0..h {
            dilate_line(&mut self.px, y * w, 1, w);
        }
        for x in 0..w {
            dilate_line(&mut self.px, x, w, h);
        }
        self.px.iter().filter(|p| !p.converged).count()
    }
}

fn dilate_line(px: &mut [PixelAcc], first: usize, stride: usize, n: usize) {
    let mut prev = false;
    for k in 0..n {
        let i = first + k * stride;
        if !px[i].converged {
            if k > 0 && !prev {
                px[i - stride].converged = false;
            }
            prev = true;
        } else {
            if prev {
                px[i].converged = false;
            }
            prev = false;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedule_matches_cycles() {
        // Cycles' own test (adaptive_sampling_test.cpp) uses step 4; with step 16 and
        // min samples 11 the first check is after index 15, then every 16.
        let a = Adaptive {
            enabled: true,
            threshold: 0.05,
            min_samples: 11,
        };
        assert_eq!(a.align_samples(0, 7), 7);
        assert_eq!(a.align_samples(0, 64), 16);
        assert_eq!(a.align_samples(16, 48), 16);
        assert_eq!(a.align_samples(20, 48), 12);
        assert!(a.need_filter(15) && a.need_filter(31) && !a.need_filter(16) && !a.need_filter(7));
        // Automatic settings: threshold 0.05 -> min ceil(16/0.05^0.3) = 40, first check at 47.
        let b = Adaptive::new(true, 0.05, 0, 128);
        assert_eq!(b.min_samples, 40);
        assert!((b.threshold - 0.25).abs() < 1e-6);
        assert_eq!(b.align_samples(0, 128), 48);
        let c = Adaptive::new(true, 0.0, 0, 128);
        assert!((c.threshold - 5.0 / 128.0).abs() < 1e-6);
    }

    #[test]
    fn class_a_is_half_of_the_samples() {
        // The odd bits decide: 0,1 are class B, 2,3 class A, and exactly half of any
        // power-of-two run of at least 4 samples is class A.
        assert_eq!(
            (0..4).map(sample_is_class_a).collect::<Vec<_>>(),
            [false, false, true, true]
        );
        assert_eq!((0..64).filter(|&s| sample_is_class_a(s)).count(), 32);
    }

    #[test]
    fn dilation_grows_runs_by_one() {
        let mut px = vec![
            PixelAcc {
                converged: true,
                ..Default::default()
            };
            5
        ];
        px[2].converged = false;
        dilate_line(&mut px, 0, 1, 5);
        assert_eq!(
            px.iter().map(|p| p.converged).collect::<Vec<_>>(),
            [true, false, false, false, true]
        );
    }
}
