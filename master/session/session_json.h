#pragma once
// The scene session's messages as JSON, for the operator's WebSocket
// (/api/session): Protobuf's JSON mapping of session.proto, so that a browser
// page or a script in any language speaks the messages the binary port takes.
// An application sends a Request; the master sends a ToApplication.

#include <string>
#include <string_view>

#include "optique/session.pb.h"
#include "optique/wire.pb.h"
#include "util/result.h"

namespace optique::master {

// A Request from its JSON text. Field names as in session.proto or in
// lowerCamelCase; 64-bit numbers as numbers or strings. Unknown fields are
// refused, and the error names what is wrong.
[[nodiscard]] Result<session::Request> request_from_json(std::string_view text);

// What the master sends an application, as the binary port would send it
// (a reply, an event, a refusal or a goodbye), in JSON: field names as in
// session.proto, every field given, 64-bit numbers as strings (the JSON
// mapping's rule: JavaScript's numbers hold 53 bits). Empty for an envelope no
// application is sent.
[[nodiscard]] std::string to_application_json(const wire::Envelope& envelope);

}  // namespace optique::master
