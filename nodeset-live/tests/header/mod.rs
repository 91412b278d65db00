//! `nodeset_live.h` (in the Modelica support package the compiler writes, [`super::header_dir`]) is
//! written by hand; this test keeps it in step with the code: the header
//! declares exactly the functions `src/lib.rs` exports (`#[no_mangle] extern "C"`), each with the C types of
//! its Rust signature and the parameter names in Modelica's camelCase. (cbindgen would generate it, at the
//! price of a build tool; the header is small and this check is exact.)

use std::collections::BTreeMap;
use std::path::Path;

/// Name -> (result type, [(parameter name, type)]), in C.
type Api = BTreeMap<String, (String, Vec<(String, String)>)>;

fn c_type(ty: &syn::Type) -> String {
    let text = quote_type(ty);
    match text.as_str() {
        "f64" => "double",
        "c_int" => "int",
        "* const c_char" => "const char*",
        "* mut c_void" => "void*",
        "* mut c_int" => "int*",
        other => panic!("an exported function uses `{other}`, which has no type in the Modelica external function interface"),
    }
    .to_string()
}

fn quote_type(ty: &syn::Type) -> String {
    match ty {
        syn::Type::Path(p) => p.path.segments.last().unwrap().ident.to_string(),
        syn::Type::Ptr(p) => format!(
            "* {} {}",
            if p.const_token.is_some() {
                "const"
            } else {
                "mut"
            },
            quote_type(&p.elem)
        ),
        other => panic!(
            "unexpected type in an exported signature: {}",
            std::any::type_name_of_val(other)
        ),
    }
}

fn camel(snake: &str) -> String {
    let mut out = String::new();
    let mut up = false;
    for ch in snake.chars() {
        if ch == '_' {
            up = true;
        } else if up {
            out.extend(ch.to_uppercase());
            up = false;
        } else {
            out.push(ch);
        }
    }
    out
}

fn exported(source: &str) -> Api {
    let file = syn::parse_file(source).expect("src/lib.rs parses");
    let mut api = Api::new();
    for item in file.items {
        let syn::Item::Fn(f) = item else { continue };
        let no_mangle = f.attrs.iter().any(|a| a.path().is_ident("no_mangle"));
        let extern_c = f
            .sig
            .abi
            .as_ref()
            .and_then(|a| a.name.as_ref())
            .is_some_and(|n| n.value() == "C");
        assert_eq!(
            no_mangle, extern_c,
            "`{}`: an exported function is both #[no_mangle] and extern \"C\"",
            f.sig.ident
        );
        if !no_mangle {
            continue;
        }
        let ret = match &f.sig.output {
            syn::ReturnType::Default => "void".to_string(),
            syn::ReturnType::Type(_, t) => c_type(t),
        };
        let params = f
            .sig
            .inputs
            .iter()
            .map(|arg| match arg {
                syn::FnArg::Typed(p) => match &*p.pat {
                    syn::Pat::Ident(i) => (camel(&i.ident.to_string()), c_type(&p.ty)),
                    _ => panic!("`{}`: a parameter without a plain name", f.sig.ident),
                },
                syn::FnArg::Receiver(_) => panic!("an exported function takes self"),
            })
            .collect();
        api.insert(f.sig.ident.to_string(), (ret, params));
    }
    api
}

/// The prototypes of a header: `type name(type name, ...);`, one a line.
fn declared(header: &str) -> Api {
    let mut api = Api::new();
    for line in header.lines().map(str::trim) {
        let Some(open) = line.find('(') else { continue };
        if !line.ends_with(");")
            || line.starts_with('#')
            || line.starts_with('*')
            || line.starts_with("/*")
        {
            continue;
        }
        let (head, args) = (&line[..open], &line[open + 1..line.len() - 2]);
        let split = |decl: &str| -> (String, String) {
            let decl = decl.trim();
            let at = decl
                .rfind([' ', '*'])
                .expect("a declaration has a type and a name");
            (
                decl[at + 1..].to_string(),
                decl[..=at]
                    .replace(' ', "")
                    .replace("constchar", "const char"),
            )
        };
        let (name, ret) = split(head);
        let params = if args.trim() == "void" || args.trim().is_empty() {
            Vec::new()
        } else {
            args.split(',').map(split).collect()
        };
        assert!(
            api.insert(name.clone(), (ret, params)).is_none(),
            "`{name}` is declared twice"
        );
    }
    api
}

#[test]
fn the_header_declares_exactly_the_exported_functions() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let code = exported(&std::fs::read_to_string(dir.join("src/lib.rs")).unwrap());
    let header =
        declared(&std::fs::read_to_string(super::header_dir().join("nodeset_live.h")).unwrap());
    assert!(
        code.len() >= 20,
        "the exported functions are found: {:?}",
        code.keys()
    );
    for (name, sig) in &code {
        assert_eq!(
            header.get(name),
            Some(sig),
            "`{name}`: the header's prototype differs from src/lib.rs (want {sig:?})"
        );
    }
    let extra: Vec<&String> = header.keys().filter(|n| !code.contains_key(*n)).collect();
    assert!(
        extra.is_empty(),
        "the header declares functions src/lib.rs does not export: {extra:?}"
    );
}

#[test]
fn the_check_sees_a_changed_prototype() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(super::header_dir().join("nodeset_live.h")).unwrap();
    let code = exported(&std::fs::read_to_string(dir.join("src/lib.rs")).unwrap());
    for (from, to) in [
        ("double previous, int* status", "int previous, int* status"),
        ("const char* passwordEnv", "const char* password"),
        ("void opcua_live_server_free", "int opcua_live_server_free"),
    ] {
        assert!(text.contains(from), "{from}");
        let planted = declared(&text.replacen(from, to, 1));
        assert!(
            code.iter().any(|(n, sig)| planted.get(n) != Some(sig)),
            "the check misses `{from}` -> `{to}`"
        );
    }
    let fewer = declared(&text.replacen("int opcua_live_client_status(void* client);", "", 1));
    assert!(
        code.keys().any(|n| !fewer.contains_key(n)),
        "a function missing from the header is seen"
    );
}
