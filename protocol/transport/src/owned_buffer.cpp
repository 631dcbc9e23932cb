#include "angio/transport/owned_buffer.hpp"

#include <utility>

#include "angio_zenoh.h"

namespace angio::transport {

OwnedBuffer::OwnedBuffer(OwnedBuffer&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)), size_(std::exchange(other.size_, 0)) {}

OwnedBuffer& OwnedBuffer::operator=(OwnedBuffer&& other) noexcept {
  if (this != &other) {
    reset();
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
  }
  return *this;
}

OwnedBuffer::~OwnedBuffer() { reset(); }

OwnedBuffer OwnedBuffer::adopt(az_bytes& raw) {
  OwnedBuffer b(raw.data, raw.len);
  raw = az_bytes{nullptr, 0};
  return b;
}

void OwnedBuffer::reset() noexcept {
  if (data_) {
    az_bytes raw{data_, size_};
    az_bytes_free(&raw);
  }
  data_ = nullptr;
  size_ = 0;
}

}  // namespace angio::transport
