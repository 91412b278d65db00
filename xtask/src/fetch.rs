//! `cargo xtask fetch-nodesets`: fetches the official NodeSet2 files the
//! project compiles into the git-ignored folder `nodesets/vendor/`.
//!
//! The files come from the MIT-licensed npm package `node-opcua-nodesets`,
//! pinned by version and tarball integrity in `nodesets/node-opcua-nodesets.lock`
//! together with the SHA-256 of every extracted file. The default mode only
//! verifies against that lock; `--update-lock` regenerates it.

mod integrity;
mod lock;

use std::collections::{BTreeMap, HashMap};
use std::fs;
use std::io::{ErrorKind, Read};
use std::path::{Path, PathBuf};
use std::process::Command;

use nodeset_compiler::diag::Diagnostics;
use nodeset_compiler::parse::{self, Limits};
use nodeset_compiler::raw::RawModel;
use nodeset_compiler::source::{SourceFile, SourceMap};

use crate::util::{display_path, workspace_root, write_atomically};
use integrity::{sha256_hex, verify_sri_sha512};
use lock::{Lock, LockedFile};

/// The npm package that ships the official NodeSet2 files.
const PACKAGE: &str = "node-opcua-nodesets";

/// The version `--update-lock` uses when neither `--package-version` nor an existing lock names one.
const DEFAULT_VERSION: &str = "2.185.0";

/// The lock file, relative to the workspace root.
const LOCK_PATH: &str = "nodesets/node-opcua-nodesets.lock";

/// The output folder, relative to the workspace root; it is git-ignored.
pub(crate) const VENDOR_DIR: &str = "nodesets/vendor";

/// A NodeSet2 file the project uses.
pub(crate) struct Wanted {
    /// The file name in `nodesets/vendor/`.
    pub(crate) name: &'static str,
    /// The path inside the package, relative to the package root.
    path: &'static str,
    /// The ModelUri the file must define; guards against files moving inside the package.
    model_uri: &'static str,
}

/// The model URI of a file that declares no `<Model>` (the older files of `nodesets/1.02/`).
const NO_MODEL: &str = "-";

/// The files the project uses: every NodeSet2 file of the package. The base namespace, DI, IA, Robotics and
/// Machinery come first (the project's own models build on them); then the other current companion
/// specifications; then the three older files of the package's `nodesets/1.02/` folder (FTNIR, and the ADI
/// and DI they were written for), which declare no `<Model>` and keep their folder in `nodesets/vendor/1.02/`
/// so that their names do not clash with the current ADI and DI. Every file goes through `check`, Rust and
/// Modelica in `cargo xtask registry`.
///
/// `--update-lock` fails if a file requires a model missing from this list.
pub(crate) const SELECTION: &[Wanted] = &[
    Wanted { name: "Opc.Ua.NodeSet2.xml", path: "nodesets/Opc.Ua.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/" },
    Wanted { name: "Opc.Ua.Di.NodeSet2.xml", path: "nodesets/Opc.Ua.Di.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/DI/" },
    Wanted { name: "Opc.Ua.IA.NodeSet2.xml", path: "nodesets/Opc.Ua.IA.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/IA/" },
    Wanted { name: "Opc.Ua.Robotics.NodeSet2.xml", path: "nodesets/Opc.Ua.Robotics.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/Robotics/" },
    Wanted { name: "Opc.Ua.Machinery.NodeSet2.xml", path: "nodesets/Opc.Ua.Machinery.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/Machinery/" },
    Wanted { name: "Opc.ISA95.NodeSet2.xml", path: "nodesets/Opc.ISA95.NodeSet2.xml", model_uri: "http://www.OPCFoundation.org/UA/2013/01/ISA95" },
    Wanted { name: "Opc.Ua.Adi.NodeSet2.xml", path: "nodesets/Opc.Ua.Adi.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/ADI/" },
    Wanted { name: "Opc.Ua.AMB.NodeSet2.xml", path: "nodesets/Opc.Ua.AMB.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/AMB/" },
    Wanted { name: "Opc.Ua.AutoID.NodeSet2.xml", path: "nodesets/Opc.Ua.AutoID.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/AutoID/" },
    Wanted { name: "Opc.Ua.CNC.NodeSet.xml", path: "nodesets/Opc.Ua.CNC.NodeSet.xml", model_uri: "http://opcfoundation.org/UA/CNC" },
    Wanted { name: "Opc.Ua.CommercialKitchenEquipment.NodeSet2.xml", path: "nodesets/Opc.Ua.CommercialKitchenEquipment.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/CommercialKitchenEquipment/" },
    Wanted { name: "Opc.Ua.Eumabois.Nodeset2.xml", path: "nodesets/Opc.Ua.Eumabois.Nodeset2.xml", model_uri: "http://opcfoundation.org/UA/Eumabois/" },
    Wanted { name: "Opc.Ua.Gds.NodeSet2.xml", path: "nodesets/Opc.Ua.Gds.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/GDS/" },
    Wanted { name: "Opc.Ua.Glass.NodeSet2.xml", path: "nodesets/Opc.Ua.Glass.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/Glass/Flat/" },
    Wanted { name: "Opc.Ua.I4AAS.NodeSet2.xml", path: "nodesets/Opc.Ua.I4AAS.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/I4AAS/" },
    Wanted { name: "Opc.Ua.Ijt.Base.NodeSet2.xml", path: "nodesets/Opc.Ua.Ijt.Base.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/IJT/Base/" },
    Wanted { name: "Opc.Ua.Ijt.Tightening.NodeSet2.xml", path: "nodesets/Opc.Ua.Ijt.Tightening.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/IJT/Tightening/" },
    Wanted { name: "Opc.Ua.IOLink.NodeSet2.xml", path: "nodesets/Opc.Ua.IOLink.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/IOLink/" },
    Wanted { name: "Opc.Ua.IOLinkIODD.NodeSet2.xml", path: "nodesets/Opc.Ua.IOLinkIODD.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/IOLink/IODD/" },
    Wanted { name: "Opc.Ua.IRDI.NodeSet2.xml", path: "nodesets/Opc.Ua.IRDI.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/Dictionary/IRDI" },
    Wanted { name: "opc.ua.isa95-jobcontrol.nodeset2.xml", path: "nodesets/opc.ua.isa95-jobcontrol.nodeset2.xml", model_uri: "http://opcfoundation.org/UA/ISA95-JOBCONTROL_V2/" },
    Wanted { name: "Opc.Ua.LADS.NodeSet2.xml", path: "nodesets/Opc.Ua.LADS.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/LADS/" },
    Wanted { name: "Opc.Ua.Machinery.Jobs.Nodeset2.xml", path: "nodesets/Opc.Ua.Machinery.Jobs.Nodeset2.xml", model_uri: "http://opcfoundation.org/UA/Machinery/Jobs/" },
    Wanted { name: "Opc.Ua.Machinery.ProcessValues.NodeSet2.xml", path: "nodesets/Opc.Ua.Machinery.ProcessValues.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/Machinery/ProcessValues/" },
    Wanted { name: "Opc.Ua.Machinery_Result.NodeSet2.xml", path: "nodesets/Opc.Ua.Machinery_Result.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/Machinery/Result/" },
    Wanted { name: "Opc.Ua.MachineTool.NodeSet2.xml", path: "nodesets/Opc.Ua.MachineTool.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/MachineTool/" },
    Wanted { name: "Opc.Ua.MachineVision.NodeSet2.xml", path: "nodesets/Opc.Ua.MachineVision.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/MachineVision" },
    Wanted { name: "Opc.Ua.MetalForming.NodeSet2.xml", path: "nodesets/Opc.Ua.MetalForming.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/MetalForming/" },
    Wanted { name: "Opc.Ua.PackML.NodeSet2.xml", path: "nodesets/Opc.Ua.PackML.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/PackML/" },
    Wanted { name: "Opc.Ua.PADIM.NodeSet2.xml", path: "nodesets/Opc.Ua.PADIM.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/PADIM/" },
    Wanted { name: "Opc.Ua.Scales.NodeSet2.xml", path: "nodesets/Opc.Ua.Scales.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/Scales/V2/" },
    Wanted { name: "Opc.Ua.ST-Mss.NodeSet2.xml", path: "nodesets/Opc.Ua.ST-Mss.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/SurfaceTechnology/OCT-MSS/" },
    Wanted { name: "Opc.Ua.STGeneralTypes.NodeSet2.xml", path: "nodesets/Opc.Ua.STGeneralTypes.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/SurfaceTechnology/GeneralTypes/" },
    Wanted { name: "Opc.Ua.Weihenstephan.NodeSet2.xml", path: "nodesets/Opc.Ua.Weihenstephan.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/Weihenstephan/" },
    Wanted { name: "Opc.Ua.Woodworking.NodeSet2.xml", path: "nodesets/Opc.Ua.Woodworking.NodeSet2.xml", model_uri: "http://opcfoundation.org/UA/Woodworking/" },
    Wanted { name: "1.02/FTNIR.NodeSet2.xml", path: "nodesets/1.02/FTNIR.NodeSet2.xml", model_uri: "-" },
    Wanted { name: "1.02/Opc.Ua.Adi.NodeSet2.xml", path: "nodesets/1.02/Opc.Ua.Adi.NodeSet2.xml", model_uri: "-" },
    Wanted { name: "1.02/Opc.Ua.Di.NodeSet2.xml", path: "nodesets/1.02/Opc.Ua.Di.NodeSet2.xml", model_uri: "-" },
];

/// Arguments of `cargo xtask fetch-nodesets`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Regenerate nodesets/node-opcua-nodesets.lock from the package instead of verifying
    /// against it (use this after bumping the pinned version).
    #[arg(long)]
    update_lock: bool,

    /// With --update-lock: the package version to pin (default: the version in the current
    /// lock file).
    #[arg(long, value_name = "VERSION", requires = "update_lock")]
    package_version: Option<String>,
}

/// Fetches and verifies the pinned files unless they are already present and verified.
pub fn ensure_fetched() -> Result<(), String> {
    run(Args { update_lock: false, package_version: None })
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<(), String> {
    let root = workspace_root();
    let lock_path = root.join(LOCK_PATH);
    let vendor_dir = root.join(VENDOR_DIR);
    if args.update_lock {
        update_lock(&lock_path, &vendor_dir, args.package_version)
    } else {
        fetch_and_verify(&lock_path, &vendor_dir)
    }
}

/// The default mode: makes `nodesets/vendor/` match the committed lock, downloading only if needed.
fn fetch_and_verify(lock_path: &Path, vendor_dir: &Path) -> Result<(), String> {
    let lock = read_lock(lock_path)?.ok_or_else(|| {
        format!(
            "{} does not exist; create it with `cargo xtask fetch-nodesets --update-lock`",
            display_path(lock_path)
        )
    })?;
    check_lock_matches_selection(&lock)?;

    let stale: Vec<(&LockedFile, String)> = lock
        .files
        .iter()
        .filter_map(|file| {
            let problem = vendor_problem(&vendor_dir.join(&file.name), file)?;
            Some((file, problem))
        })
        .collect();
    let spec = format!("{}@{}", lock.package, lock.version);
    if stale.is_empty() {
        println!(
            "{}: all {} files match {} ({spec}); nothing to do",
            display_path(vendor_dir),
            lock.files.len(),
            display_path(lock_path)
        );
        return Ok(());
    }
    for (file, problem) in &stale {
        println!("{}/{}: {problem}", display_path(vendor_dir), file.name);
    }

    println!("fetching {spec} with npm");
    let tarball = npm_pack(&spec)?;
    verify_sri_sha512(&tarball, &lock.integrity)
        .map_err(|e| format!("the tarball of {spec} does not match the lock: {e}"))?;
    let paths: Vec<&str> = lock.files.iter().map(|file| file.path.as_str()).collect();
    let mut extracted = extract(&tarball, &paths)?;

    // Check every file against the lock before writing any, so a bad lock changes nothing.
    for file in &lock.files {
        let bytes = &extracted[file.path.as_str()];
        let actual = sha256_hex(bytes);
        if actual != file.sha256 || bytes.len() as u64 != file.size {
            return Err(format!(
                "{} (package path {}) from {spec} does not match {}:\n  expected sha256 {} ({} bytes)\n  actual   sha256 {actual} ({} bytes)",
                file.name,
                file.path,
                display_path(lock_path),
                file.sha256,
                file.size,
                bytes.len()
            ));
        }
    }

    fs::create_dir_all(vendor_dir)
        .map_err(|e| format!("cannot create {}: {e}", display_path(vendor_dir)))?;
    for (file, _) in &stale {
        let bytes = extracted.remove(file.path.as_str()).unwrap_or_default();
        let path = vendor_dir.join(&file.name);
        create_parent(&path)?;
        write_atomically(&path, &bytes)?;
    }

    // Re-read what is now on disk, so success really means the folder matches the lock.
    for file in &lock.files {
        let path = vendor_dir.join(&file.name);
        if let Some(problem) = vendor_problem(&path, file) {
            return Err(format!("{} after writing: {problem}", display_path(&path)));
        }
    }
    println!(
        "{}: wrote {} of {} files; all match {} ({spec})",
        display_path(vendor_dir),
        stale.len(),
        lock.files.len(),
        display_path(lock_path)
    );
    Ok(())
}

/// `--update-lock`: downloads the package, reads the selected files and rewrites the lock.
fn update_lock(lock_path: &Path, vendor_dir: &Path, version: Option<String>) -> Result<(), String> {
    // An unreadable old lock must not block regenerating it, so only its version is reused.
    let old_version = read_lock(lock_path).ok().flatten().map(|lock| lock.version);
    let version = version
        .or(old_version)
        .unwrap_or_else(|| DEFAULT_VERSION.to_string());
    let spec = format!("{PACKAGE}@{version}");

    println!("asking the npm registry for the integrity of {spec}");
    let integrity = npm_view_integrity(&spec)?;
    println!("fetching {spec} with npm");
    let tarball = npm_pack(&spec)?;
    verify_sri_sha512(&tarball, &integrity).map_err(|e| {
        format!("the tarball of {spec} does not match the integrity the registry publishes: {e}")
    })?;
    let paths: Vec<&str> = SELECTION.iter().map(|wanted| wanted.path).collect();
    let extracted = extract(&tarball, &paths)?;

    let mut files = Vec::new();
    for wanted in SELECTION {
        let bytes = &extracted[wanted.path];
        files.push(describe(wanted, bytes)?);
    }
    check_required_models(&files)?;

    let lock = Lock {
        package: PACKAGE.to_string(),
        version,
        integrity,
        files,
    };
    fs::create_dir_all(vendor_dir)
        .map_err(|e| format!("cannot create {}: {e}", display_path(vendor_dir)))?;
    for file in &lock.files {
        let path = vendor_dir.join(&file.name);
        if vendor_problem(&path, file).is_some() {
            create_parent(&path)?;
            write_atomically(&path, &extracted[file.path.as_str()])?;
        }
    }
    write_atomically(lock_path, lock.to_text().as_bytes())?;

    println!("wrote {} for {spec}:", display_path(lock_path));
    for file in &lock.files {
        println!(
            "  {:<32} {:>9} bytes  {} {}",
            file.name,
            file.size,
            file.model_uri,
            file.model_version.as_deref().unwrap_or("(no Version)")
        );
    }
    Ok(())
}

/// Creates the folder a vendored file goes into (`nodesets/vendor/1.02/`).
fn create_parent(path: &Path) -> Result<(), String> {
    match path.parent() {
        Some(dir) => fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", display_path(dir))),
        None => Ok(()),
    }
}

/// Reads and parses the lock file; a missing file is `Ok(None)`.
fn read_lock(lock_path: &Path) -> Result<Option<Lock>, String> {
    let text = match fs::read_to_string(lock_path) {
        Ok(text) => text,
        Err(e) if e.kind() == ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("cannot read {}: {e}", display_path(lock_path))),
    };
    Lock::parse(&text)
        .map(Some)
        .map_err(|e| format!("{}: {e}", display_path(lock_path)))
}

/// Fails when the lock and [`SELECTION`] disagree, which means the selection
/// was edited without regenerating the lock.
fn check_lock_matches_selection(lock: &Lock) -> Result<(), String> {
    let in_lock: Vec<(&str, &str)> = lock
        .files
        .iter()
        .map(|file| (file.name.as_str(), file.path.as_str()))
        .collect();
    let selected: Vec<(&str, &str)> = SELECTION.iter().map(|w| (w.name, w.path)).collect();
    if lock.package != PACKAGE || in_lock != selected {
        let describe = |files: &[(&str, &str)]| {
            files
                .iter()
                .map(|(name, path)| format!("{name} <- {path}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        return Err(format!(
            "the lock does not match the selection in xtask/src/fetch.rs; run \
             `cargo xtask fetch-nodesets --update-lock` after changing either.\n  \
             lock ({}):  {}\n  xtask ({PACKAGE}): {}",
            lock.package,
            describe(&in_lock),
            describe(&selected)
        ));
    }
    Ok(())
}

/// Returns why the vendored copy at `path` does not match `file`, or `None` if it does.
fn vendor_problem(path: &Path, file: &LockedFile) -> Option<String> {
    match fs::read(path) {
        Err(e) if e.kind() == ErrorKind::NotFound => Some("missing".to_string()),
        Err(e) => Some(format!("unreadable ({e})")),
        Ok(bytes) => {
            let actual = sha256_hex(&bytes);
            if actual == file.sha256 && bytes.len() as u64 == file.size {
                None
            } else {
                Some(format!(
                    "differs from the lock (expected sha256 {} and {} bytes, found {actual} and {} bytes)",
                    file.sha256,
                    file.size,
                    bytes.len()
                ))
            }
        }
    }
}

/// Builds the lock entry of one selected file from its content.
fn describe(wanted: &Wanted, bytes: &[u8]) -> Result<LockedFile, String> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| format!("{} is not valid UTF-8: {e}", wanted.path))?;
    let models = read_models(wanted.path, text)?;
    let model = match models.as_slice() {
        [] if wanted.model_uri == NO_MODEL => {
            return Ok(LockedFile {
                name: wanted.name.to_string(),
                path: wanted.path.to_string(),
                size: bytes.len() as u64,
                sha256: sha256_hex(bytes),
                model_uri: NO_MODEL.to_string(),
                model_version: None,
                publication_date: None,
                requires: Vec::new(),
            })
        }
        [model] => model,
        _ => {
            return Err(format!(
                "{} declares {} <Model> elements; exactly one is expected",
                wanted.path,
                models.len()
            ))
        }
    };
    if model.uri != wanted.model_uri {
        return Err(format!(
            "{} defines model {}, but {} was expected",
            wanted.path, model.uri, wanted.model_uri
        ));
    }
    Ok(LockedFile {
        name: wanted.name.to_string(),
        path: wanted.path.to_string(),
        size: bytes.len() as u64,
        sha256: sha256_hex(bytes),
        model_uri: model.uri.clone(),
        model_version: model.version.clone(),
        publication_date: model.publication_date.clone(),
        requires: model
            .required
            .iter()
            .map(|required| (required.uri.clone(), required.version.clone()))
            .collect(),
    })
}

/// The `<Model>` elements of a NodeSet2 file (at `path` in the package), read by the compiler's parser.
fn read_models(path: &str, text: &str) -> Result<Vec<RawModel>, String> {
    let mut sources = SourceMap::new();
    let file = sources.add(SourceFile::new(PathBuf::from(path), path.to_string(), text.to_string(), true));
    let mut diags = Diagnostics::new();
    match parse::parse(file, &sources.get(file).text, &Limits::default(), &mut diags) {
        Some(set) => Ok(set.models),
        None => Err(format!("cannot parse {path}:\n{}", diags.render(&sources))),
    }
}

/// Fails unless every `<RequiredModel>` is defined by a selected file, and warns
/// when the selected file is older than the version required.
fn check_required_models(files: &[LockedFile]) -> Result<(), String> {
    let defined: HashMap<&str, &LockedFile> = files
        .iter()
        .filter(|file| file.model_uri != NO_MODEL)
        .map(|file| (file.model_uri.as_str(), file))
        .collect();
    for file in files {
        for (uri, version) in &file.requires {
            let Some(provider) = defined.get(uri.as_str()) else {
                return Err(format!(
                    "{} requires model {uri}, which no selected file defines; add it to SELECTION in xtask/src/fetch.rs",
                    file.name
                ));
            };
            if let (Some(required), Some(available)) = (version, &provider.model_version) {
                if compare_versions(available, required) == std::cmp::Ordering::Less {
                    eprintln!(
                        "warning: {} requires {uri} {required}, but {} is only {available}",
                        file.name, provider.name
                    );
                }
            }
        }
    }
    Ok(())
}

/// Compares dotted version strings such as `1.05.07` and `1.5.4` numerically,
/// part by part; a part that is not a number compares as text.
fn compare_versions(a: &str, b: &str) -> std::cmp::Ordering {
    let mut left = a.split('.');
    let mut right = b.split('.');
    loop {
        match (left.next(), right.next()) {
            (None, None) => return std::cmp::Ordering::Equal,
            (Some(_), None) => return std::cmp::Ordering::Greater,
            (None, Some(_)) => return std::cmp::Ordering::Less,
            (Some(x), Some(y)) => {
                let ordering = match (x.parse::<u64>(), y.parse::<u64>()) {
                    (Ok(x), Ok(y)) => x.cmp(&y),
                    _ => x.cmp(y),
                };
                if ordering != std::cmp::Ordering::Equal {
                    return ordering;
                }
            }
        }
    }
}

/// Extracts the files at `paths` (relative to the package root) from a gzipped npm tarball.
///
/// npm tarballs put everything under one top-level folder, normally `package/`,
/// so the first component of every entry is dropped before comparing. Nothing
/// is written to disk here; the caller decides where the bytes go.
fn extract<'a>(tarball: &[u8], paths: &[&'a str]) -> Result<BTreeMap<&'a str, Vec<u8>>, String> {
    /// No NodeSet2 file comes close to this; it bounds memory use on a corrupt archive.
    const MAX_FILE_SIZE: u64 = 256 * 1024 * 1024;

    let mut archive = tar::Archive::new(flate2::read::GzDecoder::new(tarball));
    let entries = archive
        .entries()
        .map_err(|e| format!("cannot read the package tarball: {e}"))?;
    let mut found: BTreeMap<&'a str, Vec<u8>> = BTreeMap::new();
    for entry in entries {
        let mut entry = entry.map_err(|e| format!("cannot read the package tarball: {e}"))?;
        let entry_path = entry
            .path()
            .map_err(|e| format!("bad path in the package tarball: {e}"))?
            .to_string_lossy()
            .replace('\\', "/");
        let inside_package = entry_path.split_once('/').map_or("", |(_, rest)| rest);
        let Some(&wanted) = paths.iter().find(|&&path| path == inside_package) else {
            continue;
        };
        if !entry.header().entry_type().is_file() {
            return Err(format!(
                "{entry_path} in the package tarball is not a regular file"
            ));
        }
        if found.contains_key(wanted) {
            return Err(format!("{entry_path} appears twice in the package tarball"));
        }
        let size = entry.size();
        if size > MAX_FILE_SIZE {
            return Err(format!(
                "{entry_path} in the package tarball is {size} bytes, which is implausibly large"
            ));
        }
        let mut bytes = Vec::with_capacity(size as usize);
        entry
            .read_to_end(&mut bytes)
            .map_err(|e| format!("cannot extract {entry_path} from the package tarball: {e}"))?;
        found.insert(wanted, bytes);
    }
    let missing: Vec<&str> = paths
        .iter()
        .copied()
        .filter(|path| !found.contains_key(path))
        .collect();
    if !missing.is_empty() {
        return Err(format!(
            "the package does not contain {}",
            missing.join(", ")
        ));
    }
    Ok(found)
}

/// Downloads the package tarball with `npm pack` into a temporary folder and returns its bytes.
fn npm_pack(spec: &str) -> Result<Vec<u8>, String> {
    let temp = TempDir::new()?;
    run_npm(&["pack", spec], &temp.path)?;
    let tarballs: Vec<PathBuf> = fs::read_dir(&temp.path)
        .map_err(|e| format!("cannot list {}: {e}", temp.path.display()))?
        .filter_map(|entry| entry.ok().map(|entry| entry.path()))
        .filter(|path| path.extension().is_some_and(|ext| ext == "tgz"))
        .collect();
    let [tarball] = tarballs.as_slice() else {
        return Err(format!(
            "`npm pack {spec}` left {} .tgz files in {}, expected exactly one",
            tarballs.len(),
            temp.path.display()
        ));
    };
    fs::read(tarball).map_err(|e| format!("cannot read {}: {e}", tarball.display()))
}

/// Asks the registry for the published integrity string of `spec`.
fn npm_view_integrity(spec: &str) -> Result<String, String> {
    let temp = TempDir::new()?;
    let output = run_npm(&["view", spec, "dist.integrity"], &temp.path)?;
    let integrity = output.trim().to_string();
    integrity::parse_sri_sha512(&integrity)
        .map_err(|e| format!("`npm view {spec} dist.integrity` printed `{integrity}`: {e}"))?;
    Ok(integrity)
}

/// Runs `npm` with `args` in `dir` and returns its standard output.
///
/// npm's own output is shown only when it fails, because it warns about
/// unrelated user configuration on many machines.
fn run_npm(args: &[&str], dir: &Path) -> Result<String, String> {
    let command_line = format!("npm {}", args.join(" "));
    let output = Command::new("npm")
        .args(args)
        .current_dir(dir)
        .output()
        .map_err(|e| {
            if e.kind() == ErrorKind::NotFound {
                format!(
                    "`npm` was not found on PATH. It is needed to download the pinned package \
                     {PACKAGE} from the npm registry. Install it (on Debian or Ubuntu: \
                     `apt-get install -y npm`) and run this command again."
                )
            } else {
                format!("cannot run `{command_line}`: {e}")
            }
        })?;
    if !output.status.success() {
        return Err(format!(
            "`{command_line}` failed ({}):\n{}{}",
            output.status,
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr)
        ));
    }
    String::from_utf8(output.stdout)
        .map_err(|e| format!("`{command_line}` printed invalid UTF-8: {e}"))
}

/// A uniquely named temporary folder that is removed when dropped.
struct TempDir {
    path: PathBuf,
}

impl TempDir {
    fn new() -> Result<TempDir, String> {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|duration| duration.subsec_nanos())
            .unwrap_or(0);
        let path = std::env::temp_dir().join(format!(
            "xtask-fetch-nodesets-{}-{nanos}",
            std::process::id()
        ));
        fs::create_dir(&path).map_err(|e| format!("cannot create {}: {e}", path.display()))?;
        Ok(TempDir { path })
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        // Best effort: a leftover folder in the system temp directory is harmless.
        let _ = fs::remove_dir_all(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cmp::Ordering;

    /// `--update-lock` describes each file with the compiler's parser; for the vendored files, that must
    /// give the entries the lock holds (model, version, date, required models, size and digest).
    #[test]
    fn describe_reproduces_the_lock_for_the_vendored_files() {
        let root = workspace_root();
        let lock = read_lock(&root.join(LOCK_PATH)).expect("the lock parses").expect("the lock exists");
        for (wanted, locked) in SELECTION.iter().zip(&lock.files) {
            let path = root.join(VENDOR_DIR).join(wanted.name);
            let bytes = fs::read(&path)
                .unwrap_or_else(|e| panic!("{}: {e} (run `cargo xtask fetch-nodesets`)", path.display()));
            assert_eq!(&describe(wanted, &bytes).expect("describes"), locked, "{}", wanted.name);
        }
        assert_eq!(lock.files.len(), SELECTION.len());
    }

    #[test]
    fn versions_compare_numerically() {
        assert_eq!(compare_versions("1.05.07", "1.05.04"), Ordering::Greater);
        assert_eq!(compare_versions("1.05.0", "1.04.0"), Ordering::Greater);
        assert_eq!(compare_versions("1.01.2", "1.01.4"), Ordering::Less);
        assert_eq!(compare_versions("1.5", "1.05"), Ordering::Equal);
        assert_eq!(compare_versions("1.02", "1.02.1"), Ordering::Less);
    }

    #[test]
    fn selection_has_unique_safe_names_and_paths() {
        let mut names: Vec<&str> = SELECTION.iter().map(|w| w.name).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), SELECTION.len(), "duplicate local names");
        for wanted in SELECTION {
            // A plain file name, or one of the package's `1.02/` folder.
            let file = wanted.name.strip_prefix("1.02/").unwrap_or(wanted.name);
            assert!(!file.contains('/') && !file.starts_with('.'), "{}", wanted.name);
            assert!(wanted.path.ends_with(wanted.name), "{} is not the end of {}", wanted.name, wanted.path);
            assert!(
                !wanted.path.starts_with('/') && !wanted.path.contains(".."),
                "{}",
                wanted.path
            );
        }
    }

    #[test]
    fn extract_finds_files_under_the_top_level_folder() {
        let tarball = gzipped_tar(&[
            ("package/nodesets/a.xml", b"<a/>"),
            ("package/nodesets/1.02/a.xml", b"old"),
            ("package/README.md", b"readme"),
        ]);
        let found = extract(&tarball, &["nodesets/a.xml"]).expect("extracts");
        assert_eq!(found.len(), 1);
        assert_eq!(found["nodesets/a.xml"], b"<a/>");

        let error = extract(&tarball, &["nodesets/b.xml"]).unwrap_err();
        assert!(error.contains("nodesets/b.xml"), "{error}");
    }

    #[test]
    fn committed_lock_matches_selection() {
        let lock_path = workspace_root().join(LOCK_PATH);
        let lock = read_lock(&lock_path)
            .expect("the committed lock parses")
            .expect("the lock file is committed");
        check_lock_matches_selection(&lock).expect("lock and selection agree");
        check_required_models(&lock.files).expect("the selection is closed under RequiredModel");
    }

    /// Builds an in-memory `.tgz` with the given regular files.
    fn gzipped_tar(files: &[(&str, &[u8])]) -> Vec<u8> {
        let encoder = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        let mut builder = tar::Builder::new(encoder);
        for (path, content) in files {
            let mut header = tar::Header::new_gnu();
            header.set_size(content.len() as u64);
            header.set_mode(0o644);
            header.set_cksum();
            builder
                .append_data(&mut header, path, *content)
                .expect("append to test tarball");
        }
        let encoder = builder.into_inner().expect("finish test tarball");
        encoder.finish().expect("finish gzip stream")
    }
}
