//! nodeset-compiler: OPC UA NodeSet2 information models to typed Rust and Modelica.
//!
//! # From NodeSet2 files to a running server
//!
//! Say you have `nodesets/MyCell.NodeSet2.xml`, your cell's information model, which requires DI and Robotics,
//! and the OPC Foundation's files in `nodesets/vendor` (`cargo xtask fetch-nodesets` pins them for this
//! workspace).
//!
//! **1. Check the files.** `nodeset-compiler check nodesets/MyCell.NodeSet2.xml --models nodesets/vendor` finds
//! the required models in the folder by ModelUri, resolves everything and prints each problem with
//! `file:line:col`, the source line and a hint, like rustc. `--deny warnings` makes warnings errors; `--warn
//! CODE` demotes an error that has a safe recovery (`nodeset-compiler codes` lists them). The library call is
//! [`compile`] (see [Pipeline](#pipeline)).
//!
//! **2. Generate Rust in your crate's build script**, with [`build::Builder`]. Namespaces that another crate
//! already holds are mapped to it instead of being generated again:
//!
//! ```rust,no_run
//! // build.rs (build-dependency: nodeset-compiler)
//! fn main() {
//!     nodeset_compiler::build::Builder::new()
//!         .file("nodesets/MyCell.NodeSet2.xml")
//!         .models_dir("nodesets/vendor")
//!         .extern_namespace("http://opcfoundation.org/UA/DI/", "nodeset_models::models::di")
//!         .extern_namespace("http://opcfoundation.org/UA/Robotics/", "nodeset_models::models::robotics")
//!         .generate()
//!         .unwrap_or_else(|e| panic!("{e}"));
//! }
//! ```
//!
//! and in `src/main.rs`, `mod my_cell_models { include!(concat!(env!("OUT_DIR"), "/nodesets.rs")); }`: one module
//! per namespace, named by the URI's last segment (`my_cell`), for the file's models and every model they
//! require that is not mapped, and `register`, as `nodeset-compiler rust` writes them ([`run_rust`]).
//!
//! Each namespace module holds NodeId constants that carry the namespace URI (`ids`), the data types with
//! their encodings (`types`, and `TypeLoader`), the address space as a static table (`TABLE`) and typed
//! handles of the instances (`objects`). A failed generation leaves the previous output as it was.
//!
//! **3. Serve it** with the runtime (`nodeset_models::runtime`, the crate `nodeset-runtime`):
//!
//! ```rust,no_run
//! # // Your crate, from step 2; here a namespace of nodeset-models stands in for it.
//! # mod my_cell_models {
//! #     use nodeset_models::runtime::server::ServerConfig;
//! #     pub fn register(config: ServerConfig) -> ServerConfig {
//! #         use nodeset_models::models::drilling_process as my_cell;
//! #         config.table(&my_cell::TABLE).type_loader(my_cell::TypeLoader)
//! #     }
//! # }
//! use nodeset_models::runtime::server::ServerConfig;
//!
//! #[tokio::main]
//! async fn main() -> Result<(), String> {
//!     // The namespaces of nodeset-models (DI, IA, Robotics, ...), then yours, dependencies first.
//!     let config = nodeset_models::models::register(ServerConfig::new("My cell"));
//!     let config = my_cell_models::register(config).port(4840);
//!     config.build()?.run().await
//! }
//! ```
//!
//! The server is secure by default: encrypted endpoints only, an application certificate created on first
//! start in the PKI folder (`pki/<name>` by default), client certificates trusted by moving them from
//! `rejected/` to `trusted/`, users
//! from a user file with Argon2id hashes, and the RolePermissions of your nodeset applied to its nodes. A
//! SecurityPolicy None endpoint exists only when asked for (`ServerConfig::insecure()`, for loopback tests).
//!
//! **4. And then:** `nodeset-compiler verify opc.tcp://host:4840/ nodesets/MyCell.NodeSet2.xml --models
//! nodesets/vendor --pki verify-pki` checks any live server, whatever its stack, against the nodesets; the
//! runtime's `client` binds the generated type handles to instances on a live server for typed reads, writes,
//! subscriptions and program runs; `nodeset-compiler modelica nodesets/MyCell.NodeSet2.xml --models
//! nodesets/vendor --out DIR` writes Modelica packages of the same model ([`emit::modelica`]). The workspace
//! README walks through each with the pinned companion specifications.
//!
//! # Pipeline
//!
//! The pipeline, one module per stage:
//!
//! ```text
//! parse    one file -> raw::RawNodeSet (lossless, byte spans)
//! load     files + model folders -> load::Loaded (dependency order, one namespace table)
//! resolve  Loaded -> model::Model (one arena, inverse references, types, members, data types,
//!          method arguments, state machines, value checks)
//! ```
//!
//! Every stage reports problems as [`diag::Diagnostic`]s with stable codes; [`compile`] runs the stages and
//! returns the model with every diagnostic.
//!
//! ```no_run
//! use nodeset_compiler::{compile, Options, load::Input};
//! let opts = Options { model_dirs: vec!["nodesets/vendor".into()], ..Options::default() };
//! let out = compile(vec![Input::Path("nodesets/vendor/Opc.Ua.Robotics.NodeSet2.xml".into())], &opts);
//! eprint!("{}", out.diagnostics.render(&out.model.sources));
//! assert!(!out.diagnostics.has_errors());
//! ```

#![deny(missing_docs)]
pub mod build;
pub mod datatypes;
pub mod diag;
pub mod emit;
pub mod fxhash;
pub mod load;
pub mod model;
pub mod names;
pub mod nodeid;
mod par;
pub mod parse;
pub mod raw;
pub mod resolve;
#[cfg(feature = "serve")]
pub mod serve;
pub mod source;
pub mod summary;
pub mod timing;
pub mod value;
pub mod verify;
pub mod write;

pub use diag::Error;
use diag::{Diagnostics, Severities, Severity};
use load::{Input, LoadOptions};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// What [`compile`] does: the configuration every front door (the command line, [`build::Builder`],
/// `cargo xtask generate`) fills in, each from its own flags or methods.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Folders searched recursively for required models.
    pub model_dirs: Vec<PathBuf>,
    /// `--allow`/`--warn`/`--deny CODE` and `--deny warnings`, applied to every stage's diagnostics.
    pub severities: Severities,
    /// Also report warnings of files that were only loaded as dependencies.
    pub all_warnings: bool,
    /// Size limits of the XML reader.
    pub limits: parse::Limits,
}

/// The model and everything said about it.
#[derive(Debug)]
pub struct Compiled {
    /// The resolved model (with every recovery made, whether or not errors remain).
    pub model: model::Model,
    /// What every stage said, with the severity settings applied, sorted.
    pub diagnostics: Diagnostics,
}

impl Compiled {
    /// Whether no error remains (after the severity settings were applied).
    pub fn ok(&self) -> bool {
        !self.diagnostics.has_errors()
    }

    /// Every diagnostic, rendered like rustc's.
    pub fn render_diagnostics(&self) -> String {
        self.diagnostics.render(&self.model.sources)
    }
}

/// Parses, loads and resolves. Stops after loading when loading found errors (a missing model would make
/// every reference into it dangle), so the user sees the cause, not a thousand consequences.
pub fn compile(inputs: Vec<Input>, opts: &Options) -> Compiled {
    let mut diags = Diagnostics::new();
    let load_opts = LoadOptions { model_dirs: opts.model_dirs.clone(), limits: opts.limits.clone() };
    let _t = timing::span("compile");
    let mut loaded = {
        let _t = timing::span("load");
        load::load(inputs, &load_opts, &mut diags)
    };
    // Demoted errors of loading (`--warn NS0110`) do not stop it.
    diags.apply(&opts.severities);
    if diags.has_errors() {
        loaded.files.clear();
    }
    let model = {
        let _t = timing::span("resolve");
        resolve::resolve(loaded, &mut diags)
    };
    finish(model, diags, opts)
}

/// How the Rust back end is configured by a front door: module names, namespaces generated elsewhere, the
/// runtime's path. [`run_rust`] plans a run with it and [`RustOptions::config_of`] turns it into the emitter's
/// [`emit::rust::RustConfig`].
#[derive(Clone, Debug)]
pub struct RustOptions {
    /// Module names by namespace URI (default: the rule of [`emit::plan::Plan::module_names`]).
    pub modules: BTreeMap<String, String>,
    /// Namespaces generated elsewhere: URI -> Rust path of their module (`--extern URI=PATH`).
    pub extern_paths: BTreeMap<String, String>,
    /// The Rust path of the runtime module.
    pub runtime_path: String,
    /// The command named in the generated files' headers.
    pub command: String,
}

impl Default for RustOptions {
    fn default() -> RustOptions {
        RustOptions {
            modules: BTreeMap::new(),
            extern_paths: BTreeMap::new(),
            runtime_path: "nodeset_models::runtime".into(),
            command: "nodeset-compiler rust ...".into(),
        }
    }
}

impl RustOptions {
    /// The emitter's configuration for the namespaces `uris`, generated in this order (the order in which
    /// `mod.rs` registers them, [`generate_rust`]), each module named by [`emit::plan::Plan::module_names_beside`]
    /// with the names of the mapped namespaces' modules (the last segment of each extern path) reserved.
    /// [`Error::Config`] when a path is not a Rust path ([`RustOptions::paths`]).
    pub fn config_of(&self, uris: &[String]) -> Result<emit::rust::RustConfig, Error> {
        self.check_modules()?;
        let (extern_paths, runtime_path) = self.paths()?;
        let plan = emit::plan::Plan { generated: uris.to_vec(), ..emit::plan::Plan::default() };
        let reserved: Vec<String> = self
            .extern_paths
            .values()
            .filter_map(|p| p.rsplit("::").next())
            .map(|s| s.trim().to_string())
            .collect();
        let modules = plan.module_names_beside(&self.modules, &reserved);
        let namespaces =
            uris.iter().map(|u| emit::rust::RustNamespace { uri: u.clone(), module: modules[u].clone() }).collect();
        Ok(emit::rust::RustConfig { namespaces, extern_paths, runtime_path, command: self.command.clone() })
    }

    /// Checks every setting before anything is read, so that a typo costs nothing: the module names
    /// ([`RustOptions::check_modules`]) and the paths ([`RustOptions::paths`]).
    pub fn check(&self) -> Result<(), Error> {
        self.check_modules()?;
        self.paths().map(|_| ())
    }

    /// Each module name given is a Rust identifier that is not a keyword, and no two namespaces share one:
    /// [`Error::Config`] otherwise, naming the first offender.
    pub fn check_modules(&self) -> Result<(), Error> {
        let mut seen: BTreeMap<&str, &str> = BTreeMap::new();
        for (uri, name) in &self.modules {
            if syn::parse_str::<syn::Ident>(name).is_err() {
                return Err(Error::Config(format!(
                    "the module name of {uri}, `{name}`, is not a Rust identifier (or is a keyword); give one such as `robotics`"
                )));
            }
            if let Some(other) = seen.insert(name, uri) {
                return Err(Error::Config(format!("{other} and {uri} are both given the module name `{name}`; give each its own")));
            }
        }
        Ok(())
    }

    /// The extern paths and the runtime path, each checked to be a Rust path: [`Error::Config`] names the first
    /// that is not.
    pub fn paths(&self) -> Result<(BTreeMap<String, emit::rust::RustPath>, emit::rust::RustPath), Error> {
        let runtime = emit::rust::RustPath::new(&self.runtime_path).map_err(|e| {
            Error::Config(format!("the runtime path {e}; give the path of the runtime module, such as `nodeset_models::runtime`"))
        })?;
        let mut externs = BTreeMap::new();
        for (uri, text) in &self.extern_paths {
            let path = emit::rust::RustPath::new(text).map_err(|e| {
                Error::Config(format!(
                    "the extern path of {uri}: {e}; give the path of the module generated for that namespace, such as `nodeset_models::models::di`"
                ))
            })?;
            externs.insert(uri.clone(), path);
        }
        Ok((externs, runtime))
    }
}

impl Compiled {
    /// The front doors' check after compiling: fails with [`Error::Diagnostics`] when errors remain, and
    /// returns the rendered warnings otherwise.
    pub fn checked(&mut self, severities: &Severities) -> Result<String, Error> {
        self.diagnostics.finalize(severities, &self.model.sources, "the NodeSet2 files do not compile")
    }
}

/// Generates Rust for `model` as one module tree: each namespace's files, the `mod.rs` that declares the
/// namespaces and registers them with a server in `cfg`'s order (dependencies first), and `rustfmt.toml`. The
/// emitter's diagnostics, with `earlier` ones (such as planning's), are finalised: the files and the rendered
/// warnings, or [`Error::Diagnostics`].
pub fn generate_rust(
    model: &model::Model,
    cfg: &emit::rust::RustConfig,
    earlier: diag::Diagnostics,
    severities: &Severities,
) -> Result<(Vec<write::OutFile>, String), Error> {
    generate_rust_tree(model, cfg, earlier, severities).map(|(files, rendered, _)| (files, rendered))
}

/// [`generate_rust`], with the warnings that remain also as items.
fn generate_rust_tree(
    model: &model::Model,
    cfg: &emit::rust::RustConfig,
    earlier: diag::Diagnostics,
    severities: &Severities,
) -> Result<(Vec<write::OutFile>, String, Diagnostics), Error> {
    let mut gen = {
        let _t = timing::span("emit rust");
        emit::rust::generate(model, cfg)
    };
    gen.diagnostics.extend(earlier);
    let rendered = gen.diagnostics.finalize(severities, &model.sources, "Rust generation failed")?;
    let mut files = gen.files;
    files.extend(emit::rust::top_files(model, cfg));
    Ok((files, rendered, gen.diagnostics))
}

/// Generates Modelica for `model` and finalises the emitter's diagnostics, like [`generate_rust`].
pub fn generate_modelica(
    model: &model::Model,
    cfg: &emit::modelica::ModelicaConfig,
    severities: &Severities,
) -> Result<(Vec<write::OutFile>, String), Error> {
    let mut gen = emit::modelica::generate_with_diagnostics(model, cfg);
    let rendered = gen.diagnostics.finalize(severities, &model.sources, "Modelica generation failed")?;
    Ok((gen.files, rendered))
}

/// One complete run of the `rust` command: what the plan generated and mapped, the module name of each
/// generated namespace, the files (with the `mod.rs` that lists the modules and `rustfmt.toml`) and the
/// rendered warnings.
#[derive(Debug)]
pub struct RustRun {
    /// Which namespaces were generated and which mapped to existing code (`--extern`).
    pub plan: emit::plan::Plan,
    /// Module names by namespace URI, of the generated namespaces.
    pub modules: BTreeMap<String, String>,
    /// The files to write.
    pub files: Vec<write::OutFile>,
    /// The warnings of planning and generation, rendered.
    pub warnings: String,
    /// The same warnings, one item each (a build script prints each as a `cargo:warning`).
    pub diagnostics: diag::Diagnostics,
}

/// The `rust` command's complete run over `model`: every loaded model that `rust` does not map
/// (`extern_paths`) is generated beside the named ones, so that the output compiles on its own; the base
/// namespace comes from async-opcua (naming its file is NS0303). Planning and generation end with the same
/// severity settings as compiling ([`diag::Diagnostics::finalize`]); [`Error::Diagnostics`] when errors remain.
pub fn run_rust(model: &model::Model, rust: &RustOptions, severities: &Severities) -> Result<RustRun, Error> {
    const STAGE: &str = "Rust generation failed";
    let (plan, mut planning) = emit::plan::plan(model, &rust.extern_paths, true);
    planning.extend(emit::plan::mapped_requirements(model, &plan));
    // A refused plan (NS0303, NS0304) stops before anything is generated.
    planning.finalize(severities, &model.sources, STAGE)?;
    let cfg = rust.config_of(&plan.generated)?;
    let modules = cfg.namespaces.iter().map(|n| (n.uri.clone(), n.module.clone())).collect();
    let (files, warnings, diagnostics) = generate_rust_tree(model, &cfg, planning, severities)?;
    Ok(RustRun { plan, modules, files, warnings, diagnostics })
}

/// One complete run of the `modelica` command: the plan, the files and the rendered warnings.
#[derive(Debug)]
pub struct ModelicaRun {
    /// Which namespaces were generated and which mapped to existing packages (`--extern`).
    pub plan: emit::plan::Plan,
    /// The files to write.
    pub files: Vec<write::OutFile>,
    /// The warnings of generation, rendered.
    pub warnings: String,
}

/// The `modelica` command's complete run over `model`: every loaded model not mapped to an existing package
/// (`packages`: URI -> package name) is generated, the base namespace completely when its file is named and
/// otherwise the part the packages use (`OpcUa`). Ends like [`run_rust`].
pub fn run_modelica(model: &model::Model, packages: &BTreeMap<String, String>, severities: &Severities) -> Result<ModelicaRun, Error> {
    // For Modelica the base namespace is a package like any other: the plan has nothing to refuse.
    let (plan, _) = emit::plan::plan(model, packages, false);
    let mut cfg = emit::modelica::ModelicaConfig::new();
    cfg.namespaces = plan.generated.clone();
    if model.models.iter().any(|m| m.uri == load::NS0_URI && model.sources.get(m.file).named) {
        cfg.namespaces.insert(0, load::NS0_URI.to_string());
    }
    cfg.package_names = packages.clone();
    let (files, warnings) = generate_modelica(model, &cfg, severities)?;
    Ok(ModelicaRun { plan, files, warnings })
}

fn finish(model: model::Model, mut diags: Diagnostics, opts: &Options) -> Compiled {
    if !opts.all_warnings {
        // Warnings about files the user did not name are not the user's problem.
        diags.items.retain(|d| {
            d.severity == Severity::Error || d.span.is_none_or(|s| model.sources.get(s.file).named)
        });
    }
    diags.apply(&opts.severities);
    diags.sort(&model.sources);
    Compiled { model, diagnostics: diags }
}

#[cfg(test)]
mod tests {
    /// Through the front doors' options, the last segment of each extern path is a reserved module name: a
    /// vendor `.../Robotics/` beside a mapping of the OPC Foundation's Robotics takes `ua_robotics`.
    #[test]
    fn extern_paths_reserve_their_module_names() {
        let generated = vec!["http://vendor.example.com/UA/Robotics/".to_string(), "http://vendor.example.com/UA/Device/".to_string()];
        let mut rust = crate::RustOptions::default();
        rust.extern_paths.insert("http://opcfoundation.org/UA/Robotics/".into(), "nodeset_models::models::robotics".into());
        let cfg = rust.config_of(&generated).unwrap();
        let got: Vec<&str> = cfg.namespaces.iter().map(|n| n.module.as_str()).collect();
        assert_eq!(got, ["ua_robotics", "device"]);
    }
}
