//! The `nodeset-compiler` command as a user runs it, where no server or nodeset is needed: `verify` with bad
//! input ends with a clear message and exit status 2, `rust` with a bad path or module name with one and
//! status 1, never a panic; and `codes` lists the verify codes.
//!
//! Being an integration test of this package, it also makes `cargo test --workspace` build the command with
//! the workspace's features, so the live tests in `tests/tests/verify.rs` take it from that build.

use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_nodeset-compiler")).args(args).output().expect("the command runs")
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

#[test]
fn rust_refuses_a_bad_path_or_module_name_before_reading_anything() {
    let out = std::env::temp_dir().join(format!("nodeset-cli-paths-{}", std::process::id()));
    // The input does not exist either: the paths are checked first, and nothing is written.
    let cases: [(&[&str], &str); 5] = [
        (&["--extern", "http://opcfoundation.org/UA/DI/=my crate::di"], "the extern path of http://opcfoundation.org/UA/DI/: `my crate::di` is not a Rust path"),
        (&["--runtime", "1bad::runtime"], "the runtime path `1bad::runtime` is not a Rust path"),
        (&["--module", "http://a.org/=1 bad"], "the module name of http://a.org/, `1 bad`, is not a Rust identifier"),
        (&["--module", "http://a.org/=type"], "the module name of http://a.org/, `type`, is not a Rust identifier (or is a keyword)"),
        (&["--module", "http://a.org/=x", "--module", "http://b.org/=x"], "http://a.org/ and http://b.org/ are both given the module name `x`"),
    ];
    for (flags, message) in cases {
        let mut args = vec!["rust", "missing.NodeSet2.xml", "--out", out.to_str().unwrap()];
        args.extend_from_slice(flags);
        let output = run(&args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(1), "{flags:?}: {stderr}");
        assert!(stderr.starts_with("error: ") && stderr.contains(message) && !stderr.contains("panicked"), "{stderr}");
        assert!(!out.exists(), "{flags:?} wrote {}", out.display());
    }
}

#[test]
fn verify_without_a_server_says_so() {
    let url = format!("opc.tcp://127.0.0.1:{}/", free_port());
    let output = run(&["verify", &url]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(stderr.starts_with("error: ") && stderr.contains(&url) && !stderr.contains("panicked"), "{stderr}");
}

#[test]
fn verify_refuses_a_url_that_is_not_opc_tcp() {
    for url in ["http://localhost:4840/", "opc.tcp://", "localhost:4840"] {
        let output = run(&["verify", url]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{url}: {stderr}");
        assert!(stderr.contains("is not an OPC UA endpoint URL (opc.tcp://HOST:PORT[/PATH])"), "{url}: {stderr}");
    }
}

#[test]
fn verify_reads_the_named_nodesets_before_the_server() {
    let manifest = concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.toml");
    let output = run(&["verify", "opc.tcp://127.0.0.1:1/", manifest]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("Cargo.toml is not a readable NodeSet2 file"), "{stderr}");
}

#[test]
fn verify_refuses_an_unknown_security_mode_and_a_missing_password() {
    let output = run(&["verify", "opc.tcp://127.0.0.1:1/", "--security-mode", "Encrypt"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("unknown security mode `Encrypt`"), "{stderr}");
    let output = Command::new(env!("CARGO_BIN_EXE_nodeset-compiler"))
        .args(["verify", "opc.tcp://127.0.0.1:1/", "--user", "op", "--password-env", "NODESET_TEST_UNSET_PASSWORD"])
        .env_remove("NODESET_TEST_UNSET_PASSWORD")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("the environment variable NODESET_TEST_UNSET_PASSWORD is not set"), "{stderr}");
}

#[test]
fn verify_turns_security_off_only_through_insecure() {
    // Secure by default: None is refused in either option and only `--insecure` asks for it.
    for args in [["--security-policy", "None"], ["--security-mode", "None"]] {
        let output = run(&[&["verify", "opc.tcp://127.0.0.1:1/"][..], &args[..]].concat());
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains("an unsecured connection is asked for with --insecure"), "{args:?}: {stderr}");
    }
    let output = run(&["verify", "opc.tcp://127.0.0.1:1/", "--insecure", "--security-mode", "Sign"]);
    assert_eq!(output.status.code(), Some(2), "{}", String::from_utf8_lossy(&output.stderr));
    let url = format!("opc.tcp://127.0.0.1:{}/", free_port());
    let output = run(&["verify", &url, "--insecure"]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.starts_with("warning: --insecure: verify connects without signing or encryption\n"), "{stderr}");
    assert_eq!(output.status.code(), Some(2), "{stderr}");
}

#[test]
fn the_codes_table_lists_the_verify_codes() {
    let output = run(&["codes", "NS0401", "NS0409"]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}");
    assert!(stdout.contains("NS0401 error   a mandatory member (or anything in a mandatory placeholder's place) is missing"), "{stdout}");
    assert!(stdout.contains("demotable: with --warn NS0409 or --allow NS0409"), "{stdout}");
}

#[test]
fn check_applies_the_instance_rules_of_verify_to_static_instances() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let fixture = format!("{root}/tests/fixtures/bad/static_instances.xml");
    let vendor = format!("{root}/nodesets/vendor");
    let output = run(&["check", &fixture, "--models", &vendor]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "the planted defects are errors, as in verify: {stderr}");
    for code in ["NS0401", "NS0403", "NS0404", "NS0405", "NS0406", "NS0408"] {
        assert!(stderr.contains(&format!("error[{code}]")), "no {code}: {stderr}");
    }
    assert!(stderr.contains("error[NS0406]: `1:Bad/1:Mode` holds a scalar UInt16, but its DataType is"), "{stderr}");
    assert!(stderr.contains("7 error(s), 1 warning(s)"), "{stderr}");
    // Demoted as in verify: `--warn` makes them warnings, and check passes.
    let demoted = ["--warn", "NS0401", "--warn", "NS0403", "--warn", "NS0404", "--warn", "NS0405", "--warn", "NS0406", "--warn", "NS0408"];
    let args: Vec<&str> = ["check", fixture.as_str(), "--models", vendor.as_str()].into_iter().chain(demoted).collect();
    let output = run(&args);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    assert!(stderr.contains("0 error(s), 8 warning(s)"), "{stderr}");
}

#[test]
fn trust_refuses_a_folder_that_is_no_pki_folder_and_a_file_that_is_no_certificate() {
    let dir = std::env::temp_dir().join(format!("nodeset-compiler-trust-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("pki/rejected")).unwrap();
    let not_a_cert = dir.join("notes.txt");
    std::fs::write(&not_a_cert, "not a certificate").unwrap();

    let output = run(&["trust", "--pki", dir.join("nowhere").to_str().unwrap(), not_a_cert.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("is not a PKI folder") && stderr.contains("help: give the folder"), "{stderr}");

    let output = run(&["trust", "--pki", dir.join("pki").to_str().unwrap(), not_a_cert.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("notes.txt: not an X.509 certificate in DER or PEM"), "{stderr}");
    assert!(!dir.join("pki/trusted").exists(), "nothing is written for a bad file");
    let _ = std::fs::remove_dir_all(&dir);
}
