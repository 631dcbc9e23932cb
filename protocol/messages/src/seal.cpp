#include "angio/messages/seal.hpp"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "angio/messages/envelope.hpp"

namespace angio::msg {
namespace {

constexpr char kDomain[] = "angio-seal-1";  // separates these tags from any other use of the key

std::string hint(const std::filesystem::path& file) {
  return " (the launcher writes one for each run; for processes started by hand: (umask 077; python3 -c "
         "'import secrets; print(secrets.token_hex(32))' > " +
         file.string() + "))";
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

RunKey RunKey::read(const std::filesystem::path& file) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0)
    throw KeyFileError(file.string() + ": expected the run's key file, got " + std::strerror(errno) + hint(file));
  if (!S_ISREG(st.st_mode)) throw KeyFileError(file.string() + ": expected a regular file (the run's key file)");
  if (st.st_uid != ::geteuid())
    throw KeyFileError(file.string() + ": expected a key file owned by this user (uid " + std::to_string(::geteuid()) +
                       "), got uid " + std::to_string(st.st_uid));
  if (st.st_mode & 077) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    throw KeyFileError(file.string() + ": expected a key file readable by its owner only (mode 0600), got mode " +
                       mode + " (chmod 600 it, or let the launcher write a new one)");
  }
  std::ifstream in(file);
  std::string text(2 * kKeyBytes + 2, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));  // bounded: never more than a line
  text.resize(static_cast<std::size_t>(in.gcount()));
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  std::array<std::uint8_t, kKeyBytes> secret{};
  bool ok = text.size() == 2 * kKeyBytes;
  for (std::size_t i = 0; ok && i < kKeyBytes; ++i) {
    const int hi = hex_digit(text[2 * i]), lo = hex_digit(text[2 * i + 1]);
    ok = hi >= 0 && lo >= 0;
    secret[i] = static_cast<std::uint8_t>(16 * hi + lo);
  }
  if (!ok)
    throw KeyFileError(file.string() + ": expected one line of " + std::to_string(2 * kKeyBytes) + " hex digits");
  RunKey key(secret);
  OPENSSL_cleanse(secret.data(), secret.size());
  return key;
}

std::array<std::uint8_t, RunKey::kTagBytes> RunKey::tag_(std::span<const std::uint8_t> envelope) const {
  std::array<std::uint8_t, kTagBytes> tag{};
  std::vector<std::uint8_t> data;  // domain || envelope; HMAC() has no streaming form
  data.reserve(sizeof kDomain - 1 + envelope.size());
  data.insert(data.end(), kDomain, kDomain + sizeof kDomain - 1);
  data.insert(data.end(), envelope.begin(), envelope.end());
  unsigned int len = 0;
  if (!HMAC(EVP_sha256(), secret_.data(), static_cast<int>(secret_.size()), data.data(), data.size(), tag.data(),
            &len) ||
      len != kTagBytes)
    throw std::runtime_error("HMAC-SHA256 failed");
  return tag;
}

std::vector<std::uint8_t> RunKey::seal(std::span<const std::uint8_t> envelope) const {
  std::vector<std::uint8_t> out(envelope.begin(), envelope.end());
  const auto tag = tag_(envelope);
  out.insert(out.end(), tag.begin(), tag.end());
  return out;
}

std::optional<std::span<const std::uint8_t>> RunKey::verified(std::span<const std::uint8_t> sealed) const noexcept {
  if (sealed.size() <= kTagBytes) return std::nullopt;
  const auto envelope = sealed.first(sealed.size() - kTagBytes);
  try {
    const auto tag = tag_(envelope);
    if (CRYPTO_memcmp(tag.data(), sealed.data() + envelope.size(), kTagBytes) != 0)
      return std::nullopt;  // constant time
  } catch (...) {           // HMAC failure (allocation): not verified
    return std::nullopt;
  }
  return envelope;
}

std::span<const std::uint8_t> RunKey::unseal(std::span<const std::uint8_t> sealed) const {
  if (sealed.size() <= kTagBytes)
    throw ProtocolError("message of " + std::to_string(sealed.size()) +
                        " bytes is too short to carry an authentication tag");
  if (const auto envelope = verified(sealed)) return *envelope;
  throw ProtocolError(
      "message is not authenticated by the run's key (a process without the run's key file, "
      "or altered on the way)");
}

}  // namespace angio::msg
