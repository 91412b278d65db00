//! The `roles` fixture (tests/fixtures/roles) served on its own, secure by default, for
//! `tests/interop/roles_check.py`: its RolePermissions decide, node by node, who may read, write and call.
//!
//! ```text
//! roles_server [--port 4856] [--pki DIR] [--users FILE] [--trust-on-first-use] [--insecure]
//! ```
//!
//! Prints `listening on URL`, then `NAME called by USER` for every call of Start or Reset that reaches the
//! server's code, and `server stopped cleanly` after SIGTERM.

use std::io::Write;
use std::process::ExitCode;

use nodeset_examples::secure::{SecureArgs, USAGE};
use nodeset_fixture_code::roles;
use nodeset_models::runtime::server::{MethodInvocation, ServerConfig};

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
    let mut port = 4856u16;
    let mut secure = SecureArgs::default();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        if secure.take(&arg, &mut args)? {
            continue;
        }
        match arg.as_str() {
            "--port" => port = args.next().ok_or("--port needs a value")?.parse().map_err(|e| format!("--port: {e}"))?,
            other => return Err(format!("unknown argument {other:?} (usage: roles_server [--port 4856] {USAGE})")),
        }
    }
    let config = secure.apply(ServerConfig::new("roles fixture"), "roles")?.port(port).table(&roles::TABLE);
    let server = config.build()?;
    let manager = server.manager().clone();
    for (name, id) in [("Start", roles::ids::methods::PRESS_START), ("Reset", roles::ids::methods::PRESS_RESET)] {
        let node = manager.resolve(id).ok_or("the roles namespace is not served")?;
        manager.on_call(&node, move |call: MethodInvocation| async move {
            println!("{name} called by {}", call.user.as_deref().unwrap_or("anonymous"));
            let _ = std::io::stdout().flush();
            Ok(Vec::new())
        });
    }
    server.run_until_stopped(None, std::future::pending()).await
}
