#include "net/auth.h"

#include <fcntl.h>
#include <openssl/crypto.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "net/openssl_error.h"
#include "util/big_endian.h"

namespace optique::net {
namespace {

constexpr std::string_view kHelloLabel = "optique hello v1";

// Closes on every return path of load_secret_file.
class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  [[nodiscard]] int get() const { return fd_; }

 private:
  int fd_;
};

std::string quoted(const std::string& path) { return "secret file '" + path + "'"; }

std::string octal_mode(mode_t mode) {
  char text[16];
  std::snprintf(text, sizeof text, "%04o", static_cast<unsigned>(mode & 07777));
  return text;
}

bool is_trailing_space(std::uint8_t byte) { return byte == '\n' || byte == '\r' || byte == ' ' || byte == '\t'; }

// A length that does not fit the 4-byte prefix would make the encoding ambiguous;
// frames are far smaller, so reaching this is a caller's bug, refused in release
// builds too rather than truncated.
void append_field(std::vector<std::uint8_t>& out, const std::uint8_t* data, std::size_t size) {
  if (size > std::numeric_limits<std::uint32_t>::max()) {
    throw std::invalid_argument("hello_mac: field longer than 4 GiB");
  }
  util::append_be32(out, static_cast<std::uint32_t>(size));
  out.insert(out.end(), data, data + size);
}

}  // namespace

Result<Secret> load_secret_file(const std::string& path) {
  // O_NONBLOCK so that a FIFO put in the secret's place cannot hang start-up
  // before fstat gets to refuse it; it changes nothing for a regular file.
  FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK));
  if (fd.get() < 0) {
    const int error = errno;
    return Error{"cannot open " + quoted(path) + ": " + std::strerror(error)};
  }
  // The checks look at the file we opened, not at whatever the path names now.
  struct stat info {};
  if (::fstat(fd.get(), &info) != 0) {
    const int error = errno;
    return Error{"cannot stat " + quoted(path) + ": " + std::strerror(error)};
  }
  if (!S_ISREG(info.st_mode)) {
    return Error{quoted(path) + " is not a regular file"};
  }
  // As ssh with a private key: nobody but the owner may read or write it, the
  // owner's group included (a group is other people too).
  const bool readable = (info.st_mode & (S_IRGRP | S_IROTH)) != 0;
  const bool writable = (info.st_mode & (S_IWGRP | S_IWOTH)) != 0;
  if (readable || writable) {
    const bool group = (info.st_mode & (S_IRGRP | S_IWGRP)) != 0;
    const bool others = (info.st_mode & (S_IROTH | S_IWOTH)) != 0;
    const char* what = readable && writable ? "readable and writable" : readable ? "readable" : "writable";
    const char* who = group && others ? "its group and other users" : group ? "its group" : "other users";
    return Error{quoted(path) + " is " + what + " by " + who + " (mode " + octal_mode(info.st_mode) +
                 "): chmod 600 it"};
  }
  if (info.st_size > static_cast<off_t>(kMaxSecretBytes)) {
    return Error{quoted(path) + " is too large: " + std::to_string(info.st_size) + " bytes, at most " +
                 std::to_string(kMaxSecretBytes)};
  }

  // Read one byte more than allowed: the file may have grown since fstat.
  Secret secret;
  secret.bytes.resize(kMaxSecretBytes + 1);
  std::size_t length = 0;
  while (length < secret.bytes.size()) {
    const ssize_t got = ::read(fd.get(), secret.bytes.data() + length, secret.bytes.size() - length);
    if (got < 0) {
      const int error = errno;
      if (error == EINTR) continue;
      return Error{"cannot read " + quoted(path) + ": " + std::strerror(error)};
    }
    if (got == 0) break;
    length += static_cast<std::size_t>(got);
  }
  if (length > kMaxSecretBytes) {
    return Error{quoted(path) + " is too large: more than " + std::to_string(kMaxSecretBytes) + " bytes"};
  }
  while (length > 0 && is_trailing_space(secret.bytes[length - 1])) --length;
  secret.bytes.resize(length);

  if (length == 0) {
    return Error{quoted(path) + " is empty"};
  }
  if (length < kMinSecretBytes) {
    return Error{quoted(path) + " is too short: " + std::to_string(length) + " bytes, need at least " +
                 std::to_string(kMinSecretBytes)};
  }
  return secret;
}

std::vector<std::uint8_t> random_nonce(std::size_t bytes) {
  if (bytes > static_cast<std::size_t>(INT_MAX)) {
    throw std::invalid_argument("random_nonce: " + std::to_string(bytes) + " bytes is too many");
  }
  std::vector<std::uint8_t> nonce(bytes);
  if (RAND_bytes(nonce.data(), static_cast<int>(bytes)) != 1) {
    throw std::runtime_error("cannot draw a random nonce: " + openssl_error());
  }
  return nonce;
}

namespace {

std::array<std::uint8_t, kHelloMacBytes> hmac_sha256(const Secret& secret, const std::vector<std::uint8_t>& message,
                                                     const char* what) {
  if (secret.bytes.empty()) {
    throw std::invalid_argument(std::string(what) + ": empty secret");
  }
  if (secret.bytes.size() > static_cast<std::size_t>(INT_MAX)) {
    throw std::invalid_argument(std::string(what) + ": secret too long");
  }
  std::array<std::uint8_t, kHelloMacBytes> mac{};
  unsigned int mac_length = 0;
  const unsigned char* done = HMAC(EVP_sha256(), secret.bytes.data(), static_cast<int>(secret.bytes.size()),
                                   message.data(), message.size(), mac.data(), &mac_length);
  // Never hand out a zero mac after a failure: two failing sides would agree on it.
  if (done == nullptr || mac_length != kHelloMacBytes) {
    throw std::runtime_error("HMAC-SHA256 failed: " + openssl_error());
  }
  return mac;
}

}  // namespace

std::array<std::uint8_t, kHelloMacBytes> hello_mac(const Secret& secret, std::span<const std::uint8_t> nonce,
                                                   std::string_view node_id, std::uint32_t protocol_version) {
  std::vector<std::uint8_t> message;
  message.reserve(kHelloLabel.size() + 4 + nonce.size() + 4 + node_id.size() + 4);
  message.insert(message.end(), kHelloLabel.begin(), kHelloLabel.end());
  append_field(message, nonce.data(), nonce.size());
  append_field(message, reinterpret_cast<const std::uint8_t*>(node_id.data()), node_id.size());
  util::append_be32(message, protocol_version);
  return hmac_sha256(secret, message, "hello_mac");
}

std::string status_token(const Secret& secret) {
  constexpr std::string_view kLabel = "optique status token v1";
  const std::array<std::uint8_t, kHelloMacBytes> mac =
      hmac_sha256(secret, std::vector<std::uint8_t>(kLabel.begin(), kLabel.end()), "status_token");
  constexpr char kHex[] = "0123456789abcdef";
  std::string token;
  for (const std::uint8_t byte : mac) {
    token += kHex[byte >> 4];
    token += kHex[byte & 15];
  }
  return token;
}

bool verify_hello_mac(const Secret& secret, std::span<const std::uint8_t> nonce, std::string_view node_id,
                      std::uint32_t protocol_version, std::span<const std::uint8_t> mac) {
  if (mac.size() != kHelloMacBytes || secret.bytes.empty()) return false;
  const std::array<std::uint8_t, kHelloMacBytes> expected = hello_mac(secret, nonce, node_id, protocol_version);
  // Constant time, so the comparison does not tell a prober how many leading bytes were right.
  return CRYPTO_memcmp(expected.data(), mac.data(), kHelloMacBytes) == 0;
}

}  // namespace optique::net
