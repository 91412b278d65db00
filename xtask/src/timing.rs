//! Where the time of `cargo xtask test` went: one row per step (and per test binary), wall and CPU seconds.
//!
//! CPU is the user + system time of this process and of every child process it waited for (and of theirs),
//! from `getrusage(RUSAGE_SELF)` and `getrusage(RUSAGE_CHILDREN)` before and after the step. Steps run one
//! after another, so the deltas belong to the step. CPU above wall means the step used both cores.

use std::time::Instant;

/// How a step ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    Passed,
    Failed,
}

/// One row of the table.
#[derive(Clone, Debug)]
pub struct Row {
    pub name: String,
    pub wall: f64,
    pub cpu: f64,
    pub outcome: Outcome,
}

/// The rows so far, in the order the steps ran.
#[derive(Debug)]
pub struct Table {
    rows: Vec<Row>,
    start: Instant,
    cpu_start: f64,
}

/// CPU seconds (user + system) of this process and of its waited-for children so far.
pub fn cpu_seconds() -> f64 {
    fn of(who: libc::c_int) -> f64 {
        // SAFETY: getrusage writes one `rusage` into the zeroed struct we own; no other memory is touched.
        let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
        if unsafe { libc::getrusage(who, &mut usage) } != 0 {
            return 0.0;
        }
        let secs = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 / 1e6;
        secs(usage.ru_utime) + secs(usage.ru_stime)
    }
    of(libc::RUSAGE_SELF) + of(libc::RUSAGE_CHILDREN)
}

impl Default for Table {
    fn default() -> Self {
        Table { rows: Vec::new(), start: Instant::now(), cpu_start: cpu_seconds() }
    }
}

impl Table {
    /// Runs `step`, adds its row (failed when it returns an error) and returns its result.
    pub fn time<T>(&mut self, name: &str, step: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
        let (wall, cpu) = (Instant::now(), cpu_seconds());
        let result = step();
        let outcome = if result.is_ok() { Outcome::Passed } else { Outcome::Failed };
        self.push(Row { name: name.to_owned(), wall: wall.elapsed().as_secs_f64(), cpu: cpu_seconds() - cpu, outcome });
        result
    }

    /// Adds a row measured elsewhere (the build of xtask itself, before this process started).
    pub fn push(&mut self, row: Row) {
        self.rows.push(row);
    }

    #[cfg(test)]
    pub fn rows(&self) -> &[Row] {
        &self.rows
    }

    /// The table as text: the rows in the order they ran, the total, then the ten largest by CPU.
    pub fn render(&self) -> String {
        let total_wall = self.start.elapsed().as_secs_f64();
        let total_cpu = cpu_seconds() - self.cpu_start;
        let width = self.rows.iter().map(|r| r.name.len()).max().unwrap_or(0).max(24);
        let mut out = format!("{:<width$} {:>9} {:>9} {:>6} {:>6}  outcome\n", "step", "wall s", "cpu s", "cores", "wall%");
        let line = |name: &str, wall: f64, cpu: f64, outcome: &str| {
            let cores = if wall > 0.0 { cpu / wall } else { 0.0 };
            let share = if total_wall > 0.0 { 100.0 * wall / total_wall } else { 0.0 };
            format!("{name:<width$} {wall:>9.1} {cpu:>9.1} {cores:>6.2} {share:>5.1}%  {outcome}\n")
        };
        for r in &self.rows {
            out.push_str(&line(&r.name, r.wall, r.cpu, if r.outcome == Outcome::Passed { "ok" } else { "FAILED" }));
        }
        let failed = self.rows.iter().filter(|r| r.outcome == Outcome::Failed).count();
        let verdict = if failed == 0 { "ok".to_owned() } else { format!("{failed} FAILED") };
        out.push_str(&line("total (this process)", total_wall, total_cpu, &verdict));
        let mut largest: Vec<&Row> = self.rows.iter().collect();
        largest.sort_by(|a, b| b.cpu.total_cmp(&a.cpu));
        out.push_str("largest by CPU:");
        for r in largest.iter().take(10) {
            out.push_str(&format!(" {} {:.0} s;", r.name, r.cpu));
        }
        out.pop();
        out.push('\n');
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A step's CPU includes the CPU of the child processes it waited for, and a failed step is a row too.
    #[test]
    fn a_step_counts_its_childrens_cpu_and_its_failure() {
        let mut table = Table::default();
        table
            .time("busy child", || {
                let status = std::process::Command::new("sh")
                    .args(["-c", "i=0; while [ $i -lt 200000 ]; do i=$((i+1)); done"])
                    .status()
                    .map_err(|e| e.to_string())?;
                if status.success() { Ok(()) } else { Err(format!("{status}")) }
            })
            .expect("sh runs");
        let _ = table.time("failing", || Err::<(), _>("planted".to_owned()));
        let rows = table.rows();
        assert_eq!(rows.len(), 2);
        assert!(rows[0].cpu > 0.05, "the child's CPU is counted: {:?}", rows[0]);
        assert!(rows[0].cpu <= rows[0].wall * 2.5 + 0.05, "{:?}", rows[0]);
        assert_eq!((rows[0].outcome.clone(), rows[1].outcome.clone()), (Outcome::Passed, Outcome::Failed));
        let text = table.render();
        assert!(text.contains("busy child") && text.contains("FAILED") && text.contains("1 FAILED"), "{text}");
    }
}
