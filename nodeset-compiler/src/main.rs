//! The `nodeset-compiler` command.

use clap::{Args, Parser, Subcommand};
use nodeset_compiler::diag::{Code, Level, Severities};
use nodeset_compiler::load::Input;
use nodeset_compiler::write::{write_tree, Mode, OutFile};
use nodeset_compiler::{compile, summary, Compiled, Error, Options, RustOptions};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The command's allocator (see the feature `mimalloc` in Cargo.toml).
#[cfg(feature = "mimalloc")]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[derive(Parser)]
#[command(name = "nodeset-compiler", version, about = "Compiles OPC UA NodeSet2 information models")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// What every command that reads NodeSet2 files takes: the files, where their models are found, and how
/// severe each diagnostic is.
#[derive(Args)]
struct Common {
    /// NodeSet2 files whose models are checked or generated.
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Folders searched recursively for the models the files require.
    #[arg(long = "models", value_name = "DIR")]
    models: Vec<PathBuf>,
    #[command(flatten)]
    levels: Levels,
}

/// The severity settings, as rustc's lint levels.
#[derive(Args)]
struct Levels {
    /// Drop the diagnostics of CODE; an error with a recovery (see `nodeset-compiler codes`) then recovers
    /// silently.
    #[arg(long = "allow", short = 'A', value_name = "CODE")]
    allow: Vec<String>,
    /// Report CODE as a warning; an error with a recovery then recovers (e.g. `--warn NS0202` drops dangling
    /// references).
    #[arg(long = "warn", short = 'W', value_name = "CODE")]
    warn: Vec<String>,
    /// Report CODE as an error; `--deny warnings` turns every warning without a level of its own into an error.
    #[arg(long = "deny", short = 'D', value_name = "CODE|warnings")]
    deny: Vec<String>,
}

impl Levels {
    /// The settings these flags say. Levels are applied allow, then warn, then deny: when one code is named
    /// twice, the stricter level wins.
    fn severities(&self) -> Result<Severities, Error> {
        let mut severities = Severities::new();
        for (level, list) in [(Level::Allow, &self.allow), (Level::Warn, &self.warn), (Level::Deny, &self.deny)] {
            for what in list {
                severities.set_named(level, what)?;
            }
        }
        Ok(severities)
    }
}

impl Common {
    /// The compile options these flags say.
    fn options(&self) -> Result<(Vec<Input>, Options), Error> {
        let severities = self.levels.severities()?;
        let inputs = self.files.iter().cloned().map(Input::Path).collect();
        Ok((inputs, Options { model_dirs: self.models.clone(), severities, ..Options::default() }))
    }
}

#[derive(Subcommand)]
enum Command {
    /// Parse, load and resolve NodeSet2 files, check their static instances with the rules of `verify`
    /// (NS0401...NS0408); print diagnostics and a per-namespace summary.
    Check {
        #[command(flatten)]
        common: Common,
        /// Also report warnings of model files that were loaded only as dependencies.
        #[arg(long)]
        all_warnings: bool,
        /// Print a type's supertypes and instance declarations (BrowseName, `URI#Name` or NodeId).
        #[arg(long, value_name = "TYPE")]
        show: Vec<String>,
        /// How many levels of instance declarations `--show` prints.
        #[arg(long, default_value_t = 3)]
        depth: usize,
    },
    /// Generate Rust for async-opcua 0.19 from NodeSet2 files: one module folder per namespace.
    Rust {
        #[command(flatten)]
        common: Common,
        /// Output folder (replaced atomically; it must hold only generated files).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// A namespace generated elsewhere, as URI=RUST_PATH (e.g. http://opcfoundation.org/UA/DI/=nodeset_models::models::di).
        #[arg(long = "extern", value_name = "URI=PATH")]
        externs: Vec<String>,
        /// The module name of a namespace, as URI=NAME.
        #[arg(long = "module", value_name = "URI=NAME")]
        modules: Vec<String>,
        /// The Rust path of the runtime module.
        #[arg(long, default_value = "nodeset_models::runtime")]
        runtime: String,
        /// Compare with the output folder instead of writing; fail if it differs.
        #[arg(long)]
        check: bool,
    },
    /// Generate Modelica component skeletons from NodeSet2 files: one package per namespace, the used part
    /// of the base namespace (`OpcUa`) and `OpcUaSupport`.
    Modelica {
        #[command(flatten)]
        common: Common,
        /// Output folder (replaced atomically; it must hold only generated files).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// A namespace whose package exists elsewhere, as URI=PACKAGE (not generated; classes extend PACKAGE).
        #[arg(long = "extern", value_name = "URI=PACKAGE")]
        externs: Vec<String>,
        /// Compare with the output folder instead of writing; fail if it differs.
        #[arg(long)]
        check: bool,
    },
    /// Print the table of diagnostic codes: default severity, meaning, and what the compiler does instead
    /// when an error is demoted (or that it cannot be).
    Codes {
        /// Only these codes.
        codes: Vec<String>,
    },
    /// Check a live server against its nodesets: every instance below the Objects folder against its type.
    ///
    /// Reads the server's NamespaceArray, loads the nodesets of the namespaces it serves (the named FILES,
    /// and for every other namespace the newest nodeset of that URI in the --models folders), and checks
    /// every instance outside namespace 0: mandatory members present with the declared BrowseName,
    /// NodeClass, TypeDefinition (or a subtype), DataType (or a subtype) and ValueRank; values of the
    /// built-in type their DataType is encoded as; children in a placeholder's place of its type; no
    /// ModellingRule on instances. Each violation names the declaration it violates and its place in the
    /// NodeSet2 file. Exit status: 0 without violations, 1 with violations (errors after --allow, --warn
    /// and --deny), 2 when the server or the nodesets cannot be read.
    #[cfg(feature = "verify")]
    #[command(after_help = "Codes: NS0401 missing mandatory member, NS0402 NodeClass, NS0403 TypeDefinition, NS0404 DataType, \
NS0405 ValueRank, NS0406 value type or shape, NS0407 placeholder type, NS0408 ModellingRule on an instance, \
NS0409 type of a namespace no nodeset defines; `nodeset-compiler codes NS0401` explains one.\n\n\
It connects over Basic256Sha256 SignAndEncrypt unless told otherwise; a server certificate it does not trust \
yet is put in PKI/rejected/ and the run stops: check it, move it to PKI/trusted/ and run again.\n\n\
Example: nodeset-compiler verify opc.tcp://localhost:4855/ --models nodesets --pki verify-pki \
--user operator --password-env OPERATOR_PASSWORD")]
    Verify(VerifyArgs),
    /// Serve NodeSet2 files on an OPC UA server: their address space and their required models' (ns0 from
    /// async-opcua), from tables built in memory; no Rust is generated or compiled.
    #[cfg(feature = "serve")]
    #[command(after_help = "Secure by default: Basic256Sha256, Aes128_Sha256_RsaOaep and Aes256_Sha256_RsaPss in Sign and \
SignAndEncrypt, the server's certificate created in the PKI folder on first start (own/, private/, trusted/, rejected/, \
issuers/); anonymous sessions may read, the users of --users FILE (`nodeset-users add FILE NAME ROLES`) write and call \
as their roles and the nodesets' RolePermissions allow. A client certificate is refused and put in PKI/rejected/ \
until moved to PKI/trusted/ (or --trust-on-first-use). --insecure adds a SecurityPolicy None endpoint.\n\n\
It prints `listening on URL` once clients may connect, and stops on Ctrl-C, SIGTERM or after --seconds.\n\n\
Example: nodeset-compiler serve nodesets/vendor/Opc.Ua.Robotics.NodeSet2.xml --models nodesets/vendor --instantiate-all")]
    Serve(ServeArgs),
    /// Trust certificates in a PKI folder of `serve`, of a server built on the runtime (the examples,
    /// `ServerConfig`) or of `verify`: each is put in DIR/trusted/ under the file name async-opcua looks
    /// for, and its copy in DIR/rejected/ (where the refusing side put it) is removed.
    #[cfg(feature = "serve")]
    #[command(after_help = "Check a certificate before you trust it (its thumbprint, with its owner). A copy under another \
file name, or a certificate left in rejected/, is not trusted by async-opcua.\n\n\
Example (a server that refused verify): nodeset-compiler trust --pki pki/robot verify-pki/own/cert.der")]
    Trust {
        /// The PKI folder (the server's --pki, or verify's --pki).
        #[arg(long, value_name = "DIR")]
        pki: PathBuf,
        /// Certificate files, DER or PEM.
        #[arg(required = true, value_name = "CERT")]
        certs: Vec<PathBuf>,
    },
}

/// The arguments of `nodeset-compiler serve`.
#[cfg(feature = "serve")]
#[derive(Args)]
struct ServeArgs {
    #[command(flatten)]
    common: Common,
    /// Create one instance of every concrete ObjectType of the named files, at Objects/Instances/<TypeName>
    /// (mandatory members, one element per MandatoryPlaceholder, state machines in their initial state).
    #[arg(long)]
    instantiate_all: bool,
    /// The TCP port (0 picks a free one).
    #[arg(long, default_value_t = 4840)]
    port: u16,
    /// The PKI folder (default: pki/nodeset-compiler-serve); the certificate is created there on first start.
    #[arg(long, value_name = "DIR")]
    pki: Option<PathBuf>,
    /// The user file (users, password hashes, roles).
    #[arg(long, value_name = "FILE")]
    users: Option<PathBuf>,
    /// Trust every client certificate on first use (development only).
    #[arg(long)]
    trust_on_first_use: bool,
    /// Also open a SecurityPolicy None endpoint, on which anonymous sessions act as Operator (loopback
    /// testing only).
    #[arg(long)]
    insecure: bool,
    /// Stop after N seconds.
    #[arg(long, value_name = "N")]
    seconds: Option<u64>,
}

/// The arguments of `nodeset-compiler verify`.
#[cfg(feature = "verify")]
#[derive(Args)]
struct VerifyArgs {
    /// The server's endpoint URL, opc.tcp://HOST:PORT[/PATH].
    url: String,
    /// NodeSet2 files of the server's namespaces (others are found in the --models folders).
    files: Vec<PathBuf>,
    /// Folders searched recursively for the nodesets of the server's namespaces and the models they require.
    #[arg(long = "models", value_name = "DIR")]
    models: Vec<PathBuf>,
    #[command(flatten)]
    levels: Levels,
    /// Print the report as one JSON object on stdout (for CI).
    #[arg(long)]
    json: bool,
    /// SecurityPolicy of the endpoint: Basic256Sha256, Aes128Sha256RsaOaep or Aes256Sha256RsaPss (None
    /// only through --insecure).
    #[arg(long, default_value = "Basic256Sha256")]
    security_policy: String,
    /// MessageSecurityMode of the endpoint: Sign or SignAndEncrypt (None only through --insecure).
    #[arg(long, default_value = "SignAndEncrypt")]
    security_mode: String,
    /// Connect without signing or encryption (SecurityPolicy None, MessageSecurityMode None): for a server
    /// on loopback that offers nothing else. Everything read and the password cross the network in clear.
    #[arg(long, conflicts_with_all = ["security_policy", "security_mode"])]
    insecure: bool,
    /// The client's PKI folder (its own certificate, created on first use; trusted and rejected server
    /// certificates). Default: nodeset-compiler-verify-pki in the temporary folder.
    #[arg(long, value_name = "DIR")]
    pki: Option<PathBuf>,
    /// Trust the server's certificate without finding it in the PKI's trusted folder (insecure).
    #[arg(long)]
    trust_server_cert: bool,
    /// Log in as this user (the password is read from the environment variable --password-env names).
    #[arg(long, value_name = "NAME", requires = "password_env")]
    user: Option<String>,
    /// The environment variable that holds the password of --user (never a password on the command line).
    #[arg(long, value_name = "VAR", requires = "user")]
    password_env: Option<String>,
}

fn pairs(items: &[String], what: &str) -> Result<Vec<(String, String)>, Error> {
    items
        .iter()
        .map(|i| {
            // URIs contain `=` rarely but `:` always; split at the last `=`.
            i.rsplit_once('=')
                .map(|(a, b)| (a.to_string(), b.to_string()))
                .ok_or_else(|| Error::Config(format!("--{what} takes URI=VALUE, got `{i}`")))
        })
        .collect()
}

/// Compiles the inputs and prints the warnings; fails when errors remain.
fn compile_checked(common: &Common) -> Result<(Compiled, Options), Error> {
    let (inputs, opts) = common.options()?;
    let mut compiled = compile(inputs, &opts);
    eprint!("{}", compiled.checked(&opts.severities)?);
    Ok((compiled, opts))
}

/// Writes (or with `check` compares) the output folder and prints what changed.
fn write_out(out: &Path, files: &[OutFile], check: bool) -> Result<(), Error> {
    let _t = nodeset_compiler::timing::span("write");
    let report = write_tree(out, files, if check { Mode::Check } else { Mode::Write }).map_err(Error::Write)?;
    if check && !report.is_clean() {
        return Err(Error::Stale(format!("{} is stale:\n{}", out.display(), report.describe(out))));
    }
    eprintln!(
        "{}: {} file(s), {} new, {} changed, {} removed, {} unchanged",
        out.display(),
        files.len(),
        report.added.len(),
        report.changed.len(),
        report.removed.len(),
        report.unchanged
    );
    Ok(())
}

fn rust_command(common: &Common, out: &Path, externs: &[String], modules: &[String], runtime: &str, check: bool) -> Result<(), Error> {
    let rust = RustOptions {
        modules: pairs(modules, "module")?.into_iter().collect(),
        extern_paths: pairs(externs, "extern")?.into_iter().collect(),
        runtime_path: runtime.to_string(),
        command: "nodeset-compiler rust ...".into(),
    };
    rust.check()?;
    let _t = nodeset_compiler::timing::span("rust command");
    let (compiled, opts) = compile_checked(common)?;
    // Every required model that is not mapped with --extern is generated too, so the output compiles alone.
    let run = nodeset_compiler::run_rust(&compiled.model, &rust, &opts.severities)?;
    eprint!("{}", run.warnings);
    write_out(out, &run.files, check)?;
    eprint!("{}", run.plan.describe(|u| run.modules.get(u).cloned().unwrap_or_default()));
    // The process ends here: the model and the files (hundreds of thousands of allocations) are left to
    // the operating system instead of being freed one by one (about 5% of the CPU of this command on DI + IA +
    // Robotics).
    std::mem::forget((compiled, run));
    Ok(())
}

fn modelica_command(common: &Common, out: &Path, externs: &[String], check: bool) -> Result<(), Error> {
    let packages = pairs(externs, "extern")?.into_iter().collect();
    let (compiled, opts) = compile_checked(common)?;
    // Every required model not mapped to an existing package is generated too (ns0: the part used, `OpcUa`).
    let run = nodeset_compiler::run_modelica(&compiled.model, &packages, &opts.severities)?;
    eprint!("{}", run.warnings);
    write_out(out, &run.files, check)?;
    eprint!("{}", run.plan.describe(|_| String::new()));
    Ok(())
}

fn check_command(common: &Common, all_warnings: bool, show: &[String], depth: usize) -> Result<(), Error> {
    let (inputs, mut opts) = common.options()?;
    opts.all_warnings = all_warnings;
    let mut out = compile(inputs, &opts);
    // The static instances meet the rules `verify` applies to a server, with the same codes.
    nodeset_compiler::verify::instances::check_compiled(&mut out, &opts);
    eprint!("{}", out.render_diagnostics());
    print!("{}", summary::render(&out.model));
    for q in show {
        let hits = out.model.find(q);
        match hits.first() {
            Some(&t) => print!("\n{}", summary::show_type(&out.model, t, depth)),
            None => eprintln!("error: `{q}` names no node (try a BrowseName, `URI#Name` or `ns=N;i=M`)"),
        }
    }
    let (e, w) = (out.diagnostics.error_count(), out.diagnostics.warning_count());
    eprintln!("{e} error(s), {w} warning(s)");
    if e > 0 {
        // The diagnostics were printed above, with the summary.
        return Err(Error::Diagnostics { stage: "the NodeSet2 files do not compile".into(), errors: e, rendered: String::new() });
    }
    Ok(())
}

fn codes_command(codes: &[String]) -> Result<(), Error> {
    let table = Code::table();
    if codes.is_empty() {
        print!("{table}");
        return Ok(());
    }
    for c in codes {
        let code = Code::parse(c).ok_or_else(|| Error::Severity(nodeset_compiler::diag::SeverityError::UnknownCode(c.clone())))?;
        // An entry is its line and the indented line below it.
        let mut lines = table.lines().skip_while(|l| !l.starts_with(code.as_str()));
        for l in lines.by_ref().take(2) {
            println!("{l}");
        }
    }
    Ok(())
}

/// The exit status of `verify` when the server or the nodesets cannot be read (1 means violations).
#[cfg(feature = "verify")]
const CANNOT_VERIFY: u8 = 2;

#[cfg(feature = "verify")]
fn verify_command(args: &VerifyArgs) -> ExitCode {
    use nodeset_compiler::verify::{client::Connect, driver, report};
    let severities = match args.levels.severities() {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(CANNOT_VERIFY);
        }
    };
    let user = match (&args.user, &args.password_env) {
        (Some(u), Some(var)) => match std::env::var(var) {
            Ok(p) => Some((u.clone(), p)),
            Err(_) => {
                eprintln!("error: --password-env {var}: the environment variable {var} is not set");
                return ExitCode::from(CANNOT_VERIFY);
            }
        },
        _ => None,
    };
    let (security_policy, security_mode) = if args.insecure {
        eprintln!("warning: --insecure: verify connects without signing or encryption");
        ("None".to_owned(), "None".to_owned())
    } else if args.security_policy == "None" || args.security_mode == "None" {
        eprintln!(
            "error: --security-policy {} with --security-mode {}: an unsecured connection is asked for with --insecure, \
             nothing else turns security off",
            args.security_policy, args.security_mode
        );
        return ExitCode::from(CANNOT_VERIFY);
    } else {
        (args.security_policy.clone(), args.security_mode.clone())
    };
    let connect = Connect {
        url: args.url.clone(),
        security_policy,
        security_mode,
        user,
        pki_dir: args.pki.clone().unwrap_or_else(|| std::env::temp_dir().join("nodeset-compiler-verify-pki")),
        trust_server_cert: args.trust_server_cert,
        verify_server_cert: true,
    };
    let runtime = match tokio::runtime::Builder::new_current_thread().enable_all().build() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: cannot start the async runtime: {e}");
            return ExitCode::from(CANNOT_VERIFY);
        }
    };
    let done = match runtime.block_on(driver::verify(&connect, &args.files, &args.models, &severities)) {
        Ok(done) => done,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(CANNOT_VERIFY);
        }
    };
    eprint!("{}", done.load_warnings);
    let sources = &done.compiled.model.sources;
    if args.json {
        print!("{}", report::render_json(&done.report, sources, &connect.url, done.millis));
    } else {
        eprint!("{}", report::render_text(&done.report, sources, &connect.url, done.millis));
    }
    if done.report.violations() > 0 || !done.report.structure_mismatches.is_empty() {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// `nodeset-compiler trust`: each certificate into `pki`'s `trusted/` folder, out of its `rejected/` folder.
#[cfg(feature = "serve")]
fn trust_command(pki: &Path, certs: &[PathBuf]) -> Result<(), Error> {
    use nodeset_runtime::server::security::trust_certificate;
    use opcua::crypto::X509;
    if !pki.join("trusted").is_dir() && !pki.join("rejected").is_dir() {
        return Err(Error::Config(format!(
            "{} is not a PKI folder (it has neither trusted/ nor rejected/)\n  = help: give the folder the server or verify \
             was started with (--pki); they create it on first start",
            pki.display()
        )));
    }
    // Every file is read before any is trusted: a bad one leaves the folder as it was.
    let mut read = Vec::new();
    for path in certs {
        let bytes = std::fs::read(path).map_err(|e| Error::Config(format!("{}: cannot read: {e}", path.display())))?;
        let cert = X509::from_der(&bytes).or_else(|_| X509::from_pem(&bytes)).map_err(|_| {
            Error::Config(format!(
                "{}: not an X.509 certificate in DER or PEM\n  = help: give the certificate file (own/cert.der of the other \
                 side's PKI folder, or the file its refusal left in rejected/)",
                path.display()
            ))
        })?;
        read.push((path, cert));
    }
    for (path, cert) in read {
        let rejected = pki.join("rejected").join(opcua::crypto::CertificateStore::cert_file_name(&cert));
        let was_rejected = rejected.exists();
        let trusted = trust_certificate(pki, &cert).map_err(|e| Error::Config(e.to_string()))?;
        println!(
            "trusted {} ({}) as {}{}",
            path.display(),
            cert.subject_name(),
            trusted.display(),
            if was_rejected { "; removed from rejected/" } else { "" }
        );
    }
    Ok(())
}

#[cfg(feature = "serve")]
fn serve_command(args: &ServeArgs) -> Result<(), Error> {
    use nodeset_compiler::serve::{serve, ServeOptions};
    let (compiled, _) = compile_checked(&args.common)?;
    let opts = ServeOptions {
        port: args.port,
        host: None,
        pki: args.pki.clone(),
        users: args.users.clone(),
        trust_on_first_use: args.trust_on_first_use,
        insecure: args.insecure,
        instantiate_all: args.instantiate_all,
        seconds: args.seconds,
    };
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(|e| Error::Config(format!("cannot start the async runtime: {e}")))?;
    runtime.block_on(serve(&compiled.model, &opts)).map_err(Error::Config)
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Rust { common, out, externs, modules, runtime, check } => rust_command(common, out, externs, modules, runtime, *check),
        Command::Modelica { common, out, externs, check } => modelica_command(common, out, externs, *check),
        Command::Check { common, all_warnings, show, depth } => check_command(common, *all_warnings, show, *depth),
        Command::Codes { codes } => codes_command(codes),
        #[cfg(feature = "verify")]
        Command::Verify(args) => return verify_command(args),
        #[cfg(feature = "serve")]
        Command::Serve(args) => serve_command(args),
        #[cfg(feature = "serve")]
        Command::Trust { pki, certs } => trust_command(pki, certs),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Error::Diagnostics { stage, rendered, .. }) => {
            eprint!("{rendered}");
            if !rendered.is_empty() {
                eprintln!("error: {stage}; nothing was written");
            }
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
