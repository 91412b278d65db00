//! Syn trees built directly instead of parsed from tokens: the bodies of the handles' `Handle::build` and
//! the types of the handles' fields in `objects.rs`.
//!
//! Every other part of a file goes from `quote!` tokens through `syn::parse2` to prettyplease. For the
//! `build` bodies (one `field: b.build_child(id, NS[k], "Name")` per member of every handle, most of the
//! expressions of `objects.rs`) that parse was the costliest step of Rust emission: syn's expression
//! parser tries its way through every token. The trees built here are the ones that parse gives for the
//! same text (the same nodes, no spans that prettyplease reads), so prettyplease prints them byte for byte
//! as before; the handle's `impl` is still parsed, with the body's index as a placeholder
//! ([`placeholder`]), and [`fill`] puts each body in its place. The field types (`Option<t::Variable<f64>>`,
//! built from the syn trees the value types already are) go the same way ([`type_placeholder`]), with the
//! fields' doc attributes ([`doc_attrs`]). `cargo xtask generate --check` and the
//! `rust_output` snapshots hold the output to what it was.

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::quote;
use syn::{
    AngleBracketedGenericArguments, AttrStyle, Attribute, Expr, ExprIndex, ExprLit, ExprMethodCall, ExprPath, ExprStruct, FieldValue, GenericArgument, ImplItem,
    Item, Lit, Member, Meta, MetaNameValue, Path, PathArguments, PathSegment, Stmt, Type, TypePath,
};

/// A one-segment path expression (`b`, `id`, `NS`).
fn path(name: &str) -> Expr {
    Expr::Path(ExprPath { attrs: Vec::new(), qself: None, path: Path::from(Ident::new(name, Span::call_site())) })
}

fn literal(lit: Literal) -> Expr {
    Expr::Lit(ExprLit { attrs: Vec::new(), lit: Lit::new(lit) })
}

/// `NS[k]`.
pub(super) fn ns(k: usize) -> Expr {
    Expr::Index(ExprIndex {
        attrs: Vec::new(),
        expr: Box::new(path("NS")),
        bracket_token: Default::default(),
        index: Box::new(literal(Literal::usize_unsuffixed(k))),
    })
}

/// A string literal expression.
pub(super) fn str_lit(s: &str) -> Expr {
    literal(Literal::string(s))
}

/// `id`.
pub(super) fn id() -> Expr {
    path("id")
}

/// `b.method(args)`.
pub(super) fn binder_call(method: &str, args: Vec<Expr>) -> Expr {
    Expr::MethodCall(ExprMethodCall {
        attrs: Vec::new(),
        receiver: Box::new(path("b")),
        dot_token: Default::default(),
        method: Ident::new(method, Span::call_site()),
        turbofish: None,
        paren_token: Default::default(),
        args: args.into_iter().collect(),
    })
}

/// `Self { name: expr, ... }`.
pub(super) fn self_struct(fields: Vec<(Ident, Expr)>) -> Expr {
    Expr::Struct(ExprStruct {
        attrs: Vec::new(),
        qself: None,
        path: Path::from(Ident::new("Self", Span::call_site())),
        brace_token: Default::default(),
        fields: fields
            .into_iter()
            .map(|(name, expr)| FieldValue { attrs: Vec::new(), member: Member::Named(name), colon_token: Some(Default::default()), expr })
            .collect(),
        dot2_token: None,
        rest: None,
    })
}

/// A path type `a::b::C<args>` (no arguments: `a::b::C`).
pub(super) fn generic(segments: &[&str], args: Vec<Type>) -> Type {
    let mut path = Path { leading_colon: None, segments: Default::default() };
    for s in segments {
        path.segments.push(PathSegment::from(Ident::new(s, Span::call_site())));
    }
    if !args.is_empty() {
        if let Some(last) = path.segments.last_mut() {
            last.arguments = PathArguments::AngleBracketed(AngleBracketedGenericArguments {
                colon2_token: None,
                lt_token: Default::default(),
                args: args.into_iter().map(GenericArgument::Type).collect(),
                gt_token: Default::default(),
            });
        }
    }
    path_type(path)
}

/// The doc attributes `super::doc` writes as tokens for `text`: `#[doc = " line"]` a line.
pub(super) fn doc_attrs(text: &str) -> Vec<Attribute> {
    text.lines()
        .map(|l| Attribute {
            pound_token: Default::default(),
            style: AttrStyle::Outer,
            bracket_token: Default::default(),
            meta: Meta::NameValue(MetaNameValue {
                path: Path::from(Ident::new("doc", Span::call_site())),
                eq_token: Default::default(),
                value: str_lit(&format!(" {}", l.trim_end())),
            }),
        })
        .collect()
}

/// A tuple type `(A, B,)` as syn reads that text: each element with its comma (`()` when empty).
pub(super) fn tuple(items: Vec<Type>) -> Type {
    let mut elems = syn::punctuated::Punctuated::new();
    for t in items {
        elems.push_value(t);
        elems.push_punct(Default::default());
    }
    Type::Tuple(syn::TypeTuple { paren_token: Default::default(), elems })
}

/// A path as a type.
pub(super) fn path_type(path: Path) -> Type {
    Type::Path(TypePath { qself: None, path })
}

/// The prefix of the stand-ins for built field types: no generated type name has it (they are UpperCamel).
const TYPE_PLACEHOLDER: &str = "NODESET_COMPILER_TYPE_";

/// The stand-in for the `k`th built field (its doc attributes and type): the type `NODESET_COMPILER_TYPE_k`.
pub(super) fn type_placeholder(k: usize) -> TokenStream {
    let name = Ident::new(&format!("{TYPE_PLACEHOLDER}{k}"), Span::call_site());
    quote! { #name }
}

/// The stand-in for the `k`th built body in the tokens of a `build` function: the literal `k`.
pub(super) fn placeholder(k: usize) -> TokenStream {
    let k = Literal::usize_unsuffixed(k);
    quote! { #k }
}

/// Puts each built body where its placeholder is: the body of a top-level `impl`'s `build` function that
/// is the literal `k` becomes `bodies[k]`; a top-level struct's field of type `NODESET_COMPILER_TYPE_k`
/// gets the type of `fields[k]`, and its doc attributes before any it has. Every one is used once.
///
/// # Panics
///
/// If a placeholder has no body or a body no placeholder: an internal error of the emitter.
pub(super) fn fill(file: &mut syn::File, bodies: Vec<Expr>, fields: Vec<(Vec<Attribute>, Type)>) {
    let mut bodies: Vec<Option<Expr>> = bodies.into_iter().map(Some).collect();
    let mut types: Vec<Option<(Vec<Attribute>, Type)>> = fields.into_iter().map(Some).collect();
    for item in &mut file.items {
        if let Item::Struct(st) = item {
            for field in st.fields.iter_mut() {
                let Type::Path(TypePath { qself: None, path }) = &field.ty else { continue };
                let Some(k) = path.get_ident().and_then(|i| i.to_string().strip_prefix(TYPE_PLACEHOLDER)?.parse::<usize>().ok()) else { continue };
                let (mut attrs, ty) = types.get_mut(k).and_then(Option::take).expect("internal error: a type placeholder without its type");
                attrs.append(&mut field.attrs);
                field.attrs = attrs;
                field.ty = ty;
            }
            continue;
        }
        let Item::Impl(imp) = item else { continue };
        for it in &mut imp.items {
            let ImplItem::Fn(f) = it else { continue };
            if f.sig.ident != "build" {
                continue;
            }
            let [Stmt::Expr(expr, None)] = f.block.stmts.as_mut_slice() else { continue };
            let Expr::Lit(ExprLit { lit: Lit::Int(k), .. }) = expr else { continue };
            let k: usize = k.base10_parse().expect("internal error: a build placeholder is not an index");
            *expr = bodies.get_mut(k).and_then(Option::take).expect("internal error: a build placeholder without its body");
        }
    }
    assert!(bodies.iter().all(Option::is_none), "internal error: a built body without its placeholder");
    assert!(types.iter().all(Option::is_none), "internal error: a built type without its placeholder");
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The trees built here print as the parsed text does (prettyplease reads no spans).
    #[test]
    fn built_bodies_print_as_their_text_parsed() {
        let long = "AVeryLongBrowseNameThatMakesTheCallWiderThanTheMarginOfPrettyplease";
        let built = self_struct(vec![
            (Ident::new("node", Span::call_site()), binder_call("build_this", vec![id()])),
            (Ident::new_raw("type", Span::call_site()), binder_call("build_child", vec![id(), ns(0), str_lit("Type")])),
            (Ident::new("long_one", Span::call_site()), binder_call("build_optional", vec![id(), ns(12), str_lit(long)])),
            (Ident::new("quoted", Span::call_site()), binder_call("build_child", vec![id(), ns(1), str_lit("a \"b\"\\ é\n")])),
        ]);
        let text = format!(
            "impl t::Handle for X {{ fn build(b: &t::Binder<'_>, id: &ua::NodeId) -> Self {{ Self {{ node: b.build_this(id), r#type: b.build_child(id, NS[0], \"Type\"), long_one: b.build_optional(id, NS[12], \"{long}\"), quoted: b.build_child(id, NS[1], \"a \\\"b\\\"\\\\ é\\n\") }} }} }}"
        );
        let parsed: syn::File = syn::parse_str(&text).unwrap();
        let mut filled: syn::File = syn::parse_str("impl t::Handle for X { fn build(b: &t::Binder<'_>, id: &ua::NodeId) -> Self { 0 } }").unwrap();
        fill(&mut filled, vec![built], Vec::new());
        assert_eq!(prettyplease::unparse(&filled), prettyplease::unparse(&parsed));
        // A single short field stays on one line (the struct literal's width limit), as parsed.
        let mut short: syn::File = syn::parse_str("impl H for Y { fn build() -> Self { 0 } }").unwrap();
        fill(&mut short, vec![self_struct(vec![(Ident::new("node", Span::call_site()), binder_call("build_this", vec![id()]))])], Vec::new());
        assert_eq!(prettyplease::unparse(&short), "impl H for Y {\n    fn build() -> Self {\n        Self { node: b.build_this(id) }\n    }\n}\n");
    }

    #[test]
    #[should_panic(expected = "without its body")]
    fn a_placeholder_without_a_body_is_an_internal_error() {
        let mut file: syn::File = syn::parse_str("impl H for Y { fn build() -> Self { 1 } }").unwrap();
        fill(&mut file, vec![path("x")], Vec::new());
    }

    /// Built types print as the parsed text does, long ones broken where prettyplease breaks them.
    #[test]
    fn built_types_print_as_their_text_parsed() {
        let value: Type = syn::parse_str("Vec<ua::LocalizedText>").unwrap();
        let string = || generic(&["String"], Vec::new());
        let method = generic(
            &["t", "Method"],
            vec![
                tuple(vec![string(), string(), generic(&["Vec"], vec![string()])]),
                tuple(vec![path_type(syn::parse_str("super::types::UpdateBehavior").unwrap())]),
            ],
        );
        let types = vec![
            generic(&["Option"], vec![generic(&["t", "Variable"], vec![value])]),
            generic(&["t", "ObjectNode"], Vec::new()),
            generic(&["t", "Placeholders"], vec![generic(&["Box"], vec![path_type(syn::parse_str("super::super::di::objects::TopologyElementType").unwrap())])]),
            method,
            generic(&["t", "Method"], vec![tuple(Vec::new()), tuple(vec![generic(&["u8"], Vec::new())])]),
        ];
        let text = "pub struct S { #[doc = \" `A` (Optional). Two\"] #[doc = \" lines, \\\"quoted\\\"\"] pub a: Option<t::Variable<Vec<ua::LocalizedText>>>, pub b: t::ObjectNode, pub c: t::Placeholders<Box<super::super::di::objects::TopologyElementType>>, pub get_update_behavior: t::Method<(String, String, Vec<String>), (super::types::UpdateBehavior,)>, pub e: t::Method<(), (u8,)> }";
        let parsed: syn::File = syn::parse_str(text).unwrap();
        let placeholders: Vec<String> = (0..types.len()).map(|k| type_placeholder(k).to_string()).collect();
        let with = format!(
            "pub struct S {{ pub a: {}, pub b: {}, pub c: {}, pub get_update_behavior: {}, pub e: {} }}",
            placeholders[0], placeholders[1], placeholders[2], placeholders[3], placeholders[4]
        );
        let mut filled: syn::File = syn::parse_str(&with).unwrap();
        let mut docs: Vec<Vec<Attribute>> = vec![doc_attrs("`A` (Optional). Two  \nlines, \"quoted\"")];
        docs.resize(types.len(), Vec::new());
        fill(&mut filled, Vec::new(), docs.into_iter().zip(types).collect());
        assert_eq!(prettyplease::unparse(&filled), prettyplease::unparse(&parsed));
    }
}
