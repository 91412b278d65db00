//! Which namespaces a run generates and which it maps to code that exists elsewhere.
//!
//! By default a run generates every model the named files need, not only theirs: a dependency that is not
//! mapped (`--extern URI=PATH`) is generated beside them, so that the output compiles on its own. The base
//! namespace is never generated as Rust: async-opcua provides it (`opcua::types`, `opcua::nodes`).

use crate::diag::{Code, Diagnostic, Diagnostics};
use crate::load::NS0_URI;
use crate::model::Model;
use std::collections::BTreeMap;

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

/// Plans a run over `model`: every loaded model that is not the base namespace and not in `mapped` (URI ->
/// path of the existing code) is generated. With `base_is_external` (Rust: async-opcua provides ns0), naming
/// the base namespace's file is an error (`NS0303`) rather than code that cannot compile; its recovery, when
/// demoted, is the plan returned anyway, which leaves the base namespace to async-opcua. The diagnostics are
/// returned unfinalised: the caller applies the run's severity settings.
pub fn plan(model: &Model, mapped: &BTreeMap<String, String>, base_is_external: bool) -> (Plan, Diagnostics) {
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
    let mut plan = Plan::default();
    for m in &model.models {
        if base_is_external && m.uri == NS0_URI {
            continue;
        }
        match mapped.get(&m.uri) {
            Some(p) => plan.mapped.push((m.uri.clone(), p.clone())),
            None if m.uri != NS0_URI => plan.generated.push(m.uri.clone()),
            None => {}
        }
    }
    plan.unused = mapped.iter().filter(|(u, _)| !model.models.iter().any(|m| m.uri == **u)).map(|(u, p)| (u.clone(), p.clone())).collect();
    (plan, diags)
}

/// The mapped namespaces of `plan` that require a namespace `plan` generates (`NS0304`). The existing code of
/// a mapped namespace was generated against its own copy of what it requires: generating that namespace again
/// here would give the user's crate two copies of it (two sets of types, two node tables for one URI). The
/// diagnostic names both models and says to map the required one too.
pub fn mapped_requirements(model: &Model, plan: &Plan) -> Diagnostics {
    let mut diags = Diagnostics::new();
    for (uri, path) in &plan.mapped {
        let Some(m) = model.models.iter().find(|m| m.uri == *uri) else { continue };
        for r in m.required.iter().filter(|r| plan.generated.contains(&r.uri)) {
            diags.push(
                Diagnostic::new(
                    Code::MappedNeedsGenerated,
                    format!("`{uri}` is mapped to `{path}`, but the model it requires, `{}`, is generated in this run", r.uri),
                )
                .at(r.span)
                .with_span_label("the required model")
                .help(format!(
                    "map `{}` to the code `{path}` was generated with too (`.extern_namespace(\"{}\", PATH)` in a build script, `--extern {}=PATH` on the command line), or map neither and generate both",
                    r.uri, r.uri, r.uri
                )),
            );
        }
    }
    diags
}

impl Plan {
    /// Rust module names of the generated namespaces: as `overrides` (`--module`) gives them, else the URI's
    /// last segment in snake case. URIs whose names would be equal, or would take an override's name, join the
    /// segments before it on, all of them, one segment at a time (`Mining/General/` and
    /// `Mining/DevelopmentSupport/General/` become `mining_general` and `development_support_general`); URIs
    /// that collide in full are numbered in URI order. Neither the order of `generated` nor the order the
    /// files were named in changes a name.
    pub fn module_names(&self, overrides: &BTreeMap<String, String>) -> BTreeMap<String, String> {
        self.module_names_beside(overrides, &[])
    }

    /// [`Plan::module_names`], with `reserved` names no namespace takes by default (as if an override had
    /// taken them): the last segments of the paths the mapped namespaces are reached by, so that a vendor
    /// namespace `.../Robotics/` generated beside a mapping to `nodeset_models::models::robotics` is not named
    /// `robotics` too (it gets its URI's segments before, `vendor_com_robotics`), and a user crate that uses both
    /// never reads one name for two namespaces.
    pub fn module_names_beside(&self, overrides: &BTreeMap<String, String>, reserved: &[String]) -> BTreeMap<String, String> {
        use crate::names::{sanitize, Case, Target};
        let mut out: BTreeMap<String, String> = BTreeMap::new();
        let mut taken: std::collections::BTreeSet<String> = overrides.values().cloned().chain(reserved.iter().cloned()).collect();
        let mut pending: std::collections::BTreeSet<&str> = std::collections::BTreeSet::new();
        for u in &self.generated {
            match overrides.get(u) {
                Some(n) => {
                    out.insert(u.clone(), n.clone());
                }
                None => {
                    pending.insert(u);
                }
            }
        }
        let segments = |u: &str| -> Vec<String> { u.trim_end_matches('/').split(['/', ':']).filter(|s| !s.is_empty()).map(str::to_string).collect() };
        let name_at = |u: &str, k: usize| -> String {
            let segs = segments(u);
            let k = k.min(segs.len()).max(1);
            sanitize(&segs[segs.len().saturating_sub(k)..].join("_"), Case::Snake, Target::Rust)
        };
        let longest = pending.iter().map(|u| segments(u).len()).max().unwrap_or(0);
        for k in 1..=longest.max(1) {
            // One round: every pending URI proposes its name of k segments; a proposal that no other pending
            // URI makes and no earlier round took is accepted. The rest try again with one segment more.
            let proposals: Vec<(&str, String)> = pending.iter().map(|u| (*u, name_at(u, k))).collect();
            let mut count: BTreeMap<&str, usize> = BTreeMap::new();
            for (_, n) in &proposals {
                *count.entry(n.as_str()).or_default() += 1;
            }
            let accepted: Vec<(&str, String)> =
                proposals.iter().filter(|(_, n)| count[n.as_str()] == 1 && !taken.contains(n)).cloned().collect();
            for (u, n) in accepted {
                pending.remove(u);
                taken.insert(n.clone());
                out.insert(u.to_string(), n);
            }
        }
        // URIs whose every name is taken (they differ only in characters the sanitizer drops): numbered.
        for u in pending {
            let base = name_at(u, usize::MAX);
            let n = if taken.contains(&base) { (2..).map(|i| format!("{base}_{i}")).find(|c| !taken.contains(c)).unwrap_or(base) } else { base };
            taken.insert(n.clone());
            out.insert(u.to_string(), n);
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

#[cfg(test)]
mod tests {
    use super::Plan;
    use std::collections::BTreeMap;

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
        let names = plan.module_names(&[("http://example.com/di".to_string(), "vendor_di".to_string())].into_iter().collect());
        let got: Vec<&str> = plan.generated.iter().map(|u| names[u].as_str()).collect();
        assert_eq!(got, ["mining_general", "development_support_general", "di", "vendor_di"]);
        // The same URIs in the reverse order get the same names.
        let reversed = Plan { generated: plan.generated.iter().rev().cloned().collect(), ..Plan::default() };
        assert_eq!(reversed.module_names(&[("http://example.com/di".to_string(), "vendor_di".to_string())].into_iter().collect()), names);
        // Two URIs that differ only in characters the sanitizer drops are numbered, in URI order.
        let same = Plan { generated: vec!["http://a.org/x-y/".into(), "http://a.org/x_y/".into()], ..Plan::default() };
        let names = same.module_names(&BTreeMap::new());
        assert_eq!((names["http://a.org/x-y/"].as_str(), names["http://a.org/x_y/"].as_str()), ("http_a_org_x_y", "http_a_org_x_y_2"));
    }

    /// A vendor namespace whose URI ends like a mapped one (`.../Robotics/` beside a mapping of the OPC
    /// Foundation's Robotics to `nodeset_models::models::robotics`) does not take the mapped module's name: the
    /// name is reserved, so it takes its URI's segment before (`ua_robotics`). An override may still use it.
    #[test]
    fn names_of_mapped_modules_are_reserved() {
        let plan = Plan { generated: vec!["http://vendor.example.com/UA/Robotics/".into(), "http://vendor.example.com/UA/Device/".into()], ..Plan::default() };
        let free = plan.module_names(&BTreeMap::new());
        assert_eq!(free["http://vendor.example.com/UA/Robotics/"], "robotics");
        let names = plan.module_names_beside(&BTreeMap::new(), &["robotics".to_string(), "di".to_string()]);
        assert_eq!(names["http://vendor.example.com/UA/Robotics/"], "ua_robotics");
        assert_eq!(names["http://vendor.example.com/UA/Device/"], "device");
        let overridden: BTreeMap<String, String> = [("http://vendor.example.com/UA/Robotics/".to_string(), "robotics".to_string())].into_iter().collect();
        assert_eq!(plan.module_names_beside(&overridden, &["robotics".to_string()])["http://vendor.example.com/UA/Robotics/"], "robotics");
    }
}
