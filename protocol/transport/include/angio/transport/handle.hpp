#pragma once
// Ownership of the opaque handles of the zenoh shim (angio_zenoh.h): each is released by its
// one matching az_*_drop / az_*_close function (src/ffi.cpp), never by delete.
#include <memory>

struct az_session;
struct az_queryable;
struct az_query;
struct az_publisher;
struct az_subscriber;
struct az_token;
struct az_liveliness_subscriber;

namespace angio::transport::detail {

struct ShimRelease {
  void operator()(az_session* s) const noexcept;  // closes the session, errors ignored
  void operator()(az_queryable* q) const noexcept;
  void operator()(az_query* q) const noexcept;  // unanswered: the requester sees "no reply"
  void operator()(az_publisher* p) const noexcept;
  void operator()(az_subscriber* s) const noexcept;
  void operator()(az_token* t) const noexcept;
  void operator()(az_liveliness_subscriber* s) const noexcept;
};

// Move-only owner of one shim handle.
template <class T>
using ShimHandle = std::unique_ptr<T, ShimRelease>;

}  // namespace angio::transport::detail
