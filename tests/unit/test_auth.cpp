// Handshake authentication without sockets: common/net/auth.h (secret file
// refusals, nonces, the hello mac and its constant-time check).

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "net/auth.h"

namespace optique::net {
namespace {

using Bytes = std::vector<std::uint8_t>;

constexpr std::uint32_t kVersion = 4;

Secret make_secret(std::string_view text) { return Secret{Bytes(text.begin(), text.end())}; }

Bytes counting_nonce() {
  Bytes nonce(kNonceBytes);
  for (std::size_t i = 0; i < nonce.size(); ++i) nonce[i] = static_cast<std::uint8_t>(i);
  return nonce;
}

std::string hex(std::span<const std::uint8_t> bytes) {
  std::string text;
  for (const std::uint8_t byte : bytes) {
    char pair[3];
    std::snprintf(pair, sizeof pair, "%02x", byte);
    text += pair;
  }
  return text;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// A file under the test's own name in gtest's temporary directory, with `mode`.
std::string write_file(const std::string& contents, mode_t mode) {
  const std::string path = ::testing::TempDir() + "optique_auth_" +
                           ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".secret";
  std::remove(path.c_str());
  {
    std::ofstream out(path, std::ios::binary);
    out << contents;
  }
  EXPECT_EQ(::chmod(path.c_str(), mode), 0);
  return path;
}

// --- hello mac ---------------------------------------------------------------

TEST(HelloMac, KnownAnswerPinsTheEncoding) {
  // Computed independently (Python hmac) from the documented encoding; if this
  // changes, nodes and masters built from different sources stop agreeing.
  const auto mac = hello_mac(make_secret("0123456789abcdef0123456789abcdef"), counting_nonce(), "node-a", 4);
  EXPECT_EQ(hex(mac), "e8a9643154dbe5954f4064957d17bf05fcb4b73eacc0ba5c6ee51f028f328a9c");
}

TEST(HelloMac, IsDeterministic) {
  const Secret secret = make_secret("a shared secret of some length");
  const Bytes nonce = counting_nonce();
  EXPECT_EQ(hello_mac(secret, nonce, "node-a", kVersion), hello_mac(secret, nonce, "node-a", kVersion));
}

TEST(HelloMac, LengthPrefixesKeepFieldsApart) {
  // Without length prefixes, nonce|"a" + "bc" and nonce + "abc" would be the same bytes.
  const Secret secret = make_secret("a shared secret of some length");
  const Bytes nonce = counting_nonce();
  Bytes longer = nonce;
  longer.push_back('a');
  EXPECT_NE(hello_mac(secret, nonce, "abc", kVersion), hello_mac(secret, longer, "bc", kVersion));
}

TEST(HelloMac, EmptySecretIsRefused) {
  EXPECT_THROW((void)hello_mac(Secret{}, counting_nonce(), "node-a", kVersion), std::invalid_argument);
  const auto mac = hello_mac(make_secret("a shared secret of some length"), counting_nonce(), "node-a", kVersion);
  EXPECT_FALSE(verify_hello_mac(Secret{}, counting_nonce(), "node-a", kVersion, mac));
}

class VerifyHelloMac : public ::testing::Test {
 protected:
  Secret secret = make_secret("a shared secret of some length");
  Bytes nonce = counting_nonce();
  std::array<std::uint8_t, kHelloMacBytes> mac = hello_mac(secret, nonce, "node-a", kVersion);
};

TEST_F(VerifyHelloMac, AcceptsTheRightMac) { EXPECT_TRUE(verify_hello_mac(secret, nonce, "node-a", kVersion, mac)); }

TEST_F(VerifyHelloMac, RejectsEverySingleBitFlip) {
  for (std::size_t bit = 0; bit < 8 * kHelloMacBytes; ++bit) {
    auto flipped = mac;
    flipped[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    EXPECT_FALSE(verify_hello_mac(secret, nonce, "node-a", kVersion, flipped)) << "bit " << bit;
  }
}

TEST_F(VerifyHelloMac, RejectsWrongNodeId) {
  EXPECT_FALSE(verify_hello_mac(secret, nonce, "node-b", kVersion, mac));
  EXPECT_FALSE(verify_hello_mac(secret, nonce, "node-a ", kVersion, mac));
  EXPECT_FALSE(verify_hello_mac(secret, nonce, "", kVersion, mac));
}

TEST_F(VerifyHelloMac, RejectsWrongNonce) {
  Bytes other = nonce;
  other[31] ^= 1;
  EXPECT_FALSE(verify_hello_mac(secret, other, "node-a", kVersion, mac));
  EXPECT_FALSE(verify_hello_mac(secret, Bytes{}, "node-a", kVersion, mac));
}

TEST_F(VerifyHelloMac, RejectsWrongVersion) {
  EXPECT_FALSE(verify_hello_mac(secret, nonce, "node-a", kVersion + 1, mac));
  EXPECT_FALSE(verify_hello_mac(secret, nonce, "node-a", kVersion - 1, mac));
}

TEST_F(VerifyHelloMac, RejectsWrongSecret) {
  EXPECT_FALSE(verify_hello_mac(make_secret("a shared secret of some lengtH"), nonce, "node-a", kVersion, mac));
}

TEST_F(VerifyHelloMac, RejectsTruncatedAndEmptyMac) {
  EXPECT_FALSE(verify_hello_mac(secret, nonce, "node-a", kVersion, std::span(mac).first(kHelloMacBytes - 1)));
  EXPECT_FALSE(verify_hello_mac(secret, nonce, "node-a", kVersion, std::span(mac).first(16)));
  EXPECT_FALSE(verify_hello_mac(secret, nonce, "node-a", kVersion, std::span<const std::uint8_t>{}));
  Bytes longer(mac.begin(), mac.end());
  longer.push_back(0);
  EXPECT_FALSE(verify_hello_mac(secret, nonce, "node-a", kVersion, longer));
}

// --- nonces --------------------------------------------------------------------

// --- status token ------------------------------------------------------------

// The known answer comes from OpenSSL's command line:
//   echo -n "optique status token v1" | openssl dgst -sha256 -hmac "0123456789abcdef-secret"
TEST(StatusToken, IsTheSecretsHmacOfItsLabelInHex) {
  const std::string text = "0123456789abcdef-secret";
  const Secret secret{std::vector<std::uint8_t>(text.begin(), text.end())};
  EXPECT_EQ(status_token(secret), "2d1c8c6e625b065097a52658dc42eb22ed0ecd6c863d254624feb957808e35f2");
  EXPECT_EQ(status_token(secret).find(text), std::string::npos) << "the secret itself never shows";
  EXPECT_THROW((void)status_token(Secret{}), std::invalid_argument);
}

TEST(RandomNonce, Is32BytesAndDiffers) {
  const Bytes first = random_nonce();
  const Bytes second = random_nonce();
  EXPECT_EQ(first.size(), 32u);
  EXPECT_EQ(second.size(), 32u);
  EXPECT_NE(first, second);
  EXPECT_EQ(random_nonce(7).size(), 7u);
}

// --- secret files --------------------------------------------------------------

TEST(LoadSecretFile, GoodFileLoadsAndStripsTrailingNewline) {
  const auto path = write_file("correct horse battery staple\n", 0600);
  const auto secret = load_secret_file(path);
  ASSERT_TRUE(secret.ok()) << secret.error();
  const std::string text = "correct horse battery staple";
  EXPECT_EQ(secret.value().bytes, Bytes(text.begin(), text.end()));
}

TEST(LoadSecretFile, StripsCrLfAndKeepsLeadingSpace) {
  const auto path = write_file("  correct horse battery staple \r\n", 0400);
  const auto secret = load_secret_file(path);
  ASSERT_TRUE(secret.ok()) << secret.error();
  const std::string text = "  correct horse battery staple";
  EXPECT_EQ(secret.value().bytes, Bytes(text.begin(), text.end()));
}

TEST(LoadSecretFile, OnlyTheOwnerMayReadOrWriteIt) {
  EXPECT_TRUE(load_secret_file(write_file("0123456789abcdef", 0600)).ok());
  EXPECT_TRUE(load_secret_file(write_file("0123456789abcdef", 0400)).ok());
  // As ssh refuses a private key: the group is other people too.
  for (const auto& [mode, text] :
       std::vector<std::pair<mode_t, std::string>>{{0640, "readable by its group (mode 0640)"},
                                                   {0660, "readable and writable by its group (mode 0660)"},
                                                   {0620, "writable by its group (mode 0620)"},
                                                   {0644, "readable by its group and other users (mode 0644)"},
                                                   {0604, "readable by other users (mode 0604)"}}) {
    const auto path = write_file("correct horse battery staple\n", mode);
    const auto secret = load_secret_file(path);
    ASSERT_FALSE(secret.ok()) << std::oct << mode;
    EXPECT_EQ(secret.error(), "secret file '" + path + "' is " + text + ": chmod 600 it");
  }
}

TEST(LoadSecretFile, WorldWritableIsRefused) {
  const auto path = write_file("correct horse battery staple\n", 0602);
  const auto secret = load_secret_file(path);
  ASSERT_FALSE(secret.ok());
  EXPECT_TRUE(contains(secret.error(), "writable by other users")) << secret.error();
}

TEST(LoadSecretFile, MissingFileIsRefusedNamingThePath) {
  const std::string path = ::testing::TempDir() + "optique_auth_does_not_exist.secret";
  std::remove(path.c_str());
  const auto secret = load_secret_file(path);
  ASSERT_FALSE(secret.ok());
  EXPECT_TRUE(contains(secret.error(), "'" + path + "'")) << secret.error();
  EXPECT_TRUE(contains(secret.error(), "No such file or directory")) << secret.error();
}

TEST(LoadSecretFile, DirectoryIsRefused) {
  const std::string path = ::testing::TempDir() + "optique_auth_directory";
  ::mkdir(path.c_str(), 0700);
  const auto secret = load_secret_file(path);
  ASSERT_FALSE(secret.ok());
  EXPECT_EQ(secret.error(), "secret file '" + path + "' is not a regular file");
}

TEST(LoadSecretFile, EmptyFileIsRefused) {
  const auto path = write_file("", 0600);
  const auto secret = load_secret_file(path);
  ASSERT_FALSE(secret.ok());
  EXPECT_EQ(secret.error(), "secret file '" + path + "' is empty");
}

TEST(LoadSecretFile, OnlyANewlineIsEmpty) {
  const auto path = write_file("\r\n", 0600);
  const auto secret = load_secret_file(path);
  ASSERT_FALSE(secret.ok());
  EXPECT_EQ(secret.error(), "secret file '" + path + "' is empty");
}

TEST(LoadSecretFile, TenBytesAreTooShort) {
  const auto path = write_file("0123456789\n", 0600);
  const auto secret = load_secret_file(path);
  ASSERT_FALSE(secret.ok());
  EXPECT_EQ(secret.error(), "secret file '" + path + "' is too short: 10 bytes, need at least 16");
}

TEST(LoadSecretFile, SixteenBytesAreEnough) {
  EXPECT_FALSE(load_secret_file(write_file(std::string(15, 'x') + "\n", 0600)).ok());
  const auto secret = load_secret_file(write_file(std::string(16, 'x') + "\n", 0600));
  ASSERT_TRUE(secret.ok()) << secret.error();
  EXPECT_EQ(secret.value().bytes.size(), 16u);
}

TEST(LoadSecretFile, FiveThousandBytesAreTooLarge) {
  const auto path = write_file(std::string(5000, 'x'), 0600);
  const auto secret = load_secret_file(path);
  ASSERT_FALSE(secret.ok());
  EXPECT_EQ(secret.error(), "secret file '" + path + "' is too large: 5000 bytes, at most 4096");
}

TEST(LoadSecretFile, SizeLimitIsOnTheFileAsWritten) {
  EXPECT_TRUE(load_secret_file(write_file(std::string(4096, 'x'), 0600)).ok());
  EXPECT_FALSE(load_secret_file(write_file(std::string(4096, 'x') + "\n", 0600)).ok());
}

TEST(LoadSecretFile, BinarySecretIsKeptByteForByte) {
  std::string bytes;
  for (int i = 0; i < 32; ++i) bytes.push_back(static_cast<char>(i * 8 + 1));
  bytes[5] = '\0';  // an interior NUL and a tab (byte 1) must survive; only trailing whitespace goes
  const auto secret = load_secret_file(write_file(bytes, 0600));
  ASSERT_TRUE(secret.ok()) << secret.error();
  EXPECT_EQ(secret.value().bytes, Bytes(bytes.begin(), bytes.end()));
}

}  // namespace
}  // namespace optique::net
