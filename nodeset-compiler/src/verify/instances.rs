//! `check`'s side of the instance rules: the static instances of the loaded files as a [`Snapshot`], the
//! same snapshot `verify` reads from a server serving them, checked by the same [`check`](super::check)
//! function, so that a static instance in a NodeSet2 file and the same instance on a live server meet one
//! set of rules with the same codes and severities.
//!
//! The snapshot holds what a server serving the files would show a client: every node of
//! [`Model::instance_nodes`] (outside namespace 0, not a type, not below one) with its forward references,
//! and, for variables, its DataType (BaseDataType when the file names none, as the XML schema says), its
//! ValueRank (-1 when absent) and the built-in type and shape of its value; the Objects folder with its
//! forward references. The walk starts where `verify`'s does, at the Objects folder; the nodes it does not
//! reach (below the Server object, or below no node at all) are then checked as instances of their own
//! types, under their browse path.

use super::check::{self, Report};
use super::{RemoteNode, RemoteReference, RemoteValue, Snapshot};
use crate::diag::{Code, Diagnostics, Label, Severities};
use crate::model::{ids, Model, NodeIx};
use crate::nodeid::NodeId;
use crate::raw::NodeClass;
use crate::value::{Content, Variant};
use crate::{Compiled, Options};

/// The snapshot of the files' static instances a server serving them would give (see the module's
/// documentation). NodeIds and BrowseNames carry the model's namespace indices.
pub fn snapshot(model: &Model) -> Snapshot {
    let instance = model.instance_nodes();
    let mut snap = Snapshot { namespaces: model.namespaces.clone(), ..Snapshot::default() };
    let objects = Snapshot::objects_folder();
    let remote = |ix: NodeIx| {
        let node = model.node(ix);
        let references = node
            .references
            .iter()
            .filter(|r| r.forward)
            .map(|r| RemoteReference { reference_type: model.node(r.reference_type).id.clone(), target: model.node(r.target).id.clone() })
            .collect();
        let variable = node.class == NodeClass::Variable;
        let base = NodeId::numeric(0, ids::BASE_DATA_TYPE);
        RemoteNode {
            id: node.id.clone(),
            class: node.class,
            browse_name: node.browse_name.clone(),
            references,
            data_type: variable.then(|| node.attrs.data_type.map(|d| model.node(d).id.clone()).unwrap_or(base)),
            value_rank: variable.then(|| node.attrs.value_rank.unwrap_or(-1)),
            value: if variable { value_shape(model, ix) } else { None },
            extension_objects: None,
        }
    };
    for (i, _) in instance.iter().enumerate().filter(|(_, &is)| is) {
        let ix = NodeIx(i as u32);
        snap.nodes.insert(model.node(ix).id.clone(), remote(ix));
    }
    let folder = model.lookup(&objects).map(remote).unwrap_or_else(RemoteNode::empty_objects_folder);
    snap.nodes.insert(objects, folder);
    snap
}

/// What a server serves for the value of variable `ix`: `Empty` without a value, `None` when it cannot be
/// decoded (NS0214 says so; a server would leave it out).
fn value_shape(model: &Model, ix: NodeIx) -> Option<RemoteValue> {
    match model.decode_value(ix, Content::Shape) {
        None => Some(RemoteValue::Empty),
        Some(Err(_)) => None,
        Some(Ok(v)) => Some(match (v.builtin(), &v) {
            (None, _) => RemoteValue::Empty,
            (Some(b), Variant::Array(..)) => RemoteValue::Array(b),
            (Some(b), _) => RemoteValue::Scalar(b),
        }),
    }
}

/// The browse path of `ix` from the Objects folder (or from the top of its parent chain), as the checker
/// writes paths: `Server/Namespaces/2:Robotics`.
fn browse_path(model: &Model, ix: NodeIx) -> String {
    let objects = model.ns0(ids::OBJECTS_FOLDER);
    let mut names: Vec<String> = Vec::new();
    let mut cur = Some(ix);
    while let Some(c) = cur {
        if Some(c) == objects || names.len() > model.nodes.len() {
            break;
        }
        let bn = &model.node(c).browse_name;
        names.push(if bn.ns == 0 { bn.name.clone() } else { format!("{}:{}", bn.ns, bn.name) });
        cur = model.node(c).parent;
    }
    names.reverse();
    names.join("/")
}

/// Checks every static instance of the model with the instance rules: from the Objects folder as `verify`
/// walks a server, then the instances the walk does not reach. The findings have the codes' default
/// severities, in the order of the walk (see [`Report::apply`]).
pub fn check(model: &Model) -> Report {
    let snap = snapshot(model);
    let instance = model.instance_nodes();
    // First the tops of the instance trees that hang elsewhere (no parent among the instances), in node
    // order; then anything still unreached (a parent that does not reference it).
    let top = |i: usize| model.nodes[i].parent.is_none_or(|p| !instance[p.index()]);
    let mut more: Vec<(NodeId, String)> = Vec::new();
    for pass_tops in [true, false] {
        for i in (0..model.nodes.len()).filter(|&i| instance[i] && top(i) == pass_tops) {
            let ix = NodeIx(i as u32);
            let parent = model.node(ix).parent.map(|p| browse_path(model, p)).unwrap_or_default();
            more.push((model.node(ix).id.clone(), parent));
        }
    }
    check::check_from(model, &snap, &more)
}

/// [`check`] as `check` reports it: the findings on instances of the files the user named (or of every
/// file, with `all`), each pointing at the instance in its file (at its value for NS0406) with the violated
/// declaration as a label and the instance's browse path in a note, after the severity settings.
pub fn diagnostics(model: &Model, severities: &Severities, all: bool) -> Diagnostics {
    let mut report = check(model);
    report.apply(severities, &model.sources);
    let mut out = Diagnostics::new();
    for f in report.findings {
        let Some(ix) = model.lookup(&f.id) else { continue };
        let node = model.node(ix);
        if !all && !model.sources.get(node.file).named {
            continue;
        }
        let mut d = f.diagnostic;
        let here = match (d.code, model.value_element(ix)) {
            (Code::WrongValueType, Some(value)) => value.span(),
            _ => node.span,
        };
        if let Some(declared) = d.span.replace(here) {
            let label = d.span_label.take().unwrap_or_else(|| "the declaration".into());
            d.labels.insert(0, Label { span: declared, message: label });
        }
        d.notes.insert(0, format!("the instance: `{}` ({})", f.path, model.display_id(&node.id)));
        out.push(d);
    }
    out
}

/// What `nodeset-compiler check` does after compiling: the findings of [`diagnostics`] on the static
/// instances of the files the user named (of every loaded file with [`Options::all_warnings`]) join the
/// compiler's diagnostics, with `opts`' severity settings, and the diagnostics are sorted again.
pub fn check_compiled(compiled: &mut Compiled, opts: &Options) {
    let found = diagnostics(&compiled.model, &opts.severities, opts.all_warnings);
    compiled.diagnostics.extend(found);
    compiled.diagnostics.sort(&compiled.model.sources);
}

/// The instance findings of `verify` that a diagnostic of `check` explains as a defect of the nodeset, for the
/// files `named` (with their required models from `model_dirs`): each `(code verify gives, file, line of the
/// declaration's start tag)` with the diagnostic's text. A value in a type that contradicts its DataType
/// (`check`'s NS0209) is served as written, and every instance of the type then holds it (`verify`'s NS0406,
/// which points at the declaration's start tag while NS0209 points into its Value).
pub fn findings_check_explains(
    named: &[std::path::PathBuf],
    model_dirs: &[std::path::PathBuf],
) -> Result<std::collections::BTreeMap<(String, String, usize), String>, String> {
    use crate::diag::Code;
    use crate::load::Input;
    let opts = Options { model_dirs: model_dirs.to_vec(), ..Options::default() };
    let compiled = crate::compile(named.iter().cloned().map(Input::Path).collect(), &opts);
    if !compiled.ok() {
        return Err(compiled.render_diagnostics().lines().next().unwrap_or_default().to_owned());
    }
    let model = &compiled.model;
    let mut out = std::collections::BTreeMap::new();
    for d in compiled.diagnostics.items.iter().filter(|d| d.code == Code::ValueTypeMismatch) {
        let Some(span) = d.span else { continue };
        // The node whose element holds the diagnostic: the last one of its file that starts before it.
        let Some(node) = model.nodes.iter().filter(|n| n.file == span.file && n.span.start <= span.start).max_by_key(|n| n.span.start)
        else {
            continue;
        };
        let file = model.sources.get(span.file);
        let (line, _) = file.line_col(node.span.start);
        let path = std::fs::canonicalize(&file.path).unwrap_or_else(|_| file.path.clone());
        out.insert(("NS0406".to_owned(), path.display().to_string(), line), format!("{}[{}]: {}", d.severity.as_str(), d.code.as_str(), d.message));
    }
    Ok(out)
}

/// What `check` finds on the static instances that a server serving `named` (with the models they require,
/// found in `model_dirs`) shows a client, comparable with `verify`'s findings on that server
/// ([`super::report::json_findings_by_uri`]): (code, severity, browse path by namespace URI), sorted. Every file
/// loaded is checked, dependencies included, since a server serves the static instances of the required
/// models too; findings below the Server object (a file's NamespaceMetadata, whose top has no namespace
/// prefix) are left out, since a server's walk starts at the Objects folder's children outside namespace 0.
/// `cargo xtask serve-corpus` and the tests of `verify` compare the two with this one function.
pub fn static_findings_by_uri(named: &[std::path::PathBuf], model_dirs: &[std::path::PathBuf]) -> Result<Vec<(String, String, String)>, String> {
    use crate::load::Input;
    let opts = Options { model_dirs: model_dirs.to_vec(), ..Options::default() };
    let loaded = crate::compile(named.iter().cloned().map(Input::Path).collect(), &opts);
    if !loaded.ok() {
        return Err(loaded.render_diagnostics().lines().next().unwrap_or_default().to_owned());
    }
    // Every file loaded, dependencies first: what the server loads. (The sources also hold files the loader
    // only compared: of two files of one model it reads the one holding every node of the other.)
    let defining: std::collections::BTreeSet<_> = loaded.model.models.iter().map(|m| m.file).collect();
    let files: Vec<std::path::PathBuf> =
        loaded.model.sources.files().filter(|(id, _)| defining.contains(id)).map(|(_, f)| f.path.clone()).collect();
    let compiled = crate::compile(files.into_iter().map(Input::Path).collect(), &Options::default());
    let mut report = check(&compiled.model);
    report.apply(&Severities::new(), &compiled.model.sources);
    let mut out: Vec<(String, String, String)> = report
        .findings
        .iter()
        .filter(|f| f.path.split('/').next().is_some_and(|top| top.contains(':')))
        .map(|f| {
            let path = super::report::path_by_uri(&f.path, &report.namespaces);
            (f.diagnostic.code.as_str().to_owned(), f.diagnostic.severity.as_str().to_owned(), path)
        })
        .collect();
    out.sort();
    Ok(out)
}
