//! The loader: from files and model folders to an ordered set of parsed files with one namespace table.
//!
//! The user names files; the models they require are taken from among them or found in model folders
//! (searched recursively, indexed by ModelUri from a cheap scan of each file's `<Models>` header, see
//! `folders`). A named file always provides its models, even when it also lies in a folder. Of several
//! versions of one model in the folders, the newest that satisfies the requirement wins (then the newest
//! publication date, the shorter path, the path); files that tie on version and date are one model if their
//! content is the same, and are otherwise reported (`duplicates`). Each file is read at most once, which is
//! what bounds the work (see the termination argument in [`load`]). Files are then ordered so that a model
//! comes after everything it requires (ties broken by ModelUri, so input order never matters), and every
//! file's namespace indices are mapped onto the global table.

use crate::fxhash::FxHashMap;
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::nodeid::{parse_node_id, looks_like_node_id, NodeId, NsRef, RawNodeId};
use crate::parse::{self, Limits};
use crate::raw::{RawModel, RawNodeSet};
use crate::source::{FileId, SourceFile, SourceMap, Span, Spanned};
use std::cmp::Ordering;
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

mod duplicates;
mod folders;

pub use folders::{cmp_version, declared_models, find_model_files, models_of_file};
use folders::{canonical, Candidate, Seen};

/// The URI of the OPC UA base namespace, always namespace index 0.
pub const NS0_URI: &str = "http://opcfoundation.org/UA/";

/// What to load.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Folders searched recursively for required models.
    pub model_dirs: Vec<PathBuf>,
    /// Size and nesting limits for parsing each file.
    pub limits: Limits,
}

/// A model a loaded file defines.
#[derive(Clone, Debug)]
pub struct ModelInfo {
    /// The ModelUri: the URI of the namespace the model defines.
    pub uri: String,
    /// The `Version` attribute, if any (`None` for a model implied by a file without `<Models>`).
    pub version: Option<String>,
    /// The `PublicationDate` attribute as written, if any.
    pub publication_date: Option<String>,
    /// The `ModelVersion` attribute, if any.
    pub model_version: Option<String>,
    /// The file that defines the model.
    pub file: FileId,
    /// Global namespace index of the model.
    pub ns: u16,
    /// The models it requires, from its `<RequiredModel>` elements.
    pub required: Vec<RequiredInfo>,
    /// The `<RolePermissions>` of the `<Model>` element: the namespace's DefaultRolePermissions.
    pub default_role_permissions: Vec<crate::raw::RawRolePermission>,
    /// The `AccessRestrictions` of the `<Model>` element: the namespace's DefaultAccessRestrictions.
    pub default_access_restrictions: Option<u16>,
    /// The `<Model>` element (the file's root element for an implied model).
    pub span: Span,
}

/// A requirement of one model on another: a `<RequiredModel>` element, or one the loader adds (the base namespace, and the namespaces a file without `<Models>` refers to).
#[derive(Clone, Debug)]
pub struct RequiredInfo {
    /// The ModelUri of the required model.
    pub uri: String,
    /// The lowest version accepted, if any.
    pub version: Option<String>,
    /// The `PublicationDate` required, if any: checked when the loaded version equals the required one.
    pub publication_date: Option<String>,
    /// The `<RequiredModel>` element (the file's root element for a requirement the loader adds).
    pub span: Span,
}

/// One parsed file with its namespace mapping and alias table.
#[derive(Debug)]
pub struct LoadedFile {
    /// The parsed file.
    pub raw: RawNodeSet,
    /// Local namespace index to global index (`ns_map[0] == 0`).
    pub ns_map: Vec<u16>,
    /// The file's aliases: each name to its target NodeId text (the first declaration of a name wins).
    pub aliases: FxHashMap<String, Spanned<String>>,
}

impl LoadedFile {
    /// Expands an alias or parses a NodeId written in this file, mapped to the global namespace table.
    pub fn resolve_node_id(&self, text: &Spanned<String>, namespaces: &[String]) -> Result<NodeId, Diagnostic> {
        resolve_node_id_in(&self.ns_map, &self.aliases, text, namespaces)
    }
}

/// Expands an alias or parses a NodeId written in a file with this namespace map and alias table.
pub fn resolve_node_id_in(
    ns_map: &[u16],
    aliases: &FxHashMap<String, Spanned<String>>,
    text: &Spanned<String>,
    namespaces: &[String],
) -> Result<NodeId, Diagnostic> {
    resolve_node_id_str(ns_map, aliases, &text.value, text.span, namespaces)
}

/// [`resolve_node_id_in`] for a string read at `span`.
pub fn resolve_node_id_str(
    ns_map: &[u16],
    aliases: &FxHashMap<String, Spanned<String>>,
    text: &str,
    span: Span,
    namespaces: &[String],
) -> Result<NodeId, Diagnostic> {
    {
        let s = text.trim();
        let (id_text, via_alias) = match aliases.get(s) {
            Some(t) => (t.value.as_str(), Some(t)),
            None => (s, None),
        };
        if via_alias.is_none() && !looks_like_node_id(id_text) {
            let mut d = Diagnostic::new(Code::UnknownAlias, format!("`{s}` is neither a declared alias nor a NodeId"))
                .at(span)
                .with_span_label("unknown alias");
            // A file with very many aliases gets no suggestion: the search is per unknown name, and over
            // thousands of aliases it made thousands of unknown names quadratic (8,000 took 48 s).
            let near = if aliases.len() <= MAX_SUGGESTION_CANDIDATES { nearest(s, aliases.keys().map(String::as_str)) } else { None };
            d = match near {
                Some(n) => d.help(format!("did you mean the alias `{n}`? Otherwise declare it in <Aliases>")),
                None => d.help("declare it in <Aliases> (<Alias Alias=\"Name\">i=...</Alias>) or write the NodeId"),
            };
            return Err(d);
        }
        let raw = parse_node_id(id_text).map_err(|why| {
            let mut d = Diagnostic::new(Code::MalformedNodeId, format!("malformed NodeId `{id_text}`: {why}"));
            if let Some(t) = via_alias {
                d = d.at(t.span).label(span, format!("used through alias `{s}` here"));
            } else {
                d = d.at(span);
            }
            d.help("NodeIds are written i=123, s=Name, g=GUID or b=Base64, with an optional ns=N; or nsu=URI; prefix")
        })?;
        let ns = match raw.ns {
            NsRef::Index(i) => match ns_map.get(i as usize) {
                Some(&g) => g,
                None => {
                    return Err(Diagnostic::new(
                        Code::UnknownNamespaceIndex,
                        format!("namespace index {i} is not declared in this file's NamespaceUris"),
                    )
                    .at(via_alias.map(|t| t.span).unwrap_or(span))
                    .with_span_label(format!("ns={i}"))
                    .note(format!("this file declares {} namespace URI(s)", ns_map.len() - 1))
                    .help("add the namespace's URI to <NamespaceUris> at that position"))
                }
            },
            NsRef::Uri(u) => match namespaces.iter().position(|n| *n == u) {
                Some(g) => g as u16,
                None => {
                    return Err(Diagnostic::new(
                        Code::UnknownNamespaceUri,
                        format!("namespace `{u}` is not a loaded model or declared namespace"),
                    )
                    .at(span)
                    .help("load the model that defines this namespace (see --models)"))
                }
            },
        };
        Ok(NodeId { ns, id: raw.id })
    }
}

/// Everything loaded, in dependency order.
#[derive(Debug)]
pub struct Loaded {
    /// Every file read, named or found in a models folder, for spans and rendering.
    pub sources: SourceMap,
    /// Parsed files, each after the files it requires.
    pub files: Vec<LoadedFile>,
    /// The global namespace table: index 0 is the OPC UA namespace.
    pub namespaces: Vec<String>,
    /// Every model the files define, declared or implied, in the order of [`Loaded::files`].
    pub models: Vec<ModelInfo>,
}

impl Loaded {
    /// The loaded file with id `id`, if it is one of [`Loaded::files`].
    pub fn file(&self, id: FileId) -> Option<&LoadedFile> {
        self.files.iter().find(|f| f.raw.file == id)
    }

    /// The model that defines global namespace `ns`, if any.
    pub fn model_of_namespace(&self, ns: u16) -> Option<&ModelInfo> {
        self.models.iter().find(|m| m.ns == ns)
    }
}

/// A source of input: a file on disk or text held in memory (tests, fuzzing, build scripts).
pub enum Input {
    /// A file to read.
    Path(PathBuf),
    /// Text held in memory.
    Text {
        /// The name shown in diagnostics, also used as the file's path.
        name: String,
        /// The file's contents.
        text: String,
    },
}

/// Loads the named inputs and the models they require.
pub fn load(inputs: Vec<Input>, opts: &LoadOptions, diags: &mut Diagnostics) -> Loaded {
    let mut sources = SourceMap::new();
    // The named files are read one after the other, then parsed all at once (on all cores); what is said
    // about each goes into the diagnostics in the order the files were named.
    let mut said: Vec<Diagnostics> = Vec::new();
    let mut texts: Vec<(usize, FileId)> = Vec::new();
    // Every file read, so that none is read twice (see the termination argument below).
    let mut seen = Seen::default();
    // While the named files are read and parsed, another thread scans the model folders and reads the
    // best file of the OPC UA base model there, which nearly every run goes on to need (every file requires
    // it): see [`Early`]. On one core, nothing is done early.
    let early_wanted = !opts.model_dirs.is_empty() && crate::par::cores() > 1;
    let (early, parsed_at) = std::thread::scope(|s| {
        let early = early_wanted.then(|| s.spawn(|| Early::gather(&opts.model_dirs)));
        let t_read = crate::timing::span("read named files");
        for input in inputs {
            let mut d = Diagnostics::new();
            let (path, display, bytes) = match input {
                Input::Path(p) => match std::fs::read(&p) {
                    Ok(b) => {
                        seen.add_path(canonical(&p));
                        (p.clone(), p.display().to_string(), b)
                    }
                    Err(e) => {
                        d.push(
                            Diagnostic::new(Code::Io, format!("cannot read {}: {}", p.display(), io_reason(&e)))
                                .help("check the path; folders of required models go after --models"),
                        );
                        said.push(d);
                        continue;
                    }
                },
                Input::Text { name, text } => (PathBuf::from(&name), name, text.into_bytes()),
            };
            if let Some(id) = add_source(&mut sources, path, display, bytes, true, &mut d) {
                seen.add_source(id, &sources);
                texts.push((said.len(), id));
            }
            said.push(d);
        }
        drop(t_read);
        let t_parse = crate::timing::span("parse named files");
        let jobs: Vec<(FileId, &str)> = texts.iter().map(|&(_, id)| (id, sources.get(id).text.as_str())).collect();
        let mut parsed_at: Vec<Option<RawNodeSet>> = (0..said.len()).map(|_| None).collect();
        for (&(i, _), (set, d)) in texts.iter().zip(parse::parse_files(&jobs, &opts.limits)) {
            said[i].extend(d);
            parsed_at[i] = set;
        }
        drop(t_parse);
        (early.map(|h| h.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))), parsed_at)
    });
    let (mut index, mut prefetched) = match early {
        Some(e) => (Some(e.index), e.ns0),
        None => (None, None),
    };
    for d in said {
        diags.extend(d);
    }
    let mut parsed: Vec<RawNodeSet> = parsed_at.into_iter().flatten().collect();

    // Models provided by the named files.
    let mut provided: BTreeMap<String, FileId> = BTreeMap::new();
    for set in &parsed {
        for m in &set.models {
            if let Some(&other) = provided.get(&m.uri) {
                if other != set.file {
                    let first = parsed.iter().find(|s| s.file == other).and_then(|s| s.models.iter().find(|x| x.uri == m.uri));
                    let mut d = Diagnostic::new(Code::DuplicateModel, format!("model `{}` is defined by two input files", m.uri))
                        .at(m.span)
                        .with_span_label("defined again here");
                    if let Some(f) = first {
                        d = d.label(f.span, "first defined here");
                    }
                    diags.push(d.help("pass only one version of each model; the others belong in a --models folder"));
                }
                continue;
            }
            provided.insert(m.uri.clone(), set.file);
        }
        if set.models.is_empty() {
            diags.push(
                Diagnostic::new(Code::NoModel, "the file declares no <Models>; its nodes are loaded but it cannot be required by others")
                    .at(set.root_span)
                    .help("add <Models><Model ModelUri=\"...\" Version=\"...\" PublicationDate=\"...\"/></Models>"),
            );
        }
    }

    // A named file without <Models> implies one model per namespace it defines nodes in (unless a declared
    // model or an earlier file provides it), and requires the namespaces of its NamespaceUris it only refers
    // to: they are found like RequiredModels, any version (see `implied_model`).
    let mut implied: BTreeMap<String, FileId> = BTreeMap::new();
    let mut implied_requires: BTreeMap<FileId, Vec<String>> = BTreeMap::new();
    for set in &parsed {
        if set.models.is_empty() {
            imply_models(set, sources.get(set.file).text.as_str(), &mut provided, &mut implied, &mut implied_requires);
        }
    }

    // Resolve requirements transitively, from the named files and from the models folders.
    //
    // Why this loop ends: the queue holds indices of `parsed`, and an index is pushed once, when its file
    // joins `parsed`: a named file at the start, or a file of the model folders just read. A folder file is
    // read only if `seen` holds neither its canonical path nor its content, and its path goes into `seen`
    // before it is parsed (`read_new`, and `duplicates::choose` for the files it reads). The folders hold
    // finitely many files (`index`, scanned once), so there are at most (named files + folder files) passes,
    // each over the finitely many requirements of one file; a requirement costs at most one read of each
    // folder file. Requirements that form cycles, files named and also found in a folder, and copies of a
    // file under other paths all end at `seen`. (Before `seen`, a named file without <Models> whose first
    // NamespaceUri it only refers to found itself in the folder as that namespace's file, read itself again,
    // and so on without end.)
    let mut queue: Vec<usize> = (0..parsed.len()).collect();
    let mut checked: BTreeSet<(String, FileId)> = BTreeSet::new();
    while let Some(i) = queue.pop() {
        let set_file = parsed[i].file;
        let mut reqs: Vec<(RequiredInfo, bool)> = Vec::new();
        for m in &parsed[i].models {
            for r in &m.required {
                reqs.push((
                    RequiredInfo { uri: r.uri.clone(), version: r.version.clone(), publication_date: r.publication_date.clone(), span: r.span },
                    true,
                ));
            }
        }
        for uri in implied_requires.get(&set_file).into_iter().flatten() {
            reqs.push((RequiredInfo { uri: uri.clone(), version: None, publication_date: None, span: parsed[i].root_span }, false));
        }
        // Every file needs the OPC UA namespace, whether or not it says so.
        let is_ns0 = parsed[i].models.iter().any(|m| m.uri == NS0_URI);
        if !is_ns0 && !reqs.iter().any(|(r, _)| r.uri == NS0_URI) {
            reqs.push((RequiredInfo { uri: NS0_URI.into(), version: None, publication_date: None, span: parsed[i].root_span }, false));
        }
        for (req, explicit) in reqs {
            if !checked.insert((req.uri.clone(), set_file)) {
                continue;
            }
            if let Some(&fid) = provided.get(&req.uri) {
                // An implied model has no version to check.
                if let Some(m) = parsed.iter().find(|s| s.file == fid).and_then(|set| set.models.iter().find(|m| m.uri == req.uri)) {
                    let requirer = &sources.get(set_file).display;
                    check_version(&req, requirer, m.version.as_deref(), m.publication_date.as_deref(), &sources.get(fid).display, diags);
                }
                continue;
            }
            let idx = index.get_or_insert_with(|| {
                let _t = crate::timing::span("scan model folders");
                folders::scan_dirs(&opts.model_dirs)
            });
            let options = folders::ranked(idx, &req.uri);
            // A file without <Models> (an older specification) that refers to a namespace takes, first, a file
            // of the same kind whose own namespace that is, from its own folder if there is one there: the
            // release it was written against, not the newest model of that URI.
            let requirer_dir = sources.get(set_file).path.parent().map(Path::to_path_buf);
            let mut same_kind: Vec<&Candidate> = if explicit || !parsed[i].models.is_empty() {
                Vec::new()
            } else {
                idx.iter().filter(|c| c.models.is_empty() && c.own_namespace.as_deref() == Some(req.uri.as_str())).collect()
            };
            same_kind.sort_by_key(|c| (c.path.parent() != requirer_dir.as_deref(), c.path.as_os_str().len(), c.path.clone()));
            let mut older: Option<(&Candidate, Vec<u8>)> = None;
            for c in same_kind {
                if let Some(bytes) = read_new(c, &mut seen, &sources, &mut prefetched, req.span, diags) {
                    older = Some((c, bytes));
                    break;
                }
            }
            let satisfies = |c: &Candidate| {
                req.version.is_none() || cmp_version(c.version_of(&req.uri).0.as_deref(), req.version.as_deref()) != Ordering::Less
            };
            let requirer = sources.get(set_file).display.clone();
            let loaded: Option<RawNodeSet> = match (older, options.first().copied().filter(|c| satisfies(c))) {
                (Some((c, bytes)), _) => {
                    let display = c.path.display().to_string();
                    read_and_parse(&mut sources, c.path.clone(), display, bytes, false, &opts.limits, diags)
                }
                (None, Some(c)) => {
                    let (v, d) = c.version_of(&req.uri);
                    check_version(&req, &requirer, v.as_deref(), d.as_deref(), &c.path.display().to_string(), diags);
                    match duplicates::choose(&req.uri, &options, req.span, &mut sources, &mut seen, &opts.limits, diags) {
                        Some(pick) => pick.set,
                        None => {
                            // A file read before provides its models, so the folder's best file for a model not
                            // provided is new unless it failed to parse (then nothing is read again).
                            let Some(bytes) = read_new(c, &mut seen, &sources, &mut prefetched, req.span, diags) else { continue };
                            let display = c.path.display().to_string();
                            read_and_parse(&mut sources, c.path.clone(), display, bytes, false, &opts.limits, diags)
                        }
                    }
                }
                (None, None) if !options.is_empty() => {
                    // The newest file of that model is too old: said as when a file already read is (whether a
                    // file was read first depends on the order requirements are met, which must not show).
                    let best = options[0];
                    let (v, d) = best.version_of(&req.uri);
                    check_version(&req, &requirer, v.as_deref(), d.as_deref(), &best.path.display().to_string(), diags);
                    continue;
                }
                (None, None) => {
                    if !explicit && req.uri != NS0_URI {
                        // An implied requirement not found: the file's references into that namespace are
                        // reported where they are written.
                        continue;
                    }
                    let looked = if opts.model_dirs.is_empty() {
                        "no --models folder was given".to_string()
                    } else {
                        format!(
                            "looked in the named files and in {} ({} NodeSet2 files)",
                            opts.model_dirs.iter().map(|d| d.display().to_string()).collect::<Vec<_>>().join(", "),
                            idx.len()
                        )
                    };
                    let msg = if explicit {
                        format!("required model `{}` is not available", req.uri)
                    } else {
                        format!("the OPC UA base model `{}` is not available", req.uri)
                    };
                    diags.push(
                        Diagnostic::new(Code::MissingModel, msg)
                            .at(req.span)
                            .with_span_label(if explicit { "required here" } else { "every NodeSet requires the base model" })
                            .note(looked)
                            .help("name the file that defines this model, or add the folder holding it with --models DIR"),
                    );
                    continue;
                }
            };
            match loaded {
                Some(set) => {
                    seen.add_source(set.file, &sources);
                    for m in &set.models {
                        provided.entry(m.uri.clone()).or_insert(set.file);
                    }
                    if set.models.is_empty() {
                        imply_models(&set, sources.get(set.file).text.as_str(), &mut provided, &mut implied, &mut implied_requires);
                    }
                    parsed.push(set);
                    queue.push(parsed.len() - 1);
                }
                // Do not try this model again for every file that requires it.
                None => {
                    provided.insert(req.uri.clone(), FileId(u32::MAX));
                }
            }
        }
    }

    let _t = crate::timing::span("order and namespace table");
    // Order files by requirement, ties by model URI then file name, never by input order.
    let order = topo_order(&parsed, &sources, &implied, &implied_requires, diags);
    let mut files_sorted: Vec<RawNodeSet> = Vec::with_capacity(parsed.len());
    let mut slots: Vec<Option<RawNodeSet>> = parsed.into_iter().map(Some).collect();
    for i in order {
        files_sorted.push(slots[i].take().expect("each file once"));
    }

    // The namespace table.
    let mut namespaces: Vec<String> = vec![NS0_URI.to_string()];
    let intern = |uri: &str, namespaces: &mut Vec<String>| -> u16 {
        match namespaces.iter().position(|n| n == uri) {
            Some(i) => i as u16,
            None => {
                namespaces.push(uri.to_string());
                (namespaces.len() - 1) as u16
            }
        }
    };
    for set in &files_sorted {
        for m in &set.models {
            intern(&m.uri, &mut namespaces);
        }
    }
    for set in &files_sorted {
        for u in &set.namespace_uris {
            intern(&u.value, &mut namespaces);
        }
    }

    let mut models: Vec<ModelInfo> = Vec::new();
    let mut files = Vec::new();
    for set in files_sorted {
        let mut ns_map = vec![0u16];
        for u in &set.namespace_uris {
            ns_map.push(intern(&u.value, &mut namespaces));
        }
        for m in &set.models {
            models.push(model_info(m, set.file, intern(&m.uri, &mut namespaces)));
        }
        for (uri, _) in implied.iter().filter(|(_, &f)| f == set.file) {
            models.push(implied_model(uri, set.file, set.root_span, intern(uri, &mut namespaces)));
        }
        let mut aliases: FxHashMap<String, Spanned<String>> = FxHashMap::with_capacity_and_hasher(set.aliases.len(), Default::default());
        for a in &set.aliases {
            if let Some(prev) = aliases.get(&a.alias) {
                if prev.value != a.target.value {
                    diags.push(
                        Diagnostic::new(Code::DuplicateAlias, format!("alias `{}` is declared twice with different targets", a.alias))
                            .at(a.span)
                            .label(prev.span, format!("first declared as {}", prev.value))
                            .help("keep one declaration"),
                    );
                }
                continue;
            }
            aliases.insert(a.alias.clone(), a.target.clone());
        }
        files.push(LoadedFile { raw: set, ns_map, aliases });
    }
    Loaded { sources, files, namespaces, models }
}

/// A file without `<Models>` implies one model per namespace it defines nodes in (unless a declared model or
/// an earlier file provides it), and requires the namespaces of its NamespaceUris it only refers to.
fn imply_models(
    set: &RawNodeSet,
    text: &str,
    provided: &mut BTreeMap<String, FileId>,
    implied: &mut BTreeMap<String, FileId>,
    implied_requires: &mut BTreeMap<FileId, Vec<String>>,
) {
    let defined = defined_namespaces(set, text);
    for uri in &defined {
        if *uri != NS0_URI && !provided.contains_key(*uri) {
            provided.insert(uri.to_string(), set.file);
            implied.insert(uri.to_string(), set.file);
        }
    }
    let referred = set.namespace_uris.iter().map(|u| u.value.as_str()).filter(|u| *u != NS0_URI && !defined.contains(u));
    implied_requires.insert(set.file, referred.map(str::to_string).collect());
}

/// The namespaces of `NamespaceUris` in which `set` defines nodes (a numeric or string `ns=N` NodeId), in
/// the order of that list.
fn defined_namespaces<'a>(set: &'a RawNodeSet, text: &str) -> Vec<&'a str> {
    let mut used = vec![false; set.namespace_uris.len() + 1];
    for node in &set.nodes {
        let ns = match node.node_id.numeric_node_id() {
            Some((ns, _)) => Some(ns),
            None => match parse_node_id(node.node_id.get(text)) {
                Ok(RawNodeId { ns: NsRef::Index(i), .. }) => Some(i),
                _ => None,
            },
        };
        if let Some(slot) = ns.and_then(|i| used.get_mut(usize::from(i))) {
            *slot = true;
        }
    }
    set.namespace_uris.iter().enumerate().filter(|(i, _)| used[i + 1]).map(|(_, u)| u.value.as_str()).collect()
}

/// The model a named file without `<Models>` implies for a namespace it defines nodes in: no version, so
/// that the file's nodes are generated like a declared model's (NS0109 says the file declares none). The
/// namespaces of its NamespaceUris it only refers to are looked for as requirements of any version, in the
/// named files and then the model folders; one not found is not reported as such (the references into it
/// are, where they are written).
fn implied_model(uri: &str, file: FileId, span: Span, ns: u16) -> ModelInfo {
    ModelInfo {
        uri: uri.to_string(),
        version: None,
        publication_date: None,
        model_version: None,
        file,
        ns,
        required: Vec::new(),
        default_role_permissions: Vec::new(),
        default_access_restrictions: None,
        span,
    }
}

fn model_info(m: &RawModel, file: FileId, ns: u16) -> ModelInfo {
    ModelInfo {
        uri: m.uri.clone(),
        version: m.version.clone(),
        publication_date: m.publication_date.clone(),
        model_version: m.model_version.clone(),
        file,
        ns,
        required: m
            .required
            .iter()
            .map(|r| RequiredInfo { uri: r.uri.clone(), version: r.version.clone(), publication_date: r.publication_date.clone(), span: r.span })
            .collect(),
        default_role_permissions: m.role_permissions.clone(),
        default_access_restrictions: m.access_restrictions,
        span: m.span,
    }
}

/// What the loader does early, on another thread, while the named files are read and parsed: the scan of
/// the model folders, and the read of the file the loader would take there for the OPC UA base model.
/// Both are what the loader would do later anyway (the folders are scanned at the first requirement the
/// named files do not meet, and every file requires the base model); the read is used only if the loader
/// goes on to read that very file ([`read_new`]), so nothing the loader decides depends on it.
struct Early {
    index: Vec<Candidate>,
    ns0: Option<Prefetched>,
}

/// A file of the model folders read early: its canonical path and what reading it gave.
struct Prefetched {
    id: PathBuf,
    bytes: std::io::Result<Vec<u8>>,
}

impl Early {
    fn gather(dirs: &[PathBuf]) -> Early {
        let index = folders::scan_dirs(dirs);
        let ns0 = folders::ranked(&index, NS0_URI).first().map(|c| Prefetched { id: c.id.clone(), bytes: std::fs::read(&c.path) });
        Early { index, ns0 }
    }
}

fn read_and_parse(
    sources: &mut SourceMap,
    path: PathBuf,
    display: String,
    bytes: Vec<u8>,
    named: bool,
    limits: &Limits,
    diags: &mut Diagnostics,
) -> Option<RawNodeSet> {
    let id = {
        let _t = crate::timing::span("decode required file");
        add_source(sources, path, display, bytes, named, diags)?
    };
    let _t = crate::timing::span("parse required file");
    let (set, d) = parse::parse_files(&[(id, sources.get(id).text.as_str())], limits).pop().expect("one file, one result");
    diags.extend(d);
    set
}

/// Reads a file of the model folders unless it was read before, under any path or with the same content
/// (then `None`): what bounds the loader's work. The file counts as read from here on, whatever comes of it.
fn read_new(
    c: &Candidate,
    seen: &mut Seen,
    sources: &SourceMap,
    prefetched: &mut Option<Prefetched>,
    at: Span,
    diags: &mut Diagnostics,
) -> Option<Vec<u8>> {
    if seen.has_path(&c.id) {
        return None;
    }
    seen.add_path(c.id.clone());
    let _t = crate::timing::span("read required file");
    let read = match prefetched.take_if(|p| p.id == c.id) {
        Some(p) => p.bytes,
        None => std::fs::read(&c.path),
    };
    match read {
        Ok(bytes) => seen.same_as(&bytes, sources).is_none().then_some(bytes),
        Err(e) => {
            diags.push(Diagnostic::new(Code::Io, format!("cannot read {}: {}", c.path.display(), io_reason(&e))).at(at));
            None
        }
    }
}

/// Adds a file to the sources: its text if it is UTF-8 (and returns its id), or else a lossy copy for
/// showing its lines, with the diagnostic.
fn add_source(sources: &mut SourceMap, path: PathBuf, display: String, bytes: Vec<u8>, named: bool, diags: &mut Diagnostics) -> Option<FileId> {
    match parse::decode_text_keeping(bytes) {
        Ok(text) => Some(sources.add(SourceFile::new(path, display, text, named))),
        Err((d, at, bytes)) => {
            let id = sources.add(SourceFile::new(path, display, displayable(&bytes), named));
            diags.push(d.at(Span::new(id, at, at + 1)));
            None
        }
    }
}

/// The reason an I/O operation failed, without the platform's error number.
fn io_reason(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        std::io::ErrorKind::IsADirectory => "it is a folder (folders of required models go after --models)".into(),
        k => k.to_string(),
    }
}

/// Text to show the lines of a file that is not UTF-8: UTF-16 decoded, NUL bytes shown as `␀`.
fn displayable(bytes: &[u8]) -> String {
    let le = bytes.starts_with(&[0xFF, 0xFE]) || bytes.starts_with(&[0x3C, 0x00]);
    let be = bytes.starts_with(&[0xFE, 0xFF]) || bytes.starts_with(&[0x00, 0x3C]);
    if le || be {
        let units: Vec<u16> = bytes
            .chunks_exact(2)
            .map(|c| if le { u16::from_le_bytes([c[0], c[1]]) } else { u16::from_be_bytes([c[0], c[1]]) })
            .collect();
        return String::from_utf16_lossy(&units).trim_start_matches('\u{feff}').to_string();
    }
    String::from_utf8_lossy(bytes).replace('\0', "\u{2400}")
}

/// Checks the version (and, for an equal version, the publication date) that `where_` holds against a
/// requirement of `requirer`.
fn check_version(req: &RequiredInfo, requirer: &str, have: Option<&str>, have_date: Option<&str>, where_: &str, diags: &mut Diagnostics) {
    let Some(want) = req.version.as_deref() else { return };
    match cmp_version(have, Some(want)) {
        Ordering::Less => diags.push(
            Diagnostic::new(
                Code::ModelTooOld,
                format!("`{requirer}` requires model `{}` version {want}, but {where_} holds version {}", req.uri, have.unwrap_or("(none)")),
            )
            .at(req.span)
            .with_span_label(format!("requires version {want}"))
            .help("get a newer release of that model (for the companion specs: `cargo xtask fetch-nodesets`), or correct the RequiredModel Version"),
        ),
        Ordering::Equal => {
            if let (Some(want_d), Some(have_d)) = (req.publication_date.as_deref(), have_date) {
                if date_key(have_d) < date_key(want_d) {
                    diags.push(
                        Diagnostic::new(
                            Code::ModelDateOlder,
                            format!(
                                "model `{}` version {want} is required as published {want_d}, but {where_} was published {have_d}",
                                req.uri
                            ),
                        )
                        .at(req.span)
                        .help("use the release published on or after the required date"),
                    );
                }
            }
        }
        Ordering::Greater => {}
    }
}

fn date_key(d: &str) -> &str {
    d.get(..10).unwrap_or(d)
}

fn topo_order(
    parsed: &[RawNodeSet],
    sources: &SourceMap,
    implied: &BTreeMap<String, FileId>,
    implied_requires: &BTreeMap<FileId, Vec<String>>,
    diags: &mut Diagnostics,
) -> Vec<usize> {
    let provider: HashMap<&str, usize> = {
        let mut m = HashMap::new();
        for (i, s) in parsed.iter().enumerate() {
            for model in &s.models {
                m.entry(model.uri.as_str()).or_insert(i);
            }
        }
        for (uri, file) in implied {
            if let Some(i) = parsed.iter().position(|s| s.file == *file) {
                m.entry(uri.as_str()).or_insert(i);
            }
        }
        m
    };
    let ns0 = provider.get(NS0_URI).copied();
    let deps: Vec<BTreeSet<usize>> = parsed
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let mut d: BTreeSet<usize> = s
                .models
                .iter()
                .flat_map(|m| m.required.iter().map(|r| r.uri.as_str()))
                .chain(implied_requires.get(&s.file).into_iter().flatten().map(String::as_str))
                .filter_map(|uri| provider.get(uri).copied())
                .filter(|&j| j != i)
                .collect();
            if let Some(n) = ns0 {
                if n != i {
                    d.insert(n);
                }
            }
            d
        })
        .collect();
    let key = |i: usize| {
        let s = &parsed[i];
        let uri = s.models.first().map(|m| m.uri.clone()).unwrap_or_default();
        let f = sources.get(s.file);
        let name = f.path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        (uri.is_empty(), uri, name, f.path.clone())
    };
    let mut done = vec![false; parsed.len()];
    let mut order = Vec::with_capacity(parsed.len());
    loop {
        let mut ready: Vec<usize> = (0..parsed.len()).filter(|&i| !done[i] && deps[i].iter().all(|&d| done[d])).collect();
        if ready.is_empty() {
            break;
        }
        ready.sort_by_key(|&i| key(i));
        let i = ready[0];
        done[i] = true;
        order.push(i);
    }
    let rest: Vec<usize> = (0..parsed.len()).filter(|&i| !done[i]).collect();
    if !rest.is_empty() {
        let mut rest_sorted = rest.clone();
        rest_sorted.sort_by_key(|&i| key(i));
        // Walk the requirements from the first file until a file repeats: that is the cycle. Of several
        // requirements, the walk follows the first by the same key (not the order files were read in, which
        // depends on the order they were named).
        let mut path: Vec<usize> = vec![rest_sorted[0]];
        loop {
            let cur = *path.last().expect("path is never empty");
            let Some(next) = deps[cur].iter().copied().filter(|d| rest.contains(d)).min_by_key(|&d| key(d)) else { break };
            if let Some(pos) = path.iter().position(|&p| p == next) {
                path.drain(..pos);
                path.push(next);
                break;
            }
            path.push(next);
        }
        let name = |i: usize| {
            parsed[i].models.first().map(|m| m.uri.clone()).unwrap_or_else(|| sources.get(parsed[i].file).display.clone())
        };
        let names: Vec<String> = path.iter().map(|&i| name(i)).collect();
        let files: Vec<String> = path.iter().take(path.len().saturating_sub(1)).map(|&i| sources.get(parsed[i].file).display.clone()).collect();
        let mut d = Diagnostic::new(Code::ModelCycle, format!("models require each other in a cycle: {}", names.join(" -> ")))
            .note(format!("files: {}", files.join(", ")))
            .help("a model cannot require itself through others; remove one of these RequiredModel elements");
        // The caret goes on the RequiredModel of the first file that closes the loop.
        if path.len() >= 2 {
            let (from, to) = (path[0], path[1]);
            let to_uris: Vec<&str> = parsed[to].models.iter().map(|m| m.uri.as_str()).collect();
            if let Some(r) = parsed[from].models.iter().flat_map(|m| m.required.iter()).find(|r| to_uris.contains(&r.uri.as_str())) {
                d = d.at(r.span).with_span_label(format!("requires {}", r.uri));
            }
            if let Some(r) = parsed[path[path.len() - 2]].models.iter().flat_map(|m| m.required.iter()).find(|r| {
                parsed[from].models.iter().any(|m| m.uri == r.uri)
            }) {
                if path.len() > 2 {
                    d = d.label(r.span, "which requires the first again");
                }
            }
        }
        diags.push(d);
        order.extend(rest_sorted);
    }
    order
}

/// The most candidates [`nearest`] is asked to search by the loader (the aliases of one file; ns0 has 30).
pub const MAX_SUGGESTION_CANDIDATES: usize = 1000;

/// The longest name [`nearest`] looks for: suggestions are for typos in names of identifier size.
const MAX_SUGGESTION_NAME: usize = 100;

/// The candidate closest to `name` by edit distance, if close enough to be a likely typo.
///
/// Each comparison costs at most the product of the two lengths and stops as soon as the distance exceeds
/// what would count as a typo; names longer than 100 bytes get no suggestion.
pub fn nearest<'a>(name: &str, candidates: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    if name.len() > MAX_SUGGESTION_NAME {
        return None;
    }
    let name_l = name.to_lowercase();
    let name_chars = name_l.chars().count();
    let mut best: Option<(usize, &str)> = None;
    for c in candidates {
        let limit = (name.len().max(c.len()) / 3).max(1);
        if c.len() > MAX_SUGGESTION_NAME {
            continue;
        }
        let c_l = c.to_lowercase();
        // The distance is at least the difference in length.
        if name_chars.abs_diff(c_l.chars().count()) > limit {
            continue;
        }
        let Some(d) = edit_distance_within(&name_l, &c_l, limit) else { continue };
        if best.is_none_or(|(bd, bc)| (d, c) < (bd, bc)) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

/// The edit (Levenshtein) distance of `a` and `b`, counted in characters.
pub fn edit_distance(a: &str, b: &str) -> usize {
    edit_distance_within(a, b, usize::MAX).unwrap_or(usize::MAX)
}

/// The edit distance of `a` and `b` if it is at most `limit`.
pub fn edit_distance_within(a: &str, b: &str, limit: usize) -> Option<usize> {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for i in 1..=a.len() {
        cur[0] = i;
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            cur[j] = (prev[j] + 1).min(cur[j - 1] + 1).min(prev[j - 1] + cost);
        }
        std::mem::swap(&mut prev, &mut cur);
        // A row's minimum never decreases further down: past the limit, the distance is too.
        if prev.iter().min().is_some_and(|&m| m > limit) {
            return None;
        }
    }
    Some(prev[b.len()]).filter(|&d| d <= limit)
}

#[cfg(test)]
mod tests;
