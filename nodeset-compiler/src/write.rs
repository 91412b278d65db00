//! Writing generated trees: only what changed, atomically, or compared in check mode.
//!
//! Emitters return files in memory ([`OutFile`]). [`write_tree`] owns one output folder completely: in
//! write mode it builds the new tree beside the old one (unchanged files are hard-linked, so their
//! modification times stay and builds stay incremental), then swaps the two folders with renames. A failure
//! before the swap leaves the old folder untouched; nothing is ever half written. In check mode it writes
//! nothing and lists what differs.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

/// One generated file, relative to its output folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OutFile {
    pub path: PathBuf,
    pub contents: String,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Write,
    Check,
}

/// What a write or check found.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Report {
    pub added: Vec<PathBuf>,
    pub changed: Vec<PathBuf>,
    pub removed: Vec<PathBuf>,
    pub unchanged: usize,
}

impl Report {
    pub fn is_clean(&self) -> bool {
        self.added.is_empty() && self.changed.is_empty() && self.removed.is_empty()
    }

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
    let mut report = Report::default();
    let wanted: BTreeSet<&Path> = files.iter().map(|f| f.path.as_path()).collect();
    if wanted.len() != files.len() {
        return Err("two generated files have the same path".into());
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
    if mode == Mode::Check || report.is_clean() {
        return Ok(report);
    }
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
    // Swap: the old folder moves aside, the new one takes its place, the old one is removed.
    let had_old = dir.exists();
    if had_old {
        fs::rename(dir, &old).map_err(|e| {
            let _ = fs::remove_dir_all(&tmp);
            format!("cannot move {} aside: {e}", dir.display())
        })?;
    }
    if let Err(e) = fs::rename(&tmp, dir) {
        if had_old {
            let _ = fs::rename(&old, dir);
        }
        let _ = fs::remove_dir_all(&tmp);
        return Err(format!("cannot move the new tree into {}: {e}", dir.display()));
    }
    if had_old {
        let _ = fs::remove_dir_all(&old);
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

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
