//! Which namespaces a run generates and which it maps to code that exists elsewhere.
//!
//! By default a run generates every model the named files need, not only theirs: a dependency that is not
//! mapped (`--extern URI=PATH`) is generated beside them, so that the output compiles on its own. The base
//! namespace is never generated as Rust: async-opcua provides it (`opcua::types`, `opcua::nodes`).

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::load::NS0_URI;
use crate::model::Model;

/// The namespaces of one run: generated here, or mapped to existing code.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Plan {
    /// URIs generated in this run, in load order (dependencies first).
    pub generated: Vec<String>,
    /// `(URI, path)` of the loaded models mapped to existing code, in load order.
    pub mapped: Vec<(String, String)>,
    /// Mappings that name no loaded model (harmless, but worth a note).
    pub unused: Vec<(String, String)>,
}

/// Plans a run over `model`: every loaded model that is not the base namespace and not in `mapped` is
/// generated. With `base_is_external` (Rust: async-opcua provides ns0), naming the base namespace's file
/// is an error (`NS0303`) rather than code that cannot compile.
pub fn plan(model: &Model, mapped: &[(String, String)], base_is_external: bool) -> Result<Plan, Diagnostics> {
    let mut diags = Diagnostics::new();
    if base_is_external {
        for m in model.models.iter().filter(|m| m.uri == NS0_URI && model.sources.get(m.file).named) {
            diags.push(
                Diagnostic::new(Code::Ns0Named, format!("`{}` is the base namespace `{NS0_URI}`, which async-opcua provides", model.sources.get(m.file).path.display()))
                    .at(m.span)
                    .with_span_label("the model of the base namespace")
                    .help("generated code uses ns0 from async-opcua (`opcua::types`, `opcua::nodes`); name the files that build on it, and this file only with `--models`"),
            );
        }
    }
    if diags.has_errors() {
        return Err(diags);
    }
    let mut plan = Plan::default();
    for m in &model.models {
        if base_is_external && m.uri == NS0_URI {
            continue;
        }
        match mapped.iter().find(|(u, _)| *u == m.uri) {
            Some((u, p)) => plan.mapped.push((u.clone(), p.clone())),
            None if m.uri != NS0_URI => plan.generated.push(m.uri.clone()),
            None => {}
        }
    }
    plan.unused = mapped.iter().filter(|(u, _)| !model.models.iter().any(|m| m.uri == *u)).cloned().collect();
    Ok(plan)
}

impl Plan {
    /// Rust module names of the generated namespaces: as `--module` gives them, else the URI's last segment
    /// in snake case; where that is taken (`Mining/General/` beside `Mining/DevelopmentSupport/General/`),
    /// the segments before it are joined on (`mining_general`), and a number as the last resort.
    pub fn module_names(&self, overrides: &[(String, String)]) -> std::collections::BTreeMap<String, String> {
        use crate::names::{sanitize, Case, Target};
        let mut taken: std::collections::BTreeSet<String> = overrides.iter().map(|(_, n)| n.clone()).collect();
        let mut out = std::collections::BTreeMap::new();
        for u in &self.generated {
            if let Some((_, n)) = overrides.iter().find(|(o, _)| o == u) {
                out.insert(u.clone(), n.clone());
                continue;
            }
            let segs: Vec<&str> = u.trim_end_matches('/').split(['/', ':']).filter(|s| !s.is_empty()).collect();
            let mut name = None;
            for k in 1..=segs.len() {
                let candidate = sanitize(&segs[segs.len() - k..].join("_"), Case::Snake, Target::Rust);
                if !taken.contains(&candidate) {
                    name = Some(candidate);
                    break;
                }
            }
            let name = name.unwrap_or_else(|| {
                let base = sanitize(segs.last().copied().unwrap_or("ns"), Case::Snake, Target::Rust);
                (2..).map(|i| format!("{base}_{i}")).find(|c| !taken.contains(c)).unwrap_or(base)
            });
            taken.insert(name.clone());
            out.insert(u.clone(), name);
        }
        out
    }

    /// The summary a command prints: what was generated (with the name given to it, if `name_of` gives one)
    /// and what was mapped.
    pub fn describe(&self, name_of: impl Fn(&str) -> String) -> String {
        let mut out = String::new();
        for u in &self.generated {
            match name_of(u) {
                n if n.is_empty() => out.push_str(&format!("generated: {u}\n")),
                n => out.push_str(&format!("generated: {u} as `{n}`\n")),
            }
        }
        for (u, p) in &self.mapped {
            out.push_str(&format!("mapped:    {u} to `{p}`\n"));
        }
        for (u, p) in &self.unused {
            out.push_str(&format!("unused:    --extern {u}={p} names no loaded model\n"));
        }
        out
    }
}

/// The Rust of a complete run, as `nodeset-compiler rust` writes it: every planned namespace (module names
/// from [`Plan::module_names`]), the `mod.rs` that lists them and `rustfmt.toml`; with the plan, for the
/// summary, and every diagnostic of planning and generation (sorted). `Err` when the plan fails (NS0303).
pub fn generate_rust(
    model: &Model,
    externs: &[(String, String)],
    modules: &[(String, String)],
    runtime_path: &str,
    command: &str,
) -> Result<(Plan, std::collections::BTreeMap<String, String>, crate::emit::rust::RustOutput), Diagnostics> {
    use crate::emit::rust::{self as r, RustConfig, RustNamespace};
    let plan = plan(model, externs, true)?;
    let names = plan.module_names(modules);
    let namespaces: Vec<RustNamespace> = plan.generated.iter().map(|u| RustNamespace { uri: u.clone(), module: names[u].clone() }).collect();
    let cfg = RustConfig {
        namespaces: namespaces.clone(),
        extern_paths: externs.iter().cloned().collect(),
        runtime_path: runtime_path.to_string(),
        command: command.to_string(),
    };
    let mut gen = r::generate(model, &cfg);
    let list: Vec<(String, String)> = namespaces.iter().map(|n| (n.module.clone(), n.uri.clone())).collect();
    gen.files.push(r::models_mod(&list, runtime_path, command));
    gen.files.push(r::rustfmt_toml());
    Ok((plan, names, gen))
}

#[cfg(test)]
mod tests {
    use super::Plan;

    /// Two models whose URIs end in the same segment get two module names; `--module` names are kept and
    /// reserved.
    #[test]
    fn module_names_do_not_collide() {
        let plan = Plan {
            generated: vec![
                "http://opcfoundation.org/UA/Mining/General/".into(),
                "http://opcfoundation.org/UA/Mining/DevelopmentSupport/General/".into(),
                "http://opcfoundation.org/UA/DI/".into(),
                "http://example.com/di".into(),
            ],
            ..Plan::default()
        };
        let names = plan.module_names(&[("http://example.com/di".into(), "vendor_di".into())]);
        let got: Vec<&str> = plan.generated.iter().map(|u| names[u].as_str()).collect();
        assert_eq!(got, ["general", "development_support_general", "di", "vendor_di"]);
    }
}
