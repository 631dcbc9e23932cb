#pragma once
// A byte buffer allocated by the Rust shim, released through the shim (never by delete/free).
#include <cstddef>
#include <cstdint>
#include <span>

#include "angio/transport/bytes.hpp"

struct az_bytes;

namespace angio::transport {

class OwnedBuffer {
 public:
  OwnedBuffer() = default;
  OwnedBuffer(std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  OwnedBuffer(OwnedBuffer&& other) noexcept;
  OwnedBuffer& operator=(OwnedBuffer&& other) noexcept;
  OwnedBuffer(const OwnedBuffer&) = delete;
  OwnedBuffer& operator=(const OwnedBuffer&) = delete;
  ~OwnedBuffer();

  // Takes ownership of a buffer filled by the shim and leaves `raw` empty.
  static OwnedBuffer adopt(az_bytes& raw);

  ByteView view() const { return {data_, size_}; }
  std::size_t size() const { return size_; }
  Bytes to_vector() const { return Bytes(data_, data_ + size_); }

 private:
  void reset() noexcept;
  std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace angio::transport
