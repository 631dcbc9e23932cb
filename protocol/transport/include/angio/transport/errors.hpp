#pragma once
// Exceptions thrown by the transport wrapper. All derive from TransportError so callers can
// catch transport problems as one family while still telling timeouts apart.
#include <stdexcept>
#include <string>

namespace angio::transport {

class TransportError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Nothing answered within the allotted time (peer absent, slow or dead).
class TimeoutError : public TransportError {
 public:
  using TransportError::TransportError;
};

// The request completed without any reply (no matching queryable reachable right now).
// Only thrown by Session::request_once; Session::request keeps retrying until its timeout.
class NoReplyError : public TransportError {
 public:
  using TransportError::TransportError;
};

// The remote queryable answered with an error reply (e.g. its handler threw).
class RemoteError : public TransportError {
 public:
  using TransportError::TransportError;
};

}  // namespace angio::transport
