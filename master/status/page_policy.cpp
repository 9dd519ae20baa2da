#include "master/status/page_policy.h"

#include <openssl/evp.h>

#include <vector>

#include "util/sha256.h"

namespace optique::master {
namespace {

// 'sha256-…' for what stands between each <tag …> and </tag>, as CSP hashes it.
std::string element_hashes(std::string_view html, std::string_view tag) {
  const std::string open = "<" + std::string(tag);
  const std::string close = "</" + std::string(tag) + ">";
  std::string sources;
  for (std::size_t at = html.find(open); at != std::string_view::npos; at = html.find(open, at)) {
    const std::size_t start = html.find('>', at);
    if (start == std::string_view::npos) break;
    const std::size_t end = html.find(close, start);
    if (end == std::string_view::npos) break;
    const std::string digest = util::sha256_raw(html.substr(start + 1, end - start - 1));
    std::vector<unsigned char> base64(4 * ((digest.size() + 2) / 3) + 1);
    const int length = EVP_EncodeBlock(base64.data(), reinterpret_cast<const unsigned char*>(digest.data()),
                                       static_cast<int>(digest.size()));
    sources +=
        " 'sha256-" + std::string(reinterpret_cast<const char*>(base64.data()), static_cast<std::size_t>(length)) + "'";
    at = end + close.size();
  }
  return sources.empty() ? " 'none'" : sources;
}

}  // namespace

std::string page_security_policy(std::string_view html) {
  return "default-src 'none'; script-src" + element_hashes(html, "script") + "; style-src" +
         element_hashes(html, "style") +
         "; connect-src 'self'; img-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'";
}

}  // namespace optique::master
