//! Adds users to a model server's user file (see `nodeset_runtime::server::users`).
//!
//! ```text
//! nodeset-users add  FILE NAME ROLES           # reads the password from stdin (one line)
//! nodeset-users cert FILE NAME ROLES CERT.der  # a user certificate (DER or PEM)
//! ```
//!
//! ROLES are well-known roles separated by commas (`Operator`, `Engineer,Supervisor`, ...). The file is
//! created if missing and rewritten atomically; passwords are stored only as Argon2id hashes.

use std::io::BufRead;
use std::path::Path;
use std::process::ExitCode;

use nodeset_runtime::server::{Role, Users};

const USAGE: &str = "usage: nodeset-users add FILE NAME ROLES  (password on stdin)\n       nodeset-users cert FILE NAME ROLES CERT.der";

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (kind, file, name, roles) = match args.as_slice() {
        [kind, file, name, roles, ..] => (kind.as_str(), Path::new(file), name, roles),
        _ => return Err(USAGE.to_owned()),
    };
    let roles = roles.split(',').map(|r| r.parse::<Role>()).collect::<Result<Vec<_>, _>>()?;
    let mut users = if file.exists() { Users::load(file).map_err(|e| e.to_string())? } else { Users::default() };
    match (kind, args.len()) {
        ("add", 4) => {
            let mut password = String::new();
            std::io::stdin().lock().read_line(&mut password).map_err(|e| format!("cannot read the password: {e}"))?;
            let password = password.trim_end_matches(['\n', '\r']);
            if password.is_empty() {
                return Err("the password (read from stdin) is empty".to_owned());
            }
            users.set_password(name, roles, password)?;
        }
        ("cert", 5) => {
            let cert = std::fs::read(&args[4]).map_err(|e| format!("cannot read {}: {e}", args[4]))?;
            users.set_certificate(name, roles, &cert)?;
        }
        _ => return Err(USAGE.to_owned()),
    }
    let tmp = file.with_extension("tmp");
    std::fs::write(&tmp, users.to_text()).map_err(|e| format!("cannot write {}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, file).map_err(|e| format!("cannot replace {}: {e}", file.display()))?;
    println!("{}: user `{name}` saved", file.display());
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
