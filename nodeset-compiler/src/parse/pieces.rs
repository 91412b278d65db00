//! Parsing several files, and large files in pieces, on all cores.
//!
//! A large file is cut between two top-level nodes into pieces that are read at the same time, and the
//! pieces are joined into the [`RawNodeSet`] the whole file gives. A cut is a guess, made on the raw text:
//! a node element (`<UAObject`, `<UAVariable`, ...) after white space after a `>`. The reading of the piece
//! before a cut checks it: the cut is right when that piece ends there with only the root element open.
//! The reading that starts at a right cut is the reading the whole file gets from there (same events, same
//! spans, same diagnostics, with the end tag of the root checked as quick-xml checks it), so the joined
//! result is the whole file's. Where a guess was wrong, or a piece stops at an error, the file is read on
//! from the last right cut to its end in one piece, which gives the whole file's result there too.

use super::{Fatal, OuterRoot, Parser, Part, PartEnd};
use crate::diag::Diagnostics;
use crate::parse::Limits;
use crate::raw::{NodeClass, RawNodeSet, ValueRef};
use crate::source::{FileId, Span};
use std::ops::Range;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Pieces are at least this long: below it, a thread costs more than it saves.
const MIN_PIECE: usize = 256 * 1024;

/// Parses files, each with its diagnostics, on all cores; the results are those of [`super::parse`] on
/// each file, in the order of `files`.
pub fn parse_files(files: &[(FileId, &str)], limits: &Limits) -> Vec<(Option<RawNodeSet>, Diagnostics)> {
    let threads = crate::par::cores();
    let total: usize = files.iter().map(|(_, t)| t.len()).sum();
    // About three pieces per thread, so that pieces of different sizes even out across the threads.
    let piece_len = (total / (threads * 3)).max(MIN_PIECE);
    let plans: Vec<Plan> =
        files.iter().map(|&(file, text)| if threads > 1 { plan(file, text, piece_len) } else { Plan::whole(text) }).collect();

    // Every piece of every file is a task; the longest go first.
    let mut tasks: Vec<(usize, usize)> =
        plans.iter().enumerate().flat_map(|(f, p)| (0..p.cuts.len() - 1).map(move |i| (f, i))).collect();
    let len = |&(f, i): &(usize, usize)| plans[f].cuts[i + 1] - plans[f].cuts[i];
    tasks.sort_by_key(|t| std::cmp::Reverse(len(t)));
    let run = |&(f, i): &(usize, usize)| {
        let (file, text) = files[f];
        read_piece(file, text, &plans[f], i, limits)
    };
    let mut done: Vec<Option<Read>> = (0..tasks.len()).map(|_| None).collect();
    if threads == 1 || tasks.len() == 1 {
        for (k, t) in tasks.iter().enumerate() {
            done[k] = Some(run(t));
        }
    } else {
        let next = AtomicUsize::new(0);
        let work = || {
            let mut out = Vec::new();
            loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(t) = tasks.get(k) else { return out };
                out.push((k, run(t)));
            }
        };
        let results: Vec<Vec<(usize, Read)>> = std::thread::scope(|s| {
            let helpers: Vec<_> = (1..threads.min(tasks.len())).map(|_| s.spawn(work)).collect();
            let mut all = vec![work()];
            all.extend(helpers.into_iter().map(|h| h.join().expect("a parsing thread panicked")));
            all
        });
        for (k, r) in results.into_iter().flatten() {
            done[k] = Some(r);
        }
    }

    // Back in file order: the pieces of each file, in order.
    let mut per_file: Vec<Vec<Option<Read>>> = plans.iter().map(|p| (0..p.cuts.len() - 1).map(|_| None).collect()).collect();
    for ((f, i), r) in tasks.into_iter().zip(done) {
        per_file[f][i] = r;
    }
    per_file
        .into_iter()
        .zip(plans)
        .zip(files)
        .map(|((reads, plan), &(file, text))| join(file, text, &plan, reads.into_iter().map(|r| r.expect("every task ran")).collect(), limits))
        .collect()
}

/// Where a file is cut, and what its pieces need to know about the root element.
struct Plan<'a> {
    /// Byte offsets: 0, the cuts, the length of the file.
    cuts: Vec<usize>,
    root: Option<(OuterRoot<'a>, Span)>,
}

impl Plan<'_> {
    fn whole(text: &str) -> Plan<'_> {
        Plan { cuts: vec![0, text.len()], root: None }
    }
}

/// The reading of one piece: what it gave (or `Err` when it stopped at an error) and its diagnostics.
type Read = (Result<Part, Fatal>, Diagnostics);

fn read_piece(file: FileId, text: &str, plan: &Plan, i: usize, limits: &Limits) -> Read {
    read_from(file, text, plan, plan.cuts[i]..plan.cuts[i + 1], limits)
}

/// Reads `text[range]`: from the start of the document, or from a cut with the root element open.
fn read_from(file: FileId, text: &str, plan: &Plan, range: Range<usize>, limits: &Limits) -> Read {
    let mut diags = Diagnostics::new();
    let start = range.start;
    let mut p = Parser::new(file, text, range, limits, &mut diags);
    let result = match plan.root {
        Some((root, span)) if start > 0 => p.piece(root, span),
        _ => p.document(),
    };
    (result, diags)
}

/// Joins the pieces of a file, reading on from the last right cut where a piece does not fit.
fn join(file: FileId, text: &str, plan: &Plan, reads: Vec<Read>, limits: &Limits) -> (Option<RawNodeSet>, Diagnostics) {
    let last = reads.len() - 1;
    // Room for all nodes in the first piece's list, so that each later piece is copied once.
    let nodes: usize = reads.iter().map(|(r, _)| r.as_ref().map_or(0, |p| p.set.nodes.len())).sum();
    let mut joined: Option<(Part, Diagnostics)> = None;
    for (i, (result, diags)) in reads.into_iter().enumerate() {
        // A piece that is not the last fits when it ended at its cut; the last one always fits, as its
        // start is a right cut (the piece before it ended there) and it ends with the file.
        let fits = i == last || matches!(&result, Ok(part) if part.end == PartEnd::Boundary);
        let (result, diags) = if fits {
            (result, diags)
        } else if i == 0 {
            read_from(file, text, &Plan::whole(text), 0..text.len(), limits)
        } else {
            read_from(file, text, plan, plan.cuts[i]..text.len(), limits)
        };
        let (mut part, mut all) = match joined.take() {
            None => match result {
                Ok(mut part) => {
                    part.set.nodes.reserve(nodes.saturating_sub(part.set.nodes.len()));
                    (part, diags)
                }
                Err(Fatal) => return (None, diags),
            },
            Some((mut part, mut all)) => {
                all.extend(diags);
                match result {
                    Ok(next) => {
                        append(&mut part, next);
                        (part, all)
                    }
                    Err(Fatal) => return (None, all),
                }
            }
        };
        if !fits || i == last {
            part.end = PartEnd::Document;
            return (Some(part.set), std::mem::take(&mut all));
        }
        joined = Some((part, all));
    }
    unreachable!("the last piece returns")
}

/// Appends a later piece of a file to the pieces before it, as if one reading had read both.
fn append(part: &mut Part, next: Part) {
    let set = &mut part.set;
    let Part { set: mut more, namespace_uris_seen, server_uris_seen, end } = next;
    if namespace_uris_seen {
        set.namespace_uris = more.namespace_uris;
        part.namespace_uris_seen = true;
    }
    if server_uris_seen {
        set.server_uris = more.server_uris;
        part.server_uris_seen = true;
    }
    set.models.append(&mut more.models);
    set.aliases.append(&mut more.aliases);
    let offset = set.values.append(more.values);
    let refs = set.references.len() as u32;
    // The nodes move with their indices into the values and references adjusted, in one pass over them.
    set.nodes.extend(more.nodes.drain(..).map(|mut node| {
        if let Some(v) = &mut node.value {
            *v = ValueRef(v.0 + offset);
        }
        node.references.start += refs;
        node.references.end += refs;
        node
    }));
    set.references.append(&mut more.references);
    part.end = end;
}

/// Plans the cuts of a file into pieces of about `piece_len` bytes.
fn plan(file: FileId, text: &str, piece_len: usize) -> Plan<'_> {
    let n = text.len() / piece_len;
    let Some(root) = (n >= 2).then(|| outer_root(file, text)).flatten() else { return Plan::whole(text) };
    let mut cuts = vec![0];
    for k in 1..n {
        let from = (k * text.len() / n).max(*cuts.last().expect("starts with 0") + 1).max(root.0.start + 1);
        if let Some(cut) = find_cut(text, from) {
            if cut + MIN_PIECE / 2 < text.len() && cut > *cuts.last().expect("starts with 0") {
                cuts.push(cut);
            }
        }
    }
    cuts.push(text.len());
    if cuts.len() == 2 {
        return Plan::whole(text);
    }
    Plan { cuts, root: Some(root) }
}

/// The root element of a file, as the parser would find it: the first start tag after the prolog (the
/// declaration, comments, processing instructions and white space). `None` for anything unusual; the file
/// is then read in one piece, which reports what is wrong.
fn outer_root(file: FileId, text: &str) -> Option<(OuterRoot<'_>, Span)> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(text);
    loop {
        let before = reader.buffer_position() as usize;
        match reader.read_event().ok()? {
            Event::Start(e) | Event::Empty(e) => {
                let after = reader.buffer_position() as usize;
                let tag = text.get(before..after)?;
                let qname_len = e.name().into_inner().len();
                let qname = tag.get(1..1 + qname_len)?;
                let name = qname.rsplit_once(':').map_or(qname, |(_, n)| n);
                return Some((OuterRoot { qname, name, start: before }, Span::new(file, before, after)));
            }
            Event::Decl(_) | Event::Comment(_) | Event::PI(_) => {}
            Event::Text(t) if t.iter().all(u8::is_ascii_whitespace) => {}
            _ => return None,
        }
    }
}

/// The first place at or after `from` that looks like the start of a top-level node: a node element
/// after white space after a `>`.
fn find_cut(text: &str, from: usize) -> Option<usize> {
    let bytes = text.as_bytes();
    let mut at = from;
    while let Some(i) = text.get(at..)?.find("<UA") {
        let cut = at + i;
        at = cut + 3;
        let name_end = bytes[cut + 1..].iter().position(|b| b.is_ascii_whitespace() || *b == b'>' || *b == b'/')?;
        let name = &text[cut + 1..cut + 1 + name_end];
        if NodeClass::from_element(name).is_none() {
            continue;
        }
        let before = bytes[..cut].iter().rposition(|b| !b.is_ascii_whitespace());
        if before.is_some_and(|b| bytes[b] == b'>') {
            return Some(cut);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Parses with the given cuts (and no thread), as `parse_files` does with the cuts it plans.
    fn parse_cut(text: &str, cuts: &[usize], limits: &Limits) -> (Option<RawNodeSet>, Diagnostics) {
        let file = FileId(0);
        let mut all = vec![0];
        let mut cuts: Vec<usize> = cuts.iter().copied().filter(|&c| c > 0 && c < text.len()).collect();
        cuts.sort();
        all.extend(cuts);
        all.push(text.len());
        all.dedup();
        let plan = match outer_root(file, text) {
            Some(root) if all.len() > 2 => Plan { cuts: all, root: Some(root) },
            _ => Plan::whole(text),
        };
        let reads = (0..plan.cuts.len() - 1).map(|i| read_piece(file, text, &plan, i, limits)).collect();
        join(file, text, &plan, reads, limits)
    }

    fn whole(text: &str, limits: &Limits) -> (Option<RawNodeSet>, Diagnostics) {
        let mut d = Diagnostics::new();
        let set = crate::parse::parse(FileId(0), text, limits, &mut d);
        (set, d)
    }

    fn node(i: usize) -> String {
        match i % 5 {
            0 => format!("<UAObject NodeId=\"ns=1;i={i}\" BrowseName=\"1:O{i}\"><DisplayName>O{i}</DisplayName><References><Reference ReferenceType=\"HasComponent\" IsForward=\"false\">i=85</Reference></References></UAObject>"),
            1 => format!("<UAVariable NodeId=\"ns=1;i={i}\" BrowseName=\"1:V{i}\" DataType=\"Int32\"><DisplayName>V &amp; {i}</DisplayName><Value><ListOfInt32 xmlns=\"http://opcfoundation.org/UA/2008/02/Types.xsd\"><Int32>{i}</Int32><Int32>2</Int32></ListOfInt32></Value></UAVariable>"),
            2 => format!("<UAObject NodeId=\"ns=1;i={i}\" BrowseName=\"1:E{i}\" />"),
            3 => format!("<!-- a comment with a node in it:\n  <UAObject NodeId=\"x\"> --><UAVariable NodeId=\"ns=1;i={i}\" BrowseName=\"1:S{i}\"><Value><String>a\r\nb</String></Value></UAVariable>"),
            _ => format!("<UADataType NodeId=\"ns=1;i={i}\" BrowseName=\"1:T{i}\"><Definition Name=\"T\"><Field Name=\"F\" DataType=\"i=6\"/></Definition></UADataType>"),
        }
    }

    fn document(body: &str, tail: &str) -> String {
        format!(
            "<?xml version=\"1.0\" encoding=\"utf-8\"?>\r\n<UANodeSet xmlns=\"http://opcfoundation.org/UA/2011/03/UANodeSet.xsd\" LastModified=\"2020\">\r\n\
             <NamespaceUris><Uri>http://x/</Uri></NamespaceUris>\r\n<Models><Model ModelUri=\"http://x/\"/></Models>\r\n\
             <Aliases><Alias Alias=\"Int32\">i=6</Alias><Alias Alias=\"HasComponent\">i=47</Alias></Aliases>\r\n{body}{tail}"
        )
    }

    /// Every way of cutting a file gives what reading it whole gives.
    #[test]
    fn cut_files_join_into_what_whole_files_give() {
        let nodes: Vec<String> = (0..12).map(node).collect();
        let body = nodes.join("\r\n  ");
        let bad_value = nodes[..6].join("\n") + "\n<UAVariable NodeId=\"ns=1;i=99\" BrowseName=\"1:B\"><Value><Int32>&bogus;</Int32></Value></UAVariable>\n" + &nodes[6..].join("\n");
        let late_header = nodes[..6].join("\n") + "\n<NamespaceUris><Uri>http://y/</Uri></NamespaceUris><Aliases><Alias Alias=\"X\">i=1</Alias></Aliases><Models><Model ModelUri=\"http://y/\"/></Models><Odd/>\n" + &nodes[6..].join("\n");
        let files = [
            document(&body, "\r\n</UANodeSet>\r\n"),
            document(&body, "\r\n</UANodeSetX>\r\n"),
            document(&body, "\r\n"),
            document(&body, "\r\n</UANodeSet>\r\n<UAObject NodeId=\"i=1\" BrowseName=\"A\"/>\r\n"),
            document(&body, "\r\n</UANodeSet>\r\n</UAObject>\r\n"),
            document(&body, "\r\n</UANodeSet>\r\njunk"),
            document(&format!("{body}</UAObject>"), "\r\n</UANodeSet>"),
            document(&bad_value, "\n</UANodeSet>"),
            document(&late_header, "\n</UANodeSet>"),
            document(&body.replacen("</UAVariable>", "</UAVariableX>", 2), "\n</UANodeSet>"),
            document(&body.replacen("<DisplayName>O5", "<DisplayName BrowseName=\"a\" BrowseName=\"b\">O5", 1), "\n</UANodeSet>"),
        ];
        let limits = Limits::default();
        for (f, text) in files.iter().enumerate() {
            let expected = format!("{:?}", whole(text, &limits));
            // Cuts at every node start and a few other places: one cut, and every third position together.
            let mut candidates: Vec<usize> = text.match_indices("<UA").map(|(i, _)| i).collect();
            candidates.extend(text.match_indices("<Value").map(|(i, _)| i));
            candidates.extend([1, text.len() / 3, text.len() - 1]);
            for &c in &candidates {
                let got = format!("{:?}", parse_cut(text, &[c], &limits));
                assert!(got == expected, "file {f}, cut at {c}:\n{}\n--- got\n{got}\n--- expected\n{expected}", &text[c.saturating_sub(20)..(c + 20).min(text.len())]);
            }
            let every: Vec<usize> = candidates.iter().copied().step_by(3).collect();
            let got = format!("{:?}", parse_cut(text, &every, &limits));
            assert!(got == expected, "file {f}, cuts at {every:?}");
            // Two cuts, so that a piece in the middle can be the one that does not fit.
            for &a in candidates.iter().step_by(2) {
                for &b in candidates.iter().skip(1).step_by(2) {
                    let got = format!("{:?}", parse_cut(text, &[a, b], &limits));
                    assert!(got == expected, "file {f}, cuts at {a} and {b}");
                }
            }
        }
    }

    #[test]
    fn cuts_are_planned_at_node_starts() {
        let nodes: Vec<String> = (0..4000).map(node).collect();
        let text = document(&nodes.join("\r\n  "), "\r\n</UANodeSet>\r\n");
        let plan = plan(FileId(0), &text, 200_000);
        assert!(plan.cuts.len() > 3, "{:?}", plan.cuts);
        for &c in &plan.cuts[1..plan.cuts.len() - 1] {
            assert!(text[c..].starts_with("<UA"), "{}", &text[c..c + 20]);
        }
        let expected = format!("{:?}", whole(&text, &Limits::default()));
        let got = parse_files(&[(FileId(0), &text)], &Limits::default()).pop().unwrap();
        assert_eq!(format!("{got:?}"), expected);
    }
}
