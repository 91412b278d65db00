//! The model folders: which NodeSet2 files they offer (known from a cheap scan of each file's header), which of
//! several files of one model the loader takes, and when two files are one file.
//!
//! The rule for choosing among the files of one ModelUri ([`ranked`]): the newest version first, then the
//! newest publication date, then the shorter path, then the path. The loader takes the first that satisfies
//! the requirement; [`find_model_files`] (for `verify`) takes the first. Files that tie on version and date
//! are one model when their contents are the same ([`same_content`]); when they differ, the loader reports it
//! (`load::duplicates`).

use crate::nodeid::{parse_node_id, NsRef};
use crate::raw::RawNodeSet;
use crate::source::{FileId, SourceMap};
use std::cmp::Ordering;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A model a file's header declares: ModelUri, Version and PublicationDate.
pub(super) type Declared = (String, Option<String>, Option<String>);

/// A file offered by a models folder, known from its header only.
#[derive(Clone, Debug)]
pub(super) struct Candidate {
    /// The path as found under the folder given (shown to the user).
    pub(super) path: PathBuf,
    /// The canonical path: two folders, or a folder and a named file, may reach one file by different paths.
    pub(super) id: PathBuf,
    pub(super) models: Vec<Declared>,
    /// For a file without `<Models>`: the first of its NamespaceUris, the namespace such files (the older
    /// specifications) define their nodes in.
    pub(super) own_namespace: Option<String>,
}

impl Candidate {
    /// The version and publication date the file declares for `uri` (none for a model it does not declare).
    pub(super) fn version_of(&self, uri: &str) -> (Option<String>, Option<String>) {
        self.models.iter().find(|m| m.0 == uri).map(|m| (m.1.clone(), m.2.clone())).unwrap_or_default()
    }
}

/// What [`scan_header`] reads of a NodeSet2 file: its declared models (URI, version, publication date)
/// and, when it declares none, the first of its NamespaceUris.
#[derive(Debug, PartialEq)]
pub(super) struct Header {
    pub(super) models: Vec<Declared>,
    pub(super) own_namespace: Option<String>,
}

/// The files of `index` that declare model `uri`, best first: the newest version, then the newest
/// publication date, then the shorter path, then the path (so the order never depends on the file system).
pub(super) fn ranked<'a>(index: &'a [Candidate], uri: &str) -> Vec<&'a Candidate> {
    let mut options: Vec<&Candidate> = index.iter().filter(|c| c.models.iter().any(|m| m.0 == uri)).collect();
    options.sort_by(|a, b| {
        let (va, da) = a.version_of(uri);
        let (vb, db) = b.version_of(uri);
        cmp_version(vb.as_deref(), va.as_deref())
            .then_with(|| db.cmp(&da))
            .then_with(|| a.path.as_os_str().len().cmp(&b.path.as_os_str().len()))
            .then_with(|| a.path.cmp(&b.path))
    });
    options
}

/// The files after the first of `ranked` that declare the same version and publication date of `uri` as it.
pub(super) fn ties<'a>(ranked: &[&'a Candidate], uri: &str) -> Vec<&'a Candidate> {
    let Some(first) = ranked.first() else { return Vec::new() };
    let (v, d) = first.version_of(uri);
    ranked[1..]
        .iter()
        .copied()
        .take_while(|c| {
            let (cv, cd) = c.version_of(uri);
            cmp_version(cv.as_deref(), v.as_deref()) == Ordering::Equal && cd == d
        })
        .collect()
}

/// Compares dotted versions numerically (`1.05.03` > `1.5.2`, `1.04` == `1.4.0`); absent is lowest.
pub fn cmp_version(a: Option<&str>, b: Option<&str>) -> Ordering {
    match (a, b) {
        (None, None) => Ordering::Equal,
        (None, Some(_)) => Ordering::Less,
        (Some(_), None) => Ordering::Greater,
        (Some(a), Some(b)) => {
            let pa: Vec<&str> = a.trim().split(['.', '-']).collect();
            let pb: Vec<&str> = b.trim().split(['.', '-']).collect();
            for i in 0..pa.len().max(pb.len()) {
                let x = pa.get(i).copied().unwrap_or("0");
                let y = pb.get(i).copied().unwrap_or("0");
                let o = match (x.parse::<u64>(), y.parse::<u64>()) {
                    (Ok(x), Ok(y)) => x.cmp(&y),
                    _ => x.cmp(y),
                };
                if o != Ordering::Equal {
                    return o;
                }
            }
            Ordering::Equal
        }
    }
}

/// A file's content as the loader compares it: without a UTF-8 byte order mark, and with CRLF line ends read
/// as LF (a copy saved on another system is the same file).
pub(super) fn normalized(bytes: &[u8]) -> impl Iterator<Item = u8> + '_ {
    let bytes = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF]).unwrap_or(bytes);
    bytes.iter().enumerate().filter(|&(i, &b)| !(b == b'\r' && bytes.get(i + 1) == Some(&b'\n'))).map(|(_, &b)| b)
}

/// Whether two files have the same content (see [`normalized`]): such files are one model, wherever they lie.
pub(super) fn same_content(a: &[u8], b: &[u8]) -> bool {
    fn strip(x: &[u8]) -> &[u8] {
        x.strip_prefix(&[0xEF, 0xBB, 0xBF]).unwrap_or(x)
    }
    let (sa, sb) = (strip(a), strip(b));
    // Without CRLF the normalised contents are the bytes themselves: compared at memcmp speed.
    if memchr::memmem::find(sa, b"\r\n").is_none() && memchr::memmem::find(sb, b"\r\n").is_none() {
        return sa == sb;
    }
    normalized(a).eq(normalized(b))
}

/// The length of a file's content as [`same_content`] compares it (without a byte order mark, CRLF counted
/// as one byte): files of different lengths differ, so only files of one length are compared. Counting the
/// line ends is a vectorised search; a digest of every byte cost more than the rest of reading ns0.
pub(super) fn normalized_len(bytes: &[u8]) -> usize {
    let bytes = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF]).unwrap_or(bytes);
    bytes.len() - memchr::memmem::find_iter(bytes, b"\r\n").count()
}

/// The canonical form of a path, for telling whether two paths are one file (the path itself when it
/// cannot be resolved).
pub(super) fn canonical(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

/// The files the loader has read, by canonical path and by content, so that it reads no file twice.
///
/// This is what bounds the loader's work: a file of the model folders is read only if it is not here, and
/// is put here when read, so each of the finitely many files is read at most once.
#[derive(Default)]
pub(super) struct Seen {
    paths: BTreeSet<PathBuf>,
    /// The files read, by the length of their content ([`normalized_len`]; equal content is confirmed byte by
    /// byte before it counts).
    lengths: BTreeMap<usize, Vec<FileId>>,
}

impl Seen {
    /// Records that the file at this canonical path was read.
    pub(super) fn add_path(&mut self, id: PathBuf) {
        self.paths.insert(id);
    }

    /// Records the content of a file that is now a source.
    pub(super) fn add_source(&mut self, file: FileId, sources: &SourceMap) {
        self.lengths.entry(normalized_len(sources.get(file).text.as_bytes())).or_default().push(file);
    }

    /// Whether the file at this canonical path was read.
    pub(super) fn has_path(&self, id: &Path) -> bool {
        self.paths.contains(id)
    }

    /// A file read before whose content is `bytes`, if any.
    pub(super) fn same_as(&self, bytes: &[u8], sources: &SourceMap) -> Option<FileId> {
        let ids = self.lengths.get(&normalized_len(bytes))?;
        ids.iter().copied().find(|&f| same_content(bytes, sources.get(f).text.as_bytes()))
    }
}

/// The nodes a parsed file defines, each as its namespace URI and identifier (so that files listing their
/// NamespaceUris in different orders compare equal); NodeIds that do not parse are left out.
pub(super) fn defined_nodes(set: &RawNodeSet, text: &str) -> BTreeSet<(String, crate::nodeid::Identifier)> {
    let uri = |i: u16| -> Option<String> {
        match i {
            0 => Some(super::NS0_URI.to_string()),
            i => set.namespace_uris.get(usize::from(i) - 1).map(|u| u.value.clone()),
        }
    };
    set.nodes
        .iter()
        .filter_map(|n| {
            let raw = parse_node_id(n.node_id.get(text)).ok()?;
            let ns = match raw.ns {
                NsRef::Index(i) => uri(i)?,
                NsRef::Uri(u) => u,
            };
            Some((ns, raw.id))
        })
        .collect()
}

/// For each of `uris`, the NodeSet2 file under `dirs` that defines that model in its newest version (the
/// choice the loader makes for a required model without a version); URIs no file defines are left out.
pub fn find_model_files(dirs: &[PathBuf], uris: &[String]) -> BTreeMap<String, PathBuf> {
    let index = scan_dirs(dirs);
    uris.iter().filter_map(|uri| ranked(&index, uri).first().map(|c| (uri.clone(), c.path.clone()))).collect()
}

/// The models the header of a NodeSet2 file declares (URIs), without parsing the rest; for a file without
/// `<Models>`, the model it implies for its first namespace (as the loader implies one, and prefers it to a
/// file of a models folder); `None` if the file cannot be read or is not a NodeSet2 file.
pub fn models_of_file(path: &Path) -> Option<Vec<String>> {
    let header = scan_header(path)?;
    if header.models.is_empty() {
        return Some(header.own_namespace.into_iter().collect());
    }
    Some(header.models.into_iter().map(|(uri, _, _)| uri).collect())
}

/// The models the header of a NodeSet2 file declares, each as its ModelUri, Version and PublicationDate, read
/// as the loader reads them when it looks for required models; `None` as for [`models_of_file`].
pub fn declared_models(path: &Path) -> Option<Vec<Declared>> {
    scan_header(path).map(|h| h.models)
}

/// Lists every NodeSet2 file under the folders with the models its header declares, each file once however
/// many of the folders reach it.
pub(super) fn scan_dirs(dirs: &[PathBuf]) -> Vec<Candidate> {
    let mut paths = Vec::new();
    for d in dirs {
        walk(d, &mut paths);
    }
    paths.sort();
    paths.dedup();
    let mut ids = BTreeSet::new();
    paths
        .into_iter()
        .filter_map(|p| {
            let id = canonical(&p);
            if !ids.insert(id.clone()) {
                return None;
            }
            scan_header(&p).map(|h| Candidate { path: p, id, models: h.models, own_namespace: h.own_namespace })
        })
        .collect()
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let p = e.path();
        let Ok(ft) = e.file_type() else { continue };
        if ft.is_dir() {
            walk(&p, out);
        } else if p.extension().and_then(|x| x.to_str()).is_some_and(|x| x.eq_ignore_ascii_case("xml")) {
            out.push(p);
        }
    }
}

/// How much of a file [`scan_header`] looks at, at most. Real NodeSet2 files close `<Models>` within the
/// first few KiB.
pub(super) const HEADER_LIMIT: usize = 256 * 1024;

/// Reads the `<Models>` element of a file without parsing the rest (and, for a file that declares no
/// models within [`HEADER_LIMIT`], its first NamespaceUri).
///
/// A models folder is scanned once per compile and may hold hundreds of files, so the file is read in
/// growing chunks and reading stops as soon as `</Models>` has been seen. The answer is the one the first
/// [`HEADER_LIMIT`] bytes give: reading stops early only when the bytes read so far already contain
/// everything the tests below look for (the first `<Models>` and the `</Models>` after it, and
/// `UANodeSet`), and reading more cannot change where those are first found.
pub(super) fn scan_header(path: &Path) -> Option<Header> {
    use std::io::Read;
    let mut f = std::fs::File::open(path).ok()?;
    let mut buf: Vec<u8> = Vec::new();
    // The `<Models>` element ends within the first 4 KiB in every file of the pinned vendor folder (at
    // 3.4 KiB at most): most files take one short read.
    let mut chunk = 4 * 1024;
    loop {
        let want = (buf.len() + chunk).min(HEADER_LIMIT);
        let mut n = buf.len();
        buf.resize(want, 0);
        while n < want {
            let k = f.read(&mut buf[n..]).ok()?;
            if k == 0 {
                break;
            }
            n += k;
        }
        let at_end = n < want || n == HEADER_LIMIT;
        buf.truncate(n);
        if at_end || header_complete(&buf) {
            break;
        }
        chunk *= 2;
    }
    // The tests look for ASCII text only, and a lossy reading as UTF-8 keeps every ASCII byte where it is
    // among the others: searching the bytes finds what searching that reading finds, without converting
    // the whole prefix (once per chunk, that conversion was most of a scan). Only the `<Models>` element
    // (or, without one, the whole prefix) is read as text, lossily as before.
    if find(&buf, b"UANodeSet").is_none() {
        return None;
    }
    let Some(start) = find(&buf, b"<Models>") else {
        return Some(Header { models: Vec::new(), own_namespace: first_namespace_uri(&String::from_utf8_lossy(&buf)) });
    };
    let end = find(&buf[start..], b"</Models>")? + start + "</Models>".len();
    let models = String::from_utf8_lossy(&buf[start..end]);
    let mut reader = quick_xml::Reader::from_str(&models);
    let mut out = Vec::new();
    loop {
        match reader.read_event() {
            Ok(quick_xml::events::Event::Start(e)) | Ok(quick_xml::events::Event::Empty(e)) => {
                if e.local_name().as_ref() == b"Model" {
                    let get = |k: &[u8]| {
                        e.attributes()
                            .flatten()
                            .find(|a| a.key.local_name().as_ref() == k)
                            .and_then(|a| a.unescape_value().ok().map(|v| v.into_owned()))
                    };
                    if let Some(uri) = get(b"ModelUri") {
                        out.push((uri, get(b"Version"), get(b"PublicationDate")));
                    }
                }
            }
            Ok(quick_xml::events::Event::Eof) | Err(_) => break,
            _ => {}
        }
    }
    Some(Header { models: out, own_namespace: None })
}

/// The first `<Uri>` of the `<NamespaceUris>` in a header's text.
fn first_namespace_uri(text: &str) -> Option<String> {
    let start = text.find("<NamespaceUris>")?;
    let end = text[start..].find("</NamespaceUris>")? + start;
    let from = text[start..end].find("<Uri>")? + start + "<Uri>".len();
    let to = text[from..end].find("</Uri>")? + from;
    let uri = quick_xml::escape::unescape(text[from..to].trim()).ok()?.into_owned();
    (!uri.is_empty()).then_some(uri)
}

/// Whether a prefix of a file already decides [`scan_header`]'s answer (see there).
fn header_complete(prefix: &[u8]) -> bool {
    find(prefix, b"UANodeSet").is_some() && find(prefix, b"<Models>").is_some_and(|start| find(&prefix[start..], b"</Models>").is_some())
}

/// Where `needle` first occurs in `haystack`.
fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    memchr::memmem::find(haystack, needle)
}
