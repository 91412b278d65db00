//! The strings the library returns to a Modelica tool: the messages of `*_error` and the values of
//! `*_read_string`.
//!
//! MLS 12.9.6 lets an external function return a `const char*` that the tool copies before the next call,
//! or one allocated with `ModelicaAllocateString` (then the tool owns it). The library does not link
//! against a Modelica runtime (it is one library for every tool), so it looks for
//! `ModelicaAllocateStringWithErrorReturn` in the process once (`dlsym`): where the tool's runtime is loaded,
//! each string is a copy allocated by the tool; elsewhere (a C program, the Rust tests, a tool whose runtime
//! does not export the symbol) it is a copy in a buffer of the calling thread, valid until that thread's
//! next call that returns a string. Either way no other thread's call, and no later call on the object,
//! changes a string already returned to a thread before its next string call. (The `WithErrorReturn`
//! variant returns NULL when memory is short; `ModelicaAllocateString` would end the simulation with a
//! `longjmp` through Rust frames, which Rust does not allow.)

use std::cell::RefCell;
use std::ffi::{c_char, CString};
use std::sync::OnceLock;

/// `char* ModelicaAllocateStringWithErrorReturn(size_t len)`: `len + 1` bytes the tool owns, or NULL.
type Allocate = unsafe extern "C" fn(usize) -> *mut c_char;

/// The tool's allocator, if the process has one.
fn allocator() -> Option<Allocate> {
    static FOUND: OnceLock<Option<Allocate>> = OnceLock::new();
    *FOUND.get_or_init(find)
}

#[cfg(unix)]
fn find() -> Option<Allocate> {
    // SAFETY: dlsym with RTLD_DEFAULT and a NUL-terminated name only looks the symbol up. The symbol, where
    // a Modelica runtime defines it, has the signature of ModelicaUtilities.h.
    unsafe {
        let p = libc::dlsym(
            libc::RTLD_DEFAULT,
            c"ModelicaAllocateStringWithErrorReturn".as_ptr(),
        );
        if p.is_null() {
            None
        } else {
            Some(std::mem::transmute::<*mut libc::c_void, Allocate>(p))
        }
    }
}

#[cfg(not(unix))]
fn find() -> Option<Allocate> {
    None
}

thread_local! {
    /// The last string returned to this thread without the tool's allocator.
    static BUFFER: RefCell<CString> = RefCell::new(CString::default());
}

/// Whether the strings go through the tool's allocator.
pub fn tool_allocates() -> bool {
    allocator().is_some()
}

/// `text` for the tool: a copy the tool owns, or one in the calling thread's buffer (a NUL inside becomes
/// a space).
pub fn give(text: &str) -> *const c_char {
    let bytes = text.replace('\0', " ");
    if let Some(allocate) = allocator() {
        // SAFETY: the allocator returns NULL or `len + 1` writable bytes, which are filled and terminated.
        unsafe {
            let p = allocate(bytes.len());
            if !p.is_null() {
                std::ptr::copy_nonoverlapping(bytes.as_ptr(), p.cast::<u8>(), bytes.len());
                *p.add(bytes.len()) = 0;
                return p;
            }
        }
    }
    let owned = CString::new(bytes).unwrap_or_default();
    BUFFER.with(|b| {
        let mut b = b.borrow_mut();
        *b = owned;
        b.as_ptr()
    })
}
