//! The live OPC UA binding of the Modelica packages nodeset-compiler generates: a shared library whose C
//! interface follows the Modelica external function interface (MLS 12.9), used by `OpcUaSupport.Live`.
//!
//! Two external objects, after the DLR OPC UA library's architecture (Schönfeld et al., Modelica
//! Conference 2021):
//!
//! - a **server** (component simulation): `opcua_live_server_new(port, nodesets, pkiDir, usersFile,
//!   insecure)` serves the namespaces of the NodeSet2 files it is given, secure by default (its PKI
//!   folder, users from a user file); write calls publish the simulation's values, read calls return what
//!   clients wrote;
//! - a **client** (interactive simulation and control): `opcua_live_client_new(url, policy, mode, pkiDir,
//!   user, passwordEnv)` connects to a server, Basic256Sha256 SignAndEncrypt unless told otherwise, the
//!   password taken from the environment variable named, never from the model; a lost connection is
//!   reported and retried.
//!
//! The C types are those of MLS 12.9: `Real` is `double`, `Integer` and `Boolean` are `int`, `String` is
//! `const char*`, an external object is a `void*` made by its constructor and released by its destructor.
//! Each read and write takes a NodeId string (`nsu=<namespace URI>;i=<n>`, `ns=<index>;i=<n>` or `i=<n>`;
//! a client's also a browse path from the ObjectsFolder, translated once per session) and reports an `int`
//! status: 0 for Good, else the OPC UA status code's 32 bits (negative for Bad). A failed read returns the
//! `previous` value it was given, so the block holds its value. The message of the last call on an object
//! is `opcua_live_*_error(object)`, for the Modelica side to pass to `ModelicaError` or `assert`: the
//! library itself does not link against a Modelica runtime. Strings returned (messages,
//! String values) are allocated by the tool's `ModelicaAllocateStringWithErrorReturn` where the process has
//! it, else kept in a buffer of the calling thread until its next call that returns a string ([`strings`]).
//!
//! No Rust panic crosses the boundary: each exported function runs under `catch_unwind`, and a panic
//! becomes the status `BadInternalError` with its message. The header is `nodeset_live.h`, which the
//! compiler writes into the Modelica support package (`OpcUaSupport/Resources/Include`); it is written by
//! hand and checked against these functions by `tests/header/mod.rs` (names, parameter and result types).

pub mod client;
pub mod server;
pub mod strings;
pub mod value;

use std::ffi::{c_char, c_int, c_void, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::Mutex;

use opcua::types::StatusCode;

use client::{ClientParams, LiveClient};
use server::{LiveServer, ServerParams};
use value::{status_int, Failure, Kind, Value};

/// An external object: what it runs (or why it could not start), and the message of its last call.
struct Object<T> {
    inner: Result<T, Failure>,
    /// The message of the last call ("" when it succeeded).
    error: Mutex<String>,
}

impl<T> Object<T> {
    fn boxed(inner: Result<T, Failure>) -> *mut c_void {
        let error = match &inner {
            Ok(_) => String::new(),
            Err(f) => f.message.clone(),
        };
        Box::into_raw(Box::new(Object {
            inner,
            error: Mutex::new(error),
        }))
        .cast()
    }

    fn set_error(&self, message: &str) {
        *self.error.lock().unwrap_or_else(|p| p.into_inner()) = message.to_owned();
    }

    /// Runs `f` on the running object, recording its message; the status as an `int`.
    fn run<R>(&self, f: impl FnOnce(&T) -> Result<R, Failure>) -> Result<R, i32> {
        let outcome = match &self.inner {
            Ok(t) => catch_unwind(AssertUnwindSafe(|| f(t))).unwrap_or_else(|p| Err(panicked(p))),
            Err(f) => Err(Failure::new(
                f.status,
                format!("the object did not start: {}", f.message),
            )),
        };
        match outcome {
            Ok(r) => {
                self.set_error("");
                Ok(r)
            }
            Err(failure) => {
                self.set_error(&failure.message);
                Err(status_int(failure.status))
            }
        }
    }
}

fn panicked(payload: Box<dyn std::any::Any + Send>) -> Failure {
    let what = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic".into());
    Failure::new(
        StatusCode::BadInternalError,
        format!("internal error of nodeset-live (please report it): {what}"),
    )
}

/// Runs an exported function's body; a panic that escapes it anyway gives `fallback`.
fn guard<R>(fallback: R, f: impl FnOnce() -> R) -> R {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(fallback)
}

/// A `const char*` argument as text: NULL is empty; text that is not UTF-8 is an error.
///
/// # Safety
/// `p` is NULL or a NUL-terminated string that lives through the call.
unsafe fn text<'a>(p: *const c_char, what: &str) -> Result<&'a str, Failure> {
    if p.is_null() {
        return Ok("");
    }
    CStr::from_ptr(p).to_str().map_err(|_| {
        Failure::new(
            StatusCode::BadInvalidArgument,
            format!("{what} is not UTF-8 text"),
        )
    })
}

/// The object behind a pointer from a constructor.
///
/// # Safety
/// `p` is NULL or a pointer returned by the constructor of `T`'s object, not yet destroyed.
unsafe fn object<'a, T>(p: *mut c_void) -> Option<&'a Object<T>> {
    p.cast::<Object<T>>().as_ref()
}

/// Writes `status` through the output pointer, if there is one.
///
/// # Safety
/// `p` is NULL or points to an `int`.
unsafe fn put(p: *mut c_int, status: i32) {
    if let Some(p) = p.as_mut() {
        *p = status;
    }
}

/// The status of a call on a NULL object: BadInvalidArgument.
const NO_OBJECT: i32 = 0x80AB_0000_u32 as i32;

// ---------------------------------------------------------------------------------------------------------
// Server

/// Starts a server of the namespaces of `nodesets` (NodeSet2 files, and folders of the models they
/// require, separated by `;`) on `port` (0: a free one), with the PKI folder `pkiDir`, the users of
/// `usersFile` (empty: anonymous sessions only, which may read) and, when `insecure` is not 0, an endpoint
/// without security where anonymous sessions may write (loopback testing only). Never NULL: a server that
/// cannot start is an object whose status says why.
///
/// # Safety
/// The strings are NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_server_new(
    port: c_int,
    nodesets: *const c_char,
    pki_dir: *const c_char,
    users_file: *const c_char,
    insecure: c_int,
) -> *mut c_void {
    guard(std::ptr::null_mut(), || {
        let started = (|| {
            let port = u16::try_from(port).map_err(|_| {
                Failure::new(
                    StatusCode::BadConfigurationError,
                    format!("port {port} is not a TCP port (0 to 65535)"),
                )
            })?;
            let params = ServerParams {
                port,
                nodesets: text(nodesets, "nodesets")?.to_owned(),
                pki_dir: PathBuf::from(text(pki_dir, "pkiDir")?),
                users_file: text(users_file, "usersFile")?.to_owned(),
                insecure: insecure != 0,
            };
            if params.pki_dir.as_os_str().is_empty() {
                return Err(Failure::new(
                    StatusCode::BadConfigurationError,
                    "pkiDir is empty: name the server's PKI folder",
                ));
            }
            catch_unwind(AssertUnwindSafe(|| LiveServer::start(&params)))
                .unwrap_or_else(|p| Err(panicked(p)))
        })();
        Object::boxed(started)
    })
}

/// Stops the server and releases the object.
///
/// # Safety
/// `server` is NULL or from [`opcua_live_server_new`], and is not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_server_free(server: *mut c_void) {
    guard((), || {
        if !server.is_null() {
            drop(Box::from_raw(server.cast::<Object<LiveServer>>()));
        }
    })
}

/// 0 when the server runs, else the status of its failed start (the message is `opcua_live_server_error`).
///
/// # Safety
/// `server` is NULL or a live server object.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_server_status(server: *mut c_void) -> c_int {
    guard(status_int(StatusCode::BadInternalError), || {
        match object::<LiveServer>(server) {
            Some(o) => match &o.inner {
                Ok(_) => 0,
                Err(f) => status_int(f.status),
            },
            None => NO_OBJECT,
        }
    })
}

/// The port the server listens on (0 if it did not start).
///
/// # Safety
/// `server` is NULL or a live server object.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_server_port(server: *mut c_void) -> c_int {
    guard(0, || {
        object::<LiveServer>(server)
            .and_then(|o| o.inner.as_ref().ok())
            .map_or(0, |s| c_int::from(s.port()))
    })
}

/// The message of the last call on the server ("" if it succeeded): the tool's copy, or one valid until
/// the calling thread's next call that returns a string.
///
/// # Safety
/// `server` is NULL or a live server object.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_server_error(server: *mut c_void) -> *const c_char {
    error_of::<LiveServer>(server)
}

unsafe fn error_of<T>(p: *mut c_void) -> *const c_char {
    guard(
        c"internal error of nodeset-live".as_ptr(),
        || match object::<T>(p) {
            Some(o) => strings::give(&o.error.lock().unwrap_or_else(|p| p.into_inner())),
            None => c"no object: the constructor was not called, or returned NULL".as_ptr(),
        },
    )
}

unsafe fn server_read(
    server: *mut c_void,
    node_id: *const c_char,
    kind: Kind,
    status: *mut c_int,
) -> Option<Value> {
    let Some(o) = object::<LiveServer>(server) else {
        put(status, NO_OBJECT);
        return None;
    };
    match o.run(|s| s.read(text(node_id, "nodeId")?, kind)) {
        Ok(v) => {
            put(status, 0);
            Some(v)
        }
        Err(e) => {
            put(status, e);
            None
        }
    }
}

unsafe fn server_write(server: *mut c_void, node_id: *const c_char, value: Value) -> c_int {
    match object::<LiveServer>(server) {
        Some(o) => o
            .run(|s| s.write(text(node_id, "nodeId")?, value))
            .err()
            .unwrap_or(0),
        None => NO_OBJECT,
    }
}

/// The value of a Real variable (what clients wrote, or what was published); `previous` when the read
/// fails, with `*status` saying why.
///
/// # Safety
/// `server` is NULL or a live server object; `nodeId` NULL or NUL-terminated; `status` NULL or an `int`.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_server_read_real(
    server: *mut c_void,
    node_id: *const c_char,
    previous: f64,
    status: *mut c_int,
) -> f64 {
    guard(previous, || {
        match server_read(server, node_id, Kind::Real, status) {
            Some(Value::Real(v)) => v,
            _ => previous,
        }
    })
}

/// The value of an Integer variable; `previous` when the read fails.
///
/// # Safety
/// As [`opcua_live_server_read_real`].
#[no_mangle]
pub unsafe extern "C" fn opcua_live_server_read_integer(
    server: *mut c_void,
    node_id: *const c_char,
    previous: c_int,
    status: *mut c_int,
) -> c_int {
    guard(previous, || {
        match server_read(server, node_id, Kind::Integer, status) {
            Some(Value::Integer(v)) => v,
            _ => previous,
        }
    })
}

/// The value of a Boolean variable (1 or 0); `previous` when the read fails.
///
/// # Safety
/// As [`opcua_live_server_read_real`].
#[no_mangle]
pub unsafe extern "C" fn opcua_live_server_read_boolean(
    server: *mut c_void,
    node_id: *const c_char,
    previous: c_int,
    status: *mut c_int,
) -> c_int {
    guard(previous, || {
        match server_read(server, node_id, Kind::Boolean, status) {
            Some(Value::Boolean(v)) => c_int::from(v),
            _ => previous,
        }
    })
}

/// Publishes a Real value (as the variable's Double or Float); the status.
///
/// # Safety
/// `server` is NULL or a live server object; `nodeId` NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_server_write_real(
    server: *mut c_void,
    node_id: *const c_char,
    value: f64,
) -> c_int {
    guard(status_int(StatusCode::BadInternalError), || {
        server_write(server, node_id, Value::Real(value))
    })
}

/// Publishes an Integer value (as the variable's integer type, if the value fits it); the status.
///
/// # Safety
/// As [`opcua_live_server_write_real`].
#[no_mangle]
pub unsafe extern "C" fn opcua_live_server_write_integer(
    server: *mut c_void,
    node_id: *const c_char,
    value: c_int,
) -> c_int {
    guard(status_int(StatusCode::BadInternalError), || {
        server_write(server, node_id, Value::Integer(value))
    })
}

/// Publishes a Boolean value (any non-zero `int` is true); the status.
///
/// # Safety
/// As [`opcua_live_server_write_real`].
#[no_mangle]
pub unsafe extern "C" fn opcua_live_server_write_boolean(
    server: *mut c_void,
    node_id: *const c_char,
    value: c_int,
) -> c_int {
    guard(status_int(StatusCode::BadInternalError), || {
        server_write(server, node_id, Value::Boolean(value != 0))
    })
}

/// The value of a String variable (or the text of a LocalizedText); a copy of `previous` when the read
/// fails. The string is the tool's copy, or one valid until the calling thread's next call that returns a
/// string.
///
/// # Safety
/// As [`opcua_live_server_read_real`]; `previous` NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_server_read_string(
    server: *mut c_void,
    node_id: *const c_char,
    previous: *const c_char,
    status: *mut c_int,
) -> *const c_char {
    let held = || strings::give(&text(previous, "previous").unwrap_or_default());
    guard(c"".as_ptr(), || {
        match server_read(server, node_id, Kind::String, status) {
            Some(Value::String(v)) => strings::give(&v),
            _ => held(),
        }
    })
}

/// Publishes a String value (as the variable's String, or LocalizedText without a locale); the status.
///
/// # Safety
/// As [`opcua_live_server_write_real`]; `value` NULL (empty) or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_server_write_string(
    server: *mut c_void,
    node_id: *const c_char,
    value: *const c_char,
) -> c_int {
    guard(status_int(StatusCode::BadInternalError), || {
        match text(value, "value") {
            Ok(v) => server_write(server, node_id, Value::String(v.to_owned())),
            Err(f) => status_int(f.status),
        }
    })
}

// ---------------------------------------------------------------------------------------------------------
// Client

/// Connects to the server at `url` with the security `policy` and `mode` (empty: Basic256Sha256,
/// SignAndEncrypt), the client's PKI folder `pkiDir`, and `user` (empty: anonymous) whose password is in
/// the environment variable named `passwordEnv`. Never NULL: a client that cannot connect is an object
/// whose calls report why, and which connects again in the background.
///
/// # Safety
/// The strings are NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_client_new(
    url: *const c_char,
    policy: *const c_char,
    mode: *const c_char,
    pki_dir: *const c_char,
    user: *const c_char,
    password_env: *const c_char,
) -> *mut c_void {
    guard(std::ptr::null_mut(), || {
        let started = (|| {
            let params = ClientParams {
                url: text(url, "url")?.to_owned(),
                policy: text(policy, "policy")?.to_owned(),
                mode: text(mode, "mode")?.to_owned(),
                pki_dir: PathBuf::from(text(pki_dir, "pkiDir")?),
                user: text(user, "user")?.to_owned(),
                password_env: text(password_env, "passwordEnv")?.to_owned(),
            };
            if params.url.is_empty() {
                return Err(Failure::new(
                    StatusCode::BadConfigurationError,
                    "url is empty: give the endpoint URL, opc.tcp://host:port/",
                ));
            }
            if params.pki_dir.as_os_str().is_empty() {
                return Err(Failure::new(
                    StatusCode::BadConfigurationError,
                    "pkiDir is empty: name the client's PKI folder",
                ));
            }
            catch_unwind(AssertUnwindSafe(|| LiveClient::start(&params)))
                .unwrap_or_else(|p| Err(panicked(p)))
        })();
        let made = Object::boxed(started);
        // The reason of a failed first connection, for the first look at the message.
        if let Some(o) = object::<LiveClient>(made) {
            let _ = o.run(LiveClient::check);
        }
        made
    })
}

/// Disconnects and releases the object.
///
/// # Safety
/// `client` is NULL or from [`opcua_live_client_new`], and is not used afterwards.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_client_free(client: *mut c_void) {
    guard((), || {
        if !client.is_null() {
            drop(Box::from_raw(client.cast::<Object<LiveClient>>()));
        }
    })
}

/// 0 when a session is open; else `BadNotConnected` (connecting again in the background) or the status of
/// a configuration the client cannot start with. The message is `opcua_live_client_error`.
///
/// # Safety
/// `client` is NULL or a live client object.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_client_status(client: *mut c_void) -> c_int {
    guard(status_int(StatusCode::BadInternalError), || {
        match object::<LiveClient>(client) {
            Some(o) => match &o.inner {
                Ok(c) if c.connected() => 0,
                Ok(_) => status_int(StatusCode::BadNotConnected),
                Err(f) => status_int(f.status),
            },
            None => NO_OBJECT,
        }
    })
}

/// The message of the last call on the client ("" if it succeeded): the tool's copy, or one valid until
/// the calling thread's next call that returns a string.
///
/// # Safety
/// `client` is NULL or a live client object.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_client_error(client: *mut c_void) -> *const c_char {
    error_of::<LiveClient>(client)
}

unsafe fn client_read(
    client: *mut c_void,
    node_id: *const c_char,
    kind: Kind,
    status: *mut c_int,
) -> Option<Value> {
    let Some(o) = object::<LiveClient>(client) else {
        put(status, NO_OBJECT);
        return None;
    };
    match o.run(|c| c.read(text(node_id, "nodeId")?, kind)) {
        Ok(v) => {
            put(status, 0);
            Some(v)
        }
        Err(e) => {
            put(status, e);
            None
        }
    }
}

unsafe fn client_write(client: *mut c_void, node_id: *const c_char, value: Value) -> c_int {
    match object::<LiveClient>(client) {
        Some(o) => o
            .run(|c| c.write(text(node_id, "nodeId")?, value))
            .err()
            .unwrap_or(0),
        None => NO_OBJECT,
    }
}

/// Reads a Real variable of the server; `previous` when the read fails, with `*status` saying why.
///
/// # Safety
/// `client` is NULL or a live client object; `nodeId` NULL or NUL-terminated; `status` NULL or an `int`.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_client_read_real(
    client: *mut c_void,
    node_id: *const c_char,
    previous: f64,
    status: *mut c_int,
) -> f64 {
    guard(previous, || {
        match client_read(client, node_id, Kind::Real, status) {
            Some(Value::Real(v)) => v,
            _ => previous,
        }
    })
}

/// Reads an Integer variable; `previous` when the read fails.
///
/// # Safety
/// As [`opcua_live_client_read_real`].
#[no_mangle]
pub unsafe extern "C" fn opcua_live_client_read_integer(
    client: *mut c_void,
    node_id: *const c_char,
    previous: c_int,
    status: *mut c_int,
) -> c_int {
    guard(previous, || {
        match client_read(client, node_id, Kind::Integer, status) {
            Some(Value::Integer(v)) => v,
            _ => previous,
        }
    })
}

/// Reads a Boolean variable (1 or 0); `previous` when the read fails.
///
/// # Safety
/// As [`opcua_live_client_read_real`].
#[no_mangle]
pub unsafe extern "C" fn opcua_live_client_read_boolean(
    client: *mut c_void,
    node_id: *const c_char,
    previous: c_int,
    status: *mut c_int,
) -> c_int {
    guard(previous, || {
        match client_read(client, node_id, Kind::Boolean, status) {
            Some(Value::Boolean(v)) => c_int::from(v),
            _ => previous,
        }
    })
}

/// Writes a Real value (as the variable's Double or Float); the status.
///
/// # Safety
/// `client` is NULL or a live client object; `nodeId` NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_client_write_real(
    client: *mut c_void,
    node_id: *const c_char,
    value: f64,
) -> c_int {
    guard(status_int(StatusCode::BadInternalError), || {
        client_write(client, node_id, Value::Real(value))
    })
}

/// Writes an Integer value (as the variable's integer type, if the value fits it); the status.
///
/// # Safety
/// As [`opcua_live_client_write_real`].
#[no_mangle]
pub unsafe extern "C" fn opcua_live_client_write_integer(
    client: *mut c_void,
    node_id: *const c_char,
    value: c_int,
) -> c_int {
    guard(status_int(StatusCode::BadInternalError), || {
        client_write(client, node_id, Value::Integer(value))
    })
}

/// Writes a Boolean value (any non-zero `int` is true); the status.
///
/// # Safety
/// As [`opcua_live_client_write_real`].
#[no_mangle]
pub unsafe extern "C" fn opcua_live_client_write_boolean(
    client: *mut c_void,
    node_id: *const c_char,
    value: c_int,
) -> c_int {
    guard(status_int(StatusCode::BadInternalError), || {
        client_write(client, node_id, Value::Boolean(value != 0))
    })
}

/// Reads a String variable (or the text of a LocalizedText); a copy of `previous` when the read fails.
/// The string is the tool's copy, or one valid until the calling thread's next call that returns a string.
///
/// # Safety
/// As [`opcua_live_client_read_real`]; `previous` NULL or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_client_read_string(
    client: *mut c_void,
    node_id: *const c_char,
    previous: *const c_char,
    status: *mut c_int,
) -> *const c_char {
    let held = || strings::give(&text(previous, "previous").unwrap_or_default());
    guard(c"".as_ptr(), || {
        match client_read(client, node_id, Kind::String, status) {
            Some(Value::String(v)) => strings::give(&v),
            _ => held(),
        }
    })
}

/// Writes a String value (as the variable's String, or LocalizedText without a locale); the status.
///
/// # Safety
/// As [`opcua_live_client_write_real`]; `value` NULL (empty) or NUL-terminated.
#[no_mangle]
pub unsafe extern "C" fn opcua_live_client_write_string(
    client: *mut c_void,
    node_id: *const c_char,
    value: *const c_char,
) -> c_int {
    guard(status_int(StatusCode::BadInternalError), || {
        match text(value, "value") {
            Ok(v) => client_write(client, node_id, Value::String(v.to_owned())),
            Err(f) => status_int(f.status),
        }
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_status_of_a_null_object_is_bad_invalid_argument() {
        assert_eq!(
            super::NO_OBJECT,
            super::status_int(super::StatusCode::BadInvalidArgument)
        );
    }
}
