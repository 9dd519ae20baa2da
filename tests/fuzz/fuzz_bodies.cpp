#include "fuzz_bodies.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <map>
#include <optional>
#include <vector>

#include "master/session/journal.h"
#include "master/session/scene_sessions.h"
#include "master/session/session_json.h"
#include "net/envelope.h"
#include "net/framing.h"
#include "scene/state.h"
#include "tracking/dtrack.h"
#include "tracking/head_tracker.h"
#include "util/finite.h"

namespace optique::fuzz {
namespace {

using Bytes = std::vector<std::uint8_t>;

// xorshift32: the fragment sizes must follow from the input alone, so a crash
// input replays the same way everywhere.
std::uint32_t next_random(std::uint32_t& state) {
  state ^= state << 13;
  state ^= state >> 17;
  state ^= state << 5;
  return state;
}

std::string check_good_frame(const net::DecodedFrame& frame) {
  OPTIQUE_FUZZ_REQUIRE(frame.consumed == net::kFrameHeaderBytes + frame.payload.size());
  OPTIQUE_FUZZ_REQUIRE(frame.payload.size() <= kMaxPayloadBytes);
  OPTIQUE_FUZZ_REQUIRE(!frame.payload.empty());
  return {};
}

// Every Envelope that parses must survive a trip through append_envelope and back
// unchanged: that is what the peer at the other end will see.
std::string check_envelope(const wire::Envelope& envelope) {
  OPTIQUE_FUZZ_REQUIRE(envelope.body_case() != wire::Envelope::BODY_NOT_SET);
  OPTIQUE_FUZZ_REQUIRE(std::string_view(net::body_name(envelope)) != "none");
  Bytes framed;
  net::append_envelope(framed, envelope);
  const net::DecodedFrame frame = net::decode_frame(framed, net::kDefaultMaxPayloadBytes);
  OPTIQUE_FUZZ_REQUIRE(frame.status == net::DecodeStatus::good);
  OPTIQUE_FUZZ_REQUIRE(frame.consumed == framed.size());
  auto again = net::parse_envelope(frame.payload);
  OPTIQUE_FUZZ_REQUIRE(again.ok());
  OPTIQUE_FUZZ_REQUIRE(again.value().body_case() == envelope.body_case());
  const std::string reserialized = again.value().SerializeAsString();
  OPTIQUE_FUZZ_REQUIRE(reserialized.size() == frame.payload.size());
  OPTIQUE_FUZZ_REQUIRE(std::equal(reserialized.begin(), reserialized.end(), frame.payload.begin(),
                                  [](char a, std::uint8_t b) { return static_cast<std::uint8_t>(a) == b; }));
  return {};
}

std::string frames(std::span<const std::uint8_t> input, Outcome& out) {
  if (input.empty()) return {};
  const std::uint32_t piece = input[0];
  const std::span<const std::uint8_t> stream = input.subspan(1);

  // The reference: the whole stream decoded in place. Fragmentation must not
  // change which frames come out, nor how the stream ends.
  std::vector<Bytes> expected;
  net::DecodedFrame expected_end;
  std::size_t expected_left = 0;
  for (std::size_t pos = 0;;) {
    net::DecodedFrame frame = net::decode_frame(stream.subspan(pos), kMaxPayloadBytes);
    if (frame.status != net::DecodeStatus::good) {
      expected_end = std::move(frame);
      expected_left = stream.size() - pos;
      break;
    }
    if (auto broken = check_good_frame(frame); !broken.empty()) return broken;
    expected.emplace_back(frame.payload.begin(), frame.payload.end());
    pos += frame.consumed;
  }
  OPTIQUE_FUZZ_REQUIRE(expected_end.status != net::DecodeStatus::bad || !expected_end.error.empty());

  net::FrameReader reader(kMaxPayloadBytes);
  std::vector<Bytes> got;
  net::DecodedFrame last;
  // Payloads are views into the reader's buffer, valid only until the next
  // append(): copy each one out before feeding more.
  auto drain = [&]() -> std::string {
    for (;;) {
      last = reader.next();
      if (last.status != net::DecodeStatus::good) return {};
      if (auto broken = check_good_frame(last); !broken.empty()) return broken;
      got.emplace_back(last.payload.begin(), last.payload.end());
    }
  };
  std::uint32_t rng_state = piece * 0x9E3779B9u + 0x7F4A7C15u;
  for (std::size_t pos = 0; pos < stream.size();) {
    std::size_t size = stream.size() - pos;
    if (piece != 0) size = std::min<std::size_t>(size, 1 + next_random(rng_state) % piece);
    reader.append(stream.subspan(pos, size));
    pos += size;
    // Sometimes let several pieces pile up before asking for frames.
    if ((next_random(rng_state) & 1u) != 0) {
      if (auto broken = drain(); !broken.empty()) return broken;
    }
  }
  if (auto broken = drain(); !broken.empty()) return broken;

  OPTIQUE_FUZZ_REQUIRE(got == expected);
  OPTIQUE_FUZZ_REQUIRE(last.status == expected_end.status);
  if (last.status == net::DecodeStatus::bad) {
    OPTIQUE_FUZZ_REQUIRE(last.error == expected_end.error);
    OPTIQUE_FUZZ_REQUIRE(reader.buffered_bytes() == 0);
    // A bad stream stays bad, whatever arrives after.
    reader.append(input);
    OPTIQUE_FUZZ_REQUIRE(reader.next().status == net::DecodeStatus::bad);
  } else {
    OPTIQUE_FUZZ_REQUIRE(reader.buffered_bytes() == expected_left);
  }

  // The same stream, cut the same way, through a reader that passes over
  // oversized frames: every good frame and every oversized one's length, in
  // order, as the stream decoded in place has them; nothing of a skipped
  // payload is ever held.
  std::vector<std::pair<std::uint32_t, Bytes>> skip_expected;  // (oversized length or 0, payload)
  for (std::size_t pos = 0; pos < stream.size();) {
    const net::DecodedFrame frame = net::decode_frame(stream.subspan(pos), kMaxPayloadBytes);
    if (frame.status == net::DecodeStatus::good) {
      skip_expected.emplace_back(0, Bytes(frame.payload.begin(), frame.payload.end()));
      pos += frame.consumed;
    } else if (frame.status == net::DecodeStatus::bad && frame.length > 0) {
      skip_expected.emplace_back(frame.length, Bytes{});
      pos += net::kFrameHeaderBytes + frame.length;
    } else {
      break;
    }
  }
  net::FrameReader skipper(kMaxPayloadBytes);
  skipper.set_skip_oversized(true);
  std::vector<std::pair<std::uint32_t, Bytes>> skip_got;
  rng_state = piece * 0x9E3779B9u + 0x7F4A7C15u;
  for (std::size_t pos = 0; pos < stream.size();) {
    std::size_t size = stream.size() - pos;
    if (piece != 0) size = std::min<std::size_t>(size, 1 + next_random(rng_state) % piece);
    skipper.append(stream.subspan(pos, size));
    pos += size;
    for (net::DecodedFrame frame = skipper.next();
         frame.status == net::DecodeStatus::good || frame.status == net::DecodeStatus::oversized;
         frame = skipper.next()) {
      OPTIQUE_FUZZ_REQUIRE(frame.status == net::DecodeStatus::good || frame.length > kMaxPayloadBytes);
      skip_got.emplace_back(frame.status == net::DecodeStatus::good ? 0 : frame.length,
                            Bytes(frame.payload.begin(), frame.payload.end()));
    }
    OPTIQUE_FUZZ_REQUIRE(skipper.buffered_bytes() <= kMaxPayloadBytes + net::kFrameHeaderBytes + size);
  }
  OPTIQUE_FUZZ_REQUIRE(skip_got == skip_expected);

  out.good_frames += static_cast<int>(got.size());
  for (const Bytes& payload : got) {
    auto envelope = net::parse_envelope(payload);
    if (!envelope.ok()) {
      OPTIQUE_FUZZ_REQUIRE(!envelope.error().empty());
      continue;
    }
    ++out.envelopes;
    if (auto broken = check_envelope(envelope.value()); !broken.empty()) return broken;
  }
  return {};
}

using util::finite;

bool same_bits(const glm::dvec3& a, const glm::dvec3& b) {
  return std::bit_cast<std::uint64_t>(a.x) == std::bit_cast<std::uint64_t>(b.x) &&
         std::bit_cast<std::uint64_t>(a.y) == std::bit_cast<std::uint64_t>(b.y) &&
         std::bit_cast<std::uint64_t>(a.z) == std::bit_cast<std::uint64_t>(b.z);
}

std::string check_pose(const scene::Pose& pose) {
  OPTIQUE_FUZZ_REQUIRE(finite(pose.position));
  OPTIQUE_FUZZ_REQUIRE(finite(pose.scale));
  OPTIQUE_FUZZ_REQUIRE(finite(pose.rotation));
  const glm::dquat& q = pose.rotation;
  OPTIQUE_FUZZ_REQUIRE(std::abs(std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z) - 1.0) <= 1e-6);
  return {};
}

// What every state that made it past from_snapshot or apply_delta must satisfy.
std::string check_state(const scene::SceneState& state) {
  for (const auto& [id, object] : state.objects) {
    if (auto broken = check_pose(object.now); !broken.empty()) return broken + " (object " + std::to_string(id) + ")";
    if (auto broken = check_pose(object.next); !broken.empty()) return broken + " (object " + std::to_string(id) + ")";
  }
  OPTIQUE_FUZZ_REQUIRE(finite(state.eye_now));
  OPTIQUE_FUZZ_REQUIRE(finite(state.eye_next));
  OPTIQUE_FUZZ_REQUIRE(state.point_lights.size() <= scene::kMaxAddedLights);
  for (const auto& [index, light] : state.point_lights) {
    OPTIQUE_FUZZ_REQUIRE(index < scene::kMaxLightIndex);
    OPTIQUE_FUZZ_REQUIRE(finite(light.position) && finite(light.colour) && std::isfinite(light.intensity));
  }

  const std::uint64_t hash = scene::state_hash(state);
  OPTIQUE_FUZZ_REQUIRE(scene::state_hash(state) == hash);
  const scene::SceneState copy = state;
  OPTIQUE_FUZZ_REQUIRE(scene::state_hash(copy) == hash);

  // Through a Snapshot, in memory and on the wire: what a joining node receives.
  const wire::Snapshot snapshot = scene::to_snapshot(state);
  auto back = scene::from_snapshot(snapshot);
  OPTIQUE_FUZZ_REQUIRE(back.ok());
  OPTIQUE_FUZZ_REQUIRE(back.value() == state);
  OPTIQUE_FUZZ_REQUIRE(scene::state_hash(back.value()) == hash);
  wire::Snapshot received;
  OPTIQUE_FUZZ_REQUIRE(received.ParseFromString(snapshot.SerializeAsString()));
  auto rebuilt = scene::from_snapshot(received);
  OPTIQUE_FUZZ_REQUIRE(rebuilt.ok());
  OPTIQUE_FUZZ_REQUIRE(rebuilt.value() == state);
  OPTIQUE_FUZZ_REQUIRE(scene::state_hash(rebuilt.value()) == hash);

  OPTIQUE_FUZZ_REQUIRE(scene::make_delta(state, state).ByteSizeLong() == 0);
  return {};
}

// After an accepted delta: it did what it said, and make_delta reproduces it.
std::string check_applied(const scene::SceneState& before, const scene::SceneState& after,
                          const wire::StateDelta& delta) {
  for (std::uint32_t id : delta.removed()) OPTIQUE_FUZZ_REQUIRE(!after.objects.contains(id));
  for (const auto& changed : delta.changed()) {
    bool removed = false;
    for (std::uint32_t id : delta.removed()) removed = removed || id == changed.id();
    OPTIQUE_FUZZ_REQUIRE(removed || after.objects.contains(changed.id()));
  }
  for (std::uint32_t light : delta.lights_off()) OPTIQUE_FUZZ_REQUIRE(after.lights_off.contains(light));
  for (std::uint32_t light : delta.lights_on()) OPTIQUE_FUZZ_REQUIRE(!after.lights_off.contains(light));
  for (const auto& light : delta.point_lights_set()) OPTIQUE_FUZZ_REQUIRE(after.point_lights.contains(light.light()));
  for (const auto& moved : delta.instances_moved()) {
    // Only its pose: everything else as it was.
    OPTIQUE_FUZZ_REQUIRE(before.instances.contains(moved.id()) && after.instances.contains(moved.id()));
    scene::InstanceState was = before.instances.at(moved.id());
    was.pose = after.instances.at(moved.id()).pose;
    OPTIQUE_FUZZ_REQUIRE(was == after.instances.at(moved.id()));
  }
  for (std::uint32_t light : delta.point_lights_removed()) OPTIQUE_FUZZ_REQUIRE(!after.point_lights.contains(light));
  if (!delta.has_viewer()) {
    OPTIQUE_FUZZ_REQUIRE(same_bits(after.eye_now, before.eye_now));
    OPTIQUE_FUZZ_REQUIRE(same_bits(after.eye_next, before.eye_next));
  }

  scene::SceneState replayed = before;
  auto replay = scene::apply_delta(replayed, scene::make_delta(before, after));
  OPTIQUE_FUZZ_REQUIRE(replay.ok());
  OPTIQUE_FUZZ_REQUIRE(replayed == after);
  OPTIQUE_FUZZ_REQUIRE(scene::state_hash(replayed) == scene::state_hash(after));
  return {};
}

std::vector<std::span<const std::uint8_t>> split_chunks(std::span<const std::uint8_t> input) {
  std::vector<std::span<const std::uint8_t>> chunks;
  const auto* begin = input.data();
  const auto* end = input.data() + input.size();
  const auto* separator = reinterpret_cast<const std::uint8_t*>(kChunkSeparator.data());
  for (;;) {
    const auto* at = std::search(begin, end, separator, separator + kChunkSeparator.size());
    chunks.emplace_back(begin, at);
    if (at == end) return chunks;
    begin = at + kChunkSeparator.size();
  }
}

std::string deltas(std::span<const std::uint8_t> input, Outcome& out) {
  const auto chunks = split_chunks(input);
  scene::SceneState state;
  wire::Snapshot snapshot;
  if (snapshot.ParseFromArray(chunks[0].data(), static_cast<int>(chunks[0].size()))) {
    auto accepted = scene::from_snapshot(snapshot);
    if (accepted.ok()) {
      out.snapshot_accepted = true;
      state = std::move(accepted).value();
    } else {
      OPTIQUE_FUZZ_REQUIRE(!accepted.error().empty());
    }
  }
  if (auto broken = check_state(state); !broken.empty()) return broken;

  // The instances' hash as a node keeps it, delta by delta (apply_delta with InstancesHash).
  scene::InstancesHash kept = scene::instances_hash(state);
  for (std::size_t i = 1; i < chunks.size(); ++i) {
    wire::StateDelta delta;
    if (!delta.ParseFromArray(chunks[i].data(), static_cast<int>(chunks[i].size()))) continue;
    const scene::SceneState before = state;
    const std::uint64_t before_hash = scene::state_hash(before);
    auto applied = scene::apply_delta(state, delta, kept);
    OPTIQUE_FUZZ_REQUIRE(kept == scene::instances_hash(state));
    if (!applied.ok()) {
      ++out.deltas_refused;
      OPTIQUE_FUZZ_REQUIRE(!applied.error().empty());
      OPTIQUE_FUZZ_REQUIRE(state == before);
      // operator== takes 0.0 for -0.0; the hash sees every bit.
      OPTIQUE_FUZZ_REQUIRE(scene::state_hash(state) == before_hash);
      continue;
    }
    ++out.deltas_applied;
    if (auto broken = check_state(state); !broken.empty()) return broken + " (after delta " + std::to_string(i) + ")";
    if (auto broken = check_applied(before, state, delta); !broken.empty()) {
      return broken + " (after delta " + std::to_string(i) + ")";
    }
  }
  return {};
}

std::string check_head(const tracking::HeadPose& pose) {
  OPTIQUE_FUZZ_REQUIRE(util::finite(pose.position));
  const glm::dquat& q = pose.orientation;
  const double norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  OPTIQUE_FUZZ_REQUIRE(std::abs(norm - 1.0) < 1e-6);
  return {};
}

std::string tracker(std::span<const std::uint8_t> input, Outcome& out) {
  const auto chunks = split_chunks(input);
  for (const config::HeadPrediction prediction :
       {config::HeadPrediction::none, config::HeadPrediction::constant_velocity,
        config::HeadPrediction::double_exponential}) {
    config::Tracking settings;
    settings.prediction = prediction;
    tracking::HeadTracker head(settings);
    tracking::Nanos now = 1'000'000'000;
    std::vector<std::string> said;
    for (const auto& chunk : chunks) {
      if (chunk.empty()) continue;
      now += static_cast<tracking::Nanos>(chunk[0]) * 100'000;
      const std::string_view datagram(reinterpret_cast<const char*>(chunk.data()) + 1, chunk.size() - 1);
      if (prediction == config::HeadPrediction::none) {
        auto parsed = tracking::parse_dtrack(datagram);
        if (parsed.ok()) {
          ++out.datagrams_parsed;
          for (const tracking::DTrackBody& body : parsed.value().bodies) {
            OPTIQUE_FUZZ_REQUIRE(util::finite(body.position));
            OPTIQUE_FUZZ_REQUIRE(std::abs(glm::determinant(body.rotation) - 1.0) < 0.01);
          }
        } else {
          OPTIQUE_FUZZ_REQUIRE(!parsed.error().empty());
        }
      }
      (void)head.datagram(datagram, now);
      head.notice(now, said);
      const tracking::HeadAt at = head.at(now + 16'666'666, glm::dvec3(0.0, 1.6, 2.0));
      if (auto broken = check_head(at.pose); !broken.empty()) return broken;
      const tracking::TrackingCounts& c = head.counts();
      OPTIQUE_FUZZ_REQUIRE(c.datagrams == c.samples + c.malformed + c.without_body + c.backwards + c.flood);
    }
    if (prediction == config::HeadPrediction::none) out.samples += static_cast<int>(head.counts().samples);
  }
  return {};
}

constexpr std::size_t kFuzzLights = 4;

// The live scene after any transactions: whole, and what the nodes accept.
std::string check_live(const master::LiveScene& live, const master::LiveSceneLimits& limits, std::uint64_t frame,
                       scene::SceneState& previous) {
  OPTIQUE_FUZZ_REQUIRE(live.instances().size() <= limits.max_instances);
  std::size_t listed = 0;
  for (const auto& [id, instance] : live.instances()) {
    OPTIQUE_FUZZ_REQUIRE(scene::is_instance_id(id));
    OPTIQUE_FUZZ_REQUIRE(live.children(instance.parent).contains(id));
    std::size_t depth = 0;
    for (std::string at = instance.parent; !at.empty();) {
      OPTIQUE_FUZZ_REQUIRE(live.instances().contains(at));
      OPTIQUE_FUZZ_REQUIRE(++depth <= limits.max_depth);
      at = live.instances().at(at).parent;
    }
    listed += live.children(id).size();
  }
  listed += live.children("").size();
  OPTIQUE_FUZZ_REQUIRE(listed == live.instances().size());
  scene::SceneState state;
  master::put_live(live, frame, state);
  // Only the scene's lights and those added are switched, and lights are added
  // only after the scene's; the navigation must pass the nodes' checks, which
  // apply_delta below makes.
  for (const auto& [light, on] : live.light_switches()) {
    OPTIQUE_FUZZ_REQUIRE(light < kFuzzLights || live.point_lights().contains(light));
  }
  OPTIQUE_FUZZ_REQUIRE(live.point_lights().size() <= limits.max_point_lights);
  for (const auto& [light, added] : live.point_lights()) {
    OPTIQUE_FUZZ_REQUIRE(light >= kFuzzLights && light < kFuzzLights + limits.max_point_lights);
  }
  if (auto broken = check_state(state); !broken.empty()) return broken;
  scene::SceneState node = previous;
  OPTIQUE_FUZZ_REQUIRE(scene::apply_delta(node, scene::make_delta(previous, state)).ok());
  OPTIQUE_FUZZ_REQUIRE(node == state);
  previous = std::move(state);
  return {};
}

std::string session(std::span<const std::uint8_t> input, Outcome& out) {
  master::LiveSceneLimits limits;
  limits.max_instances = 64;
  limits.max_edits_per_frame = 256;
  limits.max_depth = 8;
  master::LiveScene live(limits);
  live.add_asset("torus");
  live.add_asset("duck");
  live.set_light_count(kFuzzLights);
  master::SceneSessionSettings settings;
  settings.journal = true;
  master::SceneSessions sessions(live, settings);
  (void)sessions.accepted(1, "127.0.0.1:1", true, std::vector<std::uint8_t>(net::kNonceBytes, 1));
  wire::Envelope hello;
  hello.set_protocol_version(net::kProtocolVersion);
  hello.mutable_hello()->set_node_id("fuzz");
  hello.mutable_hello()->add_capabilities(master::kSceneSessionCapability);
  (void)sessions.message(1, hello, 0);
  scene::SceneState previous;
  std::uint64_t frame = 0;
  session::Subscribe subscribed;
  for (std::span<const std::uint8_t> chunk : split_chunks(input)) {
    if (chunk.size() == 1) {
      live.begin_frame();
      ++frame;
      continue;
    }
    wire::Envelope message;
    if (!chunk.empty() && chunk.front() == '{') {
      // JSON, as the operator's WebSocket takes it: a request, or one refusal
      // with id 0 that names why, and the session goes on.
      auto read =
          master::request_from_json(std::string_view(reinterpret_cast<const char*>(chunk.data()), chunk.size()));
      if (!read) {
        const master::SessionActions answer = sessions.unreadable(1, read.error());
        OPTIQUE_FUZZ_REQUIRE(answer.size() == 1);
        const auto& sent = std::get<master::session_action::Send>(answer[0]).message;
        OPTIQUE_FUZZ_REQUIRE(sent.session_reply().id() == 0 && !sent.session_reply().refused().reason().empty());
        continue;
      }
      message.set_protocol_version(net::kProtocolVersion);
      *message.mutable_session_request() = std::move(read).value();
    } else if (!message.ParseFromArray(chunk.data(), static_cast<int>(chunk.size()))) {
      continue;
    }
    ++out.envelopes;
    const std::map<std::string, master::Instance> before = live.instances();
    const master::SessionActions actions = sessions.message(1, message, frame);
    bool closed = false;
    int replies = 0;
    int journalled = 0;
    std::optional<master::session_action::LoadAsset> loading;
    for (const master::SessionAction& action : actions) {
      closed = closed || std::holds_alternative<master::session_action::Close>(action);
      if (const auto* load = std::get_if<master::session_action::LoadAsset>(&action)) {
        // An asset to load: a valid id, now taken, from one source; answered later.
        OPTIQUE_FUZZ_REQUIRE(message.session_request().has_load_asset() && !loading);
        OPTIQUE_FUZZ_REQUIRE(scene::is_instance_id(load->asset) && live.is_loading(load->asset));
        OPTIQUE_FUZZ_REQUIRE(load->path.empty() != load->glb.empty());
        OPTIQUE_FUZZ_REQUIRE(load->path.find("..") == std::string::npos);
        loading = *load;
        continue;
      }
      if (const auto* entry = std::get_if<master::session_action::Journal>(&action)) {
        // What is journalled reads back as the transaction, in this frame, before its reply.
        OPTIQUE_FUZZ_REQUIRE(replies == 0);
        auto read =
            master::read_journal(std::string(master::kJournalMagic) + master::journal_start(0, "torus") + entry->entry);
        OPTIQUE_FUZZ_REQUIRE(read.ok() && read.value().runs.size() == 1 && read.value().torn.empty());
        const auto& transactions = read.value().runs[0].transactions;
        OPTIQUE_FUZZ_REQUIRE(transactions.size() == 1 && transactions[0].frame() == frame);
        OPTIQUE_FUZZ_REQUIRE(transactions[0].transaction().SerializeAsString() ==
                             message.session_request().transaction().SerializeAsString());
        ++journalled;
        continue;
      }
      const auto* sent = std::get_if<master::session_action::Send>(&action);
      if (sent == nullptr || !sent->message.has_session_reply()) continue;
      ++replies;
      const session::Reply& reply = sent->message.session_reply();
      // Its JSON, as a WebSocket hears it, is one object naming a reply.
      const std::string json = master::to_application_json(sent->message);
      OPTIQUE_FUZZ_REQUIRE(json.rfind("{\"reply\":{", 0) == 0);
      OPTIQUE_FUZZ_REQUIRE(reply.id() == message.session_request().id());
      if (reply.has_scene()) {
        // The scene as it is: every instance, nothing changed by reading it.
        OPTIQUE_FUZZ_REQUIRE(message.session_request().has_read_scene());
        OPTIQUE_FUZZ_REQUIRE(reply.scene().frame() == frame);
        OPTIQUE_FUZZ_REQUIRE(static_cast<std::size_t>(reply.scene().instances_size()) == live.instances().size());
        OPTIQUE_FUZZ_REQUIRE(live.instances() == before);
        continue;
      }
      if (reply.has_subscribed()) {
        OPTIQUE_FUZZ_REQUIRE(message.session_request().has_subscribe());
        subscribed = reply.subscribed();
        continue;
      }
      if (reply.has_applied()) {
        OPTIQUE_FUZZ_REQUIRE(reply.applied().frame() == frame);
        OPTIQUE_FUZZ_REQUIRE(journalled == 1);
        ++out.applied;
      } else {
        OPTIQUE_FUZZ_REQUIRE(reply.has_refused());
        OPTIQUE_FUZZ_REQUIRE(live.instances() == before);  // nothing of a refused transaction stays
        ++out.refused;
      }
    }
    const bool request = message.has_session_request() && message.protocol_version() == net::kProtocolVersion;
    OPTIQUE_FUZZ_REQUIRE(replies + (loading ? 1 : 0) == (request ? 1 : 0));
    if (loading) {
      // The shell loaded it, or not (as the chunk's last byte says): the
      // application hears so, and only a usable asset is journalled, first.
      const bool usable = (chunk.back() & 1) != 0;
      const master::SessionActions answered =
          usable ? sessions.asset_loaded(loading->asset, frame, false, "/fuzz/" + loading->asset + ".glb", "sha")
                 : sessions.asset_failed(loading->asset, "load_asset", "fuzz");
      const auto* sent = answered.empty() ? nullptr : std::get_if<master::session_action::Send>(&answered.back());
      OPTIQUE_FUZZ_REQUIRE(sent != nullptr && sent->message.session_reply().id() == message.session_request().id());
      OPTIQUE_FUZZ_REQUIRE(sent->message.session_reply().has_applied() == usable);
      OPTIQUE_FUZZ_REQUIRE(!usable || std::holds_alternative<master::session_action::Journal>(answered.front()));
      OPTIQUE_FUZZ_REQUIRE(live.has_asset(loading->asset) == usable && !live.is_loading(loading->asset));
    }
    OPTIQUE_FUZZ_REQUIRE(request || closed || message.has_heartbeat());
    if (auto broken = check_live(live, limits, frame, previous); !broken.empty()) return broken;
    if (closed) break;
    // A frame event reaches the application only while it subscribes to frames.
    session::Event begun;
    begun.mutable_frame_begun()->set_frame(frame);
    OPTIQUE_FUZZ_REQUIRE(sessions.publish(begun).size() == (subscribed.frames() ? 1u : 0u));
  }
  return {};
}

}  // namespace

Outcome run_session(std::span<const std::uint8_t> input) {
  const QuietProtobuf quiet;
  Outcome out;
  out.broken = session(input, out);
  return out;
}

Outcome run_tracker(std::span<const std::uint8_t> input) {
  Outcome out;
  out.broken = tracker(input, out);
  return out;
}

Outcome run_frames(std::span<const std::uint8_t> input) {
  const QuietProtobuf quiet;
  Outcome out;
  out.broken = frames(input, out);
  return out;
}

Outcome run_deltas(std::span<const std::uint8_t> input) {
  const QuietProtobuf quiet;
  Outcome out;
  out.broken = deltas(input, out);
  return out;
}

}  // namespace optique::fuzz
