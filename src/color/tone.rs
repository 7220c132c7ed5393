//! OCIO's GradingToneTransform (log style, forward), limited to the shadows zone, which is
//! all Blender's "Punchy" looks use; other zones must be at their identity values.

use super::config::GradingTone;

#[derive(Debug, Clone, Copy)]
struct Curve {
    x: [f32; 3],
    y: [f32; 3],
    m0: f32,
    m2: f32,
    /// val > 1 evaluates the curve's inverse (OCIO's symmetric handling around 1).
    reverse: bool,
}

#[derive(Debug, Clone)]
pub struct ToneOp {
    /// Shadow curves for R, G, B, then master (applied to all three).
    shadows: [Option<Curve>; 4],
}

fn identity_zone(z: &[f64; 6]) -> bool {
    z[0] == 1.0 && z[1] == 1.0 && z[2] == 1.0 && z[3] == 1.0
}

impl ToneOp {
    pub fn new(g: &GradingTone) -> Result<ToneOp, String> {
        if !g.log {
            return Err("GradingToneTransform styles other than log are not supported".into());
        }
        if !identity_zone(&g.blacks)
            || !identity_zone(&g.midtones)
            || !identity_zone(&g.highlights)
            || !identity_zone(&g.whites)
            || g.s_contrast != 1.0
        {
            return Err("GradingToneTransform zones other than shadows are not supported".into());
        }
        let (start, pivot) = (g.shadows[4], g.shadows[5]);
        let start = if start < pivot + 0.01 {
            pivot + 0.01
        } else {
            start
        };
        let mut shadows = [None; 4];
        for (c, slot) in shadows.iter_mut().enumerate() {
            let val = g.shadows[c] as f32;
            if val == 1.0 {
                continue;
            }
            let (x0, x2) = (pivot as f32, start as f32);
            let x1 = x0 + (x2 - x0) * 0.5;
            let (y0, y2) = (x0, x2);
            let m0 = if val < 1.0 {
                val.max(0.01)
            } else {
                (2.0 - val).max(0.01)
            };
            let m2 = 1.0f32;
            let y1 = (0.5 / (x2 - x0))
                * ((2.0 * y0 + m0 * (x1 - x0)) * (x2 - x1)
                    + (2.0 * y2 - m2 * (x2 - x1)) * (x1 - x0));
            *slot = Some(Curve {
                x: [x0, x1, x2],
                y: [y0, y1, y2],
                m0,
                m2,
                reverse: val > 1.0,
            });
        }
        Ok(ToneOp { shadows })
    }

    pub fn apply(&self, p: &mut [f32; 3]) {
        for (c, curve) in self.shadows.iter().enumerate() {
            if let Some(k) = curve {
                if c < 3 {
                    p[c] = k.eval(p[c]);
                } else {
                    for v in p.iter_mut() {
                        *v = k.eval(*v);
                    }
                }
            }
        }
        for v in p.iter_mut() {
            *v = v.min(65504.0);
        }
    }
}

impl Curve {
    #[inline]
    fn eval(&self, t: f32) -> f32 {
        let [x0, x1, x2] = self.x;
        let [y0, y1, y2] = self.y;
        let (m0, m2) = (self.m0, self.m2);
        if !self.reverse {
            let tl = (t - x0) / (x1 - x0);
            let tr = (t - x1) / (x2 - x1);
            let fl = y0 * (1.0 - tl * tl) + y1 * tl * tl + m0 * (1.0 - tl) * tl * (x1 - x0);
            let fr = y1 * (1.0 - tr) * (1.0 - tr)
                + y2 * (2.0 - tr) * tr
                + m2 * (tr - 1.0) * tr * (x2 - x1);
            let mut res = if t < x1 { fl } else { fr };
            if t < x0 {
                res = (t - x0) * m0 + y0;
            }
            if !(t < x2) {
                res = (t - x2) * m2 + y2;
            }
            res
        } else {
            let bl = m0 * (x1 - x0);
            let al = y1 - y0 - m0 * (x1 - x0);
            let cl = y0 - t;
            let outl = (-2.0 * cl) / ((bl * bl - 4.0 * al * cl).sqrt() + bl) * (x1 - x0) + x0;
            let br = 2.0 * y2 - 2.0 * y1 - m2 * (x2 - x1);
            let ar = y1 - y2 + m2 * (x2 - x1);
            let cr = y1 - t;
            let outr = (-2.0 * cr) / ((br * br - 4.0 * ar * cr).sqrt() + br) * (x2 - x1) + x1;
            let mut res = if t < y1 { outl } else { outr };
            if t < y0 {
                res = (t - y0) / m0 + x0;
            }
            if !(t < y2) {
                res = (t - y2) / m2 + x2;
            }
            res
        }
    }
}
