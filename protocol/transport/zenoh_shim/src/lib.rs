//! C ABI over the `zenoh` crate for the angio co-simulation transport.
//!
//! Design rules (see `include/angio_zenoh.h` for the contract seen from C):
//! * Every entry point returns an `int` status (`AZ_*`) and never unwinds into C:
//!   each body runs inside `catch_unwind`, a panic becomes `AZ_ERR_PANIC`.
//! * The message of the last failure is kept per thread (`az_last_error`).
//! * Handles are opaque boxes handed to C; each has exactly one Rust function that frees it.
//! * Byte buffers returned to C are boxed slices, released with `az_bytes_free`.
//! * Only the synchronous `Wait` API is used: zenoh runs its own internal runtime, so the
//!   C++ side needs no async machinery.

// C-style names for the handle and buffer types, matching the header.
#![allow(non_camel_case_types)]
// The safety contract of every `unsafe extern "C"` function (valid pointers, ownership) is
// stated once in include/angio_zenoh.h rather than repeated on each function.
#![allow(clippy::missing_safety_doc)]

pub mod ffi;
pub mod liveliness;
pub mod pubsub;
pub mod query;
pub mod session;
