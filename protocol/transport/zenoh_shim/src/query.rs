//! Request/reply: queryables delivering incoming queries to a FIFO, and requests (get).

use std::ffi::{c_char, c_int, c_void, CString};
use std::time::Instant;

use zenoh::handlers::FifoChannelHandler;
use zenoh::query::{ConsolidationMode, Query, Queryable, Reply};
use zenoh::Wait;

use crate::ffi::*;
use crate::session::{az_session, declare_on};

// ---------------------------------------------------------------------------------------------
// Queryable / incoming queries
// ---------------------------------------------------------------------------------------------

pub struct az_queryable {
    queryable: Queryable<FifoChannelHandler<Query>>,
}

pub struct az_query {
    query: Query,
    key: CString,
}

/// Declares a queryable on `keyexpr`; incoming queries queue in a FIFO until `az_queryable_recv`.
#[no_mangle]
pub unsafe extern "C" fn az_queryable_declare(
    s: *const az_session,
    keyexpr: *const c_char,
    out: *mut *mut az_queryable,
) -> c_int {
    declare_on(s, keyexpr, out, "queryable", |session, key| {
        let queryable = session.declare_queryable(key.to_string()).wait()?;
        Ok(az_queryable { queryable })
    })
}

/// Undeclares the queryable and frees it. Queries already received stay valid. NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn az_queryable_drop(q: *mut az_queryable) {
    drop_handle(q, |q| {
        let _ = q.queryable.undeclare().wait();
    })
}

/// Waits up to `timeout_ms` for the next query. On AZ_OK, `*out_query` is a new handle
/// (free it with az_query_reply / az_query_reply_err / az_query_drop) and `*out_payload` holds
/// the request payload (free with az_bytes_free; may be {NULL,0}). AZ_TIMEOUT: nothing arrived.
#[no_mangle]
pub unsafe extern "C" fn az_queryable_recv(
    q: *const az_queryable,
    timeout_ms: u64,
    out_query: *mut *mut az_query,
    out_payload: *mut az_bytes,
) -> c_int {
    guard(|| {
        let out_query = out_ptr(out_query, "query")?;
        *out_query = std::ptr::null_mut();
        let out_payload = out_ptr(out_payload, "payload")?;
        *out_payload = az_bytes::empty();
        let q = handle(q, "queryable")?;
        let key = q.queryable.key_expr();
        let received = recv_fifo(
            q.queryable.handler(),
            timeout_ms,
            format_args!("queryable '{key}'"),
        )?;
        let Some(query) = received else {
            return Ok(AZ_TIMEOUT);
        };
        let payload = query.payload().map(zbytes_to_vec).unwrap_or_default();
        let key = CString::new(query.key_expr().as_str()).unwrap_or_default();
        *out_payload = az_bytes::from_vec(payload);
        *out_query = Box::into_raw(Box::new(az_query { query, key }));
        Ok(AZ_OK)
    })
}

/// Key expression of the query; valid while the query handle lives.
#[no_mangle]
pub unsafe extern "C" fn az_query_keyexpr(q: *const az_query) -> *const c_char {
    match q.as_ref() {
        Some(q) => q.key.as_ptr(),
        None => std::ptr::null(),
    }
}

/// Shared body of the two replies: frees the query handle whatever the outcome, and sends
/// `data` with `send`; a failure names `what` and the query's key.
unsafe fn answer(
    q: *mut az_query,
    data: *const u8,
    len: usize,
    what: &str,
    send: impl FnOnce(&Query, Vec<u8>) -> zenoh::Result<()>,
) -> c_int {
    guard(|| {
        if q.is_null() {
            return Err(Fail::arg("query handle is NULL"));
        }
        let q = Box::from_raw(q);
        let bytes = bytes_arg(data, len)?.to_vec();
        send(&q.query, bytes).map_err(|e| {
            Fail::err(format!(
                "cannot send {what} to query on '{}': {e}",
                q.query.key_expr()
            ))
        })?;
        Ok(AZ_OK)
    })
}

/// Sends `data` as the reply and frees the query handle (always, even on error).
#[no_mangle]
pub unsafe extern "C" fn az_query_reply(q: *mut az_query, data: *const u8, len: usize) -> c_int {
    answer(q, data, len, "reply", |query, bytes| {
        query.reply(query.key_expr().clone(), bytes).wait()
    })
}

/// Sends an error reply (e.g. a UTF-8 message) and frees the query handle (always).
/// The requester sees AZ_ERR_REPLY with this message as its last error.
#[no_mangle]
pub unsafe extern "C" fn az_query_reply_err(
    q: *mut az_query,
    data: *const u8,
    len: usize,
) -> c_int {
    answer(q, data, len, "error reply", |query, bytes| {
        query.reply_err(bytes).wait()
    })
}

/// Frees a query without replying; the requester then gets AZ_NO_REPLY. NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn az_query_drop(q: *mut az_query) {
    drop_handle(q, drop)
}

// ---------------------------------------------------------------------------------------------
// Request (get)
// ---------------------------------------------------------------------------------------------

/// Decides whether a reply is the awaited one (nonzero) or is skipped (0); must not unwind.
pub type az_accept_fn = Option<unsafe extern "C" fn(*mut c_void, *const u8, usize) -> c_int>;

/// Sends `data` to the queryable(s) on `keyexpr` and waits up to `timeout_ms` for the first
/// reply that `accept` takes (any reply when it is NULL). Refused replies, and error replies while
/// a callback filters, are skipped: a foreign replier on the key cannot pre-empt the real one.
/// AZ_OK: `*out_reply` holds it (free with az_bytes_free). AZ_TIMEOUT: nothing within the timeout. AZ_NO_REPLY: the query completed with no reply (typically: no matching queryable
/// reachable right now). AZ_ERR_REPLY: the replier sent an error (message in az_last_error).
#[no_mangle]
pub unsafe extern "C" fn az_request(
    s: *const az_session,
    keyexpr: *const c_char,
    data: *const u8,
    len: usize,
    timeout_ms: u64,
    accept: az_accept_fn,
    accept_ctx: *mut c_void,
    out_reply: *mut az_bytes,
) -> c_int {
    guard(|| {
        let out_reply = out_ptr(out_reply, "reply")?;
        *out_reply = az_bytes::empty();
        let s = handle(s, "session")?;
        let key = str_arg(keyexpr, "keyexpr")?;
        let payload = bytes_arg(data, len)?.to_vec();
        let deadline = Instant::now() + ms(timeout_ms);
        // ConsolidationMode::None hands the reply over as soon as it arrives instead of waiting
        // for the query to be finalised.
        let replies = s
            .session
            .get(key.to_string())
            .payload(payload)
            .consolidation(ConsolidationMode::None)
            .timeout(ms(timeout_ms) + ZENOH_QUERY_TIMEOUT_GRACE)
            .wait()
            .map_err(|e| Fail::err(format!("cannot send request to '{key}': {e}")))?;
        let Some(accept) = accept else {
            return match replies.recv_deadline(deadline) {
                Ok(Some(reply)) => reply_to_status(reply, key, out_reply),
                Ok(None) => Ok(AZ_TIMEOUT),
                // Channel closed without any reply: zenoh finalised the query (no route / no answer).
                Err(_) => Ok(AZ_NO_REPLY),
            };
        };
        let mut last_error: Option<Fail> = None;
        loop {
            match replies.recv_deadline(deadline) {
                Ok(Some(reply)) => match reply.result() {
                    Ok(sample) => {
                        let bytes = zbytes_to_vec(sample.payload());
                        if accept(accept_ctx, bytes.as_ptr(), bytes.len()) != 0 {
                            *out_reply = az_bytes::from_vec(bytes);
                            return Ok(AZ_OK);
                        }
                    }
                    Err(err) => {
                        let msg = String::from_utf8_lossy(&err.payload().to_bytes()).into_owned();
                        last_error = Some(Fail(AZ_ERR_REPLY, format!("error reply from '{key}': {msg}")));
                    }
                },
                Ok(None) => return Ok(AZ_TIMEOUT),
                // Finalised: every replier has answered and none was taken.
                Err(_) => return match last_error {
                    Some(fail) => Err(fail),
                    None => Ok(AZ_NO_REPLY),
                },
            }
        }
    })
}

fn reply_to_status(reply: Reply, key: &str, out: &mut az_bytes) -> Result<c_int, Fail> {
    match reply.result() {
        Ok(sample) => {
            *out = az_bytes::from_vec(zbytes_to_vec(sample.payload()));
            Ok(AZ_OK)
        }
        Err(err) => {
            let msg = String::from_utf8_lossy(&err.payload().to_bytes()).into_owned();
            Err(Fail(
                AZ_ERR_REPLY,
                format!("error reply from '{key}': {msg}"),
            ))
        }
    }
}
