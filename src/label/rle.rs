//! COCO run-length encoding, as pycocotools writes it: runs over the mask in
//! column-major order (down each column, left to right), starting with a run of zeros,
//! then compressed to a string (`rleToString` in pycocotools' maskApi.c: each count,
//! after the third delta-coded against the count two before it, in 5-bit groups with a
//! continuation bit, offset by 48 into printable ASCII).

/// Run lengths over a row-major mask (`mask[y * width + x]`), column-major as COCO wants.
pub fn counts(width: u32, height: u32, mask: impl Fn(usize) -> bool) -> Vec<u32> {
    let (w, h) = (width as usize, height as usize);
    let mut out = Vec::new();
    let mut current = false;
    let mut run = 0u32;
    for x in 0..w {
        for y in 0..h {
            let v = mask(y * w + x);
            if v != current {
                out.push(run);
                run = 0;
                current = v;
            }
            run += 1;
        }
    }
    out.push(run);
    out
}

/// pycocotools' compressed string for `counts`.
pub fn to_string(counts: &[u32]) -> String {
    let mut s = String::new();
    for i in 0..counts.len() {
        let mut x = counts[i] as i64;
        if i > 2 {
            x -= counts[i - 2] as i64;
        }
        loop {
            let mut c = x & 0x1f;
            x >>= 5;
            let more = if c & 0x10 != 0 { x != -1 } else { x != 0 };
            if more {
                c |= 0x20;
            }
            s.push((c as u8 + 48) as char);
            if !more {
                break;
            }
        }
    }
    s
}

/// Inverse of `to_string` (pycocotools' `rleFrString`).
pub fn from_string(s: &str) -> Result<Vec<u32>, String> {
    let b = s.as_bytes();
    let mut out: Vec<u32> = Vec::new();
    let mut p = 0;
    while p < b.len() {
        let mut x: i64 = 0;
        let mut k = 0;
        loop {
            let Some(&ch) = b.get(p) else {
                return Err("RLE string ends inside a count".into());
            };
            let c = ch as i64 - 48;
            if !(0..64).contains(&c) {
                return Err(format!("bad RLE character {:?}", ch as char));
            }
            x |= (c & 0x1f) << (5 * k);
            let more = c & 0x20 != 0;
            p += 1;
            k += 1;
            if !more {
                if c & 0x10 != 0 {
                    x |= -1i64 << (5 * k);
                }
                break;
            }
        }
        let i = out.len();
        if i > 2 {
            x += out[i - 2] as i64;
        }
        out.push(u32::try_from(x).map_err(|_| "negative run in RLE".to_string())?);
    }
    Ok(out)
}

/// Area (foreground pixels) and COCO bbox [x, y, w, h] of an RLE, as pycocotools'
/// `area` and `toBbox` compute them.
pub fn area_bbox(height: u32, counts: &[u32]) -> (u64, [u32; 4]) {
    let h = height as u64;
    let mut area = 0;
    let (mut x0, mut y0, mut x1, mut y1) = (u64::MAX, u64::MAX, 0u64, 0u64);
    let mut pos = 0u64;
    for (i, &c) in counts.iter().enumerate() {
        let c = c as u64;
        if i % 2 == 1 && c > 0 {
            area += c;
            let (first, last) = (pos, pos + c - 1);
            let (xa, xb) = (first / h, last / h);
            x0 = x0.min(xa);
            x1 = x1.max(xb);
            if xa == xb {
                y0 = y0.min(first % h);
                y1 = y1.max(last % h);
            } else {
                y0 = 0;
                y1 = h - 1;
            }
        }
        pos += c;
    }
    if area == 0 {
        return (0, [0; 4]);
    }
    (
        area,
        [
            x0 as u32,
            y0 as u32,
            (x1 - x0 + 1) as u32,
            (y1 - y0 + 1) as u32,
        ],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips() {
        let c = vec![5, 3, 100, 2, 40000, 1, 0, 7];
        assert_eq!(from_string(&to_string(&c)).unwrap(), c);
    }
}
