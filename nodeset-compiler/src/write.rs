//! Writing generated trees: only what changed, atomically, or compared in check mode.
//!
//! Emitters return files in memory ([`OutFile`]). [`write_tree`] owns one output folder completely: in
//! write mode it builds the new tree beside the old one (unchanged files are hard-linked, so their
//! modification times stay and builds stay incremental), then swaps the two folders with renames. A failure
//! before the swap leaves the old folder untouched; nothing is ever half written. In check mode it writes
//! nothing and lists what differs.
//!
//! [`write_trees`] does the same for several folders that belong together (the Rust and the Modelica
//! output of one model): it builds every new tree before it replaces any folder, and puts back the folders
//! it replaced if a later replacement fails, so a failure never leaves one folder new and the other old.
//!
//! A process killed between the two renames of a swap leaves the previous tree as `.<name>.old-<pid>`
//! beside the folder; that is the one state no error path can clean up.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

/// One generated file, relative to its output folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OutFile {
    /// The path, relative to the output folder.
    pub path: PathBuf,
    /// The text of the file.
    pub contents: String,
}

/// Whether [`write_tree`] changes the folder or only compares it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Make the folder hold exactly the generated files.
    Write,
    /// Write nothing; only report what differs.
    Check,
}

/// What a write or check found.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Report {
    /// Generated files the folder lacks, relative to it.
    pub added: Vec<PathBuf>,
    /// Files whose contents differ from the generated ones.
    pub changed: Vec<PathBuf>,
    /// Files in the folder that are not generated.
    pub removed: Vec<PathBuf>,
    /// How many files are already identical.
    pub unchanged: usize,
}

impl Report {
    /// Whether the folder already holds exactly the generated files.
    pub fn is_clean(&self) -> bool {
        self.added.is_empty() && self.changed.is_empty() && self.removed.is_empty()
    }

    /// One line per new, changed or removed file (`  new: PATH`), each path joined to `dir`.
    pub fn describe(&self, dir: &Path) -> String {
        let mut s = String::new();
        for (what, list) in [("new", &self.added), ("changed", &self.changed), ("removed", &self.removed)] {
            for p in list {
                s.push_str(&format!("  {what}: {}\n", dir.join(p).display()));
            }
        }
        s
    }
}

/// Files below `dir`, relative to it, sorted.
fn existing(dir: &Path) -> Vec<PathBuf> {
    fn walk(base: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = fs::read_dir(dir) else { return };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(base, &p, out);
            } else if let Ok(rel) = p.strip_prefix(base) {
                out.push(rel.to_path_buf());
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Compares `files` with the folder `dir` and, in write mode, makes the folder hold exactly `files`.
pub fn write_tree(dir: &Path, files: &[OutFile], mode: Mode) -> Result<Report, String> {
    let mut reports = write_trees(&[(dir.to_path_buf(), files.to_vec())], mode)?;
    Ok(reports.remove(0))
}

/// [`write_tree`] for several folders at once, all or nothing: every new tree is built completely beside its
/// folder before any folder is replaced, and if replacing one fails, the ones already replaced are put
/// back. On any error every folder holds what it held before.
pub fn write_trees(trees: &[(PathBuf, Vec<OutFile>)], mode: Mode) -> Result<Vec<Report>, String> {
    let mut reports = Vec::new();
    for (dir, files) in trees {
        reports.push(compare(dir, files)?);
    }
    if mode == Mode::Check {
        return Ok(reports);
    }
    // Stage every tree that changed.
    let mut staged: Vec<Staged> = Vec::new();
    for ((dir, files), report) in trees.iter().zip(&reports) {
        if report.is_clean() {
            continue;
        }
        match stage(dir, files) {
            Ok(s) => staged.push(s),
            Err(e) => {
                for s in &staged {
                    let _ = fs::remove_dir_all(&s.tmp);
                }
                return Err(e);
            }
        }
    }
    // Swap them in; on a failure, undo the swaps done so far.
    for i in 0..staged.len() {
        if let Err(e) = swap(&staged[i]) {
            for s in staged[..i].iter().rev() {
                unswap(s);
            }
            for s in &staged {
                let _ = fs::remove_dir_all(&s.tmp);
            }
            return Err(e);
        }
    }
    for s in &staged {
        if s.had_old {
            let _ = fs::remove_dir_all(&s.old);
        }
    }
    Ok(reports)
}

/// What differs between `files` and the folder `dir`.
fn compare(dir: &Path, files: &[OutFile]) -> Result<Report, String> {
    let mut report = Report::default();
    let wanted: BTreeSet<&Path> = files.iter().map(|f| f.path.as_path()).collect();
    if wanted.len() != files.len() {
        return Err(format!("two generated files of {} have the same path", dir.display()));
    }
    for f in files {
        match fs::read(dir.join(&f.path)) {
            Ok(old) if old == f.contents.as_bytes() => report.unchanged += 1,
            Ok(_) => report.changed.push(f.path.clone()),
            Err(_) => report.added.push(f.path.clone()),
        }
    }
    for old in existing(dir) {
        if !wanted.contains(old.as_path()) {
            report.removed.push(old);
        }
    }
    Ok(report)
}

/// A new tree built beside the folder it replaces.
struct Staged {
    dir: PathBuf,
    /// The new tree.
    tmp: PathBuf,
    /// Where the old folder goes while the new one moves in.
    old: PathBuf,
    had_old: bool,
}

fn stage(dir: &Path, files: &[OutFile]) -> Result<Staged, String> {
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    fs::create_dir_all(parent).map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
    let name = dir.file_name().ok_or_else(|| format!("{} has no folder name", dir.display()))?.to_string_lossy().into_owned();
    let tmp = parent.join(format!(".{name}.new-{}", std::process::id()));
    let old = parent.join(format!(".{name}.old-{}", std::process::id()));
    let _ = fs::remove_dir_all(&tmp);
    let build = || -> Result<(), String> {
        fs::create_dir_all(&tmp).map_err(|e| format!("cannot create {}: {e}", tmp.display()))?;
        for f in files {
            let dest = tmp.join(&f.path);
            if let Some(d) = dest.parent() {
                fs::create_dir_all(d).map_err(|e| format!("cannot create {}: {e}", d.display()))?;
            }
            let src = dir.join(&f.path);
            let same = fs::read(&src).map(|b| b == f.contents.as_bytes()).unwrap_or(false);
            if !(same && fs::hard_link(&src, &dest).is_ok()) {
                fs::write(&dest, &f.contents).map_err(|e| format!("cannot write {}: {e}", dest.display()))?;
            }
        }
        Ok(())
    };
    if let Err(e) = build() {
        let _ = fs::remove_dir_all(&tmp);
        return Err(e);
    }
    Ok(Staged { dir: dir.to_path_buf(), tmp, old, had_old: dir.exists() })
}

/// The old folder moves aside and the new one takes its place.
fn swap(s: &Staged) -> Result<(), String> {
    if s.had_old {
        rename(&s.dir, &s.old).map_err(|e| format!("cannot move {} aside: {e}", s.dir.display()))?;
    }
    if let Err(e) = rename(&s.tmp, &s.dir) {
        if s.had_old {
            let _ = rename(&s.old, &s.dir);
        }
        return Err(format!("cannot move the new tree into {}: {e}", s.dir.display()));
    }
    Ok(())
}

/// Undoes a [`swap`]: the new tree moves back to its temporary name (to be removed), the old one returns.
fn unswap(s: &Staged) {
    let _ = fs::rename(&s.dir, &s.tmp);
    if s.had_old {
        let _ = fs::rename(&s.old, &s.dir);
    }
}

/// `fs::rename`, which tests can make fail at the n-th call to exercise the recovery paths.
fn rename(from: &Path, to: &Path) -> std::io::Result<()> {
    #[cfg(test)]
    if tests::FAIL_RENAME.with(|f| {
        let n = f.get();
        f.set(n.saturating_sub(1));
        n == 1
    }) {
        return Err(std::io::Error::other("injected failure"));
    }
    fs::rename(from, to)
}

#[cfg(test)]
mod tests {
    use super::*;

    thread_local! {
        /// When set to n > 0, the n-th call of [`rename`] on this thread fails.
        pub(super) static FAIL_RENAME: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
    }

    /// Every file below `dir` with its bytes, and nothing else beside `dir` in its parent.
    fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
        existing(dir).into_iter().map(|p| (p.clone(), fs::read(dir.join(&p)).unwrap())).collect()
    }

    fn siblings(base: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(base).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    }

    /// Two folders are written all or nothing: a failure while building the second tree, or while swapping
    /// either in, leaves both as they were and no temporary folder behind.
    #[test]
    fn several_trees_are_written_all_or_nothing() {
        let base = std::env::temp_dir().join(format!("nodeset-write-trees-{}", std::process::id()));
        let _ = fs::remove_dir_all(&base);
        let (a, b) = (base.join("a"), base.join("b"));
        let old = vec![(a.clone(), vec![f("x.rs", "old x")]), (b.clone(), vec![f("y.mo", "old y")])];
        write_trees(&old, Mode::Write).unwrap();
        let before = (snapshot(&a), snapshot(&b), siblings(&base));
        let new = |b_files: Vec<OutFile>| vec![(a.clone(), vec![f("x.rs", "new x")]), (b.clone(), b_files)];

        // The second tree cannot be built: `z` is a file and a folder.
        let err = write_trees(&new(vec![f("z", "file"), f("z/w.mo", "below a file")]), Mode::Write).unwrap_err();
        assert!(err.contains("cannot"), "{err}");
        assert_eq!((snapshot(&a), snapshot(&b), siblings(&base)), before, "a failed build changed something");

        // Each rename of the swap fails in turn: 1 = moving a aside, 2 = a into place, 3 = b aside, 4 = b in.
        for n in 1..=4 {
            FAIL_RENAME.with(|c| c.set(n));
            let r = write_trees(&new(vec![f("y.mo", "new y")]), Mode::Write);
            FAIL_RENAME.with(|c| c.set(0));
            assert!(r.is_err(), "rename {n} did not fail");
            assert_eq!((snapshot(&a), snapshot(&b), siblings(&base)), before, "failing rename {n} changed something");
        }

        write_trees(&new(vec![f("y.mo", "new y")]), Mode::Write).unwrap();
        assert_eq!(fs::read_to_string(a.join("x.rs")).unwrap(), "new x");
        assert_eq!(fs::read_to_string(b.join("y.mo")).unwrap(), "new y");
        assert_eq!(siblings(&base), ["a", "b"]);
        let _ = fs::remove_dir_all(&base);
    }

    fn f(p: &str, c: &str) -> OutFile {
        OutFile { path: p.into(), contents: c.into() }
    }

    #[test]
    fn writes_only_changes_and_checks() {
        let base = std::env::temp_dir().join(format!("nodeset-write-test-{}", std::process::id()));
        let dir = base.join("out");
        let _ = fs::remove_dir_all(&base);
        let r = write_tree(&dir, &[f("a.txt", "1"), f("sub/b.txt", "2")], Mode::Write).unwrap();
        assert_eq!(r.added.len(), 2);
        let r = write_tree(&dir, &[f("a.txt", "1"), f("sub/b.txt", "2")], Mode::Check).unwrap();
        assert!(r.is_clean());
        fs::write(dir.join("stray.txt"), "x").unwrap();
        let r = write_tree(&dir, &[f("a.txt", "1"), f("sub/b.txt", "3")], Mode::Check).unwrap();
        assert_eq!(r.changed, vec![PathBuf::from("sub/b.txt")]);
        assert_eq!(r.removed, vec![PathBuf::from("stray.txt")]);
        assert_eq!(fs::read_to_string(dir.join("sub/b.txt")).unwrap(), "2", "check mode writes nothing");
        write_tree(&dir, &[f("a.txt", "1"), f("sub/b.txt", "3")], Mode::Write).unwrap();
        assert_eq!(fs::read_to_string(dir.join("sub/b.txt")).unwrap(), "3");
        assert!(!dir.join("stray.txt").exists());
        assert!(write_tree(&dir, &[f("a.txt", "1")], Mode::Check).unwrap().removed.len() == 1);
        let _ = fs::remove_dir_all(&base);
    }
}
