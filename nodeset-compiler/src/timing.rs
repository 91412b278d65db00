//! Where a run's time goes: with `NODESET_COMPILER_TIMINGS` set (to anything), each stage of a run prints
//! one line `timing: STAGE MS` to stderr when it ends, nested stages indented. Nothing is measured or
//! printed otherwise (one environment lookup per process). The output never depends on it.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;
use std::time::Instant;

/// The environment variable that turns the timings on.
pub const ENV: &str = "NODESET_COMPILER_TIMINGS";

fn enabled() -> bool {
    static ON: OnceLock<bool> = OnceLock::new();
    *ON.get_or_init(|| std::env::var_os(ENV).is_some())
}

/// How deep the open spans are (for the indentation only; spans on other threads share it).
static DEPTH: AtomicUsize = AtomicUsize::new(0);

/// A stage being timed: prints its time when dropped. Made by [`span`].
pub struct Span {
    open: Option<(&'static str, Instant)>,
}

/// Starts timing `stage` (a no-op unless [`ENV`] is set).
pub fn span(stage: &'static str) -> Span {
    if !enabled() {
        return Span { open: None };
    }
    DEPTH.fetch_add(1, Ordering::Relaxed);
    Span { open: Some((stage, Instant::now())) }
}

impl Drop for Span {
    fn drop(&mut self) {
        if let Some((stage, start)) = self.open.take() {
            let depth = DEPTH.fetch_sub(1, Ordering::Relaxed).saturating_sub(1);
            let ms = start.elapsed().as_secs_f64() * 1e3;
            eprintln!("timing: {:indent$}{stage} {ms:.2}", "", indent = depth * 2);
        }
    }
}
