//! The `build.rs` front door: generate Rust for your own NodeSet2 files into `OUT_DIR`.
//!
//! ```no_run
//! // build.rs
//! fn main() {
//!     nodeset_compiler::build::Builder::new()
//!         .file("nodesets/MyRobotCell.NodeSet2.xml")
//!         .models_dir("nodesets/vendor")
//!         // DI and Robotics come from the nodeset-models crate instead of being generated again.
//!         .extern_namespace("http://opcfoundation.org/UA/DI/", "nodeset_models::models::di")
//!         .extern_namespace("http://opcfoundation.org/UA/Robotics/", "nodeset_models::models::robotics")
//!         .generate()
//!         .unwrap_or_else(|e| panic!("{e}"));
//! }
//!
//! // src/main.rs
//! // mod cell { include!(concat!(env!("OUT_DIR"), "/nodesets.rs")); }
//! // ... nodeset_models::models::register(config) then cell::register(config) ...
//! ```
//!
//! It generates what `nodeset-compiler rust` generates ([`crate::run_rust`], one code path): the models of the
//! files, and every model they require that is not mapped with [`Builder::extern_namespace`], plus
//! `register`, which adds the generated namespaces to a server configuration, dependencies first. The mapped
//! namespaces are registered by the code they are mapped to (for nodeset-models,
//! `nodeset_models::models::register`), before. A mapped namespace whose own requirements would be generated
//! here is an error (`NS0304`) that names both models: map the required one too.
//!
//! Every file the compiler reads is printed as `cargo:rerun-if-changed`, warnings as `cargo:warning`. The
//! output file is replaced atomically (written as `.<file>.tmp-<pid>` beside it, then renamed over it); on
//! any error the previous output stays as it was and the error lists the diagnostics.

use crate::diag::{Level, Severities};
use crate::load::Input;
use crate::{compile, Error, Options, RustOptions};
use std::path::PathBuf;

/// The configuration of one generation from a build script; methods chain, [`Builder::generate`] runs it.
#[derive(Clone, Debug, Default)]
pub struct Builder {
    files: Vec<PathBuf>,
    options: Options,
    rust: RustOptions,
    /// Severity settings by name, checked when generating (so that the chain needs no `?`).
    levels: Vec<(Level, String)>,
    out_dir: Option<PathBuf>,
    out_file: Option<String>,
    cargo_output: bool,
}

impl Builder {
    /// A builder that prints `cargo:` lines and generates nothing yet.
    pub fn new() -> Builder {
        let rust = RustOptions { command: "cargo build (build.rs)".into(), ..RustOptions::default() };
        Builder { cargo_output: true, rust, ..Builder::default() }
    }

    /// A NodeSet2 file whose models are generated, with every model they require that is not mapped
    /// ([`Builder::extern_namespace`]): as `nodeset-compiler rust` does, the output compiles on its own.
    pub fn file(mut self, path: impl Into<PathBuf>) -> Self {
        self.files.push(path.into());
        self
    }

    /// A folder searched recursively for the models the files require.
    pub fn models_dir(mut self, path: impl Into<PathBuf>) -> Self {
        self.options.model_dirs.push(path.into());
        self
    }

    /// The module name of a namespace (default: the last segment of its URI in snake case).
    pub fn module_name(mut self, uri: &str, module: &str) -> Self {
        self.rust.modules.insert(uri.into(), module.into());
        self
    }

    /// A namespace generated elsewhere: its module's Rust path. Its types are used, not generated again. The
    /// models it requires must be mapped too (`NS0304` otherwise); the last segment of the path is reserved, so
    /// that no generated namespace gets that module name.
    pub fn extern_namespace(mut self, uri: &str, rust_path: &str) -> Self {
        self.rust.extern_paths.insert(uri.into(), rust_path.into());
        self
    }

    /// The path of the runtime module (default `nodeset_models::runtime`).
    pub fn runtime_path(mut self, path: &str) -> Self {
        self.rust.runtime_path = path.into();
        self
    }

    /// Where to write (default: the `OUT_DIR` cargo gives build scripts).
    pub fn out_dir(mut self, dir: impl Into<PathBuf>) -> Self {
        self.out_dir = Some(dir.into());
        self
    }

    /// The output file name (default `nodesets.rs`).
    pub fn out_file(mut self, name: &str) -> Self {
        self.out_file = Some(name.into());
        self
    }

    /// Whether to print `cargo:` lines (default true; turn off outside build scripts).
    pub fn cargo_output(mut self, on: bool) -> Self {
        self.cargo_output = on;
        self
    }

    /// Turn warnings into errors (`--deny warnings`).
    pub fn deny_warnings(mut self, on: bool) -> Self {
        self.options.severities.deny_warnings(on);
        self
    }

    /// Drop the diagnostics of `code` (`--allow CODE`); an error with a recovery then recovers silently.
    pub fn allow(mut self, code: &str) -> Self {
        self.levels.push((Level::Allow, code.into()));
        self
    }

    /// Report `code` as a warning (`--warn NS0202`); an error with a recovery then recovers.
    pub fn warn(mut self, code: &str) -> Self {
        self.levels.push((Level::Warn, code.into()));
        self
    }

    /// Report `code` as an error (`--deny CODE`, or `"warnings"` for every warning).
    pub fn deny(mut self, code: &str) -> Self {
        self.levels.push((Level::Deny, code.into()));
        self
    }

    /// The severity settings, checked: an unknown code or a demoted error with no recovery is refused.
    fn severities(&self) -> Result<Severities, Error> {
        let mut s = self.options.severities.clone();
        for (level, code) in &self.levels {
            s.set_named(*level, code)?;
        }
        Ok(s)
    }

    /// Compiles, generates and writes. Returns the path written.
    pub fn generate(self) -> Result<PathBuf, Error> {
        let out_dir = match self.out_dir.clone() {
            Some(d) => d,
            None => PathBuf::from(
                std::env::var_os("OUT_DIR").ok_or(Error::Config("OUT_DIR is not set; call out_dir() outside build scripts".into()))?,
            ),
        };
        let opts = Options { severities: self.severities()?, ..self.options.clone() };
        let inputs: Vec<Input> = self.files.iter().cloned().map(Input::Path).collect();
        let mut out = compile(inputs, &opts);
        if self.cargo_output {
            for (_, f) in out.model.sources.files() {
                println!("cargo:rerun-if-changed={}", f.path.display());
            }
            for d in &opts.model_dirs {
                println!("cargo:rerun-if-changed={}", d.display());
            }
        }
        out.checked(&opts.severities)?;
        let model = &out.model;
        // The `rust` command's run: every model the files require is generated too unless it is mapped, and
        // the top `mod.rs` with `register` comes with it; inlined here for `include!`.
        let run = crate::run_rust(model, &self.rust, &opts.severities)?;
        if self.cargo_output {
            for d in out.diagnostics.items.iter().chain(&run.diagnostics.items) {
                let first = d.render(&model.sources).lines().next().unwrap_or_default().to_string();
                let at = d.span.map(|s| model.sources.location(s)).unwrap_or_default();
                println!("cargo:warning={first} ({at})");
            }
            for (uri, path) in &run.plan.unused {
                println!("cargo:warning=extern_namespace(\"{uri}\", \"{path}\") names no loaded model");
            }
        }
        let text = crate::emit::rust::inline(&run.files);
        let name = self.out_file.clone().unwrap_or_else(|| "nodesets.rs".into());
        let path = out_dir.join(&name);
        std::fs::create_dir_all(&out_dir).map_err(|e| Error::Write(format!("cannot create {}: {e}", out_dir.display())))?;
        // The text goes to a temporary file beside the output, which is then renamed over it: readers see
        // the old file or the new one, and a failure leaves the old one and no temporary file.
        let tmp = out_dir.join(format!(".{name}.tmp-{}", std::process::id()));
        let written = std::fs::write(&tmp, text)
            .map_err(|e| format!("cannot write {}: {e}", tmp.display()))
            .and_then(|()| std::fs::rename(&tmp, &path).map_err(|e| format!("cannot write {}: {e}", path.display())));
        if written.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        written.map(|()| path).map_err(Error::Write)
    }
}
