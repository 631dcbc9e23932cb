//! Opening and closing a zenoh peer session from explicit endpoints.

use std::ffi::{c_char, c_int};

use zenoh::{Config, Session, Wait};

use crate::ffi::*;

// ---------------------------------------------------------------------------------------------
// Session
// ---------------------------------------------------------------------------------------------

pub struct az_session {
    pub(crate) session: Session,
}

/// Shared body of every `az_*_declare` on a session: checks the arguments, runs `declare` with
/// the session and the key expression, and hands the boxed result to C in `*out` (NULL on any
/// failure, whose message names `what` and the key).
pub(crate) unsafe fn declare_on<T>(
    s: *const az_session,
    keyexpr: *const c_char,
    out: *mut *mut T,
    what: &str,
    declare: impl FnOnce(&Session, &str) -> zenoh::Result<T>,
) -> c_int {
    guard(|| {
        let out = out_ptr(out, what)?;
        *out = std::ptr::null_mut();
        let s = handle(s, "session")?;
        let key = str_arg(keyexpr, "keyexpr")?;
        let entity = declare(&s.session, key)
            .map_err(|e| Fail::err(format!("cannot declare {what} on '{key}': {e}")))?;
        *out = Box::into_raw(Box::new(entity));
        Ok(AZ_OK)
    })
}

fn json_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for ch in s.chars() {
        match ch {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

unsafe fn endpoint_list(p: *const *const c_char, n: usize, what: &str) -> Result<String, Fail> {
    if n > 0 && p.is_null() {
        return Err(Fail::arg(format!("{what} array is NULL but count > 0")));
    }
    let mut items = Vec::with_capacity(n);
    for i in 0..n {
        items.push(json_string(str_arg(*p.add(i), what)?));
    }
    Ok(format!("[{}]", items.join(",")))
}

fn build_config(listen: &str, connect: &str) -> Result<Config, Fail> {
    let mut c = Config::default();
    let mut set = |k: &str, v: &str| {
        c.insert_json5(k, v)
            .map_err(|e| Fail::err(format!("invalid zenoh config {k}={v}: {e}")))
    };
    set("mode", "\"peer\"")?;
    // Only explicit endpoints: no multicast discovery, no gossip, and (by setting listen
    // explicitly, possibly to []) no default tcp/[::]:0 listener opened on every interface.
    set("scouting/multicast/enabled", "false")?;
    set("scouting/gossip/enabled", "false")?;
    set("listen/endpoints", listen)?;
    set("connect/endpoints", connect)?;
    // A connecting peer retries in the background until its peer listens; keep the retry
    // period short so solvers started just before the coupler connect quickly.
    set(
        "connect/retry",
        "{period_init_ms: 100, period_max_ms: 1000, period_increase_factor: 2}",
    )?;
    Ok(c)
}

/// Opens a peer session. Listening endpoints must be bindable (else error); connect endpoints
/// are retried in the background, so opening succeeds before the remote side is up.
#[no_mangle]
pub unsafe extern "C" fn az_session_open(
    listen: *const *const c_char,
    n_listen: usize,
    connect: *const *const c_char,
    n_connect: usize,
    out: *mut *mut az_session,
) -> c_int {
    guard(|| {
        let out = out_ptr(out, "session")?;
        *out = std::ptr::null_mut();
        let l = endpoint_list(listen, n_listen, "listen endpoint")?;
        let c = endpoint_list(connect, n_connect, "connect endpoint")?;
        let config = build_config(&l, &c)?;
        let session = zenoh::open(config).wait().map_err(|e| {
            Fail::err(format!(
                "cannot open zenoh session (listen {l}, connect {c}): {e}"
            ))
        })?;
        *out = Box::into_raw(Box::new(az_session { session }));
        Ok(AZ_OK)
    })
}

/// Closes the session (all its entities become inert) and frees the handle. NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn az_session_close(s: *mut az_session) -> c_int {
    guard(|| {
        if s.is_null() {
            return Ok(AZ_OK);
        }
        let s = Box::from_raw(s);
        s.session
            .close()
            .wait()
            .map_err(|e| Fail::err(format!("error while closing zenoh session: {e}")))?;
        Ok(AZ_OK)
    })
}

/// Writes this session's zenoh id (hex) into `buf` (NUL-terminated, truncated to `cap`).
#[no_mangle]
pub unsafe extern "C" fn az_session_zid(
    s: *const az_session,
    buf: *mut c_char,
    cap: usize,
) -> c_int {
    guard(|| {
        let s = handle(s, "session")?;
        if buf.is_null() || cap == 0 {
            return Err(Fail::arg("zid buffer is NULL or empty"));
        }
        let zid = s.session.zid().to_string();
        let n = zid.len().min(cap - 1);
        std::ptr::copy_nonoverlapping(zid.as_ptr() as *const c_char, buf, n);
        *buf.add(n) = 0;
        Ok(AZ_OK)
    })
}
