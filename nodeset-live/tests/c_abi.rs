//! The library through its C interface, called as a Modelica tool's generated code calls it: the
//! constructors at initialisation, the sampled reads and writes at each step (the `previous` value held,
//! the status checked), the destructors at the end. A server object serves the fixture, a client object
//! connects to it over Basic256Sha256 SignAndEncrypt as a user whose password is in an environment
//! variable; bad input gets a status and a message, never a crash.

/// The header kept in step with the exported functions (in this binary: one test binary for the crate).
mod header;
/// The two scenarios of issue 39 from C programs, with node-opcua and the robot example as peers.
mod programs;

use std::ffi::{c_int, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use nodeset_live::*;
use nodeset_runtime::server::security::{prepare_pki, trust_certificate};
use nodeset_runtime::server::{Role, Users};
use opcua::crypto::X509;
use opcua::types::StatusCode;

/// The C header of the library, `nodeset_live.h`: it has one home, the Modelica support package the compiler
/// writes (`OpcUaSupport/Resources/Include`, where a tool's `Include` annotation finds it), and these tests and
/// their C programs read it there.
fn header_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../nodeset-compiler/src/emit/modelica/support/Resources/Include")
}

/// A client PKI folder at `dir` as the simulation's client makes it (its application name and URI, no host
/// names); its certificate.
fn client_certificate(dir: &Path) -> X509 {
    prepare_pki(
        dir,
        "Modelica simulation client",
        "urn:nodeset-live:client",
        &[],
    )
    .unwrap()
    .cert
}

const NS: &str = "http://example.com/nodeset-live/";

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// The fixture and the folder of the OPC UA namespace it requires, as the `nodesets` parameter.
fn nodesets() -> CString {
    let vendor = root().join("nodesets/vendor");
    assert!(
        vendor.join("Opc.Ua.NodeSet2.xml").is_file(),
        "run `cargo xtask fetch-nodesets` first"
    );
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/Live.NodeSet2.xml");
    c(&format!("{};{}", fixture.display(), vendor.display()))
}

fn c(s: &str) -> CString {
    CString::new(s).unwrap()
}

fn node(i: u32) -> CString {
    c(&format!("nsu={NS};i={i}"))
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("nodeset-live-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn status(code: StatusCode) -> c_int {
    code.bits() as c_int
}

unsafe fn server_error(s: *mut c_void) -> String {
    CStr::from_ptr(opcua_live_server_error(s))
        .to_string_lossy()
        .into_owned()
}

unsafe fn client_error(s: *mut c_void) -> String {
    CStr::from_ptr(opcua_live_client_error(s))
        .to_string_lossy()
        .into_owned()
}

/// A server with a user `operator` (role Operator) and a client trusted by it and trusting it, as an
/// administrator sets them up; the client's password in the environment variable `password_env`.
struct Secure {
    server: *mut c_void,
    server_pki: PathBuf,
    client_pki: PathBuf,
    users: PathBuf,
    port: c_int,
}

unsafe fn secure_server(name: &str, password_env: &str, port: c_int) -> Secure {
    let dir = tmp(name);
    let (server_pki, client_pki, users) = (
        dir.join("server-pki"),
        dir.join("client-pki"),
        dir.join("users.txt"),
    );
    let mut list = Users::default();
    list.set_password("operator", vec![Role::Operator], "s3cret-Pa55")
        .unwrap();
    std::fs::write(&users, list.to_text()).unwrap();
    std::env::set_var(password_env, "s3cret-Pa55");
    let server = opcua_live_server_new(
        port,
        nodesets().as_ptr(),
        c(server_pki.to_str().unwrap()).as_ptr(),
        c(users.to_str().unwrap()).as_ptr(),
        0,
    );
    assert_eq!(
        opcua_live_server_status(server),
        0,
        "{}",
        server_error(server)
    );
    let client_cert = client_certificate(&client_pki);
    trust_certificate(&server_pki, &client_cert).unwrap();
    let server_cert =
        X509::from_der(&std::fs::read(server_pki.join("own/cert.der")).unwrap()).unwrap();
    trust_certificate(&client_pki, &server_cert).unwrap();
    let port = opcua_live_server_port(server);
    Secure {
        server,
        server_pki,
        client_pki,
        users,
        port,
    }
}

unsafe fn secure_client(s: &Secure, password_env: &str) -> *mut c_void {
    opcua_live_client_new(
        c(&format!("opc.tcp://127.0.0.1:{}/", s.port)).as_ptr(),
        c("Basic256Sha256").as_ptr(),
        c("SignAndEncrypt").as_ptr(),
        c(s.client_pki.to_str().unwrap()).as_ptr(),
        c("operator").as_ptr(),
        c(password_env).as_ptr(),
    )
}

#[test]
fn a_simulation_serves_and_a_secure_client_reads_and_writes_through_the_c_interface() {
    unsafe {
        let s = secure_server("roundtrip", "NODESET_LIVE_TEST_PASSWORD_1", 0);
        let client = secure_client(&s, "NODESET_LIVE_TEST_PASSWORD_1");
        assert_eq!(
            opcua_live_client_status(client),
            0,
            "{}",
            client_error(client)
        );
        let (position, count, enabled, ratio, level) =
            (node(6001), node(6003), node(6004), node(6006), node(6007));
        let mut st: c_int = -1;
        // Before any step: the nodeset's values.
        assert_eq!(
            opcua_live_client_read_real(client, position.as_ptr(), -1.0, &mut st),
            0.5
        );
        assert_eq!(st, 0, "{}", client_error(client));
        assert_eq!(
            opcua_live_server_read_integer(s.server, count.as_ptr(), -1, &mut st),
            7
        );
        // Steps: the simulation publishes a position, the client reads it; the client writes a count, a
        // flag and a ratio, the simulation reads them.
        for step in 0..20 {
            let x = 0.1 * step as f64;
            assert_eq!(
                opcua_live_server_write_real(s.server, position.as_ptr(), x),
                0,
                "{}",
                server_error(s.server)
            );
            assert_eq!(
                opcua_live_client_read_real(client, position.as_ptr(), -1.0, &mut st),
                x,
                "step {step}"
            );
            assert_eq!(st, 0);
            assert_eq!(
                opcua_live_client_write_integer(client, count.as_ptr(), 100 + step),
                0,
                "{}",
                client_error(client)
            );
            assert_eq!(
                opcua_live_server_read_integer(s.server, count.as_ptr(), -1, &mut st),
                100 + step
            );
            assert_eq!(
                opcua_live_client_write_boolean(client, enabled.as_ptr(), step % 2),
                0,
                "{}",
                client_error(client)
            );
            assert_eq!(
                opcua_live_server_read_boolean(s.server, enabled.as_ptr(), -1, &mut st),
                step % 2
            );
        }
        // A Real to a Float variable, an Integer to a Byte variable: the variable's type is kept.
        assert_eq!(
            opcua_live_client_write_real(client, ratio.as_ptr(), 0.75),
            0,
            "{}",
            client_error(client)
        );
        assert_eq!(
            opcua_live_server_read_real(s.server, ratio.as_ptr(), -1.0, &mut st),
            0.75
        );
        assert_eq!(
            opcua_live_client_write_integer(client, level.as_ptr(), 200),
            0,
            "{}",
            client_error(client)
        );
        assert_eq!(
            opcua_live_client_read_integer(client, level.as_ptr(), -1, &mut st),
            200
        );
        assert_eq!(
            opcua_live_server_write_integer(s.server, level.as_ptr(), 300),
            status(StatusCode::BadOutOfRange)
        );
        assert!(
            server_error(s.server).contains("300 is out of the range of Byte"),
            "{}",
            server_error(s.server)
        );
        assert_eq!(
            opcua_live_client_write_integer(client, level.as_ptr(), -1),
            status(StatusCode::BadOutOfRange)
        );
        assert!(
            client_error(client).contains("-1 is out of the range of Byte"),
            "{}",
            client_error(client)
        );
        assert_eq!(
            opcua_live_server_read_integer(s.server, level.as_ptr(), -1, &mut st),
            200,
            "the refused writes changed nothing"
        );
        // Strings: published by the simulation, written by the client; a failed read returns a copy of
        // `previous`.
        let label = node(6005);
        let text = |p: *const std::ffi::c_char| CStr::from_ptr(p).to_string_lossy().into_owned();
        assert_eq!(
            text(opcua_live_client_read_string(
                client,
                label.as_ptr(),
                c("?").as_ptr(),
                &mut st
            )),
            "axis"
        );
        assert_eq!(st, 0, "{}", client_error(client));
        assert_eq!(
            opcua_live_server_write_string(s.server, label.as_ptr(), c("axis 2 (ä)").as_ptr()),
            0,
            "{}",
            server_error(s.server)
        );
        assert_eq!(
            text(opcua_live_client_read_string(
                client,
                label.as_ptr(),
                c("?").as_ptr(),
                &mut st
            )),
            "axis 2 (ä)"
        );
        assert_eq!(
            opcua_live_client_write_string(client, label.as_ptr(), c("from the client").as_ptr()),
            0,
            "{}",
            client_error(client)
        );
        assert_eq!(
            text(opcua_live_server_read_string(
                s.server,
                label.as_ptr(),
                c("?").as_ptr(),
                &mut st
            )),
            "from the client"
        );
        let previous = c("held");
        let held =
            opcua_live_server_read_string(s.server, position.as_ptr(), previous.as_ptr(), &mut st);
        assert_eq!(
            (text(held), st),
            ("held".to_owned(), status(StatusCode::BadTypeMismatch))
        );
        assert_ne!(held, previous.as_ptr(), "a copy, not the caller's pointer");
        assert_eq!(
            opcua_live_client_write_string(client, position.as_ptr(), c("1.5").as_ptr()),
            status(StatusCode::BadTypeMismatch)
        );
        assert!(
            client_error(client)
                .contains("the variable is a Double, which a Modelica String cannot write"),
            "{}",
            client_error(client)
        );
        // A message returned to this thread stays as it was while another thread calls on the object.
        let mine = opcua_live_client_error(client);
        let before = text(mine);
        let other = client as usize;
        std::thread::spawn(move || {
            let client = other as *mut c_void;
            let mut st = 0;
            for _ in 0..3 {
                opcua_live_client_read_real(
                    client,
                    c("nsu=urn:elsewhere;i=1").as_ptr(),
                    0.0,
                    &mut st,
                );
                let _ = opcua_live_client_error(client);
            }
        })
        .join()
        .unwrap();
        assert_eq!(
            text(mine),
            before,
            "the string this thread got is its own until its next string call"
        );
        assert!(
            client_error(client).contains("urn:elsewhere"),
            "the object's message is the other thread's last"
        );

        // Throughput of one block, sampled as fast as the calls return.
        let n = 300;
        let t = Instant::now();
        for i in 0..n {
            opcua_live_client_read_real(client, position.as_ptr(), 0.0, &mut st);
            assert_eq!(st, 0, "read {i}: {}", client_error(client));
        }
        let client_reads = n as f64 / t.elapsed().as_secs_f64();
        let t = Instant::now();
        for i in 0..n {
            assert_eq!(
                opcua_live_server_write_real(s.server, position.as_ptr(), i as f64),
                0
            );
        }
        let server_writes = n as f64 / t.elapsed().as_secs_f64();
        println!("nodeset-live: {client_reads:.0} client reads/s, {server_writes:.0} server writes/s (one block, SignAndEncrypt, loopback)");
        opcua_live_client_free(client);
        opcua_live_server_free(s.server);
        let _ = (s.server_pki, s.users);
    }
}

#[test]
fn bad_input_gets_a_status_and_a_message_never_a_crash() {
    unsafe {
        let pki = tmp("bad");
        // An insecure server and an insecure client: anonymous sessions may write on the None endpoint.
        let server = opcua_live_server_new(
            0,
            nodesets().as_ptr(),
            c(pki.join("server").to_str().unwrap()).as_ptr(),
            std::ptr::null(),
            1,
        );
        assert_eq!(
            opcua_live_server_status(server),
            0,
            "{}",
            server_error(server)
        );
        let url = c(&format!(
            "opc.tcp://127.0.0.1:{}/",
            opcua_live_server_port(server)
        ));
        let client_pki = c(pki.join("client").to_str().unwrap());
        let client = opcua_live_client_new(
            url.as_ptr(),
            c("None").as_ptr(),
            c("None").as_ptr(),
            client_pki.as_ptr(),
            std::ptr::null(),
            std::ptr::null(),
        );
        assert_eq!(
            opcua_live_client_status(client),
            0,
            "{}",
            client_error(client)
        );
        let mut st: c_int = 0;

        // An unknown NodeId, an unknown namespace, text that is no NodeId: the previous value is held.
        let unknown = node(9999);
        assert_eq!(
            opcua_live_server_read_real(server, unknown.as_ptr(), 4.5, &mut st),
            4.5
        );
        assert_eq!(st, status(StatusCode::BadNodeIdUnknown));
        assert!(
            server_error(server).contains("the server has no such node"),
            "{}",
            server_error(server)
        );
        assert_eq!(
            opcua_live_client_read_real(client, unknown.as_ptr(), 4.5, &mut st),
            4.5
        );
        assert_eq!(
            st,
            status(StatusCode::BadNodeIdUnknown),
            "{}",
            client_error(client)
        );
        assert!(
            client_error(client).contains(&format!("reading `nsu={NS};i=9999`: BadNodeIdUnknown")),
            "{}",
            client_error(client)
        );
        assert_eq!(
            opcua_live_client_write_real(client, unknown.as_ptr(), 1.0),
            status(StatusCode::BadNodeIdUnknown)
        );
        let elsewhere = c("nsu=urn:nowhere;i=1");
        assert_eq!(
            opcua_live_client_read_integer(client, elsewhere.as_ptr(), 3, &mut st),
            3
        );
        assert_eq!(st, status(StatusCode::BadNodeIdUnknown));
        assert!(
            client_error(client).contains("has no namespace `urn:nowhere`")
                && client_error(client).contains(NS),
            "{}",
            client_error(client)
        );
        let garbage = c("Drive.Position");
        assert_eq!(
            opcua_live_server_write_real(server, garbage.as_ptr(), 1.0),
            status(StatusCode::BadNodeIdInvalid)
        );
        assert!(
            server_error(server).contains("`Drive.Position` is not a NodeId"),
            "{}",
            server_error(server)
        );
        assert_eq!(
            opcua_live_server_read_real(server, std::ptr::null(), 2.0, std::ptr::null_mut()),
            2.0,
            "NULL strings and outputs"
        );

        // Wrong types: a String read as a Real, a Double written as a Boolean, a Double read as a Boolean.
        let (position, enabled, label) = (node(6001), node(6004), node(6005));
        assert_eq!(
            opcua_live_server_read_real(server, label.as_ptr(), 1.5, &mut st),
            1.5
        );
        assert_eq!(st, status(StatusCode::BadTypeMismatch));
        assert!(
            server_error(server).contains("String \"axis\" is not a Modelica Real"),
            "{}",
            server_error(server)
        );
        assert_eq!(
            opcua_live_server_write_boolean(server, position.as_ptr(), 1),
            status(StatusCode::BadTypeMismatch)
        );
        assert!(
            server_error(server)
                .contains("the variable is a Double, which a Modelica Boolean cannot write"),
            "{}",
            server_error(server)
        );
        assert_eq!(
            opcua_live_client_read_boolean(client, position.as_ptr(), 1, &mut st),
            1
        );
        assert_eq!(st, status(StatusCode::BadTypeMismatch));
        assert!(
            client_error(client).contains("is not a Modelica Boolean"),
            "{}",
            client_error(client)
        );
        assert_eq!(
            opcua_live_client_write_real(client, enabled.as_ptr(), 1.0),
            status(StatusCode::BadTypeMismatch)
        );
        assert!(
            client_error(client).contains("the variable is a Boolean"),
            "{}",
            client_error(client)
        );
        // A good call clears the message.
        assert_eq!(
            opcua_live_client_read_real(client, position.as_ptr(), 0.0, &mut st),
            0.5
        );
        assert_eq!((st, client_error(client).as_str()), (0, ""));

        // An unreachable URL: the constructor returns, the status and every call say why.
        let closed = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let port = closed.local_addr().unwrap().port();
        drop(closed);
        let t = Instant::now();
        let nowhere = opcua_live_client_new(
            c(&format!("opc.tcp://127.0.0.1:{port}/")).as_ptr(),
            c("None").as_ptr(),
            c("None").as_ptr(),
            client_pki.as_ptr(),
            std::ptr::null(),
            std::ptr::null(),
        );
        assert!(
            t.elapsed() < Duration::from_secs(8),
            "the constructor gives up within its connect timeout"
        );
        assert_eq!(
            opcua_live_client_status(nowhere),
            status(StatusCode::BadNotConnected)
        );
        let why = client_error(nowhere);
        assert!(
            why.contains(&format!("not connected to opc.tcp://127.0.0.1:{port}/"))
                && why.contains("connecting again"),
            "{why}"
        );
        assert_eq!(
            opcua_live_client_read_real(nowhere, position.as_ptr(), 9.0, &mut st),
            9.0
        );
        assert_eq!(st, status(StatusCode::BadNotConnected));
        opcua_live_client_free(nowhere);

        // Configurations that cannot start: an object all the same, whose calls say why.
        let broken = opcua_live_server_new(
            0,
            c("no/such/Model.NodeSet2.xml").as_ptr(),
            c(pki.join("s2").to_str().unwrap()).as_ptr(),
            std::ptr::null(),
            0,
        );
        assert_eq!(
            opcua_live_server_status(broken),
            status(StatusCode::BadConfigurationError)
        );
        assert!(
            server_error(broken).contains("no/such/Model.NodeSet2.xml: no such file or folder"),
            "{}",
            server_error(broken)
        );
        assert_eq!(
            opcua_live_server_write_real(broken, position.as_ptr(), 1.0),
            status(StatusCode::BadConfigurationError)
        );
        assert!(
            server_error(broken).starts_with("the object did not start: "),
            "{}",
            server_error(broken)
        );
        opcua_live_server_free(broken);
        let no_password = opcua_live_client_new(
            url.as_ptr(),
            std::ptr::null(),
            std::ptr::null(),
            client_pki.as_ptr(),
            c("operator").as_ptr(),
            c("NODESET_LIVE_TEST_UNSET").as_ptr(),
        );
        assert_eq!(
            opcua_live_client_status(no_password),
            status(StatusCode::BadConfigurationError)
        );
        assert!(client_error(no_password).contains("`NODESET_LIVE_TEST_UNSET`, which should hold the password of user `operator`, is not set"), "{}", client_error(no_password));
        opcua_live_client_free(no_password);
        let bad_policy = opcua_live_client_new(
            url.as_ptr(),
            c("Basic512").as_ptr(),
            std::ptr::null(),
            client_pki.as_ptr(),
            std::ptr::null(),
            std::ptr::null(),
        );
        assert!(
            client_error(bad_policy).contains("unknown security policy `Basic512`"),
            "{}",
            client_error(bad_policy)
        );
        opcua_live_client_free(bad_policy);

        // No object at all.
        assert_eq!(
            opcua_live_client_read_integer(std::ptr::null_mut(), position.as_ptr(), 5, &mut st),
            5
        );
        assert_eq!(st, status(StatusCode::BadInvalidArgument));
        assert!(client_error(std::ptr::null_mut()).starts_with("no object"));
        opcua_live_client_free(std::ptr::null_mut());

        opcua_live_client_free(client);
        opcua_live_server_free(server);
    }
}

#[test]
fn a_lost_connection_is_reported_and_the_client_connects_again() {
    unsafe {
        let s = secure_server("reconnect", "NODESET_LIVE_TEST_PASSWORD_3", 0);
        let client = secure_client(&s, "NODESET_LIVE_TEST_PASSWORD_3");
        assert_eq!(
            opcua_live_client_status(client),
            0,
            "{}",
            client_error(client)
        );
        let position = node(6001);
        let mut st: c_int = -1;
        assert_eq!(
            opcua_live_server_write_real(s.server, position.as_ptr(), 1.25),
            0
        );
        assert_eq!(
            opcua_live_client_read_real(client, position.as_ptr(), 0.0, &mut st),
            1.25
        );
        // The server goes away: the next read reports it and holds the value.
        opcua_live_server_free(s.server);
        let gone = Instant::now();
        assert_eq!(
            opcua_live_client_read_real(client, position.as_ptr(), 1.25, &mut st),
            1.25
        );
        assert_ne!(st, 0, "a read without a server fails");
        let why = client_error(client);
        assert!(
            why.contains("connection is lost") || why.contains("not connected"),
            "{why}"
        );
        println!(
            "nodeset-live: server gone, reported after {:?}: {why}",
            gone.elapsed()
        );
        // It comes back on the same port with the same PKI folder: the client connects again by itself.
        let again = opcua_live_server_new(
            s.port,
            nodesets().as_ptr(),
            c(s.server_pki.to_str().unwrap()).as_ptr(),
            c(s.users.to_str().unwrap()).as_ptr(),
            0,
        );
        assert_eq!(
            opcua_live_server_status(again),
            0,
            "{}",
            server_error(again)
        );
        let back = Instant::now();
        assert_eq!(
            opcua_live_server_write_real(again, position.as_ptr(), 2.5),
            0
        );
        let mut value = 0.0;
        while back.elapsed() < Duration::from_secs(30) {
            value = opcua_live_client_read_real(client, position.as_ptr(), 0.0, &mut st);
            if st == 0 {
                break;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        assert_eq!(
            (st, value),
            (0, 2.5),
            "the client reads from the new server: {}",
            client_error(client)
        );
        println!(
            "nodeset-live: connected again {:?} after the server came back",
            back.elapsed()
        );
        opcua_live_client_free(client);
        opcua_live_server_free(again);
    }
}

#[test]
fn a_refused_certificate_is_a_clear_message_on_either_side() {
    unsafe {
        let s = secure_server("refused", "NODESET_LIVE_TEST_PASSWORD_4", 0);
        let url = c(&format!("opc.tcp://127.0.0.1:{}/", s.port));
        let server_cert =
            X509::from_der(&std::fs::read(s.server_pki.join("own/cert.der")).unwrap()).unwrap();
        let dir = tmp("refused-clients");
        let connect = |pki: &Path| {
            opcua_live_client_new(
                url.as_ptr(),
                std::ptr::null(),
                std::ptr::null(),
                c(pki.to_str().unwrap()).as_ptr(),
                c("operator").as_ptr(),
                c("NODESET_LIVE_TEST_PASSWORD_4").as_ptr(),
            )
        };
        let position = node(6001);
        let mut st: c_int = 0;

        // The server does not trust the client (the client trusts the server).
        let stranger = dir.join("stranger");
        client_certificate(&stranger);
        trust_certificate(&stranger, &server_cert).unwrap();
        let client = connect(&stranger);
        assert_eq!(
            opcua_live_client_status(client),
            status(StatusCode::BadNotConnected)
        );
        let why = client_error(client);
        println!("nodeset-live: the server refuses the client: {why}");
        assert!(
            why.contains("the server refused this client's certificate"),
            "{why}"
        );
        assert!(
            why.contains(&format!("{}", stranger.join("own/cert.der").display())),
            "{why}"
        );
        assert_eq!(
            opcua_live_client_read_real(client, position.as_ptr(), 7.5, &mut st),
            7.5
        );
        assert_eq!(st, status(StatusCode::BadNotConnected));
        assert!(
            client_error(client).contains("the server refused this client's certificate"),
            "{}",
            client_error(client)
        );
        opcua_live_client_free(client);

        // The client does not trust the server (the server trusts the client).
        let doubter = dir.join("doubter");
        let cert = client_certificate(&doubter);
        trust_certificate(&s.server_pki, &cert).unwrap();
        let client = connect(&doubter);
        assert_eq!(
            opcua_live_client_status(client),
            status(StatusCode::BadNotConnected)
        );
        let why = client_error(client);
        println!("nodeset-live: the client refuses the server: {why}");
        assert!(
            why.contains("this client does not trust the server's certificate"),
            "{why}"
        );
        assert!(
            why.contains(&format!("{}", doubter.join("rejected").display()))
                && why.contains("an administrator moves it to"),
            "{why}"
        );
        assert_eq!(
            opcua_live_client_write_real(client, position.as_ptr(), 1.0),
            status(StatusCode::BadNotConnected)
        );
        opcua_live_client_free(client);

        opcua_live_server_free(s.server);
    }
}
