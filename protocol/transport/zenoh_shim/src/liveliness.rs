//! Liveliness tokens and watching them, so a process notices that its peer went away.

use std::ffi::{c_char, c_int};
use std::time::Instant;

use zenoh::handlers::FifoChannelHandler;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Subscriber;
use zenoh::sample::{Sample, SampleKind};
use zenoh::Wait;

use crate::ffi::*;
use crate::session::{az_session, declare_on};

// ---------------------------------------------------------------------------------------------
// Liveliness
// ---------------------------------------------------------------------------------------------

pub struct az_token {
    token: LivelinessToken,
}

pub struct az_liveliness_subscriber {
    subscriber: Subscriber<FifoChannelHandler<Sample>>,
}

/// Declares a liveliness token on `keyexpr`. It disappears for the other peers when it is
/// dropped, when the session closes, or when the process dies (its links close).
#[no_mangle]
pub unsafe extern "C" fn az_liveliness_token_declare(
    s: *const az_session,
    keyexpr: *const c_char,
    out: *mut *mut az_token,
) -> c_int {
    declare_on(s, keyexpr, out, "liveliness token", |session, key| {
        let token = session.liveliness().declare_token(key.to_string()).wait()?;
        Ok(az_token { token })
    })
}

#[no_mangle]
pub unsafe extern "C" fn az_liveliness_token_drop(t: *mut az_token) {
    drop_handle(t, |t| {
        let _ = t.token.undeclare().wait();
    })
}

/// Asks the network which tokens matching `keyexpr` are alive, waiting at most `timeout_ms`
/// for the answers. `*out_count` receives the number of alive tokens found (0 = none).
#[no_mangle]
pub unsafe extern "C" fn az_liveliness_count(
    s: *const az_session,
    keyexpr: *const c_char,
    timeout_ms: u64,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        let out_count = out_ptr(out_count, "count")?;
        *out_count = 0;
        let s = handle(s, "session")?;
        let key = str_arg(keyexpr, "keyexpr")?;
        let replies = s
            .session
            .liveliness()
            .get(key.to_string())
            .timeout(ms(timeout_ms))
            .wait()
            .map_err(|e| Fail::err(format!("cannot query liveliness of '{key}': {e}")))?;
        let deadline = Instant::now() + ms(timeout_ms) + ZENOH_QUERY_TIMEOUT_GRACE;
        let mut count = 0usize;
        // The channel closes when the query is finalised (all routes answered or timeout).
        while let Ok(Some(reply)) = replies.recv_deadline(deadline) {
            if reply.result().is_ok() {
                count += 1;
            }
        }
        *out_count = count;
        Ok(AZ_OK)
    })
}

/// Subscribes to appearance/disappearance of liveliness tokens matching `keyexpr`. With
/// `history` != 0, tokens already alive are reported as appeared right away.
#[no_mangle]
pub unsafe extern "C" fn az_liveliness_subscriber_declare(
    s: *const az_session,
    keyexpr: *const c_char,
    history: c_int,
    out: *mut *mut az_liveliness_subscriber,
) -> c_int {
    declare_on(s, keyexpr, out, "liveliness subscriber", |session, key| {
        let subscriber = session
            .liveliness()
            .declare_subscriber(key.to_string())
            .history(history != 0)
            .wait()?;
        Ok(az_liveliness_subscriber { subscriber })
    })
}

/// Waits up to `timeout_ms` for the next liveliness change. AZ_OK: `*out_alive` is 1 if the
/// token appeared, 0 if it disappeared; `*out_key` (if not NULL) receives the token key (free
/// with az_bytes_free). AZ_TIMEOUT: no change.
#[no_mangle]
pub unsafe extern "C" fn az_liveliness_subscriber_recv(
    sub: *const az_liveliness_subscriber,
    timeout_ms: u64,
    out_alive: *mut c_int,
    out_key: *mut az_bytes,
) -> c_int {
    guard(|| {
        let out_alive = out_ptr(out_alive, "alive flag")?;
        *out_alive = 0;
        write_bytes(out_key, &[]);
        let sub = handle(sub, "liveliness subscriber")?;
        let Some(sample) = recv_fifo(sub.subscriber.handler(), timeout_ms, "liveliness")? else {
            return Ok(AZ_TIMEOUT);
        };
        *out_alive = c_int::from(sample.kind() == SampleKind::Put);
        write_bytes(out_key, sample.key_expr().as_str().as_bytes());
        Ok(AZ_OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn az_liveliness_subscriber_drop(sub: *mut az_liveliness_subscriber) {
    drop_handle(sub, |sub| {
        let _ = sub.subscriber.undeclare().wait();
    })
}
