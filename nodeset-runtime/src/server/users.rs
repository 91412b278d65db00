//! Users, their roles, and the authentication of sessions.
//!
//! A user file holds one user a line (blank lines and lines starting with `#` are ignored):
//!
//! ```text
//! # kind  name      roles (comma-separated well-known roles)   secret
//! user    alice     Operator                                   $argon2id$v=19$m=19456,t=2,p=1$...
//! cert    hmi-panel Operator,Engineer                          8c1f...  (SHA-1 thumbprint of the DER certificate, hex)
//! ```
//!
//! Passwords are stored only as Argon2id hashes in PHC form; `cargo run -p nodeset-runtime --bin
//! nodeset-users -- add FILE NAME ROLES` adds or replaces a user (reading the password from stdin), and
//! `... cert FILE NAME ROLES CERT.der` adds a user certificate. Every authenticated session has the roles
//! of its user plus `AuthenticatedUser`; an anonymous session has `Anonymous` only (or the roles of
//! [`Users::anonymous_roles`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use argon2::password_hash::{rand_core::OsRng, PasswordHash, PasswordHasher, PasswordVerifier, SaltString};
use argon2::Argon2;
use async_trait::async_trait;
use opcua::crypto::{SecurityPolicy, Thumbprint};
use opcua::server::address_space::AccessLevel;
use opcua::server::authenticator::{user_pass_security_policy_id, AuthManager, Password, UserToken};
use opcua::server::ServerEndpoint;
use opcua::types::{Error, NodeId, StatusCode, UAString, UserTokenPolicy, UserTokenType};

use super::access::{AccessPolicy, Permissions, Role};

/// A user of the server, as the user file names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct User {
    /// The user name (or the name given to a user certificate).
    pub name: String,
    /// The roles the user has besides `AuthenticatedUser`.
    pub roles: Vec<Role>,
    /// How the user proves who it is.
    pub secret: Secret,
}

/// How a user proves who it is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Secret {
    /// A password, kept as an Argon2id hash in PHC form.
    PasswordHash(String),
    /// An X.509 user certificate, kept as its SHA-1 thumbprint in lowercase hex.
    Certificate(String),
}

/// The users of a server.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Users {
    /// The users by name (password users and certificate users share the name space).
    pub users: BTreeMap<String, User>,
    /// The roles of anonymous sessions besides `Anonymous` (none by default; `--insecure` adds Operator).
    pub anonymous_roles: Vec<Role>,
}

/// A user file that cannot be read: where and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UserFileError {
    /// The file.
    pub path: PathBuf,
    /// 1-based line, 0 for the whole file.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// What is wrong.
    pub message: String,
    /// What to do about it.
    pub hint: &'static str,
}

impl std::fmt::Display for UserFileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}:{}: error: {}\n  hint: {}", self.path.display(), self.line, self.column, self.message, self.hint)
    }
}

impl std::error::Error for UserFileError {}

const LINE_HINT: &str = "a line is `user NAME ROLES ARGON2-HASH` or `cert NAME ROLES SHA1-THUMBPRINT`; \
                         add users with `cargo run -p nodeset-runtime --bin nodeset-users -- add FILE NAME ROLES`";

impl Users {
    /// Reads a user file (see the module documentation). Every line is checked before any user is
    /// accepted: a damaged file is an error, never a partly read list.
    pub fn load(path: &Path) -> Result<Users, UserFileError> {
        let text = std::fs::read_to_string(path).map_err(|e| UserFileError {
            path: path.to_owned(),
            line: 0,
            column: 0,
            message: format!("cannot read the user file: {e}"),
            hint: "create it with `cargo run -p nodeset-runtime --bin nodeset-users -- add FILE NAME ROLES`",
        })?;
        Users::parse(path, &text)
    }

    /// Parses the text of a user file; `path` names it in errors.
    pub fn parse(path: &Path, text: &str) -> Result<Users, UserFileError> {
        let mut users = Users::default();
        for (n, line) in text.lines().enumerate() {
            let error = |column: usize, message: String| UserFileError {
                path: path.to_owned(),
                line: n + 1,
                column: column + 1,
                message,
                hint: LINE_HINT,
            };
            let trimmed = line.trim_start();
            if trimmed.is_empty() || trimmed.starts_with('#') {
                continue;
            }
            // Fields with their byte columns.
            let mut fields = Vec::new();
            let mut start = None;
            for (i, c) in line.char_indices().chain([(line.len(), ' ')]) {
                match (c.is_whitespace(), start) {
                    (false, None) => start = Some(i),
                    (true, Some(s)) => {
                        fields.push((s, &line[s..i]));
                        start = None;
                    }
                    _ => {}
                }
            }
            if fields.len() != 4 {
                let column = fields.get(4).map_or(line.len(), |f| f.0);
                return Err(error(column, format!("expected 4 fields, found {}", fields.len())));
            }
            let (name_col, name) = fields[1];
            if users.users.contains_key(name) {
                return Err(error(name_col, format!("user `{name}` is defined twice")));
            }
            let (roles_col, roles_text) = fields[2];
            let mut roles = Vec::new();
            for r in roles_text.split(',') {
                let role = r.parse::<Role>().map_err(|e| error(roles_col, e))?;
                if !roles.contains(&role) {
                    roles.push(role);
                }
            }
            let (secret_col, secret) = fields[3];
            let secret = match fields[0].1 {
                "user" => {
                    let hash = PasswordHash::new(secret)
                        .map_err(|e| error(secret_col, format!("the password hash is not in PHC form: {e}")))?;
                    if hash.algorithm.as_str() != "argon2id" {
                        return Err(error(
                            secret_col,
                            format!("the password hash uses `{}`; only argon2id hashes are accepted", hash.algorithm),
                        ));
                    }
                    Secret::PasswordHash(secret.to_owned())
                }
                "cert" => {
                    if secret.len() != 40 || !secret.bytes().all(|b| b.is_ascii_hexdigit()) {
                        return Err(error(secret_col, "a certificate thumbprint is 40 hex digits (SHA-1)".to_owned()));
                    }
                    Secret::Certificate(secret.to_ascii_lowercase())
                }
                other => return Err(error(fields[0].0, format!("unknown kind `{other}` (`user` or `cert`)"))),
            };
            users.users.insert(name.to_owned(), User { name: name.to_owned(), roles, secret });
        }
        Ok(users)
    }

    /// The text of the user file (sorted by name, so that saving is deterministic).
    pub fn to_text(&self) -> String {
        let mut out = String::from("# nodeset-runtime user file: kind name roles secret (see nodeset_runtime::server::users)\n");
        for user in self.users.values() {
            let roles: Vec<_> = user.roles.iter().map(|r| r.name()).collect();
            let (kind, secret) = match &user.secret {
                Secret::PasswordHash(h) => ("user", h.as_str()),
                Secret::Certificate(t) => ("cert", t.as_str()),
            };
            out.push_str(&format!("{kind} {} {} {secret}\n", user.name, roles.join(",")));
        }
        out
    }

    /// Adds or replaces a password user; the password is hashed with Argon2id and a random salt.
    pub fn set_password(&mut self, name: &str, roles: Vec<Role>, password: &str) -> Result<(), String> {
        check_name(name)?;
        if roles.is_empty() {
            return Err("a user needs at least one role".to_owned());
        }
        let salt = SaltString::generate(&mut OsRng);
        let hash = Argon2::default()
            .hash_password(password.as_bytes(), &salt)
            .map_err(|e| format!("cannot hash the password: {e}"))?
            .to_string();
        self.users.insert(name.to_owned(), User { name: name.to_owned(), roles, secret: Secret::PasswordHash(hash) });
        Ok(())
    }

    /// Adds or replaces a certificate user, given the DER (or PEM) certificate.
    pub fn set_certificate(&mut self, name: &str, roles: Vec<Role>, certificate: &[u8]) -> Result<(), String> {
        check_name(name)?;
        if roles.is_empty() {
            return Err("a user needs at least one role".to_owned());
        }
        let cert = opcua::crypto::X509::from_der(certificate)
            .or_else(|_| opcua::crypto::X509::from_pem(certificate))
            .map_err(|e| format!("not a DER or PEM X.509 certificate: {e}"))?;
        let thumbprint = cert.thumbprint().as_hex_string().to_ascii_lowercase();
        self.users.insert(name.to_owned(), User { name: name.to_owned(), roles, secret: Secret::Certificate(thumbprint) });
        Ok(())
    }

    fn has_passwords(&self) -> bool {
        self.users.values().any(|u| matches!(u.secret, Secret::PasswordHash(_)))
    }

    fn has_certificates(&self) -> bool {
        self.users.values().any(|u| matches!(u.secret, Secret::Certificate(_)))
    }
}

fn check_name(name: &str) -> Result<(), String> {
    if name.is_empty() || name.chars().any(|c| c.is_whitespace() || c.is_control()) {
        return Err(format!("user name {name:?} must be non-empty and free of spaces"));
    }
    Ok(())
}

/// Who called: what user code sees of the session behind a method call.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Caller {
    /// The user name, `None` for an anonymous session.
    pub user: Option<String>,
    /// The session's roles.
    pub roles: Vec<Role>,
}

/// async-opcua's [`AuthManager`] for model servers: authenticates with [`Users`] and evaluates
/// UserAccessLevel and UserExecutable with an [`AccessPolicy`].
pub struct ModelAuth {
    users: Users,
    /// The configured policy, then the RolePermissions of the tables' nodes (added once the server is
    /// built, where the configuration gives the node no entry of its own).
    policy: std::sync::RwLock<AccessPolicy>,
    /// The nodes of the tables with RolePermissions that are not Variables: async-opcua asks for their
    /// CurrentRead before any attribute is read, which their Browse permission decides (Read is about a
    /// Variable's Value).
    browse_read: std::sync::RwLock<std::collections::HashSet<NodeId>>,
    anonymous: bool,
    /// Password checks in progress at once. Argon2id needs 19 MiB per check by design, so 50 sessions
    /// logging in together would hold nearly 1 GiB (measured with `cargo xtask load`); checks beyond the
    /// machine's parallelism could not run sooner anyway, so they wait their turn.
    verifying: std::sync::Arc<tokio::sync::Semaphore>,
}

/// The user token of anonymous sessions in async-opcua (its `ANONYMOUS_USER_TOKEN_ID`).
const ANONYMOUS: &str = opcua::server::ANONYMOUS_USER_TOKEN_ID;

impl ModelAuth {
    /// An authenticator; `anonymous` offers the anonymous identity token on every endpoint.
    pub fn new(users: Users, policy: AccessPolicy, anonymous: bool) -> ModelAuth {
        let parallel = std::thread::available_parallelism().map_or(1, |n| n.get());
        ModelAuth { users, policy: std::sync::RwLock::new(policy), browse_read: Default::default(), anonymous, verifying: std::sync::Arc::new(tokio::sync::Semaphore::new(parallel)) }
    }

    /// Adds the RolePermissions of single nodes (and whether each is a Variable), keeping the entries the
    /// configuration already gives.
    pub fn add_node_permissions(&self, nodes: impl IntoIterator<Item = (NodeId, BTreeMap<Role, Permissions>, bool)>) {
        let mut policy = self.policy.write().unwrap_or_else(|e| e.into_inner());
        let mut browse_read = self.browse_read.write().unwrap_or_else(|e| e.into_inner());
        for (node, permissions, variable) in nodes {
            if !variable {
                browse_read.insert(node.clone());
            }
            policy.nodes.entry(node).or_insert(permissions);
        }
    }

    /// What a session with this user token may do on `node`.
    pub fn permissions(&self, token: &UserToken, node: &NodeId) -> Permissions {
        self.policy.read().unwrap_or_else(|e| e.into_inner()).permissions(&self.roles(token), node)
    }

    /// The caller behind a user token.
    pub fn caller(&self, token: &UserToken) -> Caller {
        Caller { user: (token.0 != ANONYMOUS).then(|| token.0.clone()), roles: self.roles(token) }
    }

    /// The roles of a session with this user token.
    pub fn roles(&self, token: &UserToken) -> Vec<Role> {
        if token.0 == ANONYMOUS {
            let mut roles = vec![Role::Anonymous];
            roles.extend(self.users.anonymous_roles.iter().copied());
            return roles;
        }
        let mut roles = vec![Role::AuthenticatedUser];
        if let Some(user) = self.users.users.get(&token.0) {
            roles.extend(user.roles.iter().copied());
        }
        roles
    }

    fn rejected(what: &str) -> Error {
        Error::new(StatusCode::BadIdentityTokenRejected, what.to_owned())
    }
}

#[async_trait]
impl AuthManager for ModelAuth {
    async fn authenticate_anonymous_token(&self, _endpoint: &ServerEndpoint) -> Result<(), Error> {
        if self.anonymous {
            Ok(())
        } else {
            Err(Self::rejected("anonymous sessions are not allowed"))
        }
    }

    async fn authenticate_username_identity_token(
        &self,
        _endpoint: &ServerEndpoint,
        username: &str,
        password: &Password,
    ) -> Result<UserToken, Error> {
        let hash = match self.users.users.get(username).map(|u| &u.secret) {
            Some(Secret::PasswordHash(h)) => h.clone(),
            _ => {
                tracing::warn!("session refused: no password user `{username}`");
                return Err(Self::rejected("unknown user or wrong password"));
            }
        };
        let password = password.get().to_owned();
        let Ok(permit) = self.verifying.clone().acquire_owned().await else {
            return Err(Self::rejected("the server is shutting down"));
        };
        // Argon2 takes tens of milliseconds on purpose: keep it off the server's event loop.
        let ok = tokio::task::spawn_blocking(move || {
            let _permit = permit;
            PasswordHash::new(&hash).is_ok_and(|h| Argon2::default().verify_password(password.as_bytes(), &h).is_ok())
        })
        .await
        .unwrap_or(false);
        if ok {
            Ok(UserToken(username.to_owned()))
        } else {
            tracing::warn!("session refused: wrong password for `{username}`");
            Err(Self::rejected("unknown user or wrong password"))
        }
    }

    async fn authenticate_x509_identity_token(
        &self,
        _endpoint: &ServerEndpoint,
        signing_thumbprint: &Thumbprint,
    ) -> Result<UserToken, Error> {
        let thumbprint = signing_thumbprint.as_hex_string().to_ascii_lowercase();
        self.users
            .users
            .values()
            .find(|u| u.secret == Secret::Certificate(thumbprint.clone()))
            .map(|u| UserToken(u.name.clone()))
            .ok_or_else(|| {
                tracing::warn!("session refused: no user has the certificate {thumbprint}");
                Self::rejected("unknown user certificate")
            })
    }

    fn effective_user_access_level(&self, token: &UserToken, user_access_level: AccessLevel, node_id: &NodeId) -> AccessLevel {
        let permissions = self.permissions(token, node_id);
        let mut level = user_access_level;
        let read = if self.browse_read.read().unwrap_or_else(|e| e.into_inner()).contains(node_id) {
            Permissions::BROWSE
        } else {
            Permissions::READ
        };
        if !permissions.contains(read) {
            level.remove(AccessLevel::CURRENT_READ);
        }
        if !permissions.contains(Permissions::WRITE) {
            level.remove(AccessLevel::CURRENT_WRITE);
        }
        level
    }

    fn is_user_executable(&self, token: &UserToken, method_id: &NodeId) -> bool {
        self.permissions(token, method_id).contains(Permissions::CALL)
    }

    fn user_token_policies(&self, endpoint: &ServerEndpoint) -> Vec<UserTokenPolicy> {
        let mut policies = Vec::new();
        if self.anonymous {
            policies.push(UserTokenPolicy {
                policy_id: UAString::from("anonymous"),
                token_type: UserTokenType::Anonymous,
                issued_token_type: UAString::null(),
                issuer_endpoint_url: UAString::null(),
                security_policy_uri: UAString::null(),
            });
        }
        // A password crosses only a channel that encrypts it (the endpoint's, or none at all).
        let secure = endpoint.security_policy() != SecurityPolicy::None;
        if self.users.has_passwords() && secure {
            policies.push(UserTokenPolicy {
                policy_id: user_pass_security_policy_id(endpoint),
                token_type: UserTokenType::UserName,
                issued_token_type: UAString::null(),
                issuer_endpoint_url: UAString::null(),
                security_policy_uri: UAString::null(),
            });
        }
        if self.users.has_certificates() && secure {
            policies.push(UserTokenPolicy {
                policy_id: UAString::from("x509"),
                token_type: UserTokenType::Certificate,
                issued_token_type: UAString::null(),
                issuer_endpoint_url: UAString::null(),
                security_policy_uri: UAString::from(endpoint.security_policy().to_uri()),
            });
        }
        policies
    }
}

/// Shared so that the server and [`super::ModelManager`] see the same users.
pub type SharedAuth = Arc<ModelAuth>;

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Users, UserFileError> {
        Users::parse(Path::new("users.txt"), text)
    }

    #[test]
    fn a_password_is_stored_hashed_and_verified() {
        let mut users = Users::default();
        users.set_password("alice", vec![Role::Operator], "correct horse").unwrap();
        let text = users.to_text();
        assert!(!text.contains("correct horse"), "{text}");
        assert!(text.contains("user alice Operator $argon2id$"), "{text}");
        let back = parse(&text).unwrap();
        assert_eq!(back, users);
        let Secret::PasswordHash(h) = &back.users["alice"].secret else { panic!() };
        let h = PasswordHash::new(h).unwrap();
        assert!(Argon2::default().verify_password(b"correct horse", &h).is_ok());
        assert!(Argon2::default().verify_password(b"wrong", &h).is_err());
    }

    #[test]
    fn damaged_lines_are_errors_with_line_and_column() {
        let cases = [
            ("user alice Operator\n", 1, 20, "expected 4 fields"),
            ("# c\nuser bob Root $argon2id$v=19$m=19456,t=2,p=1$c2FsdHNhbHQ$aGFzaGhhc2hoYXNoaGFzaA\n", 2, 10, "unknown role `Root`"),
            ("user carol Operator plaintextpassword\n", 1, 21, "not in PHC form"),
            ("user dan Operator $pbkdf2-sha256$i=1000$c2FsdHNhbHQ$aGFzaGhhc2hoYXNoaGFzaA\n", 1, 19, "only argon2id"),
            ("cert hmi Operator 12ab\n", 1, 19, "40 hex digits"),
            ("root eve Operator x\n", 1, 1, "unknown kind `root`"),
        ];
        for (text, line, column, message) in cases {
            let e = parse(text).unwrap_err();
            assert_eq!((e.line, e.column), (line, column), "{text}: {e}");
            assert!(e.message.contains(message), "{text}: {e}");
            assert!(e.to_string().starts_with(&format!("users.txt:{line}:{column}: error:")), "{e}");
        }
    }

    #[test]
    fn a_user_defined_twice_is_an_error() {
        let mut users = Users::default();
        users.set_password("alice", vec![Role::Operator], "pw").unwrap();
        let text = users.to_text();
        let twice = format!("{text}{}", text.lines().nth(1).unwrap());
        let e = parse(&twice).unwrap_err();
        assert!(e.message.contains("defined twice"), "{e}");
    }

    #[test]
    fn roles_of_sessions() {
        let mut users = Users::default();
        users.set_password("op", vec![Role::Operator], "pw").unwrap();
        let auth = ModelAuth::new(users, AccessPolicy::default(), true);
        assert_eq!(auth.roles(&UserToken(ANONYMOUS.to_owned())), vec![Role::Anonymous]);
        assert_eq!(auth.roles(&UserToken("op".to_owned())), vec![Role::AuthenticatedUser, Role::Operator]);
        let node = NodeId::new(2, 1u32);
        let rw = AccessLevel::CURRENT_READ | AccessLevel::CURRENT_WRITE;
        let level = |user: &str| auth.effective_user_access_level(&UserToken(user.to_owned()), rw, &node).bits();
        assert_eq!(level(ANONYMOUS), AccessLevel::CURRENT_READ.bits());
        assert_eq!(level("op"), rw.bits());
        assert!(!auth.is_user_executable(&UserToken(ANONYMOUS.to_owned()), &node));
        assert!(auth.is_user_executable(&UserToken("op".to_owned()), &node));
    }
}

/// A random password of 22 characters (128 random bits) (for a process that provisions its own users, such as the robot
/// cell's composite skills on its device servers).
pub fn random_password() -> String {
    SaltString::generate(&mut OsRng).as_str().to_owned()
}
