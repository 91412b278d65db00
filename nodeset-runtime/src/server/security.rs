//! Endpoints and the PKI folder of a model server.
//!
//! The PKI folder has the OPC UA layout: `own/cert.der` (the application instance certificate),
//! `private/private.pem` (its key, written readable by the owner only), `trusted/` (the client certificates
//! an administrator trusts), `rejected/` (the untrusted ones that tried to connect, for the administrator to
//! move to `trusted/`) and `issuers/`. [`prepare_pki`] creates the folders, creates the certificate on first
//! start (with the application URI and the host names), and refuses to start on a certificate it cannot
//! read, a key that does not belong to it, or a certificate made for another application URI.

use std::path::{Path, PathBuf};

use opcua::crypto::{CertificateStore, KeySize, PrivateKey, SecurityPolicy, X509Data, X509};
use opcua::types::MessageSecurityMode;

/// The secure policies a server offers by default.
pub const DEFAULT_POLICIES: [SecurityPolicy; 3] =
    [SecurityPolicy::Basic256Sha256, SecurityPolicy::Aes128Sha256RsaOaep, SecurityPolicy::Aes256Sha256RsaPss];

/// The security of a server's endpoints.
#[derive(Clone, Debug, PartialEq)]
pub struct Security {
    /// The secure policies, each offered in every mode of [`Security::modes`]. Empty for a server with only
    /// the None endpoint (then [`Security::insecure`] must be set).
    pub policies: Vec<SecurityPolicy>,
    /// The modes of the secure endpoints (Sign, SignAndEncrypt by default).
    pub modes: Vec<MessageSecurityMode>,
    /// Adds an endpoint with SecurityPolicy None and lets anonymous sessions act as Operator: for loopback
    /// testing only. Off by default.
    pub insecure: bool,
    /// Trusts every client certificate on first use (stores it in `trusted/`): for development only. Off
    /// by default: an unknown certificate is refused and stored in `rejected/`.
    pub trust_on_first_use: bool,
    /// Whether anonymous sessions are accepted (with the Anonymous role only, unless `insecure`). On by
    /// default.
    pub anonymous: bool,
}

impl Default for Security {
    fn default() -> Security {
        Security {
            policies: DEFAULT_POLICIES.to_vec(),
            modes: vec![MessageSecurityMode::Sign, MessageSecurityMode::SignAndEncrypt],
            insecure: false,
            trust_on_first_use: false,
            anonymous: true,
        }
    }
}

/// Why a PKI folder cannot be used.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PkiError {
    /// The file or folder at fault.
    pub path: PathBuf,
    /// What is wrong.
    pub message: String,
    /// What to do about it.
    pub hint: String,
}

impl std::fmt::Display for PkiError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: error: {}\n  hint: {}", self.path.display(), self.message, self.hint)
    }
}

impl std::error::Error for PkiError {}

/// The certificate of a server whose PKI folder is ready.
pub struct OwnCertificate {
    /// The certificate.
    pub cert: X509,
    /// Whether it was created by this call.
    pub created: bool,
}

impl std::fmt::Debug for OwnCertificate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OwnCertificate")
            .field("thumbprint", &self.cert.thumbprint().as_hex_string())
            .field("created", &self.created)
            .finish()
    }
}

/// Creates the PKI layout below `dir` and the application instance certificate if neither it nor its key
/// exists; checks an existing pair (readable, matching, made for `application_uri`).
pub fn prepare_pki(
    dir: &Path,
    application_name: &str,
    application_uri: &str,
    host_names: &[String],
) -> Result<OwnCertificate, PkiError> {
    for sub in ["own", "private", "trusted", "rejected", "issuers"] {
        let path = dir.join(sub);
        if path.exists() && !path.is_dir() {
            return Err(PkiError { path, message: "is not a folder".into(), hint: "remove or rename it".into() });
        }
        std::fs::create_dir_all(&path).map_err(|e| PkiError {
            path: path.clone(),
            message: format!("cannot create the folder: {e}"),
            hint: "choose a PKI folder the server may write (--pki DIR)".into(),
        })?;
    }
    let cert_path = dir.join("own/cert.der");
    let key_path = dir.join("private/private.pem");
    match (cert_path.exists(), key_path.exists()) {
        (false, false) => {
            let mut names = vec![application_uri.to_owned()];
            names.extend(host_names.iter().cloned());
            let mut data = X509Data {
                key_size: 2048,
                common_name: application_name.to_owned(),
                organization: application_name.to_owned(),
                organizational_unit: application_name.to_owned(),
                country: "DE".to_owned(),
                state: String::new(),
                alt_host_names: Default::default(),
                certificate_duration_days: 365 * 2,
            };
            data.alt_host_names.add_uri(application_uri);
            for h in host_names {
                data.alt_host_names.add_address(h);
            }
            let (cert, _) = CertificateStore::create_certificate_and_key(&data, false, &cert_path, &key_path)
                .map_err(|e| PkiError {
                    path: cert_path.clone(),
                    message: format!("cannot create the application instance certificate: {e}"),
                    hint: "check that the PKI folder is writable".into(),
                })?;
            restrict(&key_path)?;
            tracing::info!("created the application instance certificate {}", cert_path.display());
            Ok(OwnCertificate { cert, created: true })
        }
        (true, false) | (false, true) => {
            let (have, missing) = if cert_path.exists() { (&cert_path, &key_path) } else { (&key_path, &cert_path) };
            Err(PkiError {
                path: missing.clone(),
                message: format!("is missing while {} exists", have.display()),
                hint: "restore it, or remove both own/cert.der and private/private.pem to create a new certificate (clients must then trust the new one)".into(),
            })
        }
        (true, true) => {
            let bytes = std::fs::read(&cert_path).map_err(|e| PkiError {
                path: cert_path.clone(),
                message: format!("cannot read: {e}"),
                hint: "check the file's permissions".into(),
            })?;
            let cert = X509::from_der(&bytes).map_err(|e| PkiError {
                path: cert_path.clone(),
                message: format!("is not a DER X.509 certificate: {e}"),
                hint: "restore the certificate, or remove own/cert.der and private/private.pem to create a new one".into(),
            })?;
            let key = PrivateKey::read_pem_file(&key_path).map_err(|e| PkiError {
                path: key_path.clone(),
                message: format!("is not a PEM RSA private key: {e}"),
                hint: "restore the key, or remove own/cert.der and private/private.pem to create a new pair".into(),
            })?;
            check_pair(&cert, &key).map_err(|message| PkiError {
                path: key_path.clone(),
                message,
                hint: "the key in private/ must be the one own/cert.der was made for; restore the matching pair".into(),
            })?;
            if cert.is_application_uri_valid(application_uri).is_err() {
                return Err(PkiError {
                    path: cert_path.clone(),
                    message: format!("was made for another application URI than `{application_uri}`"),
                    hint: "use the PKI folder of this application, or remove own/cert.der and private/private.pem to create a certificate for it".into(),
                });
            }
            Ok(OwnCertificate { cert, created: false })
        }
    }
}

/// Whether `key` is the private key of `cert`: a signature made with it verifies with the certificate.
fn check_pair(cert: &X509, key: &PrivateKey) -> Result<(), String> {
    let public = cert.public_key().map_err(|e| format!("cannot read the certificate's public key: {e}"))?;
    let data = b"nodeset-runtime key check";
    // An RSA signature is exactly as long as the key's modulus.
    let mut signature = vec![0u8; key.size()];
    let n = key.sign_sha256(data, &mut signature).map_err(|e| format!("cannot sign with the key: {e}"))?;
    match public.verify_sha256(data, &signature[..n]) {
        Ok(true) => Ok(()),
        _ => Err("does not belong to own/cert.der".to_owned()),
    }
}

#[cfg(unix)]
fn restrict(path: &Path) -> Result<(), PkiError> {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o600)).map_err(|e| PkiError {
        path: path.to_owned(),
        message: format!("cannot make the private key readable by its owner only: {e}"),
        hint: "check the PKI folder's owner".into(),
    })
}

#[cfg(not(unix))]
fn restrict(_path: &Path) -> Result<(), PkiError> {
    Ok(())
}

/// The endpoint a policy and mode are published under (`<policy>_<mode>`; `none` for the None endpoint).
pub fn endpoint_id(policy: SecurityPolicy, mode: MessageSecurityMode) -> String {
    if policy == SecurityPolicy::None {
        "none".to_owned()
    } else {
        format!("{}_{}", policy.to_str(), mode).to_ascii_lowercase()
    }
}

/// Puts `cert` into the `trusted/` folder of the PKI folder `dir`, under the file name async-opcua looks
/// for (`<common name> [<thumbprint>].der`: a copy under another name is not found), and removes the copy a
/// server put in `rejected/` when it refused the certificate (async-opcua refuses a certificate that is in
/// `rejected/`, even when it is also in `trusted/`); returns its path in `trusted/`. This is what an
/// administrator does by moving a certificate from `rejected/` to `trusted/`.
pub fn trust_certificate(dir: &Path, cert: &X509) -> Result<PathBuf, PkiError> {
    let name = CertificateStore::cert_file_name(cert);
    let rejected = dir.join("rejected").join(&name);
    match std::fs::remove_file(&rejected) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            return Err(PkiError {
                path: rejected,
                message: format!("cannot remove the rejected copy: {e}"),
                hint: "check the PKI folder's permissions; the server refuses the certificate while it is in rejected/"
                    .into(),
            })
        }
        _ => {}
    }
    let path = dir.join("trusted").join(name);
    let der = cert.to_der().map_err(|e| PkiError {
        path: path.clone(),
        message: format!("cannot encode the certificate: {e}"),
        hint: "the certificate was read from a damaged file".into(),
    })?;
    std::fs::create_dir_all(dir.join("trusted"))
        .and_then(|()| std::fs::write(&path, der))
        .map_err(|e| PkiError { path: path.clone(), message: format!("cannot write: {e}"), hint: "check the PKI folder's permissions".into() })?;
    Ok(path)
}

/// Reads the application instance certificate of the PKI folder `dir` (`own/cert.der`).
pub fn own_certificate(dir: &Path) -> Result<X509, PkiError> {
    let path = dir.join("own/cert.der");
    let bytes = std::fs::read(&path)
        .map_err(|e| PkiError { path: path.clone(), message: format!("cannot read: {e}"), hint: "start the server once to create it".into() })?;
    X509::from_der(&bytes).map_err(|e| PkiError {
        path,
        message: format!("is not a DER X.509 certificate: {e}"),
        hint: "restore it, or remove own/cert.der and private/private.pem to create a new pair".into(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("nodeset-runtime-pki-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    const URI: &str = "urn:test:pki";

    #[test]
    fn first_start_creates_the_layout_and_a_certificate_for_the_application_uri() {
        let dir = temp("create");
        let own = prepare_pki(&dir, "pki test", URI, &["127.0.0.1".to_owned()]).unwrap();
        assert!(own.created);
        for sub in ["own", "private", "trusted", "rejected", "issuers"] {
            assert!(dir.join(sub).is_dir(), "{sub}");
        }
        assert!(own.cert.is_application_uri_valid(URI).is_ok());
        let again = prepare_pki(&dir, "pki test", URI, &[]).unwrap();
        assert!(!again.created);
        assert_eq!(again.cert.thumbprint().as_hex_string(), own.cert.thumbprint().as_hex_string());
        // Another application's URI is refused: its clients would see a certificate that is not its own.
        let e = prepare_pki(&dir, "pki test", "urn:test:other", &[]).unwrap_err();
        assert!(e.message.contains("another application URI"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_trusted_certificate_leaves_rejected_and_gets_the_name_the_server_looks_for() {
        let (dir, client) = (temp("trust"), temp("trust-client"));
        prepare_pki(&dir, "pki test", URI, &[]).unwrap();
        let cert = prepare_pki(&client, "pki client", "urn:test:client", &[]).unwrap().cert;
        let name = CertificateStore::cert_file_name(&cert);
        // As a server leaves a certificate it refused.
        std::fs::write(dir.join("rejected").join(&name), cert.to_der().unwrap()).unwrap();
        let path = trust_certificate(&dir, &cert).unwrap();
        assert_eq!(path, dir.join("trusted").join(&name));
        assert_eq!(std::fs::read(&path).unwrap(), cert.to_der().unwrap());
        assert!(!dir.join("rejected").join(&name).exists(), "the rejected copy is left, and async-opcua refuses it");
        // Trusting again (nothing in rejected/) is no error.
        assert_eq!(trust_certificate(&dir, &cert).unwrap(), path);
        let _ = std::fs::remove_dir_all(&dir);
        let _ = std::fs::remove_dir_all(&client);
    }

    #[test]
    fn damaged_or_mismatched_files_are_clear_errors() {
        let dir = temp("damaged");
        prepare_pki(&dir, "pki test", URI, &[]).unwrap();
        let cert = std::fs::read(dir.join("own/cert.der")).unwrap();
        let key = std::fs::read(dir.join("private/private.pem")).unwrap();

        std::fs::write(dir.join("own/cert.der"), &cert[..cert.len() / 2]).unwrap();
        let e = prepare_pki(&dir, "pki test", URI, &[]).unwrap_err();
        assert!(e.path.ends_with("own/cert.der") && e.message.contains("not a DER X.509"), "{e}");
        std::fs::write(dir.join("own/cert.der"), &cert).unwrap();

        std::fs::write(dir.join("private/private.pem"), b"-----BEGIN PRIVATE KEY-----\nAAAA\n-----END PRIVATE KEY-----\n").unwrap();
        let e = prepare_pki(&dir, "pki test", URI, &[]).unwrap_err();
        assert!(e.path.ends_with("private/private.pem") && e.message.contains("not a PEM RSA private key"), "{e}");

        // The key of another certificate.
        let other = temp("other");
        prepare_pki(&other, "pki test", URI, &[]).unwrap();
        std::fs::copy(other.join("private/private.pem"), dir.join("private/private.pem")).unwrap();
        let e = prepare_pki(&dir, "pki test", URI, &[]).unwrap_err();
        assert!(e.message.contains("does not belong to own/cert.der"), "{e}");
        std::fs::write(dir.join("private/private.pem"), &key).unwrap();
        prepare_pki(&dir, "pki test", URI, &[]).unwrap();

        std::fs::remove_file(dir.join("private/private.pem")).unwrap();
        let e = prepare_pki(&dir, "pki test", URI, &[]).unwrap_err();
        assert!(e.message.contains("is missing while"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
        let _ = std::fs::remove_dir_all(&other);
    }
}
