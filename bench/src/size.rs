//! The size of generated Rust: files, lines and bytes, per module and in total, which the rust scenario
//! and the peer report beside their times.

use std::fs;
use std::path::Path;

use super::Step;

/// Files, lines and bytes of some generated Rust.
#[derive(Clone, Copy, Default, PartialEq)]
pub(super) struct Size {
    pub(super) files: usize,
    pub(super) lines: usize,
    pub(super) bytes: usize,
}

impl std::ops::Add for Size {
    type Output = Size;
    fn add(self, o: Size) -> Size {
        Size {
            files: self.files + o.files,
            lines: self.lines + o.lines,
            bytes: self.bytes + o.bytes,
        }
    }
}

/// Sizes per module, in `NAMESPACES` order.
pub(super) type Sizes = Vec<(&'static str, Size)>;

/// The sum of the sizes of `modules`.
pub(super) fn sum(sizes: &Sizes, modules: &[&str]) -> Size {
    sizes
        .iter()
        .filter(|(m, _)| modules.contains(m))
        .fold(Size::default(), |a, (_, s)| a + *s)
}

/// Files, lines and bytes of the `.rs` files under `dir`.
pub(super) fn count_rs(dir: &Path) -> Step<Size> {
    let mut size = Size::default();
    let entries =
        fs::read_dir(dir).map_err(|e| format!("cannot read {}: {e}", dir.display()))?;
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            size = size + count_rs(&p)?;
        } else if p.extension().is_some_and(|x| x == "rs") {
            let text = fs::read_to_string(&p)
                .map_err(|e| format!("cannot read {}: {e}", p.display()))?;
            size = size
                + Size {
                    files: 1,
                    lines: text.lines().count(),
                    bytes: text.len(),
                };
        }
    }
    Ok(size)
}
