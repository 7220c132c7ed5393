//! What a render may ask for, checked before anything is allocated: image size (by side,
//! by pixel count and by an estimate of the memory the film needs), samples and worker
//! threads. docs/limits.md lists them; an invalid value is an error naming the setting.

use super::RenderError;

/// Largest accepted image side, so a typo cannot ask for terabytes.
pub const MAX_SIDE: u32 = 16384;

/// Largest accepted image: 8192x8192 pixels (any shape up to MAX_SIDE a side).
pub const MAX_PIXELS: u64 = 1 << 26;

/// Bytes the renderer holds per pixel (an upper estimate): the film's accumulator (64),
/// the label passes and denoising guides per tile (64), the output passes (68) and the
/// colour (16), rounded up for the writers' buffers.
pub const FILM_BYTES_PER_PIXEL: u64 = 256;

/// Cycles' own limit on samples per pixel (its UI and RNA stop at 2^24).
pub const MAX_SAMPLES: u32 = 1 << 24;

/// Most worker threads a render may ask for; more would only spend memory on stacks.
pub const MAX_THREADS: usize = 1024;

/// Checks a `w` x `h` image against the size limits and the memory the machine has free
/// (when it reports it); `what` names where the size came from.
pub fn check_film(w: u32, h: u32, what: &str) -> Result<(), RenderError> {
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(RenderError(format!(
            "{what} {w}x{h}: each side must be 1 to {MAX_SIDE}"
        )));
    }
    let pixels = w as u64 * h as u64;
    let need = pixels * FILM_BYTES_PER_PIXEL;
    if pixels > MAX_PIXELS {
        return Err(RenderError(format!(
            "{what} {w}x{h}: {pixels} pixels is more than the limit of {MAX_PIXELS} \
             (8192x8192; the film would need about {} MB)",
            need >> 20
        )));
    }
    if let Some(free) = available_memory() {
        if need > free {
            return Err(RenderError(format!(
                "{what} {w}x{h}: the film needs about {} MB but only {} MB of memory is available",
                need >> 20,
                free >> 20
            )));
        }
    }
    Ok(())
}

/// Checks `--samples` / the scene's samples.
pub fn check_samples(samples: u32, what: &str) -> Result<(), RenderError> {
    if samples == 0 || samples > MAX_SAMPLES {
        return Err(RenderError(format!(
            "{what} {samples}: samples must be at least 1 and at most {MAX_SAMPLES}"
        )));
    }
    Ok(())
}

/// Checks `--threads`: 1 to MAX_THREADS (an error rather than a silent clamp).
pub fn check_threads(n: usize) -> Result<(), RenderError> {
    if n == 0 || n > MAX_THREADS {
        return Err(RenderError(format!(
            "--threads {n}: must be 1 to {MAX_THREADS}"
        )));
    }
    Ok(())
}

/// Checks `--threshold`: a finite number, 0 (adaptive sampling off) or more.
pub fn check_threshold(t: f32) -> Result<(), RenderError> {
    if !(t.is_finite() && t >= 0.0) {
        return Err(RenderError(format!(
            "--threshold {t}: must be a finite number >= 0 (0 turns adaptive sampling off)"
        )));
    }
    Ok(())
}

/// MemAvailable from /proc/meminfo (Linux), in bytes.
fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kb.checked_mul(1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert!(check_film(64, 48, "resolution").is_ok());
        assert!(check_film(0, 48, "resolution").is_err());
        assert!(check_film(16385, 1, "resolution").is_err());
        let e = check_film(16384, 16384, "resolution").unwrap_err().0;
        assert!(e.contains("16384x16384") && e.contains("limit"), "{e}");
    }

    #[test]
    fn threads_samples_threshold() {
        assert!(check_threads(1).is_ok() && check_threads(MAX_THREADS).is_ok());
        assert!(check_threads(0).is_err() && check_threads(100_000).is_err());
        assert!(check_samples(1, "s").is_ok() && check_samples(0, "s").is_err());
        assert!(check_samples(MAX_SAMPLES + 1, "s").is_err());
        assert!(check_threshold(0.0).is_ok() && check_threshold(0.01).is_ok());
        for t in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -0.5] {
            assert!(check_threshold(t).is_err(), "{t}");
        }
    }
}
