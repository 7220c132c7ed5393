//! IES Texture (Cycles `svm_node_ies`, `kernel_ies_interp`): a light's intensity by
//! direction, read from IES LM-63 photometric data as Cycles' `IESFile` parses and
//! processes it (util/ies.cpp), then looked up with bicubic interpolation.

use super::math::{safe_acos, V3};

/// Candela to Cycles' Watt: 4π / 177.83 (the luminous efficacy of D65), as Cycles.
const CANDELA_TO_WATT: f64 = 0.0706650768394;

/// IES data as Cycles packs it: horizontal and vertical angles in radians (horizontal
/// 0..2π, vertical from 0 or π/2), and `intensity[h * v_num + v]`. `None` when Cycles
/// fails to load the data: its kernel then returns 100 for every direction.
#[derive(Debug, Clone, PartialEq)]
pub struct IesTable {
    data: Option<IesData>,
}

#[derive(Debug, Clone, PartialEq)]
struct IesData {
    h_angles: Vec<f32>,
    v_angles: Vec<f32>,
    intensity: Vec<f32>,
}

impl IesTable {
    /// Parses and processes `text` as Cycles' `IESFile::load`; data it rejects gives the
    /// table Cycles uses for a failed load.
    pub fn new(text: &str) -> IesTable {
        let data = parse(text).and_then(|(kind, h, v, rows)| process(kind, h, v, rows));
        IesTable { data }
    }

    /// Whether Cycles would load this data (else every lookup is 100).
    pub fn is_valid(&self) -> bool {
        self.data.is_some()
    }

    /// Cycles' `kernel_ies_interp` at horizontal angle `h` and vertical angle `v` (radians).
    pub fn interp(&self, h: f32, v: f32) -> f32 {
        let Some(d) = &self.data else {
            return 100.0;
        };
        let (hs, vs) = (&d.h_angles, &d.v_angles);
        let (h_num, v_num) = (hs.len(), vs.len());
        let (v_low, v_high, h_low, h_high) = (vs[0], vs[v_num - 1], hs[0], hs[h_num - 1]);
        // NaN angles fail both comparisons in Cycles and reach the search loops; here they
        // are outside the table (Cycles' loops would run off the data).
        if v.is_nan() || h.is_nan() || v < v_low || v >= v_high || h < h_low || h >= h_high {
            return 0.0;
        }
        let tau = 2.0 * std::f32::consts::PI;
        let wrap_h = h_low < 1e-7 && h_high > tau - 1e-7;
        let wrap_vlow = v_low < 1e-7;
        let wrap_vhigh = v_high > std::f32::consts::PI - 1e-7;
        let mut h_i = 0;
        while hs[h_i + 1] < h {
            h_i += 1;
        }
        let mut v_i = 0;
        while vs[v_i + 1] < v {
            v_i += 1;
        }
        let h_frac = (h - hs[h_i]) / (hs[h_i + 1] - hs[h_i]);
        let v_frac = (v - vs[v_i]) / (vs[v_i + 1] - vs[v_i]);
        let column = |h: usize| {
            let at = |v: usize| d.intensity[h * v_num + v];
            let a = if v_i > 0 {
                at(v_i - 1)
            } else if wrap_vlow {
                at(1)
            } else {
                0.0
            };
            let dd = if v_i + 2 < v_num {
                at(v_i + 2)
            } else if wrap_vhigh {
                at(v_num - 2)
            } else {
                0.0
            };
            cubic_interp(a, at(v_i), at(v_i + 1), dd, v_frac)
        };
        // The 360° column repeats 0°: wrap to the one before it, and to the second.
        let a = if h_i > 0 {
            column(h_i - 1)
        } else if wrap_h {
            column(h_num - 2)
        } else {
            0.0
        };
        let dd = if h_i + 2 < h_num {
            column(h_i + 2)
        } else if wrap_h {
            column(1)
        } else {
            0.0
        };
        // Cubic interpolation can overshoot below zero.
        cubic_interp(a, column(h_i), column(h_i + 1), dd, h_frac).max(0.0)
    }
}

/// Cycles' `cubic_interp` (Catmull-Rom through b and c).
fn cubic_interp(a: f32, b: f32, c: f32, d: f32, x: f32) -> f32 {
    0.5 * (((d + 3.0 * (b - c) - a) * x + (2.0 * a - 5.0 * b + 4.0 * c - d)) * x + (c - a)) * x + b
}

/// The IES Texture node's Fac for `vector` (the light's object-space normal when
/// unlinked): Cycles measures the vertical angle from -Z and the horizontal one from +Y.
pub fn ies(table: &IesTable, vector: V3, strength: f32) -> f32 {
    // Cycles' `normalize`: a zero vector gives NaN angles, which its lookup rejects.
    let l = (vector[0] * vector[0] + vector[1] * vector[1] + vector[2] * vector[2]).sqrt();
    let n = [vector[0] / l, vector[1] / l, vector[2] / l];
    let v = safe_acos(-n[2]);
    let h = n[0].atan2(n[1]) + std::f32::consts::PI;
    strength * table.interp(h, v)
}

/// Cycles' photometric types.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Photometric {
    B,
    C,
}

/// Angles in degrees and candela per (horizontal, vertical), read as `IESFile::parse`.
type Parsed = (Photometric, Vec<f32>, Vec<f32>, Vec<Vec<f32>>);

/// `IESTextParser`: numbers as C's strtod/strtol read them, commas as spaces.
struct Numbers<'a> {
    text: &'a [u8],
    at: Option<usize>,
    error: bool,
}

impl Numbers<'_> {
    fn eof(&self) -> bool {
        self.at
            .is_none_or(|i| i >= self.text.len() || self.text[i] == 0)
    }

    /// The extent of the number at `at` after C's leading white space, as strtod (`float`)
    /// or strtol reads it; None when nothing converts.
    fn scan(&self, float: bool) -> Option<(usize, usize)> {
        let t = self.text;
        let mut i = self.at?;
        while i < t.len()
            && matches!(
                t[i],
                b' ' | b'\t' | b'\n' | b'\x0b' | b'\x0c' | b'\r' | b','
            )
        {
            i += 1;
        }
        let start = i;
        if i < t.len() && (t[i] == b'+' || t[i] == b'-') {
            i += 1;
        }
        let digits = |mut j: usize| {
            while j < t.len() && t[j].is_ascii_digit() {
                j += 1;
            }
            j
        };
        let int_end = digits(i);
        if !float {
            return (int_end > i).then_some((start, int_end));
        }
        let lower = |j: usize, word: &[u8]| {
            t.len() >= j + word.len() && t[j..j + word.len()].eq_ignore_ascii_case(word)
        };
        if int_end == i {
            if lower(i, b"infinity") {
                return Some((start, i + 8));
            }
            if lower(i, b"inf") || lower(i, b"nan") {
                return Some((start, i + 3));
            }
        }
        let mut end = int_end;
        let mut mantissa = int_end > i;
        if end < t.len() && t[end] == b'.' {
            let frac_end = digits(end + 1);
            mantissa |= frac_end > end + 1;
            end = frac_end;
        }
        if !mantissa {
            return None;
        }
        if end < t.len() && (t[end] == b'e' || t[end] == b'E') {
            let mut j = end + 1;
            if j < t.len() && (t[j] == b'+' || t[j] == b'-') {
                j += 1;
            }
            let exp_end = digits(j);
            if exp_end > j {
                end = exp_end;
            }
        }
        Some((start, end))
    }

    fn number(&mut self, float: bool) -> f64 {
        if self.eof() {
            self.error = true;
            return 0.0;
        }
        let Some((start, end)) = self.scan(float) else {
            self.at = None;
            self.error = true;
            return 0.0;
        };
        self.at = Some(end);
        let s = std::str::from_utf8(&self.text[start..end]).unwrap_or("0");
        let s = s.strip_prefix('+').unwrap_or(s);
        if float {
            s.parse::<f64>().unwrap_or(0.0)
        } else {
            // strtol saturates; the counts it feeds are bounded below anyway.
            s.parse::<i64>().unwrap_or(if s.starts_with('-') {
                i64::MIN
            } else {
                i64::MAX
            }) as f64
        }
    }
    fn double(&mut self) -> f64 {
        self.number(true)
    }
    fn long(&mut self) -> i64 {
        self.number(false) as i64
    }
}

fn find(t: &[u8], from: usize, what: &[u8]) -> Option<usize> {
    t.get(from..)?
        .windows(what.len())
        .position(|w| w == what)
        .map(|p| p + from)
}

/// `IESFile::parse`.
fn parse(text: &str) -> Option<Parsed> {
    let t = text.as_bytes();
    let mut p = Numbers {
        text: t,
        at: find(t, 0, b"\nTILT="),
        error: false,
    };
    if p.eof() {
        return None;
    }
    let tilt = p.at?;
    if t[tilt..].starts_with(b"\nTILT=INCLUDE") {
        p.at = Some(tilt + 13);
        p.double(); // lamp to luminaire geometry
        let tilts = p.long();
        for _ in 0..tilts.clamp(0, t.len() as i64) * 2 {
            p.double();
        }
    } else {
        p.at = find(t, tilt + 1, b"\n");
    }
    if p.eof() {
        return None;
    }
    p.at = p.at.map(|i| i + 1);
    p.long(); // number of lamps
    p.double(); // lumens per lamp
    let mut factor = p.double(); // candela multiplier
                                 // C's int truncation of the counts; a count the text cannot hold fails as the
                                 // parser would on running out of numbers.
    let v_num = p.long() as i32;
    let h_num = p.long() as i32;
    let kind = match p.long() {
        2 => Photometric::B,
        1 => Photometric::C,
        _ => return None,
    };
    p.long(); // unit
    p.double(); // width
    p.double(); // length
    p.double(); // height
    factor *= p.double(); // ballast factor
    factor *= p.double(); // ballast-lamp photometric factor
    p.double(); // input watts
    factor *= CANDELA_TO_WATT;
    let room = t.len() as i64;
    if v_num < 0 || h_num < 0 || (v_num as i64) * (h_num as i64 + 1) + h_num as i64 > room {
        return None;
    }
    let v: Vec<f32> = (0..v_num).map(|_| p.double() as f32).collect();
    let h: Vec<f32> = (0..h_num).map(|_| p.double() as f32).collect();
    let rows = (0..h_num)
        .map(|_| (0..v_num).map(|_| (factor * p.double()) as f32).collect())
        .collect();
    (!p.error).then_some((kind, h, v, rows))
}

/// `IESFile::process`: both types brought to horizontal 0..360° and vertical from 0° or
/// 90°, then radians.
fn process(kind: Photometric, h: Vec<f32>, v: Vec<f32>, rows: Vec<Vec<f32>>) -> Option<IesData> {
    if h.is_empty() || v.is_empty() {
        return None;
    }
    let (mut h, mut v, rows) = match kind {
        Photometric::B => process_type_b(h, v, rows)?,
        Photometric::C => process_type_c(h, v, rows)?,
    };
    let k = std::f32::consts::PI / 180.0;
    v.iter_mut().for_each(|a| *a *= k);
    h.iter_mut().for_each(|a| *a *= k);
    let intensity = rows.concat();
    Some(IesData {
        h_angles: h,
        v_angles: v,
        intensity,
    })
}

type Processed = (Vec<f32>, Vec<f32>, Vec<Vec<f32>>);

fn process_type_b(h: Vec<f32>, v: Vec<f32>, rows: Vec<Vec<f32>>) -> Option<Processed> {
    // Type B swaps the roles of the angles.
    let mut rows: Vec<Vec<f32>> = (0..v.len())
        .map(|i| (0..h.len()).map(|j| rows[j][i]).collect())
        .collect();
    let (mut h, mut v) = (v, h);
    if *h.last()? != 90.0 {
        return None;
    }
    if h[0] == 0.0 {
        // 90°..180° only: mirror to the full 180°.
        let n = h.len();
        let mut nh = Vec::with_capacity(2 * n - 1);
        let mut nr = Vec::with_capacity(2 * n - 1);
        for i in (1..n).rev() {
            nh.push(90.0 - h[i]);
            nr.push(rows[i].clone());
        }
        for i in 0..n {
            nh.push(90.0 + h[i]);
            nr.push(rows[i].clone());
        }
        h = nh;
        rows = nr;
    } else if h[0] == -90.0 {
        h.iter_mut().for_each(|a| *a += 90.0);
    }
    // Later Cycles copies 0° to 360° here; 4.5 does not, so its type B lookups beyond 180°
    // are zero (fixture case ies_type_b).
    if *v.last()? != 90.0 {
        return None;
    }
    if v[0] == 0.0 {
        let n = v.len();
        let mut nv = Vec::with_capacity(2 * n - 1);
        for i in (1..n).rev() {
            nv.push(90.0 - v[i]);
        }
        for a in &v {
            nv.push(90.0 + a);
        }
        for r in rows.iter_mut() {
            // Angle 90° - v[i] takes row value i (later Cycles pairs it with i - 1).
            let mut nr: Vec<f32> = r[1..].iter().rev().copied().collect();
            nr.extend_from_slice(r);
            *r = nr;
        }
        v = nv;
    } else if v[0] == -90.0 {
        v.iter_mut().for_each(|a| *a += 90.0);
    }
    Some((h, v, rows))
}

fn process_type_c(mut h: Vec<f32>, v: Vec<f32>, mut rows: Vec<Vec<f32>>) -> Option<Processed> {
    if h[0] == 90.0 {
        // Stored from 90° to 270°: rotate to 0°..180°.
        h.iter_mut().for_each(|a| *a -= 90.0);
    }
    if h[0] != 0.0 {
        return None;
    }
    if h.len() == 1 {
        h.push(360.0);
        rows.push(rows[0].clone());
    }
    if *h.last()? == 90.0 {
        // One quadrant: mirror to two (and to four below).
        for i in (0..h.len() - 1).rev() {
            h.push(180.0 - h[i]);
            rows.push(rows[i].clone());
        }
    }
    if *h.last()? == 180.0 {
        for i in (0..h.len() - 1).rev() {
            h.push(360.0 - h[i]);
            rows.push(rows[i].clone());
        }
    }
    // Files that leave out the 360° column, with a regular spacing, get it back.
    let n = h.len();
    if h[n - 1] != 360.0 {
        let last_step = h[n - 1] - h[n - 2];
        let first_step = h[1] - h[0];
        let gap = 360.0 - h[n - 1];
        if last_step == gap || first_step == gap {
            h.push(360.0);
            rows.push(rows[0].clone());
        } else {
            return None;
        }
    }
    let (v_first, v_last) = (v[0], *v.last()?);
    if (v_first == 90.0 && v_last != 180.0) || (v_first != 90.0 && v_first != 0.0) {
        return None;
    }
    Some((h, v, rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    const TYPE_C: &str = "IESNA:LM-63-2002\n[TEST] quadrant\nTILT=NONE\n1 1000 1.0 3 1 1 2 0 0 0\n1.0 1.0 100\n0 45 90\n0\n1000 500 0\n";

    #[test]
    fn a_single_plane_spreads_round_the_circle() {
        let t = IesTable::new(TYPE_C);
        let d = t.data.as_ref().unwrap();
        // One horizontal angle: 0° and 360°.
        assert_eq!(d.h_angles, vec![0.0, 2.0 * std::f32::consts::PI]);
        assert_eq!(d.v_angles.len(), 3);
        let k = (1.0 * CANDELA_TO_WATT * 1000.0) as f32;
        assert_eq!(d.intensity[0], k);
        // Straight down, Cycles' horizontal angle is pi, half-way between the 0° and 360°
        // columns. Its wrap test (`h_high > 2pi - 1e-7` in f32) fails for 360°, so the
        // neighbours beyond are zero and the cubic overshoots by 1/8.
        assert_eq!(ies(&t, [0.0, 0.0, -1.0], 1.0), 1.125 * k);
        // At the 0° column itself the value is the table's.
        assert_eq!(t.interp(0.0, 0.0), k);
        // Above the horizon: outside the table.
        assert_eq!(ies(&t, [0.0, 0.0, 1.0], 1.0), 0.0);
    }

    #[test]
    fn data_cycles_rejects_reads_as_100() {
        for bad in [
            "",
            "\n",
            "TILT=NONE\n1 2 3",
            "x\nTILT=NONE\n1 1000 1 -3 1 1 2",
        ] {
            let t = IesTable::new(bad);
            assert!(!t.is_valid(), "{bad:?}");
            assert_eq!(ies(&t, [0.0, 0.0, -1.0], 2.0), 200.0);
        }
    }

    #[test]
    fn hostile_counts_do_not_allocate() {
        let t = IesTable::new("x\nTILT=NONE\n1 1 1 2000000000 2000000000 1 2 0 0 0\n1 1 1\n");
        assert!(!t.is_valid());
    }
}
