/*
 * angio_zenoh.h - minimal C ABI over the Rust `zenoh` crate (see ../src/lib.rs).
 *
 * Status codes: every function returning int returns one of AZ_* below. Negative values are
 * failures; az_last_error() then gives a message (thread-local, valid until the next failing
 * call on the same thread). No function ever unwinds into C: a Rust panic becomes AZ_ERR_PANIC.
 *
 * Ownership:
 *  - Opaque handles (az_session, az_queryable, ...) are created by a *_declare / *_open
 *    function and released by exactly one matching *_drop / *_close function (NULL is a no-op).
 *  - az_query handles are released by az_query_reply, az_query_reply_err (always, even if they
 *    fail) or az_query_drop.
 *  - az_bytes buffers filled by this library belong to the caller and must be released with
 *    az_bytes_free. Output buffers are overwritten, not freed: pass empty/fresh ones.
 *    An empty result is {NULL, 0}.
 *  - Input pointers (strings, data) are only borrowed for the duration of the call.
 *  - Entities may outlive their session's close (they become inert) but should be dropped first.
 *
 * Timeouts are in milliseconds; values above 30 days are clamped to 30 days.
 *
 * Threading: a session may be used from several threads. A given queryable / subscriber should
 * be received from by one thread at a time.
 */
#ifndef ANGIO_ZENOH_H
#define ANGIO_ZENOH_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define AZ_OK 0
#define AZ_TIMEOUT 1  /* nothing arrived within the timeout */
#define AZ_NO_REPLY 2 /* request finished without reply (no matching queryable) */
#define AZ_ERR (-1)   /* generic failure, see az_last_error() */
#define AZ_ERR_INVALID_ARGUMENT (-2)
#define AZ_ERR_DISCONNECTED (-3) /* the entity's channel is closed (session closed) */
#define AZ_ERR_REPLY (-4)        /* the replier answered with an error; message in az_last_error() */
#define AZ_ERR_PANIC (-5)        /* internal bug caught at the FFI boundary */

typedef struct az_session az_session;
typedef struct az_queryable az_queryable;
typedef struct az_query az_query;
typedef struct az_publisher az_publisher;
typedef struct az_subscriber az_subscriber;
typedef struct az_token az_token;
typedef struct az_liveliness_subscriber az_liveliness_subscriber;

typedef struct az_bytes {
  uint8_t* data;
  size_t len;
} az_bytes;

/* Frees a library-allocated buffer and resets it to {NULL, 0}. */
void az_bytes_free(az_bytes* b);

/* Last failure message on the calling thread (never NULL; "" if none). Do not free. */
const char* az_last_error(void);

/* Optional: enables zenoh's log output, filtered by RUST_LOG or else fallback_filter
 * (e.g. "warn"; NULL means "error"). */
int az_init_log(const char* fallback_filter);

/* --- session ------------------------------------------------------------------------------ */

/* Opens a peer session with multicast/gossip scouting off and only the given endpoints,
 * e.g. "tcp/127.0.0.1:7447" or "unixsock-stream//tmp/run/angio.sock".
 * Listen endpoints must be bindable, else an error is returned. Connect endpoints are retried
 * in the background (100 ms .. 1 s period), so opening succeeds before the remote listens;
 * with connect endpoints, opening waits up to 0.5 s (zenoh's scouting delay) for the first
 * connection and its declarations, so a peer that is already up is usable right away. */
int az_session_open(const char* const* listen, size_t n_listen, const char* const* connect, size_t n_connect,
                    az_session** out);

/* Closes the session and frees the handle. */
int az_session_close(az_session* s);

/* Writes the session id (hex) into buf, NUL-terminated, truncated to cap. */
int az_session_zid(const az_session* s, char* buf, size_t cap);

/* --- queryable ---------------------------------------------------------------------------- */

int az_queryable_declare(const az_session* s, const char* keyexpr, az_queryable** out);
void az_queryable_drop(az_queryable* q);

/* AZ_OK: *out_query is a new handle and *out_payload the request payload.
 * AZ_TIMEOUT: nothing within timeout_ms. AZ_ERR_DISCONNECTED: session closed. */
int az_queryable_recv(const az_queryable* q, uint64_t timeout_ms, az_query** out_query, az_bytes* out_payload);

/* Key expression the query was sent to; valid while the query handle lives. */
const char* az_query_keyexpr(const az_query* q);

/* Replies with data (or an error message) and frees the query handle. */
int az_query_reply(az_query* q, const uint8_t* data, size_t len);
int az_query_reply_err(az_query* q, const uint8_t* data, size_t len);

/* Frees the query without replying: the requester gets AZ_NO_REPLY. */
void az_query_drop(az_query* q);

/* --- request ------------------------------------------------------------------------------ */

/* Decides whether a reply is the one awaited (nonzero) or is skipped (0), e.g. a reply that does
 * not carry the run's authentication tag; must not throw. */
typedef int (*az_accept_fn)(void* ctx, const uint8_t* data, size_t len);

/* Sends data to the queryable on keyexpr and waits up to timeout_ms for its first reply that
 * `accept` takes (every reply when accept is NULL); replies it refuses and error replies from
 * other repliers are skipped while another may still come.
 * AZ_OK: *out_reply holds the reply. AZ_TIMEOUT: no reply within timeout_ms.
 * AZ_NO_REPLY: finished without reply, usually because no matching queryable is reachable
 * (returned immediately in that case; callers that wait for a peer retry).
 * AZ_ERR_REPLY: the replier sent an error reply (its message is in az_last_error()). */
int az_request(const az_session* s, const char* keyexpr, const uint8_t* data, size_t len, uint64_t timeout_ms,
               az_accept_fn accept, void* accept_ctx, az_bytes* out_reply);

/* --- publish / subscribe ------------------------------------------------------------------ */

int az_publisher_declare(const az_session* s, const char* keyexpr, az_publisher** out);
int az_publisher_put(const az_publisher* p, const uint8_t* data, size_t len);
void az_publisher_drop(az_publisher* p);

int az_subscriber_declare(const az_session* s, const char* keyexpr, az_subscriber** out);
/* AZ_OK: *out_payload and (if out_key != NULL) *out_key (sample key, not NUL-terminated)
 * are filled. AZ_TIMEOUT: nothing within timeout_ms. */
int az_subscriber_recv(const az_subscriber* sub, uint64_t timeout_ms, az_bytes* out_payload, az_bytes* out_key);
void az_subscriber_drop(az_subscriber* sub);

/* --- liveliness --------------------------------------------------------------------------- */

/* The token vanishes for other peers when dropped, when its session closes, or when the
 * process dies (its links close). */
int az_liveliness_token_declare(const az_session* s, const char* keyexpr, az_token** out);
void az_liveliness_token_drop(az_token* t);

/* Number of alive tokens matching keyexpr, asking the network for at most timeout_ms. */
int az_liveliness_count(const az_session* s, const char* keyexpr, uint64_t timeout_ms, size_t* out_count);

/* Change notifications for tokens matching keyexpr; history != 0 also reports tokens that are
 * already alive. recv: AZ_OK with *out_alive = 1 (appeared) or 0 (disappeared) and the token
 * key in *out_key (if not NULL); AZ_TIMEOUT if no change within timeout_ms. */
int az_liveliness_subscriber_declare(const az_session* s, const char* keyexpr, int history,
                                     az_liveliness_subscriber** out);
int az_liveliness_subscriber_recv(const az_liveliness_subscriber* sub, uint64_t timeout_ms, int* out_alive,
                                  az_bytes* out_key);
void az_liveliness_subscriber_drop(az_liveliness_subscriber* sub);

#ifdef __cplusplus
}
#endif

#endif /* ANGIO_ZENOH_H */
