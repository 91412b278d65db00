//! The Modelica back end: one Modelica package per OPC UA namespace, plus `OpcUaSupport`.
//!
//! [`generate`] is a pure function of the resolved [`Model`] and a [`ModelicaConfig`]; it returns the files
//! (paths relative to one output root that holds every package, as Modelica tools expect a library root)
//! and writes nothing. The output follows the conventions of the Modelica Standard Library and does not
//! depend on it: one class per file, `package.mo` and `package.order` in every package folder, `within`
//! clauses, description strings, `Documentation(info=...)` on every class (the nodeset's Description, else
//! what the class stands for), an `Icon` on every model, record and package (connectors placed down its left
//! edge for inputs and its right edge for outputs), `version` and `uses` annotations from the Model and
//! RequiredModel elements, and a `UsersGuide` in `OpcUaSupport`.
//!
//! ```no_run
//! use nodeset_compiler::emit::modelica::{generate, ModelicaConfig};
//! use nodeset_compiler::{compile, load::Input, Options};
//! let dir = std::path::PathBuf::from("nodesets/vendor");
//! let out = compile(vec![Input::Path(dir.join("Opc.Ua.Robotics.NodeSet2.xml"))], &Options { model_dirs: vec![dir], ..Options::default() });
//! let cfg = ModelicaConfig::new()
//!     .namespace("http://opcfoundation.org/UA/DI/")
//!     .namespace("http://opcfoundation.org/UA/IA/")
//!     .namespace("http://opcfoundation.org/UA/Robotics/");
//! let files = generate(&out.model, &cfg).expect("no emitter errors");
//! nodeset_compiler::write::write_tree("modelica".as_ref(), &files, nodeset_compiler::write::Mode::Write).unwrap();
//! ```
//!
//! # Layout
//!
//! ```text
//! OpcUaSupport/              connectors RealInput ... StringOutput, NodeId, BrowsePath, VariableNode, Nodes,
//!                            Interfaces (read/write blocks for an OPC UA library), Loopback (tables, no server)
//! OpcUa/                     the part of the base namespace the other packages use (or all of it)
//! OpcUaRobotics/
//!   package.mo               version, uses, the namespace URI
//!   Types/                   one class per DataType (enumeration, record, type)
//!   EnumerationValues.mo     the OPC UA values of the enumeration literals
//!   ObjectTypes/             one model per ObjectType (partial when abstract), one record per event type
//!   Declarations/            classes of instance declarations that add children to their type, named
//!                            <Owner>_<BrowsePath> (AxisType_ParameterSet)
//!   Complete/                the complete variant of each class with inputs nothing binds (see ObjectTypes)
//!   Instances/               one model per top-level instance and `Objects` with the `Nodes` record
//!     Bindings/             each instance with a read or write block per variable (see `bindings.rs`)
//!   Examples/                each instance as a model that simulates as it is, with an `experiment` annotation
//! ```
//!
//! Package names derive from the namespace URI (`http://opcfoundation.org/UA/Robotics/` -> `OpcUaRobotics`,
//! `http://opcfoundation.org/UA/DI/` -> `OpcUaDI`, the base namespace -> `OpcUa`; other hosts give their
//! first label and path, `http://example.com/fixtures/union/` -> `ExampleFixturesUnion`) and can be set per
//! URI. A namespace that is not emitted is referred to by its package name, so the package must exist
//! already, except for the base namespace, of which the needed subset is emitted unless
//! [`ModelicaConfig::base_subset`] is off.
//!
//! # DataTypes
//!
//! | OPC UA | Modelica | Note |
//! |---|---|---|
//! | Boolean | `Boolean` | |
//! | SByte, Byte, Int16, UInt16 | `OpcUa.Types.<T>` = `Integer(min=..., max=...)` | exact |
//! | Int32 | `Integer` | exact |
//! | UInt32 | `OpcUa.Types.UInt32` = `Integer(min=0)` | values above 2147483647 do not fit a Modelica Integer |
//! | Int64, UInt64 | `OpcUa.Types.<T>` = `Real` | exact up to 2^53 |
//! | Float, Double, Number, Decimal | `Real` | Decimal beyond double precision is rounded |
//! | Integer, UInteger (abstract) | `Integer` | 32 bits |
//! | String | `String` | |
//! | LocalizedText | `OpcUa.Types.LocalizedText` = `String` | the text of the default locale |
//! | QualifiedName | `String` | `nsu=<URI>;<Name>`, or `<Name>` in the base namespace |
//! | NodeId, ExpandedNodeId | `String` | `nsu=<URI>;i=5`, or `i=5` in the base namespace |
//! | Guid | `String` | text form |
//! | DateTime | `OpcUa.Types.DateTime` = `Real(unit="s")` | seconds since 1970 UTC; below a microsecond is lost |
//! | StatusCode | `Integer` | the same 32 bits, signed: Bad codes are negative |
//! | ByteString, XmlElement, DataValue, DiagnosticInfo, BaseDataType (Variant), abstract Structure | none | left out with a comment and a warning |
//! | simple subtype (Duration, ...) | `type Duration = Real` | |
//! | enumeration | `type E = enumeration(...)` | literals in nodeset order; `EnumerationValues.E[Integer(x)]` is the OPC UA value |
//! | OptionSet | `record` of one `Boolean` per bit | a Modelica Integer cannot hold a UInt32/UInt64 mask and has no bit operators |
//! | structure | `record`, `extends` its supertype's record | optional fields get `Boolean has_<field>`; a union gets `Integer switchField` (0 = none, i = i-th field) and all alternatives; a field whose type contains the structure again is left out |
//!
//! Arrays: ValueRank n >= 1 gives n dimensions, fixed where ArrayDimensions gives a length, else `:` with
//! the value (or `fill(..., 0)`) deciding; ValueRank 0 is one dimension; -2 (any) and -3 (scalar or one
//! dimension) are declared as scalars. Inside a record, and for arrays of records anywhere, a dimension of
//! unknown length is sized by a parameter of its own (`parameter Integer nX = 0; T x[nX]`): a record
//! constructor cannot infer `:`.
//!
//! # ObjectTypes
//!
//! * An ObjectType becomes a `model` that `extends` the class of its supertype (across packages); an abstract
//!   one becomes a `partial model`; an event type (subtype of BaseEventType) becomes a `record` of its
//!   fields.
//! * A property becomes a `parameter`. A data variable the model publishes (AccessLevel without CurrentWrite)
//!   becomes an `OpcUaSupport` input connector that nothing binds: the physics computing it connects to it
//!   (`connect(drive.y, parameterSet.actualPosition)`). A variable clients write becomes an output connector
//!   bound to the value in the nodeset (else zero, false, ""), which the model hands on. Arrays, enumerations
//!   and records keep the nodeset's value (`input`/`output` components); so does everything in an instance.
//! * A class whose components hold unbound inputs is unbalanced, so it is a `partial model`; its complete
//!   variant `<Pkg>.Complete.<Ident>` extends it and binds each of them (and its own) to the nodeset's value
//!   (`extends AxisType(parameterSet(actualPosition=0, ...))`). Modelica tools refuse components of partial
//!   classes, so a component or a class alias whose class is partial uses the complete variant
//!   (`replaceable model AxisIdentifier = ...Complete.AxisType constrainedby ...ObjectTypes.AxisType`). An
//!   instance binds its unbound inputs itself, to the instance's values, and is complete. A subtype (or an
//!   instance) that gives such an input of a replaceable component another value gives the component a
//!   declaration class of its own, whose complete variant binds the new value and becomes the alias's class
//!   (`redeclare model Tuning = ...Complete.ArmType_Tuning`): a modifier on the component would bind the inputs
//!   of any model a user plugs in.
//!   A Real with EngineeringUnits holds its SI value, as the Modelica Standard Library does (`unit="m",
//!   displayUnit="mm", quantity="Length"`; a value from the nodeset is converted), and its `__OPCUA`
//!   annotation keeps the UNECE code and the conversion from the OPC UA value (`engineeringUnit="MMT",
//!   siFactor=0.001`; see `units.rs`).
//! * An object becomes a component whose class is a replaceable alias (`replaceable model Axes =
//!   OpcUaRobotics.Declarations.MotionDeviceType_Axes; Axes axes;`). An instance declaration that adds or
//!   changes children gets a class of its own in `Declarations`; a subtype that overrides an inherited
//!   object redeclares the alias (`redeclare model ParameterSet = ...AxisType_ParameterSet`), and a user
//!   plugs in a model of their own the same way.
//! * Optional: `parameter Boolean use_x = false` and `X x if use_x`; a subtype that makes it Mandatory writes
//!   `final use_x = true`. Placeholder `<X>`: `parameter Integer nX(min=0) = 0` (`(min=1) = 1` for a
//!   MandatoryPlaceholder), `parameter String xBrowseNames[nX] = fill("<X>", nX)` (the elements' BrowseNames,
//!   which a user sets), `replaceable model X = ...` and `X x[nX]`. Where named children fill a mandatory
//!   placeholder (always in an instance; in a type, children of the placeholder's NodeClass and TypeDefinition
//!   or a subtype), the array is empty: `nX(min=0)=0`.
//! * Only containment makes a component: a child held by HasChild (HasComponent, HasProperty,
//!   HasOrderedComponent, ...) or Organizes. A child held by any other reference (Requires, Moves, HasSlave,
//!   Controls, IsDrivenBy, ...) lives elsewhere and becomes `parameter String x = ""` (an array sized by its
//!   count for a placeholder) with the NodeId of the target, filled in by instances and users, and
//!   `referenceType` in its `__OPCUA` annotation. No class contains itself: where containment closes a cycle
//!   (FileDirectoryType organizes `<FileDirectoryName>` directories, DI's FunctionalGroupType holds
//!   `<GroupIdentifier>` groups), that member is cut to such a reference parameter too (see `recursion.rs`).
//! * Methods appear as comments (call them through an OPC UA client), except as the triggers of a state
//!   machine (see `statemachine.rs`).
//! * Every component carries `annotation(__OPCUA(browsePath="...", nodeId="...", dataType="..."))`; the
//!   browse path is relative to the object the enclosing class stands for.
//!
//! # Names
//!
//! Every identifier comes from [`crate::names::Scope`] with `Target::Modelica` and `Case::Preserve`: class
//! names keep the BrowseName (`3DFrameType` -> `N3DFrameType`; a BrowseName that already is an identifier keeps
//! its spelling, so the enumeration literal `MANUAL_REDUCED_SPEED` stays as it is), component names start with their first word
//! in lower case (`ActualPosition` -> `actualPosition`, `Model` -> `model_`), reserved words get a trailing
//! underscore, and names that collide in one scope get `_2`, `_3`, ... in the sorted order of the originals
//! (with a warning). Each scope reserves the names of the top-level packages and every name a base class
//! uses. The original BrowseName is the first thing in every description string.
//!
//! # rumoca
//!
//! The tests check every generated class with rumoca 0.10.2 (`tests/modelica/check.py`). Some choices keep
//! clear of what that compiler gets wrong, without leaving the Modelica language: classes are redeclared as
//! aliases (a component redeclaration two `extends` levels up is dropped); a declaration class is never named
//! like the alias it replaces (`redeclare model X = P.X` is ignored); a redeclaration's class has local
//! replaceable elements only when its constraining class has some (rumoca's reading of MLS 6.4); no
//! `redeclare model extends` (it crashes rumoca); record arrays get explicit sizes and array literals rather
//! than `fill` (`expression shape mismatch`). rumoca lets an enclosing instance's redeclaration of an inherited
//! alias replace a nested component's own (a MotionDeviceType's `ParameterSet` would replace the one of each
//! AxisType in its Axes), so every object component repeats its class's choice for each alias that some class
//! redeclares (`Axis axis(redeclare model ParameterSet = ...AxisType_ParameterSet)`, `plan::Mod::Pin`);
//! `tests/modelica/RumocaBehaviour` reproduces both the leak and the fix.
//!
//! pymoca 0.12.0, the second checker, has its own misreading: when a derived class changes such a repeated
//! choice on an array component sized by a parameter (a placeholder), pymoca keeps the declaration's
//! (`tests/modelica/PymocaBehaviour`). So a placeholder's array, declared through a class alias, repeats each
//! choice through an alias of the enclosing class, `replaceable model AxisIdentifier_ParameterSet = ...;
//! AxisIdentifier axisIdentifier[n](redeclare model ParameterSet = AxisIdentifier_ParameterSet)`
//! (`plan::Mod::PinVia`, `plan::Pinned`), and a
//! derived class redeclares that alias at class level (`plan::Mod::Repin`). These pin aliases are redeclared,
//! so they leak like any other and are repeated in turn; the set of repeated aliases grows until it holds.
//!
//! # Limits
//!
//! VariableTypes have no classes: a variable is a connector of its value, and of the properties of a
//! variable only EngineeringUnits (as `unit`, `displayUnit` and `quantity`) is kept; the instance `Nodes`
//! record lists all of them.
//! Children that an instance declaration adds to an inherited component that is not replaceable are left
//! out with a warning.
//!
//! # Where each concern lives
//!
//! Planning decides every class, then `mod.rs` renders the plans and writes the package skeleton. The files
//! import each other in one direction only, from the planners down to `ctx.rs` and `plan.rs`.
//!
//! | File | Concern |
//! |---|---|
//! | `plan.rs` | what planning produces: classes, elements, modifiers, DataType forms, state machines |
//! | `ctx.rs` | the planning context: package and class names, the top-level instances, caches, diagnostics |
//! | `objects.rs` | the class of an ObjectType or an event type, a class body from a base and children, values |
//! | `members.rs` | one member: new (parameter, connector, component, reference, method) or overriding |
//! | `complete.rs` | unbound inputs, partial classes and their complete variants |
//! | `statemachine.rs` | state machines: states, triggers, the equations that drive them |
//! | `instances.rs`, `bindings.rs` | instances, `Objects` with the `Nodes` record, binding models, examples |
//! | `types.rs`, `units.rs` | DataTypes, literals, engineering units |
//! | `recursion.rs` | containment cut where a class would contain itself |
//! | `text.rs`, `support.rs` | text helpers, icons; the hand-written `OpcUaSupport` package |

mod bindings;
mod complete;
mod ctx;
mod instances;
mod members;
mod objects;
mod plan;
mod recursion;
mod statemachine;
pub mod support;
mod text;
mod types;
pub mod units;

use crate::diag::{Code, Diagnostic, Diagnostics, Severity};
use crate::load::NS0_URI;
use crate::model::{Model, NodeIx};
use crate::names::{is_valid, Case, Scope, Target};
use crate::raw::NodeClass;
use crate::write::OutFile;
use ctx::{Ctx, Need};
use plan::{pin_alias, ClassPlan, ElemKind, Item, Mod, Owner, OwnerPlan, TypeRef, Value};
use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use text::string_literal;

/// What [`generate`] emits.
#[derive(Clone, Debug)]
pub struct ModelicaConfig {
    /// The namespaces (by URI) to emit completely, one top-level package each. Empty: the models of the files
    /// the user named.
    pub namespaces: Vec<String>,
    /// Package names per namespace URI, instead of the name derived from the URI.
    pub package_names: BTreeMap<String, String>,
    /// Emit the part of the base namespace that the emitted packages use as package `OpcUa`, unless the base
    /// namespace is emitted completely. Off: a complete `OpcUa` package must exist beside the output.
    pub base_subset: bool,
    /// Emit the `OpcUaSupport` package.
    pub support_package: bool,
}

impl Default for ModelicaConfig {
    fn default() -> ModelicaConfig {
        ModelicaConfig {
            namespaces: Vec::new(),
            package_names: BTreeMap::new(),
            base_subset: true,
            support_package: true,
        }
    }
}

impl ModelicaConfig {
    /// The defaults: the models of the named files, with the base-namespace subset and the support package.
    pub fn new() -> ModelicaConfig {
        ModelicaConfig::default()
    }

    /// Adds a namespace to emit.
    pub fn namespace(mut self, uri: impl Into<String>) -> ModelicaConfig {
        self.namespaces.push(uri.into());
        self
    }

    /// Sets the package name of a namespace.
    pub fn package_name(mut self, uri: impl Into<String>, name: impl Into<String>) -> ModelicaConfig {
        self.package_names.insert(uri.into(), name.into());
        self
    }

    /// Sets whether the used part of the base namespace is emitted as package `OpcUa`.
    pub fn base_subset(mut self, on: bool) -> ModelicaConfig {
        self.base_subset = on;
        self
    }

    /// Sets whether the `OpcUaSupport` package is emitted.
    pub fn support_package(mut self, on: bool) -> ModelicaConfig {
        self.support_package = on;
        self
    }
}

/// The files and everything said about them.
#[derive(Debug)]
pub struct Generated {
    /// The generated files, relative to the output folder.
    pub files: Vec<OutFile>,
    /// The errors and warnings of generation.
    pub diagnostics: Diagnostics,
}

/// Generates the Modelica packages; `Err` with the diagnostics when one of them is an error (a namespace the
/// model does not have, an invalid package name). Warnings (name collisions, types without a faithful
/// mapping) are returned by [`generate_with_diagnostics`].
pub fn generate(model: &Model, cfg: &ModelicaConfig) -> Result<Vec<OutFile>, Diagnostics> {
    let g = generate_with_diagnostics(model, cfg);
    if g.diagnostics.has_errors() {
        Err(g.diagnostics)
    } else {
        Ok(g.files)
    }
}

/// The word list of a package name derived from a namespace URI.
fn package_words(uri: &str) -> String {
    let rest = uri.split_once("://").map(|(_, r)| r).or_else(|| uri.strip_prefix("urn:")).unwrap_or(uri);
    let mut segs: Vec<&str> = rest.split(['/', ':']).filter(|s| !s.is_empty()).collect();
    let mut words: Vec<String> = Vec::new();
    if let Some(host) = segs.first().copied() {
        let host = host.trim_start_matches("www.");
        if host == "opcfoundation.org" {
            words.push("Opc Ua".into());
        } else {
            words.push(host.split('.').next().unwrap_or(host).to_string());
        }
        segs.remove(0);
    }
    if segs.first().is_some_and(|s| s.eq_ignore_ascii_case("UA")) {
        segs.remove(0);
    }
    for s in segs {
        // Version segments (`1.0.0`) do not belong in a name.
        if s.chars().all(|c| c.is_ascii_digit() || c == '.') {
            continue;
        }
        words.push(s.to_string());
    }
    words.join(" ")
}

/// Generates the packages and reports everything found.
pub fn generate_with_diagnostics(model: &Model, cfg: &ModelicaConfig) -> Generated {
    match plan(model, cfg) {
        Ok(planned) => render(planned, cfg),
        Err(diagnostics) => Generated { files: Vec::new(), diagnostics },
    }
}

/// What planning hands to rendering: the plans and facts of every class of the emitted namespaces (in the
/// context), which namespaces are emitted in full, and the base namespace when only its subset is.
struct Planned<'a> {
    ctx: Ctx<'a>,
    full: BTreeSet<u16>,
    subset: Option<u16>,
    diags: Diagnostics,
}

/// The planning step: package names, then the plan of every class of the emitted namespaces, and the aliases
/// that derived classes redeclare. It writes no Modelica; a configuration error ends it with its diagnostics.
fn plan<'a>(model: &'a Model, cfg: &ModelicaConfig) -> Result<Planned<'a>, Diagnostics> {
    let mut diags = Diagnostics::new();
    // Which namespaces to emit.
    let mut uris: Vec<String> = cfg.namespaces.clone();
    if uris.is_empty() {
        uris = model.models.iter().filter(|mi| model.sources.get(mi.file).named).map(|mi| mi.uri.clone()).collect();
    }
    let mut full: BTreeSet<u16> = BTreeSet::new();
    for uri in &uris {
        match model.namespaces.iter().position(|n| n == uri) {
            Some(i) => {
                full.insert(i as u16);
            }
            None => diags.push(
                Diagnostic::new(
                    Code::UnknownNamespaceUri,
                    format!("the Modelica configuration names namespace `{uri}`, which no loaded model defines"),
                )
                .help("load the NodeSet2 file of that model, or remove the namespace from the configuration"),
            ),
        }
    }
    // Package names: overrides as given, the others derived in one scope.
    let mut names: Vec<Option<String>> = vec![None; model.namespaces.len()];
    let mut scope: Scope<usize> = Scope::new(Target::Modelica, Case::UpperCamel);
    scope.reserve(support::PACKAGE);
    for (uri, name) in &cfg.package_names {
        if !is_valid(name, Target::Modelica) {
            // A configured package name is the user's input, like an attribute value: BadAttribute fits.
            diags.push(
                Diagnostic::new(
                    Code::BadAttribute,
                    format!("the package name `{name}` given for `{uri}` is not a Modelica identifier"),
                )
                .help("use letters, digits and `_`, starting with a letter, and no reserved word"),
            );
        }
        scope.reserve(name);
        if let Some(i) = model.namespaces.iter().position(|n| n == uri) {
            names[i] = Some(name.clone());
        }
    }
    for (i, uri) in model.namespaces.iter().enumerate() {
        if names[i].is_none() {
            scope.add(&package_words(uri), i);
        }
    }
    let (derived, collisions) = scope.finish();
    let pkg: Vec<String> =
        (0..model.namespaces.len()).map(|i| names[i].clone().unwrap_or_else(|| derived[&i].clone())).collect();
    {
        let mut seen = BTreeMap::new();
        for (i, p) in pkg.iter().enumerate() {
            if let Some(j) = seen.insert(p.clone(), i) {
                diags.push(Diagnostic::new(
                    Code::BadAttribute,
                    format!(
                        "namespaces `{}` and `{}` would both be package `{p}`",
                        model.namespaces[j], model.namespaces[i]
                    ),
                ));
            }
        }
    }
    if diags.has_errors() {
        return Err(diags);
    }
    let ns0 = model.namespaces.iter().position(|n| n == NS0_URI).map(|i| i as u16);
    let subset = if cfg.base_subset && ns0.is_some_and(|n| !full.contains(&n)) { ns0 } else { None };
    let mut ctx = Ctx::new(model, pkg, full.clone(), subset);
    for c in collisions {
        let list: Vec<String> = c.members.iter().map(|(o, i)| format!("`{}` ({o})", model.namespaces[*i])).collect();
        let mut d = Diagnostic::new(
            Code::NameCollision,
            format!(
                "namespaces {} map to one package name `{}`; they are told apart by `_2`, ...",
                list.join(", "),
                c.ident
            ),
        );
        d.severity = Severity::Warning;
        ctx.diags.push(d);
    }
    // Plan every class of the emitted namespaces, then write them; writing finds what the base-namespace
    // subset needs, which is planned and written in turn until nothing new is needed.
    for &ns in &full {
        plan_namespace(&mut ctx, ns);
    }
    // A pin alias counts once a derived class redeclares it, which it does for the choices that count: grow the
    // set until it holds.
    ctx.redeclared = redeclared_aliases(&ctx.plans);
    loop {
        let more = repinned_aliases(&ctx);
        if more.is_subset(&ctx.redeclared) {
            break;
        }
        ctx.redeclared.extend(more);
    }
    Ok(Planned { ctx, full, subset, diags })
}

/// The rendering step: every planned class as Modelica, then the classes of the base namespace that those
/// need, until nothing new is needed; then the package files around them.
fn render(planned: Planned, cfg: &ModelicaConfig) -> Generated {
    let Planned { mut ctx, full, subset, diags } = planned;
    let model = ctx.m;
    let mut out = Output::default();
    let mut done_needs: BTreeSet<Need> = BTreeSet::new();
    for &ns in &full {
        emit_namespace(&mut ctx, ns, &mut out);
    }
    loop {
        let pending: Vec<Need> = ctx.needs.iter().filter(|n| !done_needs.contains(n)).copied().collect();
        if pending.is_empty() {
            break;
        }
        for need in pending {
            done_needs.insert(need);
            match need {
                Need::DataType(dt) => emit_datatype(&mut ctx, dt, &mut out),
                Need::ObjectType(t) => {
                    if ctx.type_class(t).is_some() {
                        emit_owner(&mut ctx, Owner::Type(t), &mut out);
                    }
                }
            }
        }
    }
    if let Some(ns) = subset {
        if out.classes.keys().any(|(n, _)| *n == ns) {
            emit_enumeration_values(&mut ctx, ns, &mut out);
        }
    }
    let mut files = out.finish(&mut ctx, &full, subset);
    if cfg.support_package {
        files.extend(support::files());
    }
    files.sort_by(|a, b| a.path.cmp(&b.path));
    let mut diagnostics = diags;
    diagnostics.extend(ctx.diags);
    diagnostics.sort(&model.sources);
    Generated { files, diagnostics }
}

/// Classes by (namespace, sub-package path) and identifier.
#[derive(Default)]
struct Output {
    classes: BTreeMap<(u16, String), BTreeMap<String, String>>,
    /// Enumerations emitted per namespace, for `EnumerationValues`.
    enums: BTreeMap<u16, Vec<NodeIx>>,
    emitted_types: BTreeSet<NodeIx>,
    emitted_owners: BTreeSet<Owner>,
    /// Single-file classes directly in the namespace package (EnumerationValues).
    top_files: BTreeMap<u16, BTreeMap<String, String>>,
}

impl Output {
    fn add(&mut self, ns: u16, sub: &str, ident: &str, body: String) {
        self.classes.entry((ns, sub.to_string())).or_default().insert(ident.to_string(), body);
    }

    /// The package skeleton (package.mo and package.order of every folder) around the classes.
    fn finish(mut self, ctx: &mut Ctx, full: &BTreeSet<u16>, subset: Option<u16>) -> Vec<OutFile> {
        let m = ctx.m;
        let mut files = Vec::new();
        let mut namespaces: BTreeSet<u16> = full.clone();
        if let Some(s) = subset {
            if self.classes.keys().any(|(n, _)| *n == s) {
                namespaces.insert(s);
            }
        }
        for ns in namespaces {
            let pkg = ctx.pkg[ns as usize].clone();
            let info = m.models.iter().find(|mi| mi.ns == ns);
            let header = text::header(info);
            let root = PathBuf::from(&pkg);
            // Sub-packages, each with its classes.
            let mut subs: BTreeMap<String, Vec<String>> = BTreeMap::new();
            for ((n, sub), classes) in &self.classes {
                if *n != ns {
                    continue;
                }
                let dir = root.join(sub.replace('.', "/"));
                for (ident, body) in classes {
                    files.push(OutFile {
                        path: dir.join(format!("{ident}.mo")),
                        contents: format!("{header}within {pkg}.{sub};\n{body}"),
                    });
                }
                let mut order: Vec<String> = classes.keys().cloned().collect();
                order.sort_by_key(|a| (a.to_ascii_lowercase(), a.clone()));
                subs.insert(sub.clone(), order);
            }
            let mut top_order: Vec<String> = Vec::new();
            for (sub, what) in [
                ("Types", "DataTypes"),
                ("ObjectTypes", "ObjectTypes"),
                ("Declarations", "Classes of instance declarations"),
                ("Complete", "Complete variants of the partial classes"),
                ("Instances", "Instances"),
                ("Examples", "Examples"),
            ] {
                let mut order: Vec<String> = subs.get(sub).cloned().unwrap_or_default();
                if order.is_empty() {
                    continue;
                }
                if sub == "Instances" && subs.contains_key("Instances.Bindings") {
                    // The binding models (`bindings.rs`), a package of their own inside Instances.
                    order.insert(0, "Bindings".into());
                    let dir = root.join("Instances/Bindings");
                    files.push(OutFile {
                        path: dir.join("package.mo"),
                        contents: format!(
                            "{header}within {pkg}.Instances;\npackage Bindings {}\n  annotation (\n    {},\n    {});\nend Bindings;\n",
                            string_literal(&format!("Instances of {} bound to their OPC UA nodes", m.namespace_uri(ns))),
                            text::documentation(
                                "<p>One model per instance: the instance with a read or write block of \
                                 <code>OpcUaSupport.Interfaces</code> for each of its variables. See \
                                 <code>OpcUaSupport.UsersGuide</code>.</p>"
                            ),
                            text::PACKAGE_ICON
                        ),
                    });
                    files.push(OutFile { path: dir.join("package.order"), contents: lines(&subs["Instances.Bindings"]) });
                }
                top_order.push(sub.to_string());
                if sub == "Types" && self.top_files.get(&ns).is_some_and(|t| t.contains_key("EnumerationValues")) {
                    top_order.push("EnumerationValues".into());
                }
                let dir = root.join(sub);
                files.push(OutFile {
                    path: dir.join("package.mo"),
                    contents: format!(
                        "{header}within {pkg};\npackage {sub} {}\n  annotation (\n    {},\n    {});\nend {sub};\n",
                        string_literal(&format!("{what} of {}", m.namespace_uri(ns))),
                        text::documentation(&format!(
                            "<p>{what} of the OPC UA namespace {}.</p>",
                            text::html_escape(m.namespace_uri(ns))
                        )),
                        text::PACKAGE_ICON
                    ),
                });
                files.push(OutFile { path: dir.join("package.order"), contents: lines(&order) });
            }
            for (ident, body) in self.top_files.remove(&ns).unwrap_or_default() {
                if !top_order.contains(&ident) {
                    top_order.push(ident.clone());
                }
                files.push(OutFile {
                    path: root.join(format!("{ident}.mo")),
                    contents: format!("{header}within {pkg};\n{body}"),
                });
            }
            files.push(OutFile { path: root.join("package.order"), contents: lines(&top_order) });
            files.push(OutFile {
                path: root.join("package.mo"),
                contents: format!("{header}{}", package_mo(ctx, ns, subset == Some(ns))),
            });
        }
        files
    }
}

fn lines(v: &[String]) -> String {
    let mut s = v.join("\n");
    s.push('\n');
    s
}

/// The `package.mo` of a namespace package.
fn package_mo(ctx: &Ctx, ns: u16, subset: bool) -> String {
    let m = ctx.m;
    let pkg = &ctx.pkg[ns as usize];
    let uri = m.namespace_uri(ns);
    let info = m.models.iter().find(|mi| mi.ns == ns);
    let mut ann = Vec::new();
    if let Some(v) = info.and_then(|i| i.version.as_deref()) {
        ann.push(format!("version={}", string_literal(v)));
    }
    let mut uses: Vec<String> = Vec::new();
    if let Some(i) = info {
        for r in &i.required {
            let Some(rns) = m.namespaces.iter().position(|n| *n == r.uri) else { continue };
            if rns as u16 == ns {
                continue;
            }
            let version =
                m.models.iter().find(|x| x.uri == r.uri).and_then(|x| x.version.clone()).or_else(|| r.version.clone());
            let entry = match version {
                Some(v) => format!("{}(version={})", ctx.pkg[rns], string_literal(&v)),
                None => ctx.pkg[rns].clone(),
            };
            if !uses.contains(&entry) {
                uses.push(entry);
            }
        }
    }
    uses.push(format!("{}(version={})", support::PACKAGE, string_literal(support::VERSION)));
    ann.push(format!("uses({})", uses.join(", ")));
    let mut doc = format!("<p>Generated from the OPC UA information model <code>{}</code>", text::html_escape(uri));
    if let Some(i) = info {
        if let Some(v) = &i.version {
            doc.push_str(&format!(", version {}", text::html_escape(v)));
        }
        if let Some(d) = &i.publication_date {
            doc.push_str(&format!(", published {}", text::html_escape(d)));
        }
    }
    doc.push_str(".</p>");
    if subset {
        doc.push_str("<p>This package holds only the part of the namespace that the other generated packages use.</p>");
    }
    ann.push(text::documentation(&doc));
    ann.push(text::PACKAGE_ICON.to_string());
    ann.push(format!("__OPCUA(namespaceUri={})", string_literal(uri)));
    let desc = if subset {
        format!("OPC UA namespace {uri} (the part the generated packages use)")
    } else {
        format!("OPC UA namespace {uri}")
    };
    format!(
        "within;\npackage {pkg} {}\n  annotation (\n    {});\nend {pkg};\n",
        string_literal(&desc),
        ann.join(",\n    ")
    )
}

/// Plans the classes of a namespace: every ObjectType and every top-level instance object.
fn plan_namespace(ctx: &mut Ctx, ns: u16) {
    let m = ctx.m;
    for ix in (0..m.nodes.len() as u32).map(NodeIx) {
        if m.node(ix).id.ns == ns && m.node(ix).class == NodeClass::ObjectType {
            ctx.type_class(ix);
        }
    }
    let names = ctx.names(ns);
    for &top in &names.top_instances {
        if m.node(top).class == NodeClass::Object {
            ctx.plan_instance(top);
        }
    }
}

fn emit_namespace(ctx: &mut Ctx, ns: u16, out: &mut Output) {
    let m = ctx.m;
    let nodes: Vec<NodeIx> = (0..m.nodes.len() as u32).map(NodeIx).filter(|&ix| m.node(ix).id.ns == ns).collect();
    for &ix in &nodes {
        if m.node(ix).class == NodeClass::DataType {
            emit_datatype(ctx, ix, out);
        }
    }
    for &ix in &nodes {
        if m.node(ix).class == NodeClass::ObjectType && ctx.class_infos.contains_key(&plan::ClassKey::Type(ix)) {
            emit_owner(ctx, Owner::Type(ix), out);
        }
    }
    let names = ctx.names(ns);
    for &top in &names.top_instances {
        if m.node(top).class == NodeClass::Object {
            emit_owner(ctx, Owner::Instance(top), out);
        }
    }
    if !names.top_instances.is_empty() {
        let body = ctx.objects_model(ns);
        out.add(ns, "Instances", "Objects", body);
    }
    for &top in &names.top_instances {
        if m.node(top).class == NodeClass::Object {
            let binding = ctx.binding_model(ns, top);
            let bound = binding.is_some();
            if let Some(body) = binding {
                out.add(ns, "Instances.Bindings", &names.instances[&top], body);
            }
            let example = ctx.example_model(ns, top, bound);
            out.add(ns, "Examples", &names.instances[&top], example);
        }
    }
    emit_enumeration_values(ctx, ns, out);
}

fn emit_enumeration_values(ctx: &mut Ctx, ns: u16, out: &mut Output) {
    let enums = out.enums.get(&ns).cloned().unwrap_or_default();
    if !enums.is_empty() {
        let body = ctx.enumeration_values(ns, &enums);
        out.top_files.entry(ns).or_default().insert("EnumerationValues".into(), body);
    }
}

fn emit_datatype(ctx: &mut Ctx, dt: NodeIx, out: &mut Output) {
    if !out.emitted_types.insert(dt) {
        return;
    }
    let ns = ctx.m.node(dt).id.ns;
    if let Some((ident, body)) = ctx.datatype_class(dt) {
        if matches!(ctx.m.data_types.get(&dt).map(|i| &i.kind), Some(crate::model::DataTypeKind::Enumeration { .. })) {
            out.enums.entry(ns).or_default().push(dt);
        }
        out.add(ns, "Types", &ident, body);
    }
}

/// Writes the classes of an owner: its main class and its declaration classes.
fn emit_owner(ctx: &mut Ctx, owner: Owner, out: &mut Output) {
    if !out.emitted_owners.insert(owner) {
        return;
    }
    let ns = ctx.m.node(owner.node()).id.ns;
    let Some(plan) = ctx.plans.remove(&owner) else { return };
    let names = ctx.names(ns);
    let owner_ident = names.owners[&owner].clone();
    if let Some(main) = &plan.main {
        let (sub, ident) = match owner {
            Owner::Type(t) => ("ObjectTypes".to_string(), names.object_types[&t].clone()),
            Owner::Instance(i) => ("Instances".to_string(), names.instances[&i].clone()),
        };
        let body = render_class(ctx, main, &ident);
        out.add(ns, &sub, &ident, body);
    }
    for (path, decl) in &plan.decls {
        let ident = ctx::decl_class_ident(&owner_ident, &ctx.decl_names[&(owner, path.clone())]);
        let body = render_class(ctx, decl, &ident);
        out.add(ns, "Declarations", &ident, body);
    }
    // The complete variants of the classes that leave inputs unbound (`complete.rs`).
    let mains = plan.main.iter().filter_map(|main| match owner {
        Owner::Type(t) => Some((plan::ClassKey::Type(t), main)),
        Owner::Instance(_) => None,
    });
    let decls = plan.decls.iter().map(|(path, decl)| (plan::ClassKey::Decl(owner, path.clone()), decl));
    for (key, class) in mains.chain(decls) {
        if let Some((ns, ident, variant)) = complete::complete_plan(ctx, &key, class) {
            let body = render_class(ctx, &variant, &ident);
            out.add(ns, "Complete", &ident, body);
        }
    }
    ctx.plans.insert(owner, plan);
}

/// A class name where a component is declared (or a class alias or redeclaration names the class of one): a
/// class partial by its inputs is replaced by its complete variant.
fn type_ref(ctx: &mut Ctx, t: &TypeRef) -> String {
    match t {
        TypeRef::Path(p) => p.clone(),
        TypeRef::Class(k) => ctx.component_class_path(k),
    }
}

fn render_mod(ctx: &mut Ctx, m: &Mod) -> String {
    match m {
        Mod::Value { ident, is_final, attrs, value } => {
            let mut s = String::new();
            if *is_final {
                s.push_str("final ");
            }
            s.push_str(ident);
            if !attrs.is_empty() {
                s.push_str(&format!("({})", attrs.join(", ")));
            }
            if let Some(v) = value {
                s.push_str(&format!("={}", render_value(ctx, v)));
            }
            s
        }
        Mod::Nested { ident, mods } => {
            let inner = render_parts(ctx, mods);
            if inner.is_empty() {
                // Only pins, and the class has no choice to repeat: no modifier at all.
                String::new()
            } else {
                format!("{ident}({})", inner.join(", "))
            }
        }
        Mod::Redeclare { ident, class } => format!("redeclare model {ident} = {}", type_ref(ctx, class)),
        Mod::Pin { class } => pinned(ctx, class).join(", "),
        Mod::PinVia { .. } | Mod::Repin { .. } => render_parts(ctx, std::slice::from_ref(m)).join(", "),
    }
}

/// The modifiers of a modification list, a [`Mod::Pin`] expanded, empty ones left out.
fn render_parts(ctx: &mut Ctx, mods: &[Mod]) -> Vec<String> {
    mods.iter()
        .flat_map(|x| match x {
            Mod::Pin { class } => pinned(ctx, class),
            Mod::PinVia { pin, class } => {
                pins(ctx, class).into_iter().map(|(a, _)| format!("redeclare model {a} = {}", pin_alias(pin, &a))).collect()
            }
            Mod::Repin { ident, pin, class, declared } => {
                let old: BTreeSet<String> = pin_choices(ctx, declared).into_iter().map(|(a, _)| a).collect();
                let (via, nested): (Vec<_>, Vec<_>) = pins(ctx, class).into_iter().partition(|(a, _)| old.contains(a));
                let mut parts: Vec<String> =
                    via.into_iter().map(|(a, path)| format!("redeclare model {} = {path}", pin_alias(pin, &a))).collect();
                if !nested.is_empty() {
                    let inner: Vec<String> = nested.into_iter().map(|(a, path)| format!("redeclare model {a} = {path}")).collect();
                    parts.push(format!("{ident}({})", inner.join(", ")));
                }
                parts
            }
            _ => vec![render_mod(ctx, x)],
        })
        .filter(|s| !s.is_empty())
        .collect()
}

/// The redeclarations a [`Mod::Pin`] on a component of `class` stands for, one per alias.
fn pinned(ctx: &mut Ctx, class: &plan::ClassKey) -> Vec<String> {
    pins(ctx, class).into_iter().map(|(a, path)| format!("redeclare model {a} = {path}")).collect()
}

/// The choices a pin on a component of `class` repeats: each of its aliases that some class redeclares, with
/// the class `class` chooses for it.
fn pins(ctx: &mut Ctx, class: &plan::ClassKey) -> Vec<(String, String)> {
    pin_classes(ctx, class).into_iter().map(|(a, path, _)| (a, path)).collect()
}

/// [`pins`], with the class that constrains each choice when the choice is a complete variant (the partial
/// class, as the alias it repeats is constrained: a redeclaration may choose any model extending it).
fn pin_classes(ctx: &mut Ctx, class: &plan::ClassKey) -> Vec<(String, String, Option<String>)> {
    let mut out = Vec::new();
    for (alias, k) in pin_choices(ctx, class) {
        let partial = ctx.class_infos.get(&k).is_some_and(|i| i.is_partial_by_inputs());
        let constraint = partial.then(|| ctx.class_path(&k));
        out.push((alias, ctx.component_class_path(&k), constraint));
    }
    out
}

/// The choices of `class` that a pin repeats, by name: each alias of its components that some class redeclares
/// ([`Ctx::redeclared`](ctx::Ctx::redeclared)) and, for a component declared through an alias, each of the pin
/// aliases holding that component's pins that some class redeclares ([`plan::Pinned`]); with the class chosen.
/// A pin alias is redeclared by a derived class ([`Mod::Repin`]) and, like any alias, leaks into nested
/// components in rumoca, so it is pinned like one.
fn pin_choices(ctx: &Ctx, class: &plan::ClassKey) -> Vec<(String, plan::ClassKey)> {
    let Some(info) = ctx.class_infos.get(class) else { return Vec::new() };
    let mut out = Vec::new();
    for e in &info.elements {
        let ElemKind::Object { class: k } = &e.kind else { continue };
        if let Some(alias) = e.alias.as_ref().filter(|a| ctx.redeclared.contains(*a)) {
            out.push((alias.clone(), k.clone()));
        }
        if let Some(p) = &e.pinned {
            // The pin aliases the declaring class has, with the choices of the component's class here.
            let declared: BTreeSet<String> = pin_choices(ctx, &p.declared).into_iter().map(|(a, _)| a).collect();
            for (a, c) in pin_choices(ctx, k) {
                let name = pin_alias(&p.pin, &a);
                if declared.contains(&a) && ctx.redeclared.contains(&name) {
                    out.push((name, c));
                }
            }
        }
    }
    out
}

/// The pin aliases that derived classes redeclare ([`Mod::Repin`]), given the aliases known to be redeclared.
fn repinned_aliases(ctx: &Ctx) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    each_mod(&ctx.plans, &mut |m| {
        if let Mod::Repin { pin, class, declared, .. } = m {
            let old: BTreeSet<String> = pin_choices(ctx, declared).into_iter().map(|(a, _)| a).collect();
            for (a, _) in pin_choices(ctx, class) {
                if old.contains(&a) {
                    out.insert(pin_alias(pin, &a));
                }
            }
        }
    });
    out
}

/// The aliases that some class redeclares (`redeclare model X = ...` in any modification of any plan).
fn redeclared_aliases(plans: &BTreeMap<Owner, OwnerPlan>) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    each_mod(plans, &mut |m| {
        if let Mod::Redeclare { ident, .. } = m {
            out.insert(ident.clone());
        }
    });
    out
}

/// Calls `f` with every modifier of every plan, nested ones included.
fn each_mod(plans: &BTreeMap<Owner, OwnerPlan>, f: &mut impl FnMut(&Mod)) {
    fn walk(mods: &[Mod], f: &mut impl FnMut(&Mod)) {
        for m in mods {
            f(m);
            if let Mod::Nested { mods, .. } = m {
                walk(mods, f);
            }
        }
    }
    for plan in plans.values() {
        for class in plan.main.iter().chain(plan.decls.iter().map(|(_, c)| c)) {
            if let Some((_, mods)) = &class.extends {
                walk(mods, f);
            }
            for item in &class.items {
                if let Item::Decl { mods, .. } = item {
                    walk(mods, f);
                }
            }
        }
    }
}

/// A modification list: inline when short, else one modifier per line.
fn render_mods(ctx: &mut Ctx, mods: &[Mod], indent: usize) -> String {
    if mods.is_empty() {
        return String::new();
    }
    let parts = render_parts(ctx, mods);
    if parts.is_empty() {
        return String::new();
    }
    let inline = parts.join(", ");
    if inline.len() + indent <= 90 && !inline.contains('\n') {
        format!("({inline})")
    } else {
        let pad = " ".repeat(indent + 2);
        format!("(\n{pad}{})", parts.join(&format!(",\n{pad}")))
    }
}

/// A planned value as Modelica.
fn render_value(ctx: &mut Ctx, v: &Value) -> String {
    match v {
        Value::Text(t) => t.clone(),
        Value::Of { node, ty, dims } => ctx.value_of(*node, ty, dims.as_deref()),
        Value::Fill { ty, sizes } => format!("fill({}, {})", ctx.default_literal(ty), sizes.join(", ")),
        Value::Each { ty, count } => format!("{{{} for i in 1:{count}}}", ctx.default_literal(ty)),
    }
}

fn render_class(ctx: &mut Ctx, plan: &ClassPlan, ident: &str) -> String {
    let mut s = format!("{} {ident} {}\n", plan.keyword, plan.desc);
    if let Some((base, mods)) = &plan.extends {
        let base = match base {
            TypeRef::Path(p) => p.clone(),
            TypeRef::Class(k) => ctx.class_path(k),
        };
        let mods = render_mods(ctx, mods, 2);
        s.push_str(&format!("  extends {base}{mods};\n"));
    }
    for item in &plan.items {
        match item {
            Item::Comment(c) => s.push_str(&format!("  // {c}\n")),
            Item::Alias { ident, class, desc } => {
                // A complete variant as the default: a redeclaration may choose any model that extends the
                // partial class (and connects the inputs the variant binds).
                let constraint = match class {
                    TypeRef::Class(k) if ctx.class_infos.get(k).is_some_and(|i| i.is_partial_by_inputs()) => {
                        format!(" constrainedby {}", ctx.class_path(k))
                    }
                    _ => String::new(),
                };
                let class = type_ref(ctx, class);
                s.push_str(&format!("  replaceable model {ident} = {class}{constraint}\n    {desc};\n"));
            }
            Item::PinAliases { alias, pin, class } => {
                for (a, path, constraint) in pin_classes(ctx, class) {
                    let desc = string_literal(&format!("Class of {a} in {alias}; redeclare it together with {alias}"));
                    let constraint = constraint.map(|c| format!(" constrainedby {c}")).unwrap_or_default();
                    s.push_str(&format!("  replaceable model {} = {path}{constraint}\n    {desc};\n", pin_alias(pin, &a)));
                }
            }
            Item::Decl { prefix, ty, ident, dims, mods, value, cond, desc, annotation } => {
                let ty = type_ref(ctx, ty);
                let mut line = String::from("  ");
                if !prefix.is_empty() {
                    line.push_str(prefix);
                    line.push(' ');
                }
                line.push_str(&format!("{ty} {ident}{dims}"));
                line.push_str(&render_mods(ctx, mods, 4));
                if let Some(v) = value {
                    line.push_str(&format!(" = {}", render_value(ctx, v)));
                }
                if let Some(c) = cond {
                    line.push_str(&format!(" if {c}"));
                }
                line.push_str(&format!("\n    {desc}"));
                if !annotation.is_empty() {
                    line.push_str(&format!("\n    annotation ({annotation})"));
                }
                line.push_str(";\n");
                s.push_str(&line);
            }
        }
    }
    if !plan.equations.is_empty() {
        s.push_str("equation\n");
        for e in &plan.equations {
            s.push_str(&text::indent(e, 2));
        }
    }
    let mut ann = Vec::new();
    if !plan.doc_html.is_empty() {
        ann.push(text::documentation(&plan.doc_html));
    }
    if plan.keyword.ends_with("model") {
        ann.push(text::MODEL_ICON.to_string());
    } else if plan.keyword == "record" {
        ann.push(text::RECORD_ICON.to_string());
    }
    ann.push(plan.opcua.clone());
    s.push_str(&format!("  annotation (\n    {});\nend {ident};\n", ann.join(",\n    ")));
    s
}

#[cfg(test)]
mod tests;
#[cfg(test)]
mod plan_tests;
