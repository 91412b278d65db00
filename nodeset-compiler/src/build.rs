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
//! // src/lib.rs
//! // include!(concat!(env!("OUT_DIR"), "/nodesets.rs"));
//! ```
//!
//! Every file the compiler reads is printed as `cargo:rerun-if-changed`, warnings as `cargo:warning`. The
//! output file is replaced atomically (written as `.<file>.tmp-<pid>` beside it, then renamed over it); on
//! any error the previous output stays as it was and the error lists the diagnostics.

use crate::emit::rust::{self as rust_emit, RustConfig, RustNamespace};
use crate::load::Input;
use crate::{compile, Options};
use std::collections::BTreeMap;
use std::path::PathBuf;

#[derive(Clone, Debug, Default)]
pub struct Builder {
    files: Vec<PathBuf>,
    model_dirs: Vec<PathBuf>,
    modules: BTreeMap<String, String>,
    extern_paths: BTreeMap<String, String>,
    runtime_path: Option<String>,
    out_dir: Option<PathBuf>,
    out_file: Option<String>,
    cargo_output: bool,
    deny_warnings: bool,
}

impl Builder {
    pub fn new() -> Builder {
        Builder { cargo_output: true, ..Builder::default() }
    }

    /// A NodeSet2 file whose models are generated.
    pub fn file(mut self, path: impl Into<PathBuf>) -> Self {
        self.files.push(path.into());
        self
    }

    /// A folder searched recursively for the models the files require.
    pub fn models_dir(mut self, path: impl Into<PathBuf>) -> Self {
        self.model_dirs.push(path.into());
        self
    }

    /// The module name of a namespace (default: the last segment of its URI in snake case).
    pub fn module_name(mut self, uri: &str, module: &str) -> Self {
        self.modules.insert(uri.into(), module.into());
        self
    }

    /// A namespace generated elsewhere: its module's Rust path. Its types are used, not generated again.
    pub fn extern_namespace(mut self, uri: &str, rust_path: &str) -> Self {
        self.extern_paths.insert(uri.into(), rust_path.into());
        self
    }

    /// The path of the runtime module (default `nodeset_models::runtime`).
    pub fn runtime_path(mut self, path: &str) -> Self {
        self.runtime_path = Some(path.into());
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

    /// Turn warnings into errors.
    pub fn deny_warnings(mut self, on: bool) -> Self {
        self.deny_warnings = on;
        self
    }

    /// Compiles, generates and writes. Returns the path written.
    pub fn generate(self) -> Result<PathBuf, String> {
        let out_dir = match self.out_dir.clone() {
            Some(d) => d,
            None => PathBuf::from(std::env::var_os("OUT_DIR").ok_or("OUT_DIR is not set; call out_dir() outside build scripts")?),
        };
        let inputs: Vec<Input> = self.files.iter().cloned().map(Input::Path).collect();
        let opts = Options { model_dirs: self.model_dirs.clone(), deny_warnings: self.deny_warnings, ..Options::default() };
        let out = compile(inputs, &opts);
        if self.cargo_output {
            for (_, f) in out.model.sources.files() {
                println!("cargo:rerun-if-changed={}", f.path.display());
            }
            for d in &self.model_dirs {
                println!("cargo:rerun-if-changed={}", d.display());
            }
        }
        if !out.ok() {
            return Err(format!("nodeset-compiler: the NodeSet2 files do not compile:\n{}", out.render_diagnostics()));
        }
        let model = &out.model;
        let named: Vec<&crate::load::ModelInfo> =
            model.models.iter().filter(|m| model.sources.get(m.file).named).collect();
        let namespaces: Vec<RustNamespace> = named
            .iter()
            .map(|m| RustNamespace {
                uri: m.uri.clone(),
                module: self.modules.get(&m.uri).cloned().unwrap_or_else(|| rust_emit::default_module_name(&m.uri)),
            })
            .collect();
        let cfg = RustConfig {
            namespaces: namespaces.clone(),
            extern_paths: self.extern_paths.clone(),
            runtime_path: self.runtime_path.clone().unwrap_or_else(|| "nodeset_models::runtime".into()),
            command: "cargo build (build.rs)".into(),
        };
        let mut gen = rust_emit::generate(model, &cfg);
        if self.deny_warnings {
            gen.diagnostics.deny_warnings();
        }
        gen.diagnostics.sort(&model.sources);
        if gen.diagnostics.has_errors() {
            return Err(format!("nodeset-compiler: generation failed:\n{}", gen.diagnostics.render(&model.sources)));
        }
        if self.cargo_output {
            for d in &gen.diagnostics.items {
                let first = d.render(&model.sources).lines().next().unwrap_or_default().to_string();
                let at = d.span.map(|s| model.sources.location(s)).unwrap_or_default();
                println!("cargo:warning={first} ({at})");
            }
        }
        let text = rust_emit::inline(&gen.files, &namespaces);
        let name = self.out_file.clone().unwrap_or_else(|| "nodesets.rs".into());
        let path = out_dir.join(&name);
        std::fs::create_dir_all(&out_dir).map_err(|e| format!("cannot create {}: {e}", out_dir.display()))?;
        // The text goes to a temporary file beside the output, which is then renamed over it: readers see
        // the old file or the new one, and a failure leaves the old one and no temporary file.
        let tmp = out_dir.join(format!(".{name}.tmp-{}", std::process::id()));
        let written = std::fs::write(&tmp, text)
            .map_err(|e| format!("cannot write {}: {e}", tmp.display()))
            .and_then(|()| std::fs::rename(&tmp, &path).map_err(|e| format!("cannot write {}: {e}", path.display())));
        if written.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        written.map(|()| path)
    }
}
