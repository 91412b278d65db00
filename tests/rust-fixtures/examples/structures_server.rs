//! The `structure_values` fixture (tests/fixtures/structure_values) served with the type loaders of its two
//! namespaces, for `tests/interop/structures_check.py`, which reads every structure value back.
//!
//! ```text
//! structures_server [--port 4857] [--pki DIR] [--users FILE] [--trust-on-first-use] [--insecure]
//! ```
//!
//! Prints `listening on URL`, and `server stopped cleanly` after SIGTERM.

use std::process::ExitCode;

use nodeset_examples::secure::{SecureArgs, USAGE};
use nodeset_fixture_code::{parts, structure_values};
use nodeset_models::runtime::server::ServerConfig;

#[tokio::main]
async fn main() -> ExitCode {
    match run().await {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

async fn run() -> Result<(), String> {
    let mut port = 4857u16;
    let mut secure = SecureArgs::default();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        if secure.take(&arg, &mut args)? {
            continue;
        }
        match arg.as_str() {
            "--port" => port = args.next().ok_or("--port needs a value")?.parse().map_err(|e| format!("--port: {e}"))?,
            other => return Err(format!("unknown argument {other:?} (usage: structures_server [--port 4857] {USAGE})")),
        }
    }
    let config = secure
        .apply(ServerConfig::new("structure values fixture"), "structures")?
        .port(port)
        .table(&parts::TABLE)
        .type_loader(parts::TypeLoader)
        .table(&structure_values::TABLE)
        .type_loader(structure_values::TypeLoader);
    let server = config.build()?;
    server.run_until_stopped(None, std::future::pending()).await
}
