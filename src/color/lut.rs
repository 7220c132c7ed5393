//! LUT files an OCIO config refers to (.spi1d, .cube 1D/3D, .spi3d, .spimtx), parsed
//! into plain tables, with OCIO's interpolation: linear for 1D, trilinear or tetrahedral
//! for 3D, and the exact inverse of a monotonic 1D LUT (OCIO's "inverse" direction).

use std::path::Path;

use super::ColorError;

/// A 1D LUT: `channels` is 1 (same curve for R, G, B) or 3, over the input domain
/// `from..to` (values outside are clamped to it, as OCIO does).
#[derive(Debug, Clone)]
pub struct Lut1D {
    pub from: [f32; 3],
    pub to: [f32; 3],
    /// Per channel tables (one shared table when the file has one component).
    pub tables: Vec<Vec<f32>>,
}

/// A 3D LUT of `size`^3 RGB entries, red index fastest, domain `min..max` per axis.
#[derive(Debug, Clone)]
pub struct Lut3D {
    pub size: usize,
    pub min: [f32; 3],
    pub max: [f32; 3],
    pub data: Vec<[f32; 3]>,
}

/// What a FileTransform file holds.
#[derive(Debug, Clone)]
pub enum LutFile {
    OneD(Lut1D),
    ThreeD(Lut3D),
    /// A 3x4 matrix (row-major, offset in column 3), from .spimtx.
    Matrix([[f64; 4]; 3]),
}

fn bad(path: &Path, msg: impl std::fmt::Display) -> ColorError {
    ColorError::Lut {
        path: path.to_path_buf(),
        message: msg.to_string(),
    }
}

pub fn load(path: &Path) -> Result<LutFile, ColorError> {
    let bytes = crate::scene::file::read_regular(path, crate::scene::limits::MAX_COLOR_FILE_BYTES)
        .map_err(|m| bad(path, m))?;
    let text = String::from_utf8(bytes).map_err(|_| bad(path, "not a text file (not UTF-8)"))?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "spi1d" => parse_spi1d(&text)
            .map(LutFile::OneD)
            .map_err(|m| bad(path, m)),
        "cube" => parse_cube(&text).map_err(|m| bad(path, m)),
        "spi3d" => parse_spi3d(&text)
            .map(LutFile::ThreeD)
            .map_err(|m| bad(path, m)),
        "spimtx" => parse_spimtx(&text)
            .map(LutFile::Matrix)
            .map_err(|m| bad(path, m)),
        _ => Err(bad(
            path,
            format!("unsupported LUT format .{ext} (supported: spi1d, cube, spi3d, spimtx)"),
        )),
    }
}

/// Largest 3D LUT edge accepted (256^3 entries, 200 MB): sizes come from the file.
pub const MAX_LUT_3D_SIZE: usize = 256;

fn num(tok: &str) -> Result<f32, String> {
    tok.parse::<f32>()
        .map_err(|_| "a value is not a number".to_string())
}

fn parse_spi1d(text: &str) -> Result<Lut1D, String> {
    let (mut from, mut to, mut length, mut comps) = (0.0f32, 1.0f32, None, 1usize);
    let mut values: Vec<f32> = Vec::new();
    let mut in_body = false;
    for line in text.lines() {
        let line = line.trim();
        if line.is_empty() {
            continue;
        }
        if in_body {
            if line.starts_with('}') {
                in_body = false;
                continue;
            }
            for t in line.split_whitespace() {
                values.push(num(t)?);
            }
            continue;
        }
        let mut it = line.split_whitespace();
        match it.next() {
            Some("Version") => {}
            Some("From") => {
                from = num(it.next().ok_or("From needs two numbers")?)?;
                to = num(it.next().ok_or("From needs two numbers")?)?;
            }
            Some("Length") => {
                length = Some(
                    it.next()
                        .ok_or("Length needs a number")?
                        .parse::<usize>()
                        .map_err(|e| e.to_string())?,
                )
            }
            Some("Components") => {
                comps = it
                    .next()
                    .ok_or("Components needs a number")?
                    .parse::<usize>()
                    .map_err(|e| e.to_string())?
            }
            Some("{") => in_body = true,
            // The word itself is not quoted: errors never echo a file's content.
            Some(_) => return Err("a line starts with an unknown keyword".into()),
            None => {}
        }
    }
    let n = length.ok_or("missing Length")?;
    if comps != 1 && comps != 3 && comps != 2 {
        return Err(format!("Components {comps} not supported"));
    }
    if n < 2 || values.len() != n * comps {
        return Err(format!(
            "expected {} values, found {}",
            n * comps,
            values.len()
        ));
    }
    let tables = if comps == 1 {
        vec![values]
    } else {
        (0..comps)
            .map(|c| values.iter().skip(c).step_by(comps).copied().collect())
            .collect()
    };
    Ok(Lut1D {
        from: [from; 3],
        to: [to; 3],
        tables,
    })
}

fn parse_cube(text: &str) -> Result<LutFile, String> {
    let (mut size3, mut size1) = (None, None);
    let (mut dmin, mut dmax) = ([0.0f32; 3], [1.0f32; 3]);
    let mut rows: Vec<[f32; 3]> = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let mut it = line.split_whitespace();
        let first = it.next().unwrap();
        match first {
            "TITLE" => {}
            "LUT_3D_SIZE" => {
                size3 = Some(
                    it.next()
                        .ok_or("LUT_3D_SIZE needs a number")?
                        .parse::<usize>()
                        .map_err(|e| e.to_string())?,
                )
            }
            "LUT_1D_SIZE" => {
                size1 = Some(
                    it.next()
                        .ok_or("LUT_1D_SIZE needs a number")?
                        .parse::<usize>()
                        .map_err(|e| e.to_string())?,
                )
            }
            "DOMAIN_MIN" | "DOMAIN_MAX" => {
                let v = [
                    num(it.next().ok_or("domain needs 3 numbers")?)?,
                    num(it.next().ok_or("domain needs 3 numbers")?)?,
                    num(it.next().ok_or("domain needs 3 numbers")?)?,
                ];
                if first == "DOMAIN_MIN" {
                    dmin = v
                } else {
                    dmax = v
                }
            }
            _ => {
                let r = num(first)?;
                let g = num(it.next().ok_or("row needs 3 numbers")?)?;
                let b = num(it.next().ok_or("row needs 3 numbers")?)?;
                rows.push([r, g, b]);
            }
        }
    }
    match (size3, size1) {
        (Some(n), _) => {
            if n > MAX_LUT_3D_SIZE {
                return Err(format!(
                    "LUT_3D_SIZE is more than the limit of {MAX_LUT_3D_SIZE}"
                ));
            }
            if n < 2 || rows.len() != n * n * n {
                return Err(format!(
                    "LUT_3D_SIZE {n} needs {} rows, found {}",
                    n * n * n,
                    rows.len()
                ));
            }
            Ok(LutFile::ThreeD(Lut3D {
                size: n,
                min: dmin,
                max: dmax,
                data: rows,
            }))
        }
        (None, Some(n)) => {
            if n < 2 || rows.len() != n {
                return Err(format!(
                    "LUT_1D_SIZE {n} needs {n} rows, found {}",
                    rows.len()
                ));
            }
            let tables = (0..3)
                .map(|c| rows.iter().map(|r| r[c]).collect())
                .collect();
            Ok(LutFile::OneD(Lut1D {
                from: dmin,
                to: dmax,
                tables,
            }))
        }
        _ => Err("neither LUT_3D_SIZE nor LUT_1D_SIZE given".into()),
    }
}

fn parse_spi3d(text: &str) -> Result<Lut3D, String> {
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let _header = lines.next().ok_or("empty file")?;
    let sizes: Vec<usize> = lines
        .next()
        .ok_or("missing size line")?
        .split_whitespace()
        .map(|t| t.parse::<usize>().map_err(|e| e.to_string()))
        .collect::<Result<_, _>>()?;
    if sizes.len() != 3 || sizes[0] != sizes[1] || sizes[1] != sizes[2] || sizes[0] < 2 {
        return Err("unsupported spi3d sizes (need three equal sizes of at least 2)".into());
    }
    if sizes[0] > MAX_LUT_3D_SIZE {
        return Err(format!(
            "spi3d size is more than the limit of {MAX_LUT_3D_SIZE}"
        ));
    }
    let n = sizes[0];
    let mut data = vec![[0.0f32; 3]; n * n * n];
    let mut count = 0;
    for line in lines {
        let t: Vec<&str> = line.split_whitespace().collect();
        if t.len() != 6 {
            return Err(format!("spi3d row {} needs 6 fields", count + 1));
        }
        let (i, j, k) = (
            t[0].parse::<usize>().map_err(|e| e.to_string())?,
            t[1].parse::<usize>().map_err(|e| e.to_string())?,
            t[2].parse::<usize>().map_err(|e| e.to_string())?,
        );
        if i >= n || j >= n || k >= n {
            return Err(format!("spi3d row {}: index out of range", count + 1));
        }
        data[i + n * (j + n * k)] = [num(t[3])?, num(t[4])?, num(t[5])?];
        count += 1;
    }
    if count != n * n * n {
        return Err(format!("expected {} rows, found {count}", n * n * n));
    }
    Ok(Lut3D {
        size: n,
        min: [0.0; 3],
        max: [1.0; 3],
        data,
    })
}

fn parse_spimtx(text: &str) -> Result<[[f64; 4]; 3], String> {
    let v: Vec<f64> = text
        .split_whitespace()
        .map(|t| {
            t.parse::<f64>()
                .map_err(|_| "a value is not a number".to_string())
        })
        .collect::<Result<_, _>>()?;
    if v.len() != 12 {
        return Err(format!("spimtx needs 12 numbers, found {}", v.len()));
    }
    // The offset column of .spimtx is in 16-bit code values (OCIO divides it by 65535).
    Ok([
        [v[0], v[1], v[2], v[3] / 65535.0],
        [v[4], v[5], v[6], v[7] / 65535.0],
        [v[8], v[9], v[10], v[11] / 65535.0],
    ])
}

impl Lut1D {
    #[inline]
    fn table(&self, c: usize) -> &[f32] {
        if self.tables.len() == 1 {
            &self.tables[0]
        } else {
            &self.tables[c.min(self.tables.len() - 1)]
        }
    }

    #[inline]
    pub fn eval(&self, c: usize, x: f32) -> f32 {
        let t = self.table(c);
        let n = t.len();
        let span = self.to[c] - self.from[c];
        let mut p = (x - self.from[c]) / span * (n - 1) as f32;
        // NaN becomes the domain start, as a clamp does in OCIO.
        if !(p > 0.0) {
            p = 0.0;
        }
        if p >= (n - 1) as f32 {
            return t[n - 1];
        }
        let i = p as usize;
        let f = p - i as f32;
        t[i] + f * (t[i + 1] - t[i])
    }

    /// Exact inverse of a monotonic (non-decreasing or non-increasing) table with linear
    /// interpolation; outputs outside the table's range clamp to the domain ends.
    pub fn eval_inverse(&self, c: usize, y: f32) -> f32 {
        let t = self.table(c);
        let n = t.len();
        let increasing = t[n - 1] >= t[0];
        let key = |v: f32| if increasing { v } else { -v };
        let yk = key(y);
        let (lo_v, hi_v) = (key(t[0]), key(t[n - 1]));
        let pos = if !(yk > lo_v) {
            // First index still at the lowest value (start of a flat run).
            0.0
        } else if yk >= hi_v {
            // First index reaching the highest value.
            let mut i = n - 1;
            while i > 0 && key(t[i - 1]) >= hi_v {
                i -= 1;
            }
            i as f32
        } else {
            // Largest i with key(t[i]) < yk, then interpolate within [i, i+1].
            let (mut lo, mut hi) = (0usize, n - 1);
            while hi - lo > 1 {
                let mid = (lo + hi) / 2;
                if key(t[mid]) < yk {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            let (a, b) = (key(t[lo]), key(t[hi]));
            lo as f32 + if b > a { (yk - a) / (b - a) } else { 0.0 }
        };
        self.from[c] + pos / (n - 1) as f32 * (self.to[c] - self.from[c])
    }
}

impl Lut3D {
    #[inline]
    fn at(&self, r: usize, g: usize, b: usize) -> [f32; 3] {
        self.data[r + self.size * (g + self.size * b)]
    }

    /// Grid coordinates of `rgb`, clamped to the domain.
    #[inline]
    fn coords(&self, rgb: [f32; 3]) -> ([usize; 3], [usize; 3], [f32; 3]) {
        let m = (self.size - 1) as f32;
        let mut i0 = [0usize; 3];
        let mut i1 = [0usize; 3];
        let mut f = [0.0f32; 3];
        for c in 0..3 {
            let mut p = (rgb[c] - self.min[c]) / (self.max[c] - self.min[c]) * m;
            if !(p > 0.0) {
                p = 0.0;
            }
            if p > m {
                p = m;
            }
            let i = (p.floor() as usize).min(self.size - 1);
            i0[c] = i;
            i1[c] = (i + 1).min(self.size - 1);
            f[c] = p - i as f32;
        }
        (i0, i1, f)
    }

    /// Tetrahedral interpolation (OCIO's `interpolation: tetrahedral`).
    pub fn tetrahedral(&self, rgb: [f32; 3]) -> [f32; 3] {
        let (i0, i1, [fr, fg, fb]) = self.coords(rgb);
        let c000 = self.at(i0[0], i0[1], i0[2]);
        let c111 = self.at(i1[0], i1[1], i1[2]);
        let mut out = [0.0f32; 3];
        // Pick the tetrahedron containing the point by ordering the fractions.
        if fr > fg {
            if fg > fb {
                let c100 = self.at(i1[0], i0[1], i0[2]);
                let c110 = self.at(i1[0], i1[1], i0[2]);
                for k in 0..3 {
                    out[k] = (1.0 - fr) * c000[k]
                        + (fr - fg) * c100[k]
                        + (fg - fb) * c110[k]
                        + fb * c111[k];
                }
            } else if fr > fb {
                let c100 = self.at(i1[0], i0[1], i0[2]);
                let c101 = self.at(i1[0], i0[1], i1[2]);
                for k in 0..3 {
                    out[k] = (1.0 - fr) * c000[k]
                        + (fr - fb) * c100[k]
                        + (fb - fg) * c101[k]
                        + fg * c111[k];
                }
            } else {
                let c001 = self.at(i0[0], i0[1], i1[2]);
                let c101 = self.at(i1[0], i0[1], i1[2]);
                for k in 0..3 {
                    out[k] = (1.0 - fb) * c000[k]
                        + (fb - fr) * c001[k]
                        + (fr - fg) * c101[k]
                        + fg * c111[k];
                }
            }
        } else if fb > fg {
            let c001 = self.at(i0[0], i0[1], i1[2]);
            let c011 = self.at(i0[0], i1[1], i1[2]);
            for k in 0..3 {
                out[k] =
                    (1.0 - fb) * c000[k] + (fb - fg) * c001[k] + (fg - fr) * c011[k] + fr * c111[k];
            }
        } else if fb > fr {
            let c010 = self.at(i0[0], i1[1], i0[2]);
            let c011 = self.at(i0[0], i1[1], i1[2]);
            for k in 0..3 {
                out[k] =
                    (1.0 - fg) * c000[k] + (fg - fb) * c010[k] + (fb - fr) * c011[k] + fr * c111[k];
            }
        } else {
            let c010 = self.at(i0[0], i1[1], i0[2]);
            let c110 = self.at(i1[0], i1[1], i0[2]);
            for k in 0..3 {
                out[k] =
                    (1.0 - fg) * c000[k] + (fg - fr) * c010[k] + (fr - fb) * c110[k] + fb * c111[k];
            }
        }
        out
    }

    /// Trilinear interpolation (OCIO's `linear` for 3D LUTs).
    pub fn trilinear(&self, rgb: [f32; 3]) -> [f32; 3] {
        let (i0, i1, [fr, fg, fb]) = self.coords(rgb);
        let mut out = [0.0f32; 3];
        let lerp = |a: [f32; 3], b: [f32; 3], t: f32| {
            [
                a[0] + t * (b[0] - a[0]),
                a[1] + t * (b[1] - a[1]),
                a[2] + t * (b[2] - a[2]),
            ]
        };
        let c00 = lerp(
            self.at(i0[0], i0[1], i0[2]),
            self.at(i1[0], i0[1], i0[2]),
            fr,
        );
        let c10 = lerp(
            self.at(i0[0], i1[1], i0[2]),
            self.at(i1[0], i1[1], i0[2]),
            fr,
        );
        let c01 = lerp(
            self.at(i0[0], i0[1], i1[2]),
            self.at(i1[0], i0[1], i1[2]),
            fr,
        );
        let c11 = lerp(
            self.at(i0[0], i1[1], i1[2]),
            self.at(i1[0], i1[1], i1[2]),
            fr,
        );
        let c0 = lerp(c00, c10, fg);
        let c1 = lerp(c01, c11, fg);
        let c = lerp(c0, c1, fb);
        out.copy_from_slice(&c);
        out
    }
}
