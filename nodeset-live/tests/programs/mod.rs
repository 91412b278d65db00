//! The two scenarios of issue 39 from C programs (`tests/c/*.c`), compiled with the system's C compiler
//! against the header `nodeset_live.h` and the shared library of the workspace build, as a Modelica tool links
//! them, and run as child processes:
//!
//! - (a) component simulation (`drive.c`): the program integrates a drive and publishes ActualPosition and
//!   ActualSpeed of a served Robotics axis; node-opcua (`tests/node-peer/subscribe.js`) subscribes over
//!   Basic256Sha256 SignAndEncrypt as a user and must see the trajectory, value for value; the latency from
//!   each write call to node-opcua's notification is printed (median and maximum), not asserted;
//! - (b) control (`control.c`): the program connects as a client to the robot example (`nodeset-examples`,
//!   its executable from the same workspace build), first refusing its certificate, reads the six joint
//!   positions by browse path and converts them to SI, and writes the controller's ConfiguredDefaultStopMode,
//!   which the robot prints.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use nodeset_runtime::server::security::{own_certificate, prepare_pki, trust_certificate};
use nodeset_runtime::server::{Role, Users};
use process_support::Process;

use super::{root, tmp};

/// How long a child may stay silent before the test gives up on it.
const QUIET: Duration = Duration::from_secs(60);

/// A child process the test talks to: its stdin written line by line, its stdout read line by line (on a
/// thread of its own, with a timeout); killed when dropped.
struct Talk {
    child: std::process::Child,
    lines: std::sync::mpsc::Receiver<String>,
}

impl Talk {
    fn spawn(command: &mut Command) -> Talk {
        let mut child = command
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {:?}: {e}", command.get_program()));
        let out = child.stdout.take().unwrap();
        let (tx, lines) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Talk { child, lines }
    }

    /// The next line, or a failure after [`QUIET`].
    fn next_line(&self) -> String {
        match self.lines.recv_timeout(QUIET) {
            Ok(line) => line,
            Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                panic!("the child printed nothing for {} s", QUIET.as_secs())
            }
            Err(_) => panic!("the child ended (its stderr says why)"),
        }
    }

    /// The rest of the first line to come that starts with `marker`.
    fn line(&self, marker: &str) -> String {
        loop {
            if let Some(rest) = self.next_line().strip_prefix(marker) {
                return rest.to_owned();
            }
        }
    }

    fn send(&mut self, line: &str) {
        let stdin = self.child.stdin.as_mut().unwrap();
        writeln!(stdin, "{line}")
            .and_then(|()| stdin.flush())
            .unwrap();
    }

    /// Closes its stdin and waits for the end: its exit status and the lines it printed until then.
    fn finish(mut self) -> (std::process::ExitStatus, Vec<String>) {
        drop(self.child.stdin.take());
        let mut rest = Vec::new();
        loop {
            match self.lines.recv_timeout(QUIET) {
                Ok(line) => rest.push(line),
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
                Err(_) => panic!(
                    "the child printed nothing for {} s: {rest:?}",
                    QUIET.as_secs()
                ),
            }
        }
        (self.child.wait().unwrap(), rest)
    }
}

impl Drop for Talk {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The JSON lines of the workspace build `.ci/run` makes (`cargo build --workspace --bins --tests
/// --examples`: in CI a no-op that reports its artifacts), run once per test binary. (`cargo test` builds
/// this crate as an rlib for the tests and does not always write the cdylib again; and `cargo build -p
/// nodeset-live` alone resolves the dependencies' features for this crate only, compiling async-opcua a
/// second time.)
fn workspace_build() -> &'static str {
    static BUILD: OnceLock<String> = OnceLock::new();
    BUILD.get_or_init(|| {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
        let out = Command::new(cargo)
            .current_dir(root())
            .args([
                "build",
                "--workspace",
                "--bins",
                "--tests",
                "--examples",
                "--message-format=json-render-diagnostics",
            ])
            .stderr(Stdio::inherit())
            .output()
            .expect("cargo runs");
        assert!(
            out.status.success(),
            "cargo build --workspace --bins --tests --examples failed"
        );
        String::from_utf8_lossy(&out.stdout).into_owned()
    })
}

/// The artifact line of target `name` whose line also contains `marker`, and the files its `key` lists.
fn artifact(name: &str, marker: &str, key: &str) -> Vec<String> {
    let line = workspace_build()
        .lines()
        .find(|l| {
            // Not the unit-test harness of the same name (`"test":true`).
            l.contains("\"reason\":\"compiler-artifact\"")
                && l.contains(&format!("\"name\":\"{name}\""))
                && l.contains(marker)
                && l.contains("\"test\":false")
        })
        .unwrap_or_else(|| panic!("cargo reports no artifact {name} ({marker})"));
    let at = line
        .find(key)
        .unwrap_or_else(|| panic!("the artifact {name} has no {key}"));
    let rest = &line[at + key.len()..];
    let end = if key.ends_with('[') {
        rest.find(']')
    } else {
        rest.find(',')
    }
    .unwrap_or(rest.len());
    rest[..end]
        .split('"')
        .filter(|f| !f.is_empty() && *f != ",")
        .map(str::to_owned)
        .collect()
}

/// The shared library as a Modelica tool gets it.
fn shared_library() -> PathBuf {
    artifact("nodeset_live", "\"cdylib\"", "\"filenames\":[")
        .into_iter()
        .find(|f| f.ends_with(".so"))
        .map(PathBuf::from)
        .expect("the library is built as a cdylib")
}

/// Compiles `tests/c/<name>.c` into `dir`, linked against the shared library as a tool links it.
fn compile(name: &str, dir: &Path) -> PathBuf {
    let lib = shared_library().parent().unwrap().to_path_buf();
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let exe = dir.join(name);
    let cc = Command::new("cc")
        // -rdynamic: the program's own symbols visible to dlsym, as a tool's runtime is to the library.
        .args([
            "-std=c99",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-g",
            "-rdynamic",
            "-I",
        ])
        .arg(super::header_dir())
        .arg(manifest.join(format!("tests/c/{name}.c")))
        .arg("-L")
        .arg(&lib)
        .args(["-lnodeset_live", "-lm"])
        // RPATH, not RUNPATH: searched before LD_LIBRARY_PATH, which `cargo test` sets to folders that hold
        // an older copy of the library (target/debug/libnodeset_live.so, uplifted by an earlier build).
        .arg(format!("-Wl,--disable-new-dtags,-rpath,{}", lib.display()))
        .arg("-o")
        .arg(&exe)
        .output()
        .expect("cc runs (apt-get install gcc)");
    assert!(
        cc.status.success(),
        "cc failed:\n{}",
        String::from_utf8_lossy(&cc.stderr)
    );
    exe
}

/// A user file with `operator` (role Operator) and `password`.
fn operator(path: &Path, password: &str) {
    let mut list = Users::default();
    list.set_password("operator", vec![Role::Operator], password)
        .unwrap();
    std::fs::write(path, list.to_text()).unwrap();
}

/// The number after `key=` in a line (up to the next space or comma).
fn field(line: &str, key: &str) -> f64 {
    let at = line
        .find(&format!(" {key}="))
        .unwrap_or_else(|| panic!("no {key}= in {line}"))
        + key.len()
        + 2;
    let rest = &line[at..];
    rest[..rest.find([' ', ',']).unwrap_or(rest.len())]
        .parse()
        .unwrap_or_else(|e| panic!("{key} in {line}: {e}"))
}

/// A notification node-opcua printed (`change <index> <value> <ms>`): (index, value, arrival time). Its
/// other lines (node-opcua's own warnings) are passed over.
fn note(seen: &mut Vec<(usize, f64, f64)>, line: &str) {
    assert!(!line.starts_with("error "), "node-opcua: {line}");
    if !line.starts_with("change ") {
        eprintln!("node-opcua: {line}");
        return;
    }
    let words: Vec<&str> = line.split(' ').collect();
    assert!(
        words.len() == 4 && words[0] == "change",
        "node-opcua: {line}"
    );
    seen.push((
        words[1].parse().unwrap(),
        words[2].parse().unwrap(),
        words[3].parse().unwrap(),
    ));
}

/// The median and the maximum.
fn median_max(mut xs: Vec<f64>) -> (f64, f64) {
    xs.sort_by(f64::total_cmp);
    (xs[xs.len() / 2], xs[xs.len() - 1])
}

/// Consecutive repeats dropped: a subscription reports changes, so a value published twice is seen once.
fn changes(xs: &[f64]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::new();
    for &x in xs {
        if out.last() != Some(&x) {
            out.push(x);
        }
    }
    out
}

const AXIS: &str = "nsu=http://example.com/nodeset-live/axis/;i=";

const DRIVE_PASSWORD: &str = "dr1ve-Pa55";

/// What drive.c is run with: its arguments, and the server's PKI folder and certificate.
struct DriveFiles {
    args: Vec<String>,
    server_pki: PathBuf,
    server_cert: opcua::crypto::X509,
}

/// The administrator's part for drive.c, in `dir`: the server's and the client's PKI folders, each
/// certificate trusted by the other side; a user file with `operator` ([`DRIVE_PASSWORD`], in the
/// environment variable DRIVE_PASSWORD); the nodesets (the Robotics axis fixture and the vendor folder).
fn drive_files(dir: &Path) -> DriveFiles {
    let (server_pki, client_pki, users) = (
        dir.join("server-pki"),
        dir.join("client-pki"),
        dir.join("users.txt"),
    );
    let server_cert = prepare_pki(
        &server_pki,
        "Modelica simulation",
        "urn:nodeset-models:modelica-simulation",
        &["127.0.0.1".into()],
    )
    .unwrap()
    .cert;
    let client_cert = super::client_certificate(&client_pki);
    trust_certificate(&server_pki, &client_cert).unwrap();
    trust_certificate(&client_pki, &server_cert).unwrap();
    operator(&users, DRIVE_PASSWORD);
    let nodesets = format!(
        "{};{}",
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/LiveAxis.NodeSet2.xml")
            .display(),
        root().join("nodesets/vendor").display()
    );
    let path = |p: &Path| p.to_str().unwrap().to_owned();
    DriveFiles {
        args: vec![
            nodesets,
            path(&server_pki),
            path(&client_pki),
            path(&users),
            "DRIVE_PASSWORD".into(),
        ],
        server_pki,
        server_cert,
    }
}

/// Scenario (a) under valgrind's memcheck, without the subscriber: no invalid read or write, no use of
/// uninitialised memory, no memory definitely lost but the node tables a server leaks by design
/// (`tests/c/valgrind.supp`), through the server's start, 41 samples, bad input and both destructors.
#[test]
fn the_c_drive_runs_clean_under_valgrind() {
    let found = Command::new("valgrind").arg("--version").output();
    assert!(
        found.is_ok_and(|o| o.status.success()),
        "valgrind is not installed (apt-get install valgrind)"
    );
    let dir = tmp("valgrind");
    let exe = compile("drive", &dir);
    let files = drive_files(&dir);
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let started = Instant::now();
    let mut drive = Talk::spawn(
        Command::new("valgrind")
            .args([
                "--leak-check=full",
                "--errors-for-leak-kinds=definite",
                "--error-exitcode=99",
            ])
            .arg(format!(
                "--suppressions={}",
                manifest.join("tests/c/valgrind.supp").display()
            ))
            .arg(format!("--log-file={}", dir.join("valgrind.log").display()))
            .arg(&exe)
            .args(&files.args)
            .env("DRIVE_PASSWORD", DRIVE_PASSWORD),
    );
    drive.line("drive: listening on ");
    drive.send("go");
    drive.line("drive: simulated");
    drive.send("stop");
    let (exit, rest) = drive.finish();
    let log = std::fs::read_to_string(dir.join("valgrind.log")).unwrap();
    assert!(
        exit.success() && rest.iter().any(|l| l.ends_with(" 0 failures")),
        "drive under valgrind ({exit}): {rest:?}\n{log}"
    );
    assert!(log.contains("ERROR SUMMARY: 0 errors"), "{log}");
    println!(
        "nodeset-live: the C drive ran clean under valgrind memcheck in {:?}",
        started.elapsed()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn scenario_a_a_c_drive_publishes_a_robotics_axis_and_node_opcua_subscribes_over_sign_and_encrypt()
{
    let dir = tmp("drive");
    let exe = compile("drive", &dir);
    let peer = root().join("tests/node-peer");
    assert!(
        peer.join("node_modules/node-opcua/package.json").is_file(),
        "node-opcua is not installed in {}; run `cargo xtask node-peer`",
        peer.display()
    );
    let files = drive_files(&dir);
    // node-opcua's certificate, trusted by the server; it trusts the server's.
    let node_pki = dir.join("node-pki");
    let node_cert = prepare_pki(
        &node_pki,
        "nodeset-live node-opcua subscriber",
        "urn:nodeset-live:node-subscriber",
        &[],
    )
    .unwrap()
    .cert;
    trust_certificate(&files.server_pki, &node_cert).unwrap();
    let node_trust = dir.join("node-cm");
    std::fs::create_dir_all(node_trust.join("trusted/certs")).unwrap();
    // async-opcua ends the key's PEM lines with CR alone, which OpenSSL (node's crypto) does not read.
    let node_key = node_trust.join("key.pem");
    let key = std::fs::read_to_string(node_pki.join("private/private.pem")).unwrap();
    std::fs::write(&node_key, key.replace("\r\n", "\n").replace('\r', "\n")).unwrap();
    std::fs::write(
        node_trust.join("trusted/certs/server.der"),
        files.server_cert.to_der().unwrap(),
    )
    .unwrap();

    let started = Instant::now();
    let mut drive = Talk::spawn(
        Command::new(&exe)
            .args(&files.args)
            .env("DRIVE_PASSWORD", DRIVE_PASSWORD),
    );
    let url = drive.line("drive: listening on ");
    let (position, speed) = (format!("{AXIS}6001"), format!("{AXIS}6002"));
    let node = Talk::spawn(
        Command::new("node")
            .current_dir(&peer)
            .arg("subscribe.js")
            .arg(&url)
            .arg(node_pki.join("own/cert.der"))
            .arg(&node_key)
            .arg(&node_trust)
            .args(["operator", "DRIVE_PASSWORD", &position, &speed])
            .env("DRIVE_PASSWORD", DRIVE_PASSWORD),
    );
    node.line("ready");
    // Its first notification of each item (the values before the simulation starts).
    let mut seen: Vec<(usize, f64, f64)> = Vec::new();
    while !(seen.iter().any(|s| s.0 == 0) && seen.iter().any(|s| s.0 == 1)) {
        note(&mut seen, &node.next_line());
    }

    // The simulation runs (2 s in real time, a sample every 50 ms).
    drive.send("go");
    let mut samples = Vec::new();
    loop {
        let line = drive.next_line();
        if line == "drive: simulated" {
            break;
        }
        assert!(line.starts_with("sample "), "drive: {line}");
        samples.push(line);
    }
    // The trajectory, integrated here as the program integrates it (same operations, same order: the same
    // doubles), sample for sample; the program's own client read each back.
    assert_eq!(samples.len(), 41, "a sample every 50 ms for 2 s");
    let (mut x, mut v) = (0.0_f64, 0.0_f64);
    let mut published = Vec::new();
    for step in 0..=200 {
        if step % 5 == 0 {
            let line = &samples[step / 5];
            assert_eq!(
                (field(line, "position"), field(line, "speed")),
                (x, v),
                "{line}"
            );
            let read = line
                .split(" read=")
                .nth(1)
                .and_then(|r| r.split(' ').next())
                .unwrap_or_default();
            let read: Vec<f64> = read.split(',').map(|r| r.parse().unwrap()).collect();
            assert_eq!(
                read,
                [x, v],
                "the program's client read back what it published: {line}"
            );
            published.push((x, v, field(line, "published")));
        }
        v = (1.0 - x) / 0.2;
        x += v * 0.01;
    }
    assert!(
        (field(&samples[4], "position") - (1.0 - 0.95_f64.powi(20))).abs() < 1e-12,
        "after one time constant, 1 - 0.95^20: {}",
        samples[4]
    );
    // node-opcua sees every value, in order: wait for the last of each.
    let (last_x, last_v) = (published[40].0, published[40].1);
    let deadline = Instant::now() + QUIET;
    while !(seen.iter().any(|s| s.0 == 0 && s.1 == last_x)
        && seen.iter().any(|s| s.0 == 1 && s.1 == last_v))
    {
        assert!(
            Instant::now() < deadline,
            "node-opcua did not see the end of the trajectory: {seen:?}"
        );
        note(&mut seen, &node.next_line());
    }
    let (exit, rest) = node.finish();
    assert!(
        exit.success() && rest.last().map(String::as_str) == Some("closed"),
        "node-opcua: {exit} {rest:?}"
    );
    for (item, pick) in [(0usize, 0usize), (1, 1)] {
        let got: Vec<f64> = seen.iter().filter(|s| s.0 == item).map(|s| s.1).collect();
        let want: Vec<f64> = published
            .iter()
            .map(|p| if pick == 0 { p.0 } else { p.1 })
            .collect();
        // The initial value (0 in the nodeset) is the first sample's value too.
        assert_eq!(
            changes(&got),
            changes(&want),
            "item {item}: node-opcua's notifications against the integration"
        );
    }
    // The latency from each write call to node-opcua's notification of that value.
    let mut latency = Vec::new();
    for (k, &(x, v, at)) in published.iter().enumerate().skip(1) {
        for (item, value) in [(0, x), (1, v)] {
            let before = if item == 0 {
                published[k - 1].0
            } else {
                published[k - 1].1
            };
            if value == before {
                continue;
            }
            let arrived = seen
                .iter()
                .find(|s| s.0 == item && s.1 == value)
                .unwrap_or_else(|| panic!("node-opcua never saw {value} of item {item}"))
                .2;
            latency.push(arrived - at);
        }
    }
    let (median, max) = median_max(latency.clone());

    drive.send("stop");
    let (exit, rest) = drive.finish();
    let out = rest.join("\n");
    assert!(exit.success(), "drive failed ({exit}):\n{out}");
    assert!(
        out.contains(&format!(
            "drive: unknown NodeId: status -2144075776: reading `{AXIS}999999`: BadNodeIdUnknown"
        )),
        "{out}"
    );
    assert!(
        out.contains(&format!(
            "drive: wrong type: status -2139881472: writing `{AXIS}6001`: the variable is a Double"
        )),
        "{out}"
    );
    let allocated: usize = out
        .lines()
        .find_map(|l| {
            l.strip_prefix("drive: ")?
                .strip_suffix(" strings allocated by the tool")
        })
        .unwrap_or_else(|| panic!("{out}"))
        .parse()
        .unwrap();
    assert!(
        allocated >= 4,
        "the messages the program printed came from its allocator: {out}"
    );
    assert!(
        out.contains("drive: 41 samples, final position 0.999967, 0 failures"),
        "{out}"
    );
    println!(
        "nodeset-live: write block -> node-opcua notification (SignAndEncrypt, publishing interval 10 ms, loopback): median {median:.1} ms, max {max:.1} ms over {} writes; the scenario ran in {:?}",
        latency.len(),
        started.elapsed()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The robot's joint `i` (0-based) at `t` seconds: `examples/robot.rs` moves it along a sine, in degrees.
fn joint(i: usize, t: f64) -> f64 {
    (90.0 - 10.0 * i as f64) * (t * (0.2 + 0.05 * i as f64)).sin()
}

/// The UnitId of the EngineeringUnits of the variable at `path`, read from the server by the runtime's
/// client (not through the library under test).
fn unit_id(url: &str, pki: &Path, password: &str, path: &str) -> i32 {
    use opcua::types::{AttributeId, EUInformation, ReadValueId, TimestampsToReturn, Variant};
    let runtime = tokio::runtime::Runtime::new().unwrap();
    runtime.block_on(async {
        let server = nodeset_runtime::client::ClientConfig::new(pki)
            .application("Modelica simulation client", "urn:nodeset-live:client")
            .user("operator", password)
            .connect(url)
            .await
            .unwrap();
        let id = server
            .find(&format!("{path}/EngineeringUnits"))
            .await
            .unwrap();
        let request = ReadValueId {
            node_id: id,
            attribute_id: AttributeId::Value as u32,
            ..Default::default()
        };
        let values = server
            .session()
            .read(&[request], TimestampsToReturn::Neither, 0.0)
            .await
            .unwrap();
        let unit = match values[0].value.as_ref() {
            Some(Variant::ExtensionObject(o)) => o.inner_as::<EUInformation>().map(|u| u.unit_id),
            _ => None,
        };
        server.disconnect().await;
        unit.unwrap_or_else(|| panic!("{path} has no EUInformation: {values:?}"))
    })
}

#[test]
fn scenario_b_a_c_controller_reads_the_robots_joints_in_si_and_writes_a_setting() {
    let dir = tmp("control");
    let exe = compile("control", &dir);
    let robot_exe = artifact("robot", "\"kind\":[\"example\"]", "\"executable\":").remove(0);
    let (server_pki, client_pki, users) = (
        dir.join("robot-pki"),
        dir.join("client-pki"),
        dir.join("users.txt"),
    );
    operator(&users, "c0ntrol-Pa55");
    // The robot as a user starts it, secure; it trusts a client's certificate on first use.
    let robot = Process::start(
        Path::new(&robot_exe),
        &[
            "--port",
            "0",
            "--pki",
            server_pki.to_str().unwrap(),
            "--users",
            users.to_str().unwrap(),
            "--trust-on-first-use",
        ],
    );
    let url = robot.line("listening on ");
    let robot_started = Instant::now();
    let control = |factor: f64, offset: f64| {
        let out = Command::new(&exe)
            .args([
                url.as_str(),
                client_pki.to_str().unwrap(),
                "CONTROL_PASSWORD",
                &format!("{factor:?}"),
                &format!("{offset:?}"),
            ])
            .env("CONTROL_PASSWORD", "c0ntrol-Pa55")
            .output()
            .expect("control runs");
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };

    // The client does not trust the robot's certificate yet: the constructor returns, and says why and what
    // to do.
    let (code, out, err) = control(1.0, 0.0);
    assert_eq!(code, Some(3), "{out}\n{err}");
    assert!(
        out.contains("status -2138439680: not connected to")
            && out.contains("this client does not trust the server's certificate, which it put in")
            && out.contains("client-pki/rejected/"),
        "{out}"
    );
    // The administrator moves it from rejected/ to trusted/ (async-opcua refuses a certificate that is
    // in rejected/ before it looks in trusted/).
    let rejected: Vec<PathBuf> = std::fs::read_dir(client_pki.join("rejected"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(rejected.len(), 1, "{rejected:?}");
    let robot_cert = own_certificate(&server_pki).unwrap();
    std::fs::remove_file(&rejected[0]).unwrap();
    trust_certificate(&client_pki, &robot_cert).unwrap();

    // The unit the robot gives its joints, and the conversion the generated bindings carry for it.
    let path = "Robot/MotionDevices/Arm/Axes/A1/ParameterSet/ActualPosition";
    let id = unit_id(&url, &client_pki, "c0ntrol-Pa55", path);
    let unit = nodeset_compiler::emit::modelica::units::modelica_unit(id)
        .unwrap_or_else(|| panic!("UnitId {id} is not in the unit table"));
    assert_eq!(
        (unit.code, unit.si),
        ("DD", "rad"),
        "the robot's joints are in degrees"
    );
    let (code, out, err) = control(unit.factor, unit.offset);
    let elapsed = robot_started.elapsed().as_secs_f64();
    assert_eq!(code, Some(0), "{out}\n{err}");
    let joints: Vec<&str> = out.lines().filter(|l| l.starts_with("joint ")).collect();
    assert_eq!(joints.len(), 30, "six joints, five samples:\n{out}");
    for sample in joints.chunks(6) {
        let values: Vec<f64> = sample.iter().map(|l| field(l, "value")).collect();
        for (l, v) in sample.iter().zip(&values) {
            assert_eq!(field(l, "si"), unit.to_si(*v), "siFactor applied once: {l}");
        }
        // The six values fit the robot's motion at one time t since its start (the reads of one sample lie
        // within milliseconds of each other; the robot moves its joints every 10 ms, at most 21 deg/s).
        let error = |t: f64| {
            (0..6)
                .map(|i| (joint(i, t) - values[i]).abs())
                .fold(0.0, f64::max)
        };
        let best = (0..=(elapsed * 1e4) as usize)
            .map(|k| k as f64 * 1e-4)
            .min_by(|a, b| error(*a).total_cmp(&error(*b)))
            .unwrap();
        assert!(error(best) < 1.0, "the joints {values:?} fit no time of the robot's motion (best t = {best} s, {} deg off)", error(best));
    }
    assert!(
        out.contains("control: ConfiguredDefaultStopMode 2 status 0"),
        "{out}"
    );
    assert_eq!(
        robot.line("ConfiguredDefaultStopMode written by a client: "),
        "2"
    );
    assert!(out.contains("control: read-only: status -2143617024: writing `Robot/MotionDevices/Arm/ParameterSet/SpeedOverride`: BadNotWritable"), "{out}");
    assert!(out.contains("control: wrong type: status -2139881472: writing `Robot/Controllers/Controller/SystemOperation/SystemOperationStateMachine/ConfiguredDefaultStopMode`: the variable is a Int16, which a Modelica Real cannot write"), "{out}");
    assert!(out.contains("control: no such joint: status -2140209152: finding `Robot/MotionDevices/Arm/Axes/A7/ParameterSet/ActualPosition`"), "{out}");
    assert!(out.contains("has no child `A7`"), "{out}");
    assert!(out.contains("control: 0 failures"), "{out}");
    let rate = out
        .lines()
        .find(|l| l.contains("reads/s"))
        .unwrap_or_default()
        .to_owned();
    robot.stop().unwrap_or_else(|e| panic!("{e}"));
    let _ = std::fs::remove_dir_all(&dir);
    println!("nodeset-live: scenario (b) against the robot example: {rate}");
}
