#include "angio/recording/recording.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace angio::recording {
namespace {

constexpr char kMagic[8] = {'A', 'N', 'G', 'I', 'O', 'R', 'E', 'C'};
constexpr std::uint32_t kFormat = 1;

template <class T>
void put(std::ofstream& o, T v) {
  o.write(reinterpret_cast<const char*>(&v), sizeof v);
}
void put_bytes(std::ofstream& o, const void* p, std::uint32_t n) {
  put(o, n);
  o.write(static_cast<const char*>(p), n);
}

struct In {
  std::ifstream in;
  std::string path;
  std::uint64_t size = 0;  // of the file: no length field may ask for more than what is left
  template <class T>
  T get() {
    T v{};
    if (!in.read(reinterpret_cast<char*>(&v), sizeof v)) truncated();
    return v;
  }
  std::vector<std::uint8_t> bytes(std::uint32_t n) {
    // checked before allocating: a corrupted length (e.g. 0xFFFFFFFF) must not allocate 4 GiB
    const auto at = static_cast<std::uint64_t>(in.tellg());
    if (n > size - std::min(at, size))
      throw std::runtime_error(path + ": recording is corrupt or truncated: a length of " + std::to_string(n) +
                               " bytes for the data at offset " + std::to_string(at) + " exceeds the " +
                               std::to_string(size - std::min(at, size)) + " bytes left in the file");
    std::vector<std::uint8_t> b(n);
    if (n && !in.read(reinterpret_cast<char*>(b.data()), n)) truncated();
    return b;
  }
  [[noreturn]] void truncated() { throw std::runtime_error(path + ": recording is truncated"); }
};

}  // namespace

Recorder::Recorder(const std::string& path, const std::string& run_id)
    : path_(path), out_(path, std::ios::binary | std::ios::trunc) {
  if (!out_) throw std::runtime_error(path + ": cannot open the recording for writing");
  out_.write(kMagic, sizeof kMagic);
  put(out_, kFormat);
  put_bytes(out_, run_id.data(), static_cast<std::uint32_t>(run_id.size()));
  out_.flush();
}

void Recorder::add(fb::Role role, const std::string& verb, const msg::Buffer& request, const msg::Buffer& reply) {
  put(out_, static_cast<std::uint8_t>(role));
  put(out_, static_cast<std::uint16_t>(verb.size()));
  out_.write(verb.data(), static_cast<std::streamsize>(verb.size()));
  put_bytes(out_, request.data(), static_cast<std::uint32_t>(request.size()));
  put_bytes(out_, reply.data(), static_cast<std::uint32_t>(reply.size()));
  // Flushed per exchange so a crashed run still leaves a readable recording up to that point.
  out_.flush();
  if (!out_) throw std::runtime_error(path_ + ": writing the recording failed");
}

Recording read(const std::string& path) {
  In r{std::ifstream(path, std::ios::binary), path};
  if (!r.in) throw std::runtime_error(path + ": cannot open the recording");
  r.in.seekg(0, std::ios::end);
  r.size = static_cast<std::uint64_t>(r.in.tellg());
  r.in.seekg(0, std::ios::beg);
  char magic[8];
  if (!r.in.read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0)
    throw std::runtime_error(path + ": not an angio recording (bad magic)");
  if (auto v = r.get<std::uint32_t>(); v != kFormat)
    throw std::runtime_error(path + ": recording format " + std::to_string(v) + ", expected " +
                             std::to_string(kFormat));
  Recording rec;
  auto id = r.bytes(r.get<std::uint32_t>());
  rec.run_id.assign(id.begin(), id.end());
  while (r.in.peek() != std::char_traits<char>::eof()) {
    Exchange e;
    const auto role = r.get<std::uint8_t>();
    if (role > static_cast<std::uint8_t>(fb::Role::MAX))
      throw std::runtime_error(path + ": recording is corrupt: exchange " + std::to_string(rec.exchanges.size()) +
                               " has role " + std::to_string(role) + " (expected 0 to " +
                               std::to_string(static_cast<int>(fb::Role::MAX)) + ")");
    e.role = static_cast<fb::Role>(role);
    auto verb = r.bytes(r.get<std::uint16_t>());
    e.verb.assign(verb.begin(), verb.end());
    e.request = r.bytes(r.get<std::uint32_t>());
    e.reply = r.bytes(r.get<std::uint32_t>());
    rec.exchanges.push_back(std::move(e));
  }
  return rec;
}

}  // namespace angio::recording
