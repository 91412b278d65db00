//! The measurement helpers of the workspace's benches, in one place.
//!
//! The measured programs (`nodeset-compiler/examples/{load_bench,rust_bench}.rs`,
//! `nodeset-examples/examples/{import_bench,robot_bench}.rs`) take the same figures the same way: wall and
//! CPU time in milliseconds, the peak resident memory from `/proc/self/status`, and the median, minimum and
//! maximum of a series of runs. Each prints one line `BENCH key=value ...` on stdout, which
//! `cargo xtask bench` reads back with [`Report::parse`]. Writing ([`Line`]) and reading ([`Report`]) that
//! line live here together, so the two sides cannot drift apart.
//!
//! The crate has no dependencies: the benches take it as a dev-dependency, so the compiler library and the
//! runtime gain nothing. CPU times come from `clock_gettime` and `getrusage` through their C declarations
//! on 64-bit Linux (the platform the benches are judged on); elsewhere they are NaN.

use std::collections::BTreeMap;
use std::fmt::Display;
use std::time::{Duration, Instant};

/// A duration in milliseconds.
pub fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Milliseconds since `t`.
pub fn ms_since(t: Instant) -> f64 {
    ms(t.elapsed())
}

/// The median of `v` (the mean of the middle two for an even count); NaN for no values.
pub fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    match s.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => s[n / 2],
        n => (s[n / 2 - 1] + s[n / 2]) / 2.0,
    }
}

/// The smallest of `v`; NaN for no values.
pub fn min(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::NAN, f64::min)
}

/// The largest of `v`; NaN for no values.
pub fn max(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::NAN, f64::max)
}

/// A field of `/proc/self/status` in KiB, such as `VmHWM` (the peak resident memory so far) or `VmRSS`;
/// None where there is no procfs or no such field.
pub fn proc_status_kib(field: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    status
        .lines()
        .find_map(|l| l.strip_prefix(field)?.strip_prefix(':'))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
}

/// CPU time the calling thread has run, ms (NaN where unavailable). Unlike wall time, it does not grow
/// when other processes compete for the CPU.
pub fn thread_cpu_ms() -> f64 {
    sys::cpu_ms(sys::CLOCK_THREAD_CPUTIME_ID)
}

/// CPU time this process has run on all its threads, ms (NaN where unavailable); for work that uses more
/// than one thread, where the calling thread's time alone would undercount it.
pub fn process_cpu_ms() -> f64 {
    sys::cpu_ms(sys::CLOCK_PROCESS_CPUTIME_ID)
}

/// The terminated children of this process (`getrusage(RUSAGE_CHILDREN)`): the peak resident memory of
/// the largest, KiB, and the CPU time (user + system) of all of them, ms. `(0, NaN)` where unavailable.
pub fn children_usage() -> (u64, f64) {
    sys::children_usage()
}

#[cfg(all(target_os = "linux", target_pointer_width = "64"))]
mod sys {
    pub const CLOCK_PROCESS_CPUTIME_ID: i32 = 2;
    pub const CLOCK_THREAD_CPUTIME_ID: i32 = 3;
    const RUSAGE_CHILDREN: i32 = -1;

    #[repr(C)]
    #[derive(Default)]
    struct Timespec {
        tv_sec: i64,
        tv_nsec: i64,
    }

    #[repr(C)]
    #[derive(Default)]
    struct Timeval {
        tv_sec: i64,
        tv_usec: i64,
    }

    /// `struct rusage` of 64-bit Linux: two timevals, then 14 longs starting with `ru_maxrss` (KiB).
    #[repr(C)]
    #[derive(Default)]
    struct Rusage {
        utime: Timeval,
        stime: Timeval,
        maxrss: i64,
        rest: [i64; 13],
    }

    extern "C" {
        fn clock_gettime(clock: i32, tp: *mut Timespec) -> i32;
        fn getrusage(who: i32, usage: *mut Rusage) -> i32;
    }

    pub fn cpu_ms(clock: i32) -> f64 {
        let mut ts = Timespec::default();
        // SAFETY: `ts` is a valid, writable timespec of the 64-bit Linux layout.
        if unsafe { clock_gettime(clock, &mut ts) } == 0 {
            ts.tv_sec as f64 * 1e3 + ts.tv_nsec as f64 / 1e6
        } else {
            f64::NAN
        }
    }

    pub fn children_usage() -> (u64, f64) {
        let mut ru = Rusage::default();
        // SAFETY: `ru` is a valid, writable rusage of the 64-bit Linux layout.
        if unsafe { getrusage(RUSAGE_CHILDREN, &mut ru) } != 0 {
            return (0, f64::NAN);
        }
        let ms = |t: &Timeval| t.tv_sec as f64 * 1e3 + t.tv_usec as f64 / 1e3;
        (ru.maxrss.max(0) as u64, ms(&ru.utime) + ms(&ru.stime))
    }
}

#[cfg(not(all(target_os = "linux", target_pointer_width = "64")))]
mod sys {
    pub const CLOCK_PROCESS_CPUTIME_ID: i32 = 2;
    pub const CLOCK_THREAD_CPUTIME_ID: i32 = 3;

    pub fn cpu_ms(_clock: i32) -> f64 {
        f64::NAN
    }

    pub fn children_usage() -> (u64, f64) {
        (0, f64::NAN)
    }
}

/// The `BENCH key=value ...` line a measured program prints, built key by key in print order.
#[derive(Debug, Default)]
pub struct Line(Vec<(String, String)>);

impl Line {
    /// An empty line.
    pub fn new() -> Line {
        Line::default()
    }

    /// Adds `key=value`. Values must not contain white space (the reader splits on it).
    pub fn kv(&mut self, key: impl Into<String>, value: impl Display) -> &mut Line {
        self.0.push((key.into(), value.to_string()));
        self
    }

    /// Adds `key` as a number with `decimals` places.
    pub fn num(&mut self, key: impl Into<String>, value: f64, decimals: usize) -> &mut Line {
        self.kv(key, format!("{value:.decimals$}"))
    }

    /// Adds `<prefix>_median_ms`, `<prefix>_min_ms` and `<prefix>_max_ms` of the times `v`, with
    /// `decimals` places.
    pub fn stats(&mut self, prefix: &str, v: &[f64], decimals: usize) -> &mut Line {
        self.num(format!("{prefix}_median_ms"), median(v), decimals)
            .num(format!("{prefix}_min_ms"), min(v), decimals)
            .num(format!("{prefix}_max_ms"), max(v), decimals)
    }

    /// Prints the line on stdout.
    pub fn print(&self) {
        println!("{self}");
    }
}

impl Display for Line {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("BENCH")?;
        for (k, v) in &self.0 {
            write!(f, " {k}={v}")?;
        }
        Ok(())
    }
}

/// A `BENCH` line read back from a measured program's stdout.
#[derive(Debug, Clone, Default)]
pub struct Report(BTreeMap<String, String>);

impl Report {
    /// The first `BENCH ` line of `stdout`, or None where there is none.
    pub fn parse(stdout: &str) -> Option<Report> {
        let line = stdout.lines().find_map(|l| l.strip_prefix("BENCH "))?;
        let map = line
            .split_whitespace()
            .filter_map(|kv| kv.split_once('='))
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        Some(Report(map))
    }

    /// The value of `key` as a number; NaN where it is missing or not a number.
    pub fn f(&self, key: &str) -> f64 {
        self.0
            .get(key)
            .and_then(|v| v.parse().ok())
            .unwrap_or(f64::NAN)
    }

    /// The value of `key` as text; `?` where it is missing.
    pub fn s(&self, key: &str) -> &str {
        self.0.get(key).map(String::as_str).unwrap_or("?")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan() && min(&[]).is_nan() && max(&[]).is_nan());
        assert_eq!((min(&[2.0, 1.0, 3.0]), max(&[2.0, 1.0, 3.0])), (1.0, 3.0));
    }

    #[test]
    fn a_written_line_reads_back() {
        let mut line = Line::new();
        line.kv("scenario", "robotics").stats("total", &[1.0, 2.0, 4.0], 3);
        assert_eq!(
            line.to_string(),
            "BENCH scenario=robotics total_median_ms=2.000 total_min_ms=1.000 total_max_ms=4.000"
        );
        let report = Report::parse(&format!("progress\n{line}\n")).unwrap();
        assert_eq!((report.s("scenario"), report.f("total_max_ms")), ("robotics", 4.0));
        assert!(report.f("missing").is_nan());
        assert!(Report::parse("no line here").is_none());
    }

    #[test]
    fn clocks_and_memory() {
        if cfg!(all(target_os = "linux", target_pointer_width = "64")) {
            assert!(thread_cpu_ms() >= 0.0 && process_cpu_ms() >= thread_cpu_ms() - 1.0);
            assert!(proc_status_kib("VmHWM").is_some_and(|k| k > 0));
        }
        assert!(proc_status_kib("NoSuchField").is_none());
    }
}
