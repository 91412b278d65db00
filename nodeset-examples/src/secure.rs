//! The security options every example server accepts:
//!
//! - `--pki DIR`: the PKI folder (default `pki/<server name>`), created with a certificate on first start;
//! - `--users FILE`: the user file (see `nodeset_runtime::server::users`; add users with
//!   `cargo run -p nodeset-runtime --bin nodeset-users -- add FILE NAME ROLES`);
//! - `--trust-on-first-use`: trusts unknown client certificates (development only);
//! - `--insecure`: adds a SecurityPolicy None endpoint on which anonymous sessions act as Operator, for
//!   loopback testing; the server says so when it starts.

use std::path::PathBuf;

use nodeset_runtime::server::{ServerConfig, Users};

/// The parsed security options.
#[derive(Clone, Debug, Default)]
pub struct SecureArgs {
    /// `--pki DIR`.
    pub pki: Option<PathBuf>,
    /// `--users FILE`.
    pub users: Option<PathBuf>,
    /// `--trust-on-first-use`.
    pub trust_on_first_use: bool,
    /// `--insecure`.
    pub insecure: bool,
}

/// The usage text of the options.
pub const USAGE: &str = "[--pki DIR] [--users FILE] [--trust-on-first-use] [--insecure]";

impl SecureArgs {
    /// Takes `arg` (and its value from `rest`) if it is a security option; `Ok(false)` if it is not one.
    pub fn take(&mut self, arg: &str, rest: &mut impl Iterator<Item = String>) -> Result<bool, String> {
        let mut value = |name: &str| rest.next().ok_or(format!("{name} needs a value"));
        match arg {
            "--pki" => self.pki = Some(value("--pki")?.into()),
            "--users" => self.users = Some(value("--users")?.into()),
            "--trust-on-first-use" => self.trust_on_first_use = true,
            "--insecure" => self.insecure = true,
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// Applies the options to a server's configuration; `pki` is the default folder below `pki/` (the
    /// examples of one process need one folder each). Prints a warning for `--insecure` and
    /// `--trust-on-first-use`.
    pub fn apply(&self, mut config: ServerConfig, pki: &str) -> Result<ServerConfig, String> {
        config = config.pki_dir(self.pki.clone().unwrap_or_else(|| PathBuf::from("pki").join(pki)));
        if let Some(file) = &self.users {
            config = config.users(Users::load(file).map_err(|e| e.to_string())?);
        }
        if self.trust_on_first_use {
            config = config.trust_on_first_use();
        }
        if self.insecure {
            config = config.insecure();
        }
        for warning in config.warnings() {
            eprintln!("{warning}");
        }
        Ok(config)
    }
}
