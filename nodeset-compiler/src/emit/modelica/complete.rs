//! Complete variants. A value a model publishes is an input connector that nothing binds, for the physics computing
//! it to connect to; a class whose components hold such inputs is partial. Its complete variant
//! `<Pkg>.Complete.<Ident>` extends it and binds every one of them to the nodeset's value, so that it simulates as
//! it is; components and class aliases whose class is partial use it (Modelica tools refuse components of partial
//! classes).

use super::ctx::{class_ident, decl_class_ident, Ctx};
use super::plan::{ClassKey, ClassPlan, ElemKind, Element, Free, Mod, TypeRef, Value};
use super::text;

impl Ctx<'_> {
    /// The free inputs of a class with these elements: its own, and those of its components. A component whose
    /// class leaves inputs of its components free uses the complete variant, which binds them all.
    pub fn free_of(&self, elements: &[Element]) -> Vec<Free> {
        let mut out = Vec::new();
        for e in elements {
            match &e.kind {
                ElemKind::Signal { free: true, ty, .. } => {
                    out.push(Free { path: vec![(e.ident.clone(), false)], node: e.node, ty: ty.clone() })
                }
                ElemKind::Object { class } => {
                    let inner = match &e.nested_free {
                        Some(f) => f.clone(),
                        None => match self.class_infos.get(class) {
                            Some(info) if !info.is_partial_by_inputs() => info.free.clone(),
                            _ => continue,
                        },
                    };
                    for f in inner.iter() {
                        let mut path = vec![(e.ident.clone(), e.count.is_some())];
                        path.extend(f.path.iter().cloned());
                        out.push(Free { path, node: f.node, ty: f.ty.clone() });
                    }
                }
                _ => {}
            }
        }
        out
    }

    /// The class a component of `key` is declared with: the class, or its complete variant when members of its
    /// components are inputs nothing binds (Modelica tools refuse components of partial classes).
    pub fn component_class_path(&mut self, key: &ClassKey) -> String {
        if self.class_infos.get(key).is_some_and(|i| i.is_partial_by_inputs()) {
            self.complete_path(key)
        } else {
            self.class_path(key)
        }
    }

    /// The qualified name of a class's complete variant, `<Pkg>.Complete.<Ident>`.
    pub fn complete_path(&mut self, key: &ClassKey) -> String {
        self.class_path(key); // what it records as needed
        let ns = match key {
            ClassKey::Type(t) => self.m.node(*t).id.ns,
            ClassKey::Decl(owner, _) => self.m.node(owner.node()).id.ns,
        };
        let ident = self.complete_ident(key);
        format!("{}.Complete.{ident}", self.pkg[ns as usize])
    }

    /// The identifier of a class's complete variant: the class's own; for a declaration class that an ObjectType
    /// of the namespace already names, with `_Declaration` (and a number) added.
    pub fn complete_ident(&mut self, key: &ClassKey) -> String {
        match key {
            ClassKey::Type(t) => {
                let names = self.names(self.m.node(*t).id.ns);
                names.object_types[t].clone()
            }
            ClassKey::Decl(owner, path) => {
                let names = self.names(self.m.node(owner.node()).id.ns);
                let decl = self.decl_names.get(&(*owner, path.clone())).cloned().unwrap_or_else(|| class_ident(path));
                let base = decl_class_ident(&names.owners[owner], &decl);
                let taken = |x: &String| names.object_types.values().any(|t| t == x);
                if !taken(&base) {
                    return base;
                }
                let mut ident = format!("{base}_Declaration");
                let mut k = 2;
                while taken(&ident) {
                    ident = format!("{base}_Declaration{k}");
                    k += 1;
                }
                ident
            }
        }
    }
}

/// The note on a class that is partial because members of its components are inputs nothing binds.
pub const COMPLETE_NOTE: &str = "<p>Members of its components are inputs that nothing binds (values the model \
publishes, which the physics computing them connects to), so the class is partial: extend it and connect them, or \
use its complete variant in the package <code>Complete</code>, which binds them to the nodeset's values.</p>";

/// Adds `path = value` to a modification list, inside the modifiers already there for the same components
/// (`a(b(x(unit="m")))` becomes `a(b(x(unit="m")=v))`); `each` after an array component.
pub fn bind_free(mods: &mut Vec<Mod>, path: &[(String, bool)], value: Value) {
    bind_at(mods, path, value, false)
}

fn bind_at(mods: &mut Vec<Mod>, path: &[(String, bool)], value: Value, each: bool) {
    let Some(((first, array), rest)) = path.split_first() else { return };
    let ident = if each { format!("each {first}") } else { first.clone() };
    if rest.is_empty() {
        for m in mods.iter_mut() {
            if let Mod::Value { ident: i, value: v @ None, .. } = m {
                if *i == ident {
                    *v = Some(value);
                    return;
                }
            }
        }
        mods.push(Mod::Value { ident, is_final: false, attrs: Vec::new(), value: Some(value) });
        return;
    }
    for m in mods.iter_mut() {
        if let Mod::Nested { ident: i, mods: inner } = m {
            if *i == ident {
                bind_at(inner, rest, value, *array);
                return;
            }
        }
    }
    let mut inner = Vec::new();
    bind_at(&mut inner, rest, value, *array);
    mods.push(Mod::Nested { ident, mods: inner });
}

/// The plan of the complete variant of a class with inputs nothing binds: the class with each of them bound to
/// its value in the nodeset, so that it simulates as it is (`<Pkg>.Complete.<Ident>`); with its namespace and
/// identifier. `None` for a class that binds all its inputs.
pub fn complete_plan(ctx: &mut Ctx, key: &ClassKey, plan: &ClassPlan) -> Option<(u16, String, ClassPlan)> {
    let info = ctx.class_infos.get(key).cloned()?;
    if info.free.is_empty() {
        return None;
    }
    let mut mods = Vec::new();
    for f in info.free.iter() {
        bind_free(&mut mods, &f.path, f.value());
    }
    let base = ctx.class_path(key);
    let ident = ctx.complete_ident(key);
    let ns = match key {
        ClassKey::Type(t) => ctx.m.node(*t).id.ns,
        ClassKey::Decl(o, _) => ctx.m.node(o.node()).id.ns,
    };
    let listed: Vec<String> = info
        .free
        .iter()
        .map(|f| {
            let p: Vec<&str> = f.path.iter().map(|(i, _)| i.as_str()).collect();
            format!("<code>{}</code>", p.join("."))
        })
        .collect();
    let doc_html = format!(
        "<p><code>{}</code> with each input that nothing binds bound to its value in the nodeset, so that it \
         simulates as it is: {}. To compute them, extend <code>{}</code> instead and connect them.</p>",
        text::html_escape(&base),
        listed.join(", "),
        text::html_escape(&base)
    );
    let abstract_type = matches!(key, ClassKey::Type(t) if ctx.m.node(*t).is_abstract());
    let keyword = if plan.keyword == "partial model" && !abstract_type { "model" } else { plan.keyword };
    let variant = ClassPlan {
        keyword,
        desc: plan.desc.clone(),
        doc_html,
        extends: Some((TypeRef::Class(key.clone()), mods)),
        items: Vec::new(),
        equations: Vec::new(),
        opcua: plan.opcua.clone(),
    };
    Some((ns, ident, variant))
}
