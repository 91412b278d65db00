//! nodeset-compiler: OPC UA NodeSet2 information models to typed Rust and Modelica.
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

pub mod build;
pub mod datatypes;
pub mod diag;
pub mod emit;
pub mod fxhash;
pub mod load;
pub mod model;
pub mod names;
pub mod nodeid;
pub mod parse;
pub mod raw;
pub mod resolve;
pub mod source;
pub mod summary;
pub mod value;
pub mod write;

use diag::{Diagnostics, Severity};
use load::{Input, LoadOptions};
use std::path::PathBuf;

/// What [`compile`] does.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Folders searched recursively for required models.
    pub model_dirs: Vec<PathBuf>,
    /// Turn warnings into errors.
    pub deny_warnings: bool,
    /// Also report warnings of files that were only loaded as dependencies.
    pub all_warnings: bool,
    pub limits: parse::Limits,
}

/// The model and everything said about it.
#[derive(Debug)]
pub struct Compiled {
    pub model: model::Model,
    pub diagnostics: Diagnostics,
}

impl Compiled {
    pub fn ok(&self) -> bool {
        !self.diagnostics.has_errors()
    }

    pub fn render_diagnostics(&self) -> String {
        self.diagnostics.render(&self.model.sources)
    }
}

/// Parses, loads and resolves. Stops after loading when loading found errors (a missing model would make
/// every reference into it dangle), so the user sees the cause, not a thousand consequences.
pub fn compile(inputs: Vec<Input>, opts: &Options) -> Compiled {
    let mut diags = Diagnostics::new();
    let load_opts = LoadOptions { model_dirs: opts.model_dirs.clone(), limits: opts.limits.clone() };
    let mut loaded = load::load(inputs, &load_opts, &mut diags);
    if diags.has_errors() {
        loaded.files.clear();
    }
    let model = resolve::resolve(loaded, &mut diags);
    finish(model, diags, opts)
}

/// The number of threads the compiler uses: the cores this process may run on.
pub(crate) fn cores() -> usize {
    static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// Runs `a` and `b` and returns both results: `a` on another thread where there is more than one core.
/// A panic in `a` is passed on.
pub(crate) fn join<A: Send, B>(a: impl FnOnce() -> A + Send, b: impl FnOnce() -> B) -> (A, B) {
    if cores() == 1 {
        return (a(), b());
    }
    std::thread::scope(|s| {
        let other = s.spawn(a);
        let rb = b();
        let ra = other.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (ra, rb)
    })
}

/// Maps `f` over `items` on up to [`cores`] threads; the results are in the order of `items`. Threads take
/// the next item when they finish one, so put the expensive items first. A panic in `f` is passed on.
pub(crate) fn par_map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let threads = cores().min(items.len());
    if threads <= 1 {
        return items.iter().map(f).collect();
    }
    let next = std::sync::atomic::AtomicUsize::new(0);
    let work = || {
        let mut done = Vec::new();
        loop {
            let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let Some(item) = items.get(i) else { return done };
            done.push((i, f(item)));
        }
    };
    let mut all: Vec<(usize, R)> = std::thread::scope(|s| {
        let others: Vec<_> = (1..threads).map(|_| s.spawn(work)).collect();
        let mut all = work();
        for t in others {
            all.extend(t.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)));
        }
        all
    });
    all.sort_by_key(|(i, _)| *i);
    all.into_iter().map(|(_, r)| r).collect()
}

fn finish(model: model::Model, mut diags: Diagnostics, opts: &Options) -> Compiled {
    if !opts.all_warnings {
        // Warnings about files the user did not name are not the user's problem.
        diags.items.retain(|d| {
            d.severity == Severity::Error || d.span.is_none_or(|s| model.sources.get(s.file).named)
        });
    }
    if opts.deny_warnings {
        diags.deny_warnings();
    }
    diags.sort(&model.sources);
    Compiled { model, diagnostics: diags }
}
