//! Files of the model folders that declare one model in the same version and publication date.
//!
//! A folder tree may hold copies of a model (an unpacked release beside a checkout) or, worse, two different
//! files that both claim the same ModelUri, Version and PublicationDate. The loader never takes one of those
//! silently. Of the files that tie for the place the folder rule gives (`folders::ranked`):
//!
//! - files with the same content (byte for byte, or differing only in a UTF-8 byte order mark or CRLF line
//!   ends) are one model: the first by the folder rule is read, and nothing is said;
//! - of different files, one that holds every node of each of the others and more (the OPC Foundation tree's
//!   `Schema/Opc.Ua.NodeSet2.Services.xml` beside `Schema/Opc.Ua.NodeSet2.xml`) is read, and a note
//!   (NS0115; a warning with `--warn NS0115`) names the files. The choice is safe, so it is no warning: the
//!   whole tree would warn on every run. Taking the file that lacks nodes is how references end up dangling;
//! - different files otherwise: an error (NS0114) names them all and says how to choose. It cannot be
//!   demoted; so that the rest of the run can still say what it finds, the first by the folder rule (shorter
//!   path, then path order) is read, and the error says which.
//!
//! A file named on the command line is never among them: a named file that declares the model provides it,
//! and the model folders are not searched for that model at all. Naming one of the files (whether or not it
//! lies in a model folder) is therefore how a user chooses, and then nothing is said. Different versions, or
//! different publication dates, of one model are not ties: the newest that satisfies the requirement is read.

use super::folders::{defined_nodes, same_content, ties, Candidate, Seen};
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::parse::{self, Limits};
use crate::raw::RawNodeSet;
use crate::source::{FileId, SourceMap, Span};

/// The file the loader reads for a model after looking at its ties: a source already, and parsed.
pub(super) struct Pick {
    /// The parsed file (`None` if it does not parse; its diagnostics are reported).
    pub(super) set: Option<RawNodeSet>,
}

/// Looks at the files of `ranked` (the files of model `uri`, best first, the first satisfying the
/// requirement at `at`) that tie with the first, and says which to read when they differ (see the module).
/// `None` when no file ties with the first, or all that do have its content: read the first as usual.
pub(super) fn choose(
    uri: &str,
    ranked: &[&Candidate],
    at: Span,
    sources: &mut SourceMap,
    seen: &mut Seen,
    limits: &Limits,
    diags: &mut Diagnostics,
) -> Option<Pick> {
    let tied = ties(ranked, uri);
    let first = *ranked.first()?;
    if tied.is_empty() {
        return None;
    }
    // Each distinct content once, the first by the folder rule first.
    let mut distinct: Vec<(&Candidate, Vec<u8>)> = vec![(first, std::fs::read(&first.path).ok()?)];
    for c in tied {
        seen.add_path(c.id.clone());
        // A tie that cannot be read is not a choice: nothing of it could be loaded.
        let Ok(bytes) = std::fs::read(&c.path) else { continue };
        if !distinct.iter().any(|(_, b)| same_content(b, &bytes)) {
            distinct.push((c, bytes));
        }
    }
    if distinct.len() == 1 {
        return None;
    }
    seen.add_path(first.id.clone());
    let files: Vec<(&Candidate, Option<FileId>)> = distinct
        .into_iter()
        .map(|(c, bytes)| {
            let mut ignored = Diagnostics::new();
            let id = super::add_source(sources, c.path.clone(), c.path.display().to_string(), bytes, false, &mut ignored);
            (c, id)
        })
        .collect();
    let jobs: Vec<(FileId, &str)> = files.iter().filter_map(|(_, id)| id.map(|id| (id, sources.get(id).text.as_str()))).collect();
    let mut parsed = parse::parse_files(&jobs, limits).into_iter();
    let mut sets: Vec<(Option<RawNodeSet>, Diagnostics)> =
        files.iter().map(|(_, id)| if id.is_some() { parsed.next().expect("one result a job") } else { (None, Diagnostics::new()) }).collect();
    // The nodes of each file; a file that does not parse holds none for this comparison.
    let nodes: Vec<Option<std::collections::BTreeSet<_>>> =
        sets.iter().map(|(set, _)| set.as_ref().map(|s| defined_nodes(s, sources.get(s.file).text.as_str()))).collect();
    let holds_all = |j: usize| {
        let Some(mine) = &nodes[j] else { return false };
        nodes.iter().enumerate().all(|(k, other)| {
            k == j || other.as_ref().is_some_and(|o| o.len() < mine.len() && o.is_subset(mine))
        })
    };
    let superset = (0..files.len()).find(|&j| holds_all(j));
    let (v, d) = first.version_of(uri);
    let release = format!("version {}{}", v.as_deref().unwrap_or("(none)"), d.map(|d| format!(" published {d}")).unwrap_or_default());
    let names: Vec<String> = files.iter().map(|(c, _)| c.path.display().to_string()).collect();
    let listed = match names.as_slice() {
        [a, b] => format!("{a} and {b}"),
        more => more.join(", "),
    };
    let pick = superset.unwrap_or(0);
    let mut diag = match superset {
        Some(j) => {
            let others = nodes.iter().enumerate().filter(|&(k, _)| k != j).filter_map(|(_, n)| n.as_ref().map(|n| n.len())).max().unwrap_or(0);
            let more = nodes[j].as_ref().map_or(0, |n| n.len()) - others;
            Diagnostic::new(
                Code::ModelFilesDiffer,
                format!("{} different files in the model folders define model `{uri}` {release}: {listed}", files.len()),
            )
            .note(format!("{} is used: it defines every node the other{} define{}, and {more} more", names[j], plural(files.len() - 1), if files.len() == 2 { "s" } else { "" }))
        }
        None => Diagnostic::new(
            Code::AmbiguousModel,
            format!("{} different files in the model folders define model `{uri}` {release}: {listed}", files.len()),
        )
        .note("they differ, and none of them defines every node of the others; taking the wrong one leaves references dangling")
        .note(format!("{} is used for the rest of this run (the shorter path, then the first in path order)", names[0])),
    }
    .at(at)
    .with_span_label("required here");
    for ((set, _), name) in sets.iter().zip(&names) {
        if let Some(m) = set.as_ref().and_then(|s| s.models.iter().find(|m| m.uri == uri)) {
            diag = diag.label(m.span, format!("defined in {name}"));
        }
    }
    diags.push(diag.help(
        "name the file you mean on the command line (a named file wins over the model folders), or remove the others from the folders",
    ));
    let (set, said) = std::mem::take(&mut sets[pick]);
    diags.extend(said);
    Some(Pick { set })
}

fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}
