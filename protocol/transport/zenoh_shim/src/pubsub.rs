//! Publish/subscribe, used for status lines.

use std::ffi::{c_char, c_int};

use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::sample::Sample;
use zenoh::Wait;

use crate::ffi::*;
use crate::session::{az_session, declare_on};

// ---------------------------------------------------------------------------------------------
// Publish / subscribe
// ---------------------------------------------------------------------------------------------

pub struct az_publisher {
    publisher: Publisher<'static>,
}

pub struct az_subscriber {
    subscriber: Subscriber<FifoChannelHandler<Sample>>,
}

#[no_mangle]
pub unsafe extern "C" fn az_publisher_declare(
    s: *const az_session,
    keyexpr: *const c_char,
    out: *mut *mut az_publisher,
) -> c_int {
    declare_on(s, keyexpr, out, "publisher", |session, key| {
        let publisher = session.declare_publisher(key.to_string()).wait()?;
        Ok(az_publisher { publisher })
    })
}

#[no_mangle]
pub unsafe extern "C" fn az_publisher_put(
    p: *const az_publisher,
    data: *const u8,
    len: usize,
) -> c_int {
    guard(|| {
        let p = handle(p, "publisher")?;
        let bytes = bytes_arg(data, len)?.to_vec();
        p.publisher.put(bytes).wait().map_err(|e| {
            Fail::err(format!(
                "cannot publish on '{}': {e}",
                p.publisher.key_expr()
            ))
        })?;
        Ok(AZ_OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn az_publisher_drop(p: *mut az_publisher) {
    drop_handle(p, |p| {
        let _ = p.publisher.undeclare().wait();
    })
}

#[no_mangle]
pub unsafe extern "C" fn az_subscriber_declare(
    s: *const az_session,
    keyexpr: *const c_char,
    out: *mut *mut az_subscriber,
) -> c_int {
    declare_on(s, keyexpr, out, "subscriber", |session, key| {
        let subscriber = session.declare_subscriber(key.to_string()).wait()?;
        Ok(az_subscriber { subscriber })
    })
}

/// Waits up to `timeout_ms` for the next sample. AZ_OK: `*out_payload` (and `*out_key` if not
/// NULL) are filled; free both with az_bytes_free. AZ_TIMEOUT: nothing arrived.
#[no_mangle]
pub unsafe extern "C" fn az_subscriber_recv(
    sub: *const az_subscriber,
    timeout_ms: u64,
    out_payload: *mut az_bytes,
    out_key: *mut az_bytes,
) -> c_int {
    guard(|| {
        let out_payload = out_ptr(out_payload, "payload")?;
        *out_payload = az_bytes::empty();
        write_bytes(out_key, &[]);
        let sub = handle(sub, "subscriber")?;
        let Some(sample) = recv_fifo(sub.subscriber.handler(), timeout_ms, "subscriber")? else {
            return Ok(AZ_TIMEOUT);
        };
        *out_payload = az_bytes::from_vec(zbytes_to_vec(sample.payload()));
        write_bytes(out_key, sample.key_expr().as_str().as_bytes());
        Ok(AZ_OK)
    })
}

#[no_mangle]
pub unsafe extern "C" fn az_subscriber_drop(sub: *mut az_subscriber) {
    drop_handle(sub, |sub| {
        let _ = sub.subscriber.undeclare().wait();
    })
}
