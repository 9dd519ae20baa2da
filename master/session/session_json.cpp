#include "master/session/session_json.h"

#include <google/protobuf/util/json_util.h>

namespace optique::master {

Result<session::Request> request_from_json(std::string_view text) {
  session::Request request;
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  const auto status = google::protobuf::util::JsonStringToMessage(
      google::protobuf::StringPiece(text.data(), text.size()), &request, options);
  if (!status.ok()) return Error{"not a Request: " + std::string(status.message())};
  return request;
}

std::string to_application_json(const wire::Envelope& envelope) {
  session::ToApplication message;
  switch (envelope.body_case()) {
    case wire::Envelope::kSessionReply:
      *message.mutable_reply() = envelope.session_reply();
      break;
    case wire::Envelope::kSessionEvent:
      *message.mutable_event() = envelope.session_event();
      break;
    case wire::Envelope::kRefuse:
      message.mutable_closing()->set_reason(envelope.refuse().reason());
      message.mutable_closing()->set_retriable(envelope.refuse().retriable());
      break;
    case wire::Envelope::kGoodbye:
      message.mutable_closing()->set_reason(envelope.goodbye().reason());
      break;
    default:
      return {};
  }
  google::protobuf::util::JsonPrintOptions options;
  options.always_print_primitive_fields = true;
  options.preserve_proto_field_names = true;
  std::string json;
  // Printing a message built here fails only on a bug (it holds no Any).
  const auto status = google::protobuf::util::MessageToJsonString(message, &json, options);
  assert(status.ok());
  (void)status;
  return json;
}

}  // namespace optique::master
