// Framing (4-byte big-endian length + payload) and Envelope (de)serialization:
// common/net/framing.h and common/net/envelope.h.

#include <gtest/gtest.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "net/envelope.h"
#include "net/framing.h"

namespace optique::net {
namespace {

using Bytes = std::vector<std::uint8_t>;

constexpr std::uint32_t kOneMiB = 1u << 20;

wire::Envelope make_frame_begin(std::uint64_t sequence, std::uint64_t frame_id) {
  wire::Envelope e;
  e.set_protocol_version(kProtocolVersion);
  e.set_sequence(sequence);
  auto& begin = *e.mutable_frame_begin();
  begin.set_frame_id(frame_id);
  begin.set_simulation_time_ns(static_cast<std::int64_t>(frame_id) * 16'666'667);
  begin.set_present_time_ns(-123'456'789);
  begin.set_state_hash(0xDEADBEEFCAFEF00Dull);
  auto& changed = *begin.mutable_delta()->add_changed();
  changed.set_id(7);
  changed.mutable_now()->mutable_position()->set_x(1.25);
  changed.mutable_now()->mutable_rotation()->set_w(1.0);
  begin.mutable_delta()->add_removed(3);
  return e;
}

wire::Envelope make_hello(std::uint64_t sequence, const std::string& node_id) {
  wire::Envelope e;
  e.set_protocol_version(kProtocolVersion);
  e.set_sequence(sequence);
  auto& hello = *e.mutable_hello();
  hello.set_node_id(node_id);
  hello.add_capabilities("headless");
  hello.add_capabilities("window");
  hello.set_nonce_mac(std::string("\x00\x01\xff\x7f", 4));
  return e;
}

std::vector<wire::Envelope> sample_messages() {
  return {make_hello(1, "wall-left"), make_frame_begin(2, 0), make_frame_begin(3, 1), make_hello(4, "n"),
          make_frame_begin(5, 1'000'000)};
}

Bytes encode_all(const std::vector<wire::Envelope>& messages) {
  Bytes out;
  for (const auto& m : messages) append_envelope(out, m);
  return out;
}

// Drains every good frame currently available; stops at need_more or bad.
DecodeStatus drain(FrameReader& reader, std::vector<wire::Envelope>& got) {
  for (;;) {
    DecodedFrame frame = reader.next();
    if (frame.status != DecodeStatus::good) return frame.status;
    auto parsed = parse_envelope(frame.payload);
    EXPECT_TRUE(parsed.ok()) << (parsed.ok() ? "" : parsed.error());
    if (parsed.ok()) got.push_back(std::move(parsed).value());
  }
}

void expect_same_messages(const std::vector<wire::Envelope>& expected, const std::vector<wire::Envelope>& got) {
  ASSERT_EQ(expected.size(), got.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(expected[i].SerializeAsString(), got[i].SerializeAsString()) << "message " << i;
    EXPECT_EQ(expected[i].body_case(), got[i].body_case()) << "message " << i;
    EXPECT_EQ(expected[i].sequence(), got[i].sequence()) << "message " << i;
  }
}

Bytes header(std::uint32_t length) {
  return {static_cast<std::uint8_t>(length >> 24), static_cast<std::uint8_t>(length >> 16),
          static_cast<std::uint8_t>(length >> 8), static_cast<std::uint8_t>(length)};
}

// --- Envelope encoding --------------------------------------------------------

TEST(AppendEnvelope, WritesBigEndianLengthThenSerializedMessage) {
  const wire::Envelope hello = make_hello(9, "abc");
  const std::string serialized = hello.SerializeAsString();
  Bytes out{0xAA};  // appends, does not overwrite
  append_envelope(out, hello);
  ASSERT_EQ(out.size(), 1 + kFrameHeaderBytes + serialized.size());
  EXPECT_EQ(out[0], 0xAA);
  const std::uint32_t length = (std::uint32_t{out[1]} << 24) | (std::uint32_t{out[2]} << 16) |
                               (std::uint32_t{out[3]} << 8) | std::uint32_t{out[4]};
  EXPECT_EQ(length, serialized.size());
  EXPECT_EQ(std::string(out.begin() + 5, out.end()), serialized);
}

TEST(AppendEnvelope, MatchesAppendFrameOfSerializedBytes) {
  const wire::Envelope begin = make_frame_begin(1, 42);
  const std::string serialized = begin.SerializeAsString();
  Bytes via_envelope;
  append_envelope(via_envelope, begin);
  Bytes via_frame;
  append_frame(via_frame, std::span(reinterpret_cast<const std::uint8_t*>(serialized.data()), serialized.size()));
  EXPECT_EQ(via_envelope, via_frame);
}

TEST(BodyName, NamesTheOneofField) {
  EXPECT_STREQ(body_name(make_hello(1, "x")), "hello");
  EXPECT_STREQ(body_name(make_frame_begin(1, 1)), "frame_begin");
  EXPECT_STREQ(body_name(wire::Envelope{}), "none");
}

// --- FrameReader over a stream ------------------------------------------------

TEST(FrameReader, OneByteAtATimeYieldsEveryMessageInOrder) {
  const auto messages = sample_messages();
  const Bytes stream = encode_all(messages);
  FrameReader reader(kOneMiB);
  std::vector<wire::Envelope> got;
  for (std::uint8_t byte : stream) {
    reader.append(std::span(&byte, 1));
    ASSERT_EQ(drain(reader, got), DecodeStatus::need_more);
  }
  expect_same_messages(messages, got);
  EXPECT_EQ(reader.buffered_bytes(), 0u);
}

TEST(FrameReader, CoalescedStreamYieldsEveryMessageInOrder) {
  const auto messages = sample_messages();
  const Bytes stream = encode_all(messages);
  FrameReader reader(kOneMiB);
  reader.append(stream);
  std::vector<wire::Envelope> got;
  EXPECT_EQ(drain(reader, got), DecodeStatus::need_more);
  expect_same_messages(messages, got);
  EXPECT_EQ(reader.buffered_bytes(), 0u);
}

TEST(FrameReader, IrregularChunksAcrossFrameBoundaries) {
  const auto messages = sample_messages();
  const Bytes stream = encode_all(messages);
  FrameReader reader(kOneMiB);
  std::vector<wire::Envelope> got;
  std::size_t pos = 0;
  std::size_t chunk = 1;
  while (pos < stream.size()) {
    const std::size_t n = std::min(chunk, stream.size() - pos);
    reader.append(std::span(stream.data() + pos, n));
    pos += n;
    chunk = chunk * 3 % 17 + 1;  // 1, 4, 13, 6, ...: splits headers and payloads
    ASSERT_EQ(drain(reader, got), DecodeStatus::need_more);
  }
  expect_same_messages(messages, got);
}

TEST(FrameReader, EmptyReaderNeedsMore) {
  FrameReader reader;
  const DecodedFrame frame = reader.next();
  EXPECT_EQ(frame.status, DecodeStatus::need_more);
  EXPECT_TRUE(frame.payload.empty());
  EXPECT_EQ(frame.consumed, 0u);
  EXPECT_TRUE(frame.error.empty());
}

TEST(FrameReader, HeaderOnlyNeedsMoreAndNothingElse) {
  Bytes stream;
  append_envelope(stream, make_hello(1, "wall"));
  FrameReader reader(kOneMiB);
  reader.append(std::span(stream.data(), kFrameHeaderBytes));
  for (int i = 0; i < 3; ++i) {  // asking again changes nothing
    const DecodedFrame frame = reader.next();
    EXPECT_EQ(frame.status, DecodeStatus::need_more);
    EXPECT_TRUE(frame.payload.empty());
    EXPECT_EQ(frame.consumed, 0u);
    EXPECT_TRUE(frame.error.empty());
  }
  EXPECT_EQ(reader.buffered_bytes(), kFrameHeaderBytes);
}

TEST(FrameReader, PartialPayloadNeedsMoreThenCompletes) {
  Bytes stream;
  const wire::Envelope hello = make_hello(1, "wall");
  append_envelope(stream, hello);
  ASSERT_GT(stream.size(), kFrameHeaderBytes + 2);
  FrameReader reader(kOneMiB);
  reader.append(std::span(stream.data(), stream.size() - 1));
  DecodedFrame frame = reader.next();
  EXPECT_EQ(frame.status, DecodeStatus::need_more);
  EXPECT_TRUE(frame.payload.empty());
  EXPECT_TRUE(frame.error.empty());
  EXPECT_EQ(reader.buffered_bytes(), stream.size() - 1);

  reader.append(std::span(stream.data() + stream.size() - 1, 1));
  frame = reader.next();
  ASSERT_EQ(frame.status, DecodeStatus::good);
  auto parsed = parse_envelope(frame.payload);
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed.value().hello().node_id(), "wall");
  EXPECT_EQ(reader.next().status, DecodeStatus::need_more);
}

TEST(FrameReader, OversizedLengthIsBadAndNamesTheSize) {
  FrameReader reader(kOneMiB);
  reader.append(header(0xFFFFFFFFu));  // header only: judged before any payload arrives
  const DecodedFrame frame = reader.next();
  ASSERT_EQ(frame.status, DecodeStatus::bad);
  EXPECT_NE(frame.error.find("4294967295"), std::string::npos) << frame.error;
  EXPECT_NE(frame.error.find("1048576"), std::string::npos) << frame.error;
  EXPECT_TRUE(frame.payload.empty());
  // Nothing was kept for the payload.
  EXPECT_EQ(reader.buffered_bytes(), 0u);
}

TEST(FrameReader, LengthOneOverMaxIsBadLengthAtMaxIsGood) {
  {
    FrameReader reader(16);
    reader.append(header(17));
    EXPECT_EQ(reader.next().status, DecodeStatus::bad);
  }
  {
    FrameReader reader(16);
    Bytes stream = header(16);
    stream.resize(stream.size() + 16, 0x5A);
    reader.append(stream);
    const DecodedFrame frame = reader.next();
    ASSERT_EQ(frame.status, DecodeStatus::good);
    EXPECT_EQ(frame.payload.size(), 16u);
    EXPECT_EQ(frame.consumed, 20u);
  }
}

TEST(FrameReader, ZeroLengthIsBad) {
  FrameReader reader(kOneMiB);
  reader.append(header(0));
  const DecodedFrame frame = reader.next();
  ASSERT_EQ(frame.status, DecodeStatus::bad);
  EXPECT_NE(frame.error.find("length 0"), std::string::npos) << frame.error;
}

TEST(FrameReader, StaysBadAfterBadFrame) {
  const Bytes good_stream = encode_all(sample_messages());
  FrameReader reader(kOneMiB);
  Bytes stream;
  append_envelope(stream, make_hello(1, "before"));
  const Bytes zero = header(0);
  stream.insert(stream.end(), zero.begin(), zero.end());
  stream.insert(stream.end(), good_stream.begin(), good_stream.end());
  reader.append(stream);

  DecodedFrame first = reader.next();
  ASSERT_EQ(first.status, DecodeStatus::good);  // the frame before the bad one still comes out
  DecodedFrame bad = reader.next();
  ASSERT_EQ(bad.status, DecodeStatus::bad);
  const std::string error = bad.error;
  ASSERT_FALSE(error.empty());

  // Neither asking again nor feeding good frames brings it back.
  for (int i = 0; i < 3; ++i) {
    const DecodedFrame again = reader.next();
    EXPECT_EQ(again.status, DecodeStatus::bad);
    EXPECT_EQ(again.error, error);
  }
  reader.append(good_stream);
  EXPECT_EQ(reader.buffered_bytes(), 0u);
  const DecodedFrame after = reader.next();
  EXPECT_EQ(after.status, DecodeStatus::bad);
  EXPECT_EQ(after.error, error);
}

// --- parse_envelope -------------------------------------------------------------

TEST(ParseEnvelope, RoundTripsHelloFields) {
  Bytes stream;
  append_envelope(stream, make_hello(77, "proj-3"));
  const DecodedFrame frame = decode_frame(stream, kOneMiB);
  ASSERT_EQ(frame.status, DecodeStatus::good);
  auto parsed = parse_envelope(frame.payload);
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  const wire::Envelope& e = parsed.value();
  EXPECT_EQ(e.protocol_version(), kProtocolVersion);
  EXPECT_EQ(e.sequence(), 77u);
  ASSERT_EQ(e.body_case(), wire::Envelope::kHello);
  EXPECT_EQ(e.hello().node_id(), "proj-3");
  ASSERT_EQ(e.hello().capabilities_size(), 2);
  EXPECT_EQ(e.hello().capabilities(1), "window");
  EXPECT_EQ(e.hello().nonce_mac(), std::string("\x00\x01\xff\x7f", 4));
}

TEST(ParseEnvelope, GarbagePayloadFailsWithMessage) {
  // An over-long varint (11 continuation bytes) is never valid protobuf.
  const Bytes garbage(11, 0xFF);
  Bytes stream;
  append_frame(stream, garbage);
  FrameReader reader(kOneMiB);
  reader.append(stream);
  const DecodedFrame frame = reader.next();
  ASSERT_EQ(frame.status, DecodeStatus::good);  // framing is fine, the content is not
  auto parsed = parse_envelope(frame.payload);
  ASSERT_FALSE(parsed.ok());
  EXPECT_NE(parsed.error().find("undecodable"), std::string::npos) << parsed.error();
  EXPECT_NE(parsed.error().find("11 bytes"), std::string::npos) << parsed.error();
}

TEST(ParseEnvelope, TruncatedSubmessageFails) {
  // Field 11 (hello), length-delimited, claims 16 bytes but only 2 follow.
  const Bytes truncated{0x5A, 0x10, 0x0A, 0x00};
  auto parsed = parse_envelope(truncated);
  ASSERT_FALSE(parsed.ok());
  EXPECT_FALSE(parsed.error().empty());
}

TEST(ParseEnvelope, EnvelopeWithoutBodyFails) {
  wire::Envelope no_body;
  no_body.set_protocol_version(kProtocolVersion);
  no_body.set_sequence(12);
  Bytes stream;
  append_envelope(stream, no_body);
  const DecodedFrame frame = decode_frame(stream, kOneMiB);
  ASSERT_EQ(frame.status, DecodeStatus::good);
  auto parsed = parse_envelope(frame.payload);
  ASSERT_FALSE(parsed.ok());
  EXPECT_NE(parsed.error().find("without a body"), std::string::npos) << parsed.error();
}

TEST(ParseEnvelope, UnknownBodyFieldFromNewerProtocolFails) {
  // Field 99, varint 1: well-formed protobuf, but no body this protocol knows.
  const Bytes newer{0x08, 0x01, 0x98, 0x06, 0x01};
  auto parsed = parse_envelope(newer);
  ASSERT_FALSE(parsed.ok());
  EXPECT_NE(parsed.error().find("without a body"), std::string::npos) << parsed.error();
}

// --- decode_frame (pure) ----------------------------------------------------------

TEST(DecodeFrame, FewerThanHeaderBytesNeedsMore) {
  for (std::size_t n = 0; n < kFrameHeaderBytes; ++n) {
    const Bytes bytes(n, 0x00);
    const DecodedFrame frame = decode_frame(bytes, kOneMiB);
    EXPECT_EQ(frame.status, DecodeStatus::need_more) << n << " bytes";
    EXPECT_EQ(frame.consumed, 0u);
  }
}

TEST(DecodeFrame, GoodFrameIsAViewIntoTheInput) {
  Bytes bytes = header(3);
  bytes.insert(bytes.end(), {0x10, 0x20, 0x30, 0x99, 0x98});  // 2 bytes of the next frame
  const DecodedFrame frame = decode_frame(bytes, kOneMiB);
  ASSERT_EQ(frame.status, DecodeStatus::good);
  EXPECT_EQ(frame.consumed, 7u);
  ASSERT_EQ(frame.payload.size(), 3u);
  EXPECT_EQ(frame.payload.data(), bytes.data() + 4);
  EXPECT_EQ(frame.payload[0], 0x10);
  EXPECT_EQ(frame.payload[2], 0x30);
  EXPECT_TRUE(frame.error.empty());
}

TEST(DecodeFrame, LengthIsBigEndian) {
  // 0x00000102 = 258 bytes; little-endian would read 0x02010000.
  Bytes bytes = header(0x0102);
  bytes.resize(4 + 258, 0x01);
  const DecodedFrame frame = decode_frame(bytes, kOneMiB);
  ASSERT_EQ(frame.status, DecodeStatus::good);
  EXPECT_EQ(frame.payload.size(), 258u);
}

TEST(DecodeFrame, OnePayloadByteShortNeedsMore) {
  Bytes bytes = header(5);
  bytes.resize(4 + 4, 0x01);
  const DecodedFrame frame = decode_frame(bytes, kOneMiB);
  EXPECT_EQ(frame.status, DecodeStatus::need_more);
  EXPECT_EQ(frame.consumed, 0u);
  EXPECT_TRUE(frame.payload.empty());
}

TEST(DecodeFrame, OversizedIsBadEvenWithoutPayload) {
  const DecodedFrame frame = decode_frame(header(kOneMiB + 1), kOneMiB);
  ASSERT_EQ(frame.status, DecodeStatus::bad);
  EXPECT_NE(frame.error.find(std::to_string(kOneMiB + 1)), std::string::npos) << frame.error;
}

TEST(DecodeFrame, ZeroLengthIsBad) {
  const DecodedFrame frame = decode_frame(header(0), kOneMiB);
  EXPECT_EQ(frame.status, DecodeStatus::bad);
  EXPECT_FALSE(frame.error.empty());
}

}  // namespace
}  // namespace optique::net
