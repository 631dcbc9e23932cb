//! FFI plumbing shared by all entry points: status codes, the thread-local last error,
//! panic containment, argument checks and Rust-owned byte buffers.

use std::cell::RefCell;
use std::ffi::{c_char, c_int, CStr, CString};
use std::fmt::Display;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::Duration;

use zenoh::handlers::FifoChannelHandler;

pub const AZ_OK: c_int = 0;
pub const AZ_TIMEOUT: c_int = 1;
pub const AZ_NO_REPLY: c_int = 2;
pub const AZ_ERR: c_int = -1;
pub const AZ_ERR_INVALID_ARGUMENT: c_int = -2;
pub const AZ_ERR_DISCONNECTED: c_int = -3;
pub const AZ_ERR_REPLY: c_int = -4;
pub const AZ_ERR_PANIC: c_int = -5;

/// Extra time given to zenoh's own query timeout beyond the caller's deadline, so that the
/// caller's deadline always fires first and a timeout is reported as `AZ_TIMEOUT` rather than
/// as zenoh's synthetic "Timeout" error reply (indistinguishable without unstable features).
pub(crate) const ZENOH_QUERY_TIMEOUT_GRACE: Duration = Duration::from_millis(1000);

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

pub(crate) fn set_last_error(msg: impl Into<String>) {
    let mut bytes = msg.into().into_bytes();
    bytes.retain(|&b| b != 0);
    let c = CString::new(bytes).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
}

/// Internal error carrying the status code to return and the message to store.
pub(crate) struct Fail(pub c_int, pub String);

impl Fail {
    pub(crate) fn err(msg: impl Into<String>) -> Self {
        Fail(AZ_ERR, msg.into())
    }
    pub(crate) fn arg(msg: impl Into<String>) -> Self {
        Fail(AZ_ERR_INVALID_ARGUMENT, msg.into())
    }
}

/// Runs `f`, converting `Err` and panics into a status code plus thread-local message.
pub(crate) fn guard(f: impl FnOnce() -> Result<c_int, Fail>) -> c_int {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(code)) => code,
        Ok(Err(Fail(code, msg))) => {
            set_last_error(msg);
            code
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_string());
            set_last_error(format!("panic inside angio_zenoh: {what}"));
            AZ_ERR_PANIC
        }
    }
}

/// Like `guard` for functions with no status to report (destructors).
pub(crate) fn guard_void(f: impl FnOnce()) {
    let _ = catch_unwind(AssertUnwindSafe(f));
}

/// Shared body of every `az_*_drop`: takes back the box handed to C and passes its content to
/// `release` (an undeclare, or plain `drop`). NULL is a no-op.
pub(crate) unsafe fn drop_handle<T>(p: *mut T, release: impl FnOnce(T)) {
    guard_void(|| {
        if !p.is_null() {
            release(*Box::from_raw(p));
        }
    })
}

/// Shared wait of the receive functions (subscriber, liveliness subscriber, queryable):
/// `Some(item)`, `None` when nothing arrived within `timeout_ms`, or `AZ_ERR_DISCONNECTED`
/// naming `what` once the channel is closed (session closed).
pub(crate) fn recv_fifo<T>(
    handler: &FifoChannelHandler<T>,
    timeout_ms: u64,
    what: impl Display,
) -> Result<Option<T>, Fail> {
    handler
        .recv_timeout(ms(timeout_ms))
        .map_err(|e| Fail(AZ_ERR_DISCONNECTED, format!("{what} channel closed: {e}")))
}

pub(crate) unsafe fn str_arg<'a>(p: *const c_char, what: &str) -> Result<&'a str, Fail> {
    if p.is_null() {
        return Err(Fail::arg(format!("{what} is NULL")));
    }
    CStr::from_ptr(p)
        .to_str()
        .map_err(|_| Fail::arg(format!("{what} is not valid UTF-8")))
}

pub(crate) unsafe fn bytes_arg<'a>(p: *const u8, len: usize) -> Result<&'a [u8], Fail> {
    if len == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(Fail::arg("data is NULL but len > 0"));
    }
    Ok(std::slice::from_raw_parts(p, len))
}

pub(crate) unsafe fn handle<'a, T>(p: *const T, what: &str) -> Result<&'a T, Fail> {
    p.as_ref()
        .ok_or_else(|| Fail::arg(format!("{what} handle is NULL")))
}

pub(crate) unsafe fn out_ptr<'a, T>(p: *mut T, what: &str) -> Result<&'a mut T, Fail> {
    p.as_mut()
        .ok_or_else(|| Fail::arg(format!("output {what} is NULL")))
}

/// Timeouts are clamped to 30 days so that "wait forever" values such as UINT64_MAX cannot
/// overflow the `Instant` arithmetic done here and inside zenoh.
pub(crate) fn ms(timeout_ms: u64) -> Duration {
    const MAX_TIMEOUT_MS: u64 = 30 * 24 * 3600 * 1000;
    Duration::from_millis(timeout_ms.min(MAX_TIMEOUT_MS))
}

/// Byte buffer owned by Rust, handed to C. Free with `az_bytes_free`.
#[repr(C)]
pub struct az_bytes {
    pub data: *mut u8,
    pub len: usize,
}

impl az_bytes {
    pub(crate) fn empty() -> Self {
        az_bytes {
            data: std::ptr::null_mut(),
            len: 0,
        }
    }
    pub(crate) fn from_vec(v: Vec<u8>) -> Self {
        if v.is_empty() {
            return Self::empty();
        }
        let boxed: Box<[u8]> = v.into_boxed_slice();
        let len = boxed.len();
        az_bytes {
            data: Box::into_raw(boxed) as *mut u8,
            len,
        }
    }
}

/// Fills an optional output buffer with a copy of `v`; nothing is copied when `out` is NULL.
pub(crate) fn write_bytes(out: *mut az_bytes, v: &[u8]) {
    // SAFETY: callers check `out` for NULL or pass a pointer validated by `out_ptr`.
    if let Some(o) = unsafe { out.as_mut() } {
        *o = az_bytes::from_vec(v.to_vec());
    }
}

pub(crate) fn zbytes_to_vec(z: &zenoh::bytes::ZBytes) -> Vec<u8> {
    z.to_bytes().into_owned()
}

/// Frees a buffer returned by this library and resets it to {NULL, 0}. NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn az_bytes_free(b: *mut az_bytes) {
    guard_void(|| {
        if let Some(b) = b.as_mut() {
            if !b.data.is_null() && b.len > 0 {
                let slice = std::ptr::slice_from_raw_parts_mut(b.data, b.len);
                drop(Box::from_raw(slice));
            }
            *b = az_bytes::empty();
        }
    })
}

/// Message of the last failure on the calling thread; valid until the next failing call on it.
#[no_mangle]
pub extern "C" fn az_last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// Enables zenoh's own tracing output, filtered by RUST_LOG or else `fallback_filter`.
#[no_mangle]
pub unsafe extern "C" fn az_init_log(fallback_filter: *const c_char) -> c_int {
    guard(|| {
        let f = if fallback_filter.is_null() {
            "error"
        } else {
            str_arg(fallback_filter, "fallback_filter")?
        };
        zenoh::init_log_from_env_or(f);
        Ok(AZ_OK)
    })
}
