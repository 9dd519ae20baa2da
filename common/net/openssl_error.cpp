#include "net/openssl_error.h"

#include <openssl/err.h>

namespace optique::net {

std::string openssl_error() {
  const unsigned long code = ERR_get_error();
  if (code == 0) return "no OpenSSL error recorded";
  char text[256];
  ERR_error_string_n(code, text, sizeof text);
  return text;
}

}  // namespace optique::net
