#pragma once
// A message as a peer of this protocol version sends it, before its body is set
// (the protocol cores' unit tests feed these).

#include "net/envelope.h"
#include "optique/wire.pb.h"

namespace optique::testing {

[[nodiscard]] inline wire::Envelope envelope() {
  wire::Envelope e;
  e.set_protocol_version(net::kProtocolVersion);
  return e;
}

}  // namespace optique::testing
