//! The loader: from files and model folders to an ordered set of parsed files with one namespace table.
//!
//! The user names files; the models they require are taken from among them or found in model folders
//! (searched recursively, indexed by ModelUri from a cheap scan of each file's `<Models>` header). Of several
//! versions of one model, the newest that satisfies the requirement wins. Files are then ordered so that a
//! model comes after everything it requires (ties broken by ModelUri, so input order never matters), and
//! every file's namespace indices are mapped onto the global table.

use crate::fxhash::FxHashMap;
use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::nodeid::{parse_node_id, looks_like_node_id, NodeId, NsRef, RawNodeId};
use crate::parse::{self, Limits};
use crate::raw::{RawModel, RawNodeSet};
use crate::source::{FileId, SourceFile, SourceMap, Span, Spanned};
use std::cmp::Ordering;
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

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

/// A file offered by a models folder, known from its header only.
#[derive(Clone, Debug)]
struct Candidate {
    path: PathBuf,
    models: Vec<(String, Option<String>, Option<String>)>,
    /// For a file without `<Models>`: the first of its NamespaceUris, the namespace such files (the older
    /// specifications) define their nodes in.
    own_namespace: Option<String>,
}

/// What [`scan_header`] reads of a NodeSet2 file: its declared models (URI, version, publication date)
/// and, when it declares none, the first of its NamespaceUris.
#[derive(Debug, PartialEq)]
struct Header {
    models: Vec<(String, Option<String>, Option<String>)>,
    own_namespace: Option<String>,
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
    for input in inputs {
        let mut d = Diagnostics::new();
        let (path, display, bytes) = match input {
            Input::Path(p) => match std::fs::read(&p) {
                Ok(b) => (p.clone(), p.display().to_string(), b),
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
            texts.push((said.len(), id));
        }
        said.push(d);
    }
    let jobs: Vec<(FileId, &str)> = texts.iter().map(|&(_, id)| (id, sources.get(id).text.as_str())).collect();
    let mut parsed_at: Vec<Option<RawNodeSet>> = (0..said.len()).map(|_| None).collect();
    for (&(i, _), (set, d)) in texts.iter().zip(parse::parse_files(&jobs, &opts.limits)) {
        said[i].extend(d);
        parsed_at[i] = set;
    }
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
    let mut index: Option<Vec<Candidate>> = None;
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
                    check_version(&req, m.version.as_deref(), m.publication_date.as_deref(), &sources.get(fid).display, diags);
                }
                continue;
            }
            let idx = index.get_or_insert_with(|| scan_dirs(&opts.model_dirs));
            let mut options: Vec<&Candidate> = idx.iter().filter(|c| c.models.iter().any(|m| m.0 == req.uri)).collect();
            let version_of = |c: &Candidate| c.models.iter().find(|m| m.0 == req.uri).map(|m| (m.1.clone(), m.2.clone())).unwrap_or_default();
            options.sort_by(|a, b| {
                let (va, da) = version_of(a);
                let (vb, db) = version_of(b);
                cmp_version(vb.as_deref(), va.as_deref())
                    .then_with(|| db.cmp(&da))
                    .then_with(|| a.path.as_os_str().len().cmp(&b.path.as_os_str().len()))
                    .then_with(|| a.path.cmp(&b.path))
            });
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
            let satisfying = same_kind.first().copied().or_else(|| {
                options.iter().copied().find(|c| {
                    let (v, _) = version_of(c);
                    req.version.is_none() || cmp_version(v.as_deref(), req.version.as_deref()) != Ordering::Less
                })
            });
            let requirer = sources.get(set_file).display.clone();
            match satisfying {
                Some(c) => {
                    let path = c.path.clone();
                    let (v, d) = version_of(c);
                    check_version(&req, v.as_deref(), d.as_deref(), &path.display().to_string(), diags);
                    let bytes = match std::fs::read(&path) {
                        Ok(b) => b,
                        Err(e) => {
                            diags.push(Diagnostic::new(Code::Io, format!("cannot read {}: {e}", path.display())).at(req.span));
                            continue;
                        }
                    };
                    let display = path.display().to_string();
                    if let Some(set) = read_and_parse(&mut sources, path, display, bytes, false, &opts.limits, diags) {
                        for m in &set.models {
                            provided.entry(m.uri.clone()).or_insert(set.file);
                        }
                        if set.models.is_empty() {
                            imply_models(&set, sources.get(set.file).text.as_str(), &mut provided, &mut implied, &mut implied_requires);
                        }
                        parsed.push(set);
                        queue.push(parsed.len() - 1);
                    } else {
                        // Do not try this model again for every file that requires it.
                        provided.insert(req.uri.clone(), FileId(u32::MAX));
                    }
                }
                None if !options.is_empty() => {
                    let best = options[0];
                    let (v, _) = version_of(best);
                    diags.push(
                        Diagnostic::new(
                            Code::ModelTooOld,
                            format!(
                                "`{}` requires model `{}` version {}, but only version {} is available",
                                requirer,
                                req.uri,
                                req.version.as_deref().unwrap_or("?"),
                                v.as_deref().unwrap_or("(none)")
                            ),
                        )
                        .at(req.span)
                        .with_span_label(format!("requires version {}", req.version.as_deref().unwrap_or("?")))
                        .note(format!("newest available: {} in {}", v.as_deref().unwrap_or("(no version)"), best.path.display()))
                        .help("get a newer release of that model (for the companion specs: `cargo xtask fetch-nodesets`), or correct the RequiredModel Version"),
                    );
                }
                None => {
                    if provided.get(&req.uri) == Some(&FileId(u32::MAX)) || (!explicit && req.uri != NS0_URI) {
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
                }
            }
        }
    }

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

fn read_and_parse(
    sources: &mut SourceMap,
    path: PathBuf,
    display: String,
    bytes: Vec<u8>,
    named: bool,
    limits: &Limits,
    diags: &mut Diagnostics,
) -> Option<RawNodeSet> {
    let id = add_source(sources, path, display, bytes, named, diags)?;
    let (set, d) = parse::parse_files(&[(id, sources.get(id).text.as_str())], limits).pop().expect("one file, one result");
    diags.extend(d);
    set
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

fn check_version(req: &RequiredInfo, have: Option<&str>, have_date: Option<&str>, where_: &str, diags: &mut Diagnostics) {
    let Some(want) = req.version.as_deref() else { return };
    match cmp_version(have, Some(want)) {
        Ordering::Less => diags.push(
            Diagnostic::new(
                Code::ModelTooOld,
                format!("model `{}` is required in version {want}, but {where_} holds version {}", req.uri, have.unwrap_or("(none)")),
            )
            .at(req.span)
            .with_span_label(format!("requires version {want}"))
            .help("use a newer release of the required model"),
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

/// For each of `uris`, the NodeSet2 file under `dirs` that defines that model in its newest version (the
/// choice the loader makes for a required model without a version); URIs no file defines are left out.
pub fn find_model_files(dirs: &[PathBuf], uris: &[String]) -> BTreeMap<String, PathBuf> {
    let index = scan_dirs(dirs);
    let mut out = BTreeMap::new();
    for uri in uris {
        let version_of = |c: &Candidate| c.models.iter().find(|m| m.0 == *uri).map(|m| (m.1.clone(), m.2.clone())).unwrap_or_default();
        let mut options: Vec<&Candidate> = index.iter().filter(|c| c.models.iter().any(|m| m.0 == *uri)).collect();
        options.sort_by(|a, b| {
            let (va, da) = version_of(a);
            let (vb, db) = version_of(b);
            cmp_version(vb.as_deref(), va.as_deref())
                .then_with(|| db.cmp(&da))
                .then_with(|| a.path.as_os_str().len().cmp(&b.path.as_os_str().len()))
                .then_with(|| a.path.cmp(&b.path))
        });
        if let Some(c) = options.first() {
            out.insert(uri.clone(), c.path.clone());
        }
    }
    out
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
pub fn declared_models(path: &Path) -> Option<Vec<(String, Option<String>, Option<String>)>> {
    scan_header(path).map(|h| h.models)
}

/// Lists every NodeSet2 file under the folders with the models its header declares.
fn scan_dirs(dirs: &[PathBuf]) -> Vec<Candidate> {
    let mut paths = Vec::new();
    for d in dirs {
        walk(d, &mut paths);
    }
    paths.sort();
    paths.dedup();
    paths
        .into_iter()
        .filter_map(|p| scan_header(&p).map(|h| Candidate { path: p, models: h.models, own_namespace: h.own_namespace }))
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
const HEADER_LIMIT: usize = 256 * 1024;

/// Reads the `<Models>` element of a file without parsing the rest (and, for a file that declares no
/// models within [`HEADER_LIMIT`], its first NamespaceUri).
///
/// A models folder is scanned once per compile and may hold hundreds of files, so the file is read in
/// growing chunks and reading stops as soon as `</Models>` has been seen. The answer is the one the first
/// [`HEADER_LIMIT`] bytes give: reading stops early only when the bytes read so far already contain
/// everything the tests below look for (the first `<Models>` and the `</Models>` after it, and
/// `UANodeSet`), and reading more cannot change where those are first found.
fn scan_header(path: &Path) -> Option<Header> {
    use std::io::Read;
    let mut f = std::fs::File::open(path).ok()?;
    let mut buf: Vec<u8> = Vec::new();
    let mut chunk = 16 * 1024;
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
        if at_end || header_complete(&String::from_utf8_lossy(&buf)) {
            break;
        }
        chunk *= 2;
    }
    let text = String::from_utf8_lossy(&buf);
    if !text.contains("UANodeSet") {
        return None;
    }
    let Some(start) = text.find("<Models>") else {
        return Some(Header { models: Vec::new(), own_namespace: first_namespace_uri(&text) });
    };
    let end = text[start..].find("</Models>")? + start + "</Models>".len();
    let mut reader = quick_xml::Reader::from_str(&text[start..end]);
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
fn header_complete(text: &str) -> bool {
    text.contains("UANodeSet") && text.find("<Models>").is_some_and(|start| text[start..].contains("</Models>"))
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
        // Walk the requirements from the first file until a file repeats: that is the cycle.
        let mut path: Vec<usize> = vec![rest_sorted[0]];
        loop {
            let cur = *path.last().expect("path is never empty");
            let Some(&next) = deps[cur].iter().find(|d| rest.contains(d)) else { break };
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
mod tests {
    use super::*;

    #[test]
    fn versions_compare_numerically() {
        assert_eq!(cmp_version(Some("1.05.03"), Some("1.5.2")), Ordering::Greater);
        assert_eq!(cmp_version(Some("1.04"), Some("1.4.0")), Ordering::Equal);
        assert_eq!(cmp_version(Some("1.02"), Some("1.04.0")), Ordering::Less);
        assert_eq!(cmp_version(None, Some("1.0")), Ordering::Less);
        assert_eq!(cmp_version(Some("9.99.99"), Some("1.05")), Ordering::Greater);
    }

    #[test]
    fn header_scan_stops_at_models_but_answers_as_the_full_prefix_would() {
        let dir = std::env::temp_dir().join(format!("nodeset-header-scan-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let model = "<Model ModelUri=\"http://x/\" Version=\"1.0\" PublicationDate=\"2020-01-01\"/>";
        // A header past the first chunk, one that straddles chunks, one past the limit, and no UANodeSet.
        let pad = "<!--".to_string() + &"x".repeat(40_000) + "-->";
        // A file without <Models> answers with its first NamespaceUri (none when it has none).
        let uris = "<NamespaceUris><Uri>http://old/</Uri><Uri>http://other/</Uri></NamespaceUris>";
        let x = || vec![("http://x/".to_string(), Some("1.0".to_string()), Some("2020-01-01".to_string()))];
        let none = |own: Option<&str>| Some(Header { models: Vec::new(), own_namespace: own.map(str::to_string) });
        let cases = [
            (format!("<UANodeSet>{pad}<Models>{model}</Models></UANodeSet>"), Some(Header { models: x(), own_namespace: None })),
            (format!("<UANodeSet><Models>{pad}{model}</Models></UANodeSet>"), Some(Header { models: x(), own_namespace: None })),
            (format!("<UANodeSet>{}<Models>{model}</Models></UANodeSet>", "x".repeat(HEADER_LIMIT)), none(None)),
            (format!("<Other><Models>{model}</Models></Other>"), None),
            (format!("<UANodeSet>{uris}{pad}<UAObject NodeId=\"ns=1;i=1\"/></UANodeSet>"), none(Some("http://old/"))),
        ];
        for (i, (text, want)) in cases.iter().enumerate() {
            let path = dir.join(format!("{i}.xml"));
            std::fs::write(&path, text).unwrap();
            assert_eq!(&scan_header(&path), want, "case {i}");
        }
        // What a named file provides, for `verify`: the models it declares, or the one its first namespace
        // implies (an old ADI named beside the current one in a models folder must keep its namespace).
        assert_eq!(models_of_file(&dir.join("0.xml")), Some(vec!["http://x/".to_string()]));
        assert_eq!(models_of_file(&dir.join("4.xml")), Some(vec!["http://old/".to_string()]));
        assert_eq!(models_of_file(&dir.join("3.xml")), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A named file without `<Models>` implies one model per namespace it defines nodes in (numeric and
    /// string NodeIds), in the order of its NamespaceUris; a namespace it only refers to implies none.
    #[test]
    fn a_file_without_models_implies_one_per_namespace_it_defines_nodes_in() {
        let text = r#"<UANodeSet xmlns="http://opcfoundation.org/UA/2011/03/UANodeSet.xsd">
  <NamespaceUris><Uri>http://a/</Uri><Uri>http://only-referenced/</Uri><Uri>http://b/</Uri></NamespaceUris>
  <UAObject NodeId="ns=3;s=Pump" BrowseName="3:Pump">
    <References><Reference ReferenceType="HasTypeDefinition">i=58</Reference>
      <Reference ReferenceType="Organizes">ns=2;i=7</Reference></References>
  </UAObject>
  <UAObjectType NodeId="ns=1;i=1" BrowseName="1:ValveType">
    <References><Reference ReferenceType="HasSubtype" IsForward="false">i=58</Reference></References>
  </UAObjectType>
</UANodeSet>"#;
        let mut diags = Diagnostics::new();
        let input = Input::Text { name: "implied.xml".into(), text: text.into() };
        let loaded = load(vec![input], &LoadOptions::default(), &mut diags);
        let implied: Vec<(&str, bool, bool)> =
            loaded.models.iter().map(|m| (m.uri.as_str(), m.version.is_none(), m.required.is_empty())).collect();
        assert_eq!(implied, vec![("http://a/", true, true), ("http://b/", true, true)]);
        let said = format!("{diags:?}");
        assert!(!said.contains("only-referenced"), "a namespace only referred to is looked for, not required: {said}");
    }

    /// A file without `<Models>` found in a models folder: an older file that refers to its namespace takes
    /// it (from its own folder), not the newest model of that URI, and the namespace is its implied model.
    #[test]
    fn an_older_file_takes_the_older_file_of_its_folder_for_a_namespace_it_refers_to() {
        let dir = std::env::temp_dir().join(format!("nodeset-older-{}", std::process::id()));
        let file = |rel: &str, text: &str| {
            let p = dir.join(rel);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(&p, text).unwrap();
            p
        };
        let head = r#"<UANodeSet xmlns="http://opcfoundation.org/UA/2011/03/UANodeSet.xsd">"#;
        let object = r#"<UAObject NodeId="ns=1;i=1" BrowseName="1:X"><References><Reference ReferenceType="HasTypeDefinition">i=58</Reference></References></UAObject>"#;
        file(
            "current/A.xml",
            &format!(r#"{head}<NamespaceUris><Uri>http://a/</Uri></NamespaceUris><Models><Model ModelUri="http://a/" Version="2.0"/></Models>{object}</UANodeSet>"#),
        );
        let old_a = file("old/A.xml", &format!("{head}<NamespaceUris><Uri>http://a/</Uri></NamespaceUris>{object}</UANodeSet>"));
        let old_b = file(
            "old/B.xml",
            &format!("{head}<NamespaceUris><Uri>http://b/</Uri><Uri>http://a/</Uri></NamespaceUris>{object}</UANodeSet>"),
        );
        let mut diags = Diagnostics::new();
        let loaded = load(vec![Input::Path(old_b.clone())], &LoadOptions { model_dirs: vec![dir.clone()], ..Default::default() }, &mut diags);
        let mut paths: Vec<&Path> = loaded.files.iter().map(|f| loaded.sources.get(f.raw.file).path.as_path()).collect();
        paths.sort();
        assert_eq!(paths, vec![old_a.as_path(), old_b.as_path()]);
        let a = loaded.models.iter().find(|m| m.uri == "http://a/").expect("http://a/ is a model");
        assert_eq!((a.version.as_deref(), loaded.sources.get(a.file).path.as_path()), (None, old_a.as_path()));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn nearest_finds_typos_only() {
        let c = ["HasComponent", "HasProperty", "Organizes"];
        assert_eq!(nearest("HasComponnet", c.iter().copied()), Some("HasComponent"));
        assert_eq!(nearest("Zebra", c.iter().copied()), None);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance_within("kitten", "sitting", 2), None);
        assert_eq!(edit_distance_within("kitten", "sitting", 3), Some(3));
        assert_eq!(nearest(&"x".repeat(101), ["x".repeat(101).as_str()].into_iter()), None, "long names get no suggestion");
    }
}
