#include "http/message.h"

namespace optique::http {

Response text_response(unsigned status, std::string text) {
  Response response;
  response.status = status;
  if (text.empty() || text.back() != '\n') text += '\n';
  response.body = std::make_shared<const std::string>(std::move(text));
  return response;
}

}  // namespace optique::http
