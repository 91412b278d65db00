//! Snapshots of the Rust the back end generates for each one-feature fixture (the same code
//! tests/rust-fixtures compiles under deny(warnings)).

use nodeset_compiler::build::Builder;
use nodeset_tests::{root, vendor};

fn generated(case: &str) -> String {
    let dir = root().join("tests/fixtures").join(case);
    let mut files: Vec<_> = std::fs::read_dir(&dir).expect("fixture folder").flatten().map(|e| e.path()).collect();
    files.sort();
    let out = std::env::temp_dir().join(format!("nodeset-rust-snap-{}-{case}", std::process::id()));
    let mut b = Builder::new().cargo_output(false).models_dir(vendor()).models_dir(&dir).out_dir(&out);
    for f in files.into_iter().filter(|f| f.extension().is_some_and(|x| x == "xml")) {
        b = b.file(f);
    }
    let path = b.generate().unwrap_or_else(|e| panic!("{e}"));
    let text = std::fs::read_to_string(&path).expect("generated file");
    let _ = std::fs::remove_dir_all(&out);
    text
}

macro_rules! fixture {
    ($($case:ident),*) => {$(
        #[test]
        fn $case() {
            let text = generated(stringify!($case));
            assert!(text.contains("pub static TABLE"), "every namespace has its address-space table");
            insta::assert_snapshot!(stringify!($case), text);
        }
    )*};
}

fixture!(
    structure, optional_fields, union, enum_gaps, option_set, abstract_base, arrays, names, method, event_type,
    two_namespaces, state_machine, instances, variable_type
);
