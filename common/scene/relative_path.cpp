#include "scene/relative_path.h"

#include <cctype>
#include <cstdint>

namespace optique::scene {

namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// The length of a URI scheme and its colon at the start of `uri` (RFC 3986:
// a letter, then letters, digits, '+', '-', '.'), or 0.
std::size_t scheme_length(std::string_view uri) {
  if (uri.empty() || !std::isalpha(static_cast<unsigned char>(uri[0]))) return 0;
  for (std::size_t i = 1; i < uri.size(); ++i) {
    const char c = uri[i];
    if (c == ':') return i + 1;
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '+' && c != '-' && c != '.') return 0;
  }
  return 0;
}

// Whether `text` is well-formed UTF-8 (no overlong forms, surrogates or code
// points past U+10FFFF): file names travel in protobuf strings, which must be.
bool is_utf8(std::string_view text) {
  for (std::size_t i = 0; i < text.size();) {
    const auto byte = static_cast<unsigned char>(text[i]);
    std::size_t length = 0;
    std::uint32_t code = 0;
    if (byte < 0x80) {
      ++i;
      continue;
    } else if ((byte & 0xE0) == 0xC0) {
      length = 2;
      code = byte & 0x1F;
    } else if ((byte & 0xF0) == 0xE0) {
      length = 3;
      code = byte & 0x0F;
    } else if ((byte & 0xF8) == 0xF0) {
      length = 4;
      code = byte & 0x07;
    } else {
      return false;
    }
    if (i + length > text.size()) return false;
    for (std::size_t k = 1; k < length; ++k) {
      const auto next = static_cast<unsigned char>(text[i + k]);
      if ((next & 0xC0) != 0x80) return false;
      code = (code << 6) | (next & 0x3F);
    }
    const std::uint32_t least[] = {0, 0, 0x80, 0x800, 0x10000};
    if (code < least[length] || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return false;
    i += length;
  }
  return true;
}

}  // namespace

bool is_data_uri(std::string_view uri) {
  return uri.size() >= 5 && (uri.substr(0, 5) == "data:" || uri.substr(0, 5) == "DATA:");
}

Result<std::string> checked_relative_path(std::string_view path) {
  if (path.empty()) return Error{"is empty"};
  if (path.find('\0') != std::string_view::npos) return Error{"holds a NUL byte"};
  if (path.find('\\') != std::string_view::npos) return Error{"holds a backslash (use '/' between folders)"};
  if (!is_utf8(path)) return Error{"is not UTF-8 (rename the file, or write its name in UTF-8)"};
  if (path.front() == '/') return Error{"is an absolute path: only files inside the scene's folder are read"};
  std::string out;
  std::size_t start = 0;
  while (start <= path.size()) {
    const std::size_t end = std::min(path.find('/', start), path.size());
    const std::string_view segment = path.substr(start, end - start);
    if (segment == "..") return Error{"leaves the scene's folder ('..'): only files inside it are read"};
    if (!segment.empty() && segment != ".") {
      if (!out.empty()) out += '/';
      out += segment;
    }
    start = end + 1;
  }
  if (out.empty()) return Error{"names the folder itself, not a file"};
  return out;
}

Result<std::string> relative_file_of_uri(std::string_view uri) {
  if (const std::size_t scheme = scheme_length(uri); scheme > 0) {
    return Error{"names a scheme ('" + std::string(uri.substr(0, scheme)) +
                 "'): only files beside the glTF, or data: URIs, are read"};
  }
  if (uri.find('?') != std::string_view::npos || uri.find('#') != std::string_view::npos) {
    return Error{"has a query or a fragment ('?' or '#'), which no file name has"};
  }
  std::string decoded;
  decoded.reserve(uri.size());
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] != '%') {
      decoded += uri[i];
      continue;
    }
    const int high = i + 2 < uri.size() ? hex_value(uri[i + 1]) : -1;
    const int low = i + 2 < uri.size() ? hex_value(uri[i + 2]) : -1;
    if (high < 0 || low < 0) return Error{"has a '%' that is not followed by two hex digits"};
    decoded += static_cast<char>(high * 16 + low);
    i += 2;
  }
  return checked_relative_path(decoded);
}

}  // namespace optique::scene
