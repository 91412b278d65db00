//! An OPC UA server with the generated companion specifications.
//!
//! ```text
//! cargo run -p nodeset-examples --example server -- [--port 4855] [--seconds N] [--demo]
//! ```
//!
//! It serves the OPC UA namespace and the generated DI, IA and Robotics namespaces on
//! `opc.tcp://127.0.0.1:<port>/` (Basic256Sha256, Aes128_Sha256_RsaOaep, Aes256_Sha256_RsaPss in Sign and
//! SignAndEncrypt; `--insecure` adds SecurityPolicy None; see `nodeset_examples::secure` for `--pki`,
//! `--users`, `--trust-on-first-use`). `--port 0` picks a free port; the
//! first line on stdout is always `listening on <url>`. `--demo` adds the runtime's demo namespace with
//! live handlers (a range-checked Speed, the Start and Move methods, a Counter that ticks every 500 ms).
//! The server stops cleanly on SIGINT or SIGTERM, or after `--seconds N`, and then prints
//! `server stopped cleanly`.
//!
//! `RUST_LOG` controls the log on stderr. The default shows warnings, except async-opcua's complaints
//! that the server has no certificate (which the unencrypted endpoint does not need) and its notes about
//! instance declarations shared between types while it builds the type tree.

use std::process::ExitCode;
use std::time::Duration;

use nodeset_examples::demo::{self, DemoMode, DemoPoint};
use nodeset_examples::secure::{SecureArgs, USAGE};
use nodeset_models::runtime::server::{MethodError, MethodInvocation, ModelManager, ServerConfig};
use opcua::types::{StatusCode, TryFromVariant, Variant};

/// Command line options.
struct Options {
    port: u16,
    secure: SecureArgs,
    seconds: Option<u64>,
    demo: bool,
}

fn options() -> Result<Options, String> {
    let mut options = Options { port: 4855, seconds: None, demo: false, secure: SecureArgs::default() };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        if options.secure.take(&arg, &mut args)? {
            continue;
        }
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match arg.as_str() {
            "--port" => options.port = value("--port")?.parse().map_err(|e| format!("--port: {e}"))?,
            "--seconds" => options.seconds = Some(value("--seconds")?.parse().map_err(|e| format!("--seconds: {e}"))?),
            "--demo" => options.demo = true,
            "--help" | "-h" => {
                println!("usage: server [--port 4855] [--seconds N] [--demo] {USAGE}");
                std::process::exit(0);
            }
            other => {
                return Err(format!("unknown argument {other:?} (usage: server [--port 4855] [--seconds N] [--demo] {USAGE})"))
            }
        }
    }
    Ok(options)
}

/// The generated namespaces, in dependency order (their namespace indices follow it).
fn generated_models(config: ServerConfig) -> ServerConfig {
    use nodeset_models::models::{di, ia, robotics};
    config
        .table(&di::TABLE)
        .type_loader(di::TypeLoader)
        .table(&ia::TABLE)
        .type_loader(ia::TypeLoader)
        .table(&robotics::TABLE)
        .type_loader(robotics::TypeLoader)
}

#[tokio::main]
async fn main() -> ExitCode {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| {
        "warn,opcua_crypto::certificate_store=off,opcua_core::comms::secure_channel=off,opcua_server::server=error,opcua_server::address_space=error".into()
    });
    tracing_subscriber::fmt().with_env_filter(filter).with_writer(std::io::stderr).init();
    match run().await {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

async fn run() -> Result<(), String> {
    let options = options()?;
    let demo = options.demo;
    let config = ServerConfig::new("nodeset-models example server");
    let mut config = generated_models(options.secure.apply(config, "server")?.port(options.port));
    if demo {
        config = config.table(&demo::TABLE).type_loader(demo::TypeLoader);
    }
    let server = config.build()?;
    let manager = server.manager().clone();
    if demo {
        demo_handlers(&manager)?;
    }
    let counter = async {
        match demo.then(|| manager.resolve(demo::node(demo::ids::PUMP1_COUNTER))).flatten() {
            Some(counter) => {
                let mut tick = tokio::time::interval(Duration::from_millis(500));
                for i in 1i32.. {
                    tick.tick().await;
                    let _ = manager.set_value(&counter, i);
                }
            }
            None => std::future::pending().await,
        }
    };
    server.run_until_stopped(options.seconds, counter).await
}

/// Handlers of the demo namespace.
fn demo_handlers(manager: &ModelManager) -> Result<(), String> {
    let id = |n: u32| manager.resolve(demo::node(n)).ok_or("the demo namespace is not served");
    manager.on_write(&id(demo::ids::PUMP1_SPEED)?, |v| match v {
        Variant::Double(d) if !(0.0..=100.0).contains(d) => Err(StatusCode::BadOutOfRange),
        _ => Ok(None),
    });
    let (speed, mode) = (id(demo::ids::PUMP1_SPEED)?, id(demo::ids::PUMP1_MODE)?);
    manager.on_call(&id(demo::ids::PUMP1_START)?, move |call: MethodInvocation| {
        let (speed, mode) = (speed.clone(), mode.clone());
        async move {
            let s = f64::try_from_variant(call.arguments[0].clone()).map_err(|_| StatusCode::BadTypeMismatch)?;
            let m = i32::try_from_variant(call.arguments[1].clone()).map_err(|_| StatusCode::BadTypeMismatch)?;
            let results = [
                if (0.0..=100.0).contains(&s) { StatusCode::Good } else { StatusCode::BadOutOfRange },
                if DemoMode::try_from(m).is_ok() { StatusCode::Good } else { StatusCode::BadOutOfRange },
            ];
            if results.iter().any(|r| r.is_bad()) {
                return Err(MethodError::Arguments(results.to_vec()));
            }
            call.manager.set_value(&speed, s)?;
            call.manager.set_value(&mode, m)?;
            Ok(vec![Variant::Boolean(true)])
        }
    });
    let position = id(demo::ids::PUMP1_POSITION)?;
    manager.on_call(&id(demo::ids::PUMP1_MOVE)?, move |call: MethodInvocation| {
        let position = position.clone();
        async move {
            let p = DemoPoint::try_from_variant(call.arguments[0].clone()).map_err(|_| StatusCode::BadTypeMismatch)?;
            let distance = (p.x * p.x + p.y * p.y).sqrt();
            call.manager.set_value(&position, p)?;
            Ok(vec![Variant::Double(distance)])
        }
    });
    Ok(())
}
