//! Control of a running render from outside it: a cancel flag checked between pixels and
//! a progress count, both atomics so another thread (a UI, the Python bindings) can read
//! and set them while the render's workers run. A render without a `Control` behaves as
//! before; one with it renders the same bits unless it is cancelled.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;

#[derive(Debug, Default)]
pub struct Control {
    cancel: Arc<AtomicBool>,
    done: AtomicU64,
    total: AtomicU64,
}

/// The error text of a cancelled render (`RenderError::is_cancelled` tests for it).
pub const CANCELLED: &str = "render cancelled";

impl Control {
    pub fn new() -> Control {
        Control::default()
    }

    /// A control whose cancel flag is shared with the caller (one flag may stop several
    /// renders).
    pub fn with_flag(cancel: Arc<AtomicBool>) -> Control {
        Control {
            cancel,
            ..Control::default()
        }
    }

    /// Asks the render to stop: workers stop at their next pixel, and the render returns
    /// `RenderError(CANCELLED)` once they have.
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// (pixel samples done, pixel samples planned): planned is pixels x samples, and
    /// done jumps to it when adaptive sampling ends the render early.
    pub fn progress(&self) -> (u64, u64) {
        (
            self.done.load(Ordering::Relaxed),
            self.total.load(Ordering::Relaxed),
        )
    }

    pub(crate) fn start(&self, total: u64) {
        self.done.store(0, Ordering::Relaxed);
        self.total.store(total, Ordering::Relaxed);
    }

    pub(crate) fn add(&self, n: u64) {
        self.done.fetch_add(n, Ordering::Relaxed);
    }

    pub(crate) fn finish(&self) {
        self.done
            .store(self.total.load(Ordering::Relaxed), Ordering::Relaxed);
    }
}
