//! Small helpers shared by the xtask subcommands.

use std::fs;
use std::io::Write;
use std::path::Path;

pub use process_support::workspace::{cargo, display_path, target_dir, workspace_root};

/// Writes `bytes` to `path` so that readers see either the old or the new
/// content, never a partial file.
///
/// The bytes go to a hidden temporary file in the same directory, which is
/// flushed to disk and then renamed over the destination; a rename within one
/// directory is atomic on the file systems we use.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let dir = path
        .parent()
        .ok_or_else(|| format!("{} has no parent directory", path.display()))?;
    let file_name = path
        .file_name()
        .ok_or_else(|| format!("{} has no file name", path.display()))?
        .to_string_lossy();
    let temp = dir.join(format!(".{file_name}.tmp-{}", std::process::id()));

    let result = (|| {
        let mut file = fs::File::create(&temp)
            .map_err(|e| format!("cannot create {}: {e}", display_path(&temp)))?;
        file.write_all(bytes)
            .and_then(|()| file.sync_all())
            .map_err(|e| format!("cannot write {}: {e}", display_path(&temp)))?;
        fs::rename(&temp, path).map_err(|e| {
            format!(
                "cannot rename {} to {}: {e}",
                display_path(&temp),
                display_path(path)
            )
        })
    })();
    if result.is_err() {
        // Best effort: the original error is more useful than a failure to clean up.
        let _ = fs::remove_file(&temp);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn write_atomically_replaces_content_and_leaves_no_temp_file() {
        let dir = std::env::temp_dir().join(format!("xtask-util-test-{}", std::process::id()));
        fs::create_dir_all(&dir).expect("create test dir");
        let target = dir.join("file.txt");
        fs::write(&target, b"old content that is longer").expect("seed file");

        write_atomically(&target, b"new").expect("atomic write");

        assert_eq!(fs::read(&target).expect("read back"), b"new");
        let leftovers: Vec<_> = fs::read_dir(&dir)
            .expect("list test dir")
            .filter_map(|entry| entry.ok())
            .map(|entry| entry.file_name())
            .filter(|name| name != "file.txt")
            .collect();
        assert!(leftovers.is_empty(), "unexpected files: {leftovers:?}");
        fs::remove_dir_all(&dir).expect("clean up test dir");
    }
}
