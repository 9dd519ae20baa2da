#include "net/envelope.h"

#include "net/framing.h"

namespace optique::net {

void append_envelope(std::vector<std::uint8_t>& out, const wire::Envelope& envelope) {
  const std::size_t size = envelope.ByteSizeLong();
  const std::size_t start = out.size();
  out.resize(start + kFrameHeaderBytes + size);
  write_frame_header(out.data() + start, static_cast<std::uint32_t>(size));
  const bool serialized = envelope.SerializeWithCachedSizesToArray(out.data() + start + kFrameHeaderBytes) != nullptr;
  assert(serialized);
  (void)serialized;
}

std::vector<std::uint8_t> with_header(std::span<const std::uint8_t> body, std::uint32_t version,
                                      std::uint64_t sequence) {
  wire::Envelope header;
  header.set_protocol_version(version);
  header.set_sequence(sequence);
  std::vector<std::uint8_t> payload(body.begin(), body.end());
  const std::size_t at = payload.size();
  payload.resize(at + header.ByteSizeLong());
  (void)header.SerializeWithCachedSizesToArray(payload.data() + at);
  return payload;
}

Result<void> parse_envelope_into(std::span<const std::uint8_t> payload, wire::Envelope& envelope) {
  if (!envelope.ParseFromArray(payload.data(), static_cast<int>(payload.size()))) {
    return Error{"undecodable message (" + std::to_string(payload.size()) + " bytes are not an Envelope)"};
  }
  if (envelope.body_case() == wire::Envelope::BODY_NOT_SET) {
    return Error{"message without a body (unknown type, or a newer protocol)"};
  }
  return {};
}

Result<wire::Envelope> parse_envelope(std::span<const std::uint8_t> payload) {
  wire::Envelope envelope;
  if (auto parsed = parse_envelope_into(payload, envelope); !parsed) return Error{parsed.error()};
  return envelope;
}

const char* body_name(const wire::Envelope& envelope) {
  const auto* field = wire::Envelope::descriptor()->FindFieldByNumber(envelope.body_case());
  return field != nullptr ? field->name().c_str() : "none";
}

wire::Envelope refusal(const std::string& reason, bool retriable) {
  wire::Envelope envelope;
  envelope.set_protocol_version(kProtocolVersion);
  envelope.mutable_refuse()->set_reason(reason);
  envelope.mutable_refuse()->set_retriable(retriable);
  return envelope;
}

}  // namespace optique::net
