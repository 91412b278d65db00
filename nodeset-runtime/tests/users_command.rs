//! The `nodeset-users` command as an administrator runs it: a password user added from stdin, a user
//! certificate, a user replaced, and the refusals (unknown role, empty password, unreadable certificate).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use argon2::password_hash::{PasswordHash, PasswordVerifier};
use argon2::Argon2;
use nodeset_runtime::server::users::Secret;
use nodeset_runtime::server::{Role, Users};

/// Whether the file's hash for `name` verifies `password`.
fn verifies(users: &Users, name: &str, password: &str) -> bool {
    let Secret::PasswordHash(h) = &users.users[name].secret else { panic!("`{name}` is a password user") };
    Argon2::default().verify_password(password.as_bytes(), &PasswordHash::new(h).unwrap()).is_ok()
}

fn users_command(args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_nodeset-users"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("nodeset-users starts");
    // A call the command refuses may exit before it reads standard input: a broken pipe is no error then.
    if let Err(e) = child.stdin.take().unwrap().write_all(stdin.as_bytes()) {
        assert_eq!(e.kind(), std::io::ErrorKind::BrokenPipe, "writing to nodeset-users: {e}");
    }
    child.wait_with_output().unwrap()
}

fn temp(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("users-command-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn text(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn adds_replaces_and_refuses() {
    let dir = temp("add");
    let file = dir.join("users.txt");
    let out = users_command(&["add", text(&file), "op", "Operator"], "s3cret-pw\n");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let users = Users::load(&file).unwrap();
    let saved = std::fs::read_to_string(&file).unwrap();
    assert!(!saved.contains("s3cret-pw") && saved.contains("$argon2id$"), "only the hash is stored:\n{saved}");
    assert!(verifies(&users, "op", "s3cret-pw"), "the stored hash verifies the password");
    assert!(!verifies(&users, "op", "wrong"));

    // The same name again replaces the user; a second user is added beside it.
    let out = users_command(&["add", text(&file), "op", "Engineer,Supervisor"], "other-pw\n");
    assert!(out.status.success());
    let out = users_command(&["add", text(&file), "obs", "Observer"], "obs-pw\n");
    assert!(out.status.success());
    let users = Users::load(&file).unwrap();
    assert!(verifies(&users, "op", "other-pw") && !verifies(&users, "op", "s3cret-pw"));
    assert_eq!(users.users["op"].roles, [Role::Engineer, Role::Supervisor]);
    assert_eq!(users.users["obs"].roles, [Role::Observer]);

    // Refusals leave the file as it was.
    let before = std::fs::read_to_string(&file).unwrap();
    let out = users_command(&["add", text(&file), "x", "Root"], "pw\n");
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("Root"));
    let out = users_command(&["add", text(&file), "x", "Operator"], "\n");
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("empty"));
    let out = users_command(&["cert", text(&file), "hmi", "Operator", text(&dir.join("missing.der"))], "");
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("cannot read"));
    let out = users_command(&["add", text(&file)], "");
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("usage"));
    assert_eq!(std::fs::read_to_string(&file).unwrap(), before);
}
