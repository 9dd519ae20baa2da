#include "master/report_json.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/util/json_util.h>

#include <cassert>
#include <nlohmann/json.hpp>

namespace optique::master {
namespace {

using Json = nlohmann::ordered_json;  // keeps the fields in the order of the .proto
using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;

// Walks the message type beside its JSON and unquotes every 64-bit integer.
void unquote_64_bit_integers(const Descriptor& type, Json& object) {
  for (int i = 0; i < type.field_count(); ++i) {
    const FieldDescriptor& field = *type.field(i);
    const auto found = object.find(field.name());
    if (found == object.end()) continue;
    const auto unquote = [&field](Json& value) {
      switch (field.cpp_type()) {
        case FieldDescriptor::CPPTYPE_INT64:
          if (value.is_string()) value = std::stoll(value.get<std::string>());
          break;
        case FieldDescriptor::CPPTYPE_UINT64:
          if (value.is_string()) value = std::stoull(value.get<std::string>());
          break;
        case FieldDescriptor::CPPTYPE_MESSAGE:
          if (value.is_object()) unquote_64_bit_integers(*field.message_type(), value);
          break;
        default:
          break;
      }
    };
    if (field.is_repeated()) {
      for (Json& element : *found) unquote(element);
    } else {
      unquote(*found);
    }
  }
}

}  // namespace

std::string report_json(const report::RunReport& report) {
  std::string text;
  google::protobuf::util::JsonPrintOptions print;
  print.always_print_primitive_fields = true;
  print.preserve_proto_field_names = true;
  const auto status = google::protobuf::util::MessageToJsonString(report, &text, print);
  // A message of our own schema always prints.
  assert(status.ok());
  (void)status;
  Json json = Json::parse(text);
  unquote_64_bit_integers(*report::RunReport::descriptor(), json);
  return json.dump(2) + "\n";
}

}  // namespace optique::master
