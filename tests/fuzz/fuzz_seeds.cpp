#include "fuzz_seeds.h"

#include <algorithm>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string_view>

#include "fuzz_bodies.h"
#include "master/run/run_config.h"
#include "net/envelope.h"
#include "net/framing.h"
#include "optique/session.pb.h"
#include "protocol/welcome.h"
#include "scene/manifest.h"
#include "scene/state.h"

namespace optique::fuzz {
namespace {

using Bytes = std::vector<std::uint8_t>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Fixed, so that regenerating the corpus gives the same files.
Bytes noise(std::size_t size, std::uint32_t state) {
  Bytes out(size);
  for (auto& b : out) {
    state = state * 1664525u + 1013904223u;
    b = static_cast<std::uint8_t>(state >> 24);
  }
  return out;
}

Bytes serialize(const google::protobuf::MessageLite& message) {
  const std::string s = message.SerializeAsString();
  return {s.begin(), s.end()};
}

// --- frames ---

wire::Envelope envelope(std::uint64_t sequence) {
  wire::Envelope e;
  e.set_protocol_version(net::kProtocolVersion);
  e.set_sequence(sequence);
  return e;
}

void set(wire::Vec3& v, double x, double y, double z) {
  v.set_x(x);
  v.set_y(y);
  v.set_z(z);
}

wire::ObjectState object(std::uint32_t id, double x, double y, double z) {
  wire::ObjectState o;
  o.set_id(id);
  for (wire::Pose* pose : {o.mutable_now(), o.mutable_next()}) {
    set(*pose->mutable_position(), x, y, z);
    pose->mutable_rotation()->set_w(1.0);
    set(*pose->mutable_scale(), 1.0, 1.0, 1.0);
  }
  o.mutable_next()->mutable_position()->set_x(x + 0.01);
  return o;
}

wire::StateDelta sample_delta() {
  wire::StateDelta d;
  *d.add_changed() = object(7, 1.25, 0.5, -2.0);
  *d.add_changed() = object(8, -1.0, 0.0, 0.0);
  d.add_removed(3);
  set(*d.mutable_viewer()->mutable_eye_now(), 0.0, 1.6, 2.0);
  set(*d.mutable_viewer()->mutable_eye_next(), 0.01, 1.6, 2.0);
  d.add_lights_off(4);
  d.add_lights_on(1);
  return d;
}

std::vector<std::pair<std::string, wire::Envelope>> one_of_each_body() {
  std::vector<std::pair<std::string, wire::Envelope>> out;
  std::uint64_t sequence = 0;
  auto add = [&](std::string name) -> wire::Envelope& {
    out.emplace_back(std::move(name), envelope(++sequence));
    return out.back().second;
  };
  {
    const Bytes nonce = noise(32, 1);
    add("challenge").mutable_challenge()->set_nonce(std::string(nonce.begin(), nonce.end()));
  }
  {
    auto& hello = *add("hello").mutable_hello();
    hello.set_node_id("wall-left");
    hello.add_capabilities("headless");
    hello.add_capabilities("window");
    const Bytes mac = noise(32, 2);
    hello.set_nonce_mac(std::string(mac.begin(), mac.end()));
  }
  {
    auto& welcome = *add("welcome").mutable_welcome();
    auto& projector = *welcome.mutable_projector();
    projector.set_id("left");
    projector.set_host("localhost");
    projector.set_width(320);
    projector.set_height(200);
    projector.set_screen("wall");
    for (double h : {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}) projector.add_homography(h);
    *welcome.add_blend_group() = projector;
    auto& screen = *welcome.mutable_screen();
    screen.set_id("wall");
    for (double v : {0.0, 0.0, 0.0}) screen.add_origin(v);
    for (double v : {1.0, 0.0, 0.0}) screen.add_right(v);
    for (double v : {0.0, 1.0, 0.0}) screen.add_up(v);
    screen.set_width(2.0);
    screen.set_height(1.25);
    for (double v : {0.0, 1.6, 2.0}) welcome.mutable_viewer()->add_eye(v);
    welcome.mutable_scene()->set_builtin("cubes");
    welcome.set_frame_period_ns(16'666'667);
    welcome.set_heartbeat_ms(250);
    welcome.set_liveness_timeout_ms(3000);
    welcome.set_scene_sha256(std::string(64, 'a'));
    welcome.mutable_depth_of_field()->set_focal_depth(2.5);
    welcome.mutable_lights()->add_lights(0);
    welcome.mutable_lights()->add_lights(2);
    welcome.mutable_lights()->set_ambient(true);
  }
  {
    auto& refuse = *add("refuse").mutable_refuse();
    refuse.set_reason("node id wall-left is already connected");
    refuse.set_retriable(true);
  }
  add("configured").mutable_configured()->set_renderer("llvmpipe (LLVM 15.0.6, 256 bits), headless");
  {
    auto& request = *add("scene_request").mutable_scene_request();
    request.set_scene_sha256(std::string(64, 'a'));
    request.set_file(1);
    request.set_chunk(3);
  }
  {
    auto& chunk = *add("scene_chunk").mutable_scene_chunk();
    chunk.set_file(1);
    chunk.set_chunk(3);
    chunk.set_data(std::string(300, '\x5a'));
  }
  {
    auto& resync = *add("resync").mutable_resync();
    auto& snapshot = *resync.mutable_snapshot();
    *snapshot.add_objects() = object(1, 0.0, 1.0, -0.5);
    *snapshot.add_objects() = object(3, 2.0, 0.0, 0.0);
    set(*snapshot.mutable_viewer()->mutable_eye_now(), 0.0, 1.6, 2.0);
    set(*snapshot.mutable_viewer()->mutable_eye_next(), 0.0, 1.6, 2.0);
    snapshot.add_lights_off(1);
    resync.set_next_frame_id(42);
    resync.set_state_hash(0x0123456789ABCDEFull);
  }
  {
    auto& begin = *add("frame_begin").mutable_frame_begin();
    begin.set_frame_id(42);
    begin.set_simulation_time_ns(700'000'014);
    begin.set_present_time_ns(-123'456'789);
    *begin.mutable_delta() = sample_delta();
    begin.set_state_hash(0xDEADBEEFCAFEF00Dull);
    begin.set_capture(true);
    begin.mutable_focus()->set_depth(1.5);
    begin.mutable_focus()->set_gaze_x(0.25);
    begin.mutable_focus()->set_gaze_y(-0.125);
    begin.mutable_lights()->add_lights(1);
  }
  {
    auto& ready = *add("frame_ready").mutable_frame_ready();
    ready.set_frame_id(42);
    ready.set_render_ns(3'000'000);
    ready.set_state_hash(0xDEADBEEFCAFEF00Dull);
  }
  {
    auto& swap = *add("swap").mutable_swap();
    swap.set_frame_id(42);
    swap.set_present_deadline_ns(716'666'681);
  }
  {
    auto& presented = *add("presented").mutable_presented();
    presented.set_frame_id(42);
    presented.set_presented_ns(716'700'000);
    presented.set_clock_offset_ns(-5'000);
    presented.set_clock_rtt_ns(120'000);
    presented.set_content_frame_id(41);
  }
  add("ping").mutable_ping()->set_t1(1'000);
  {
    auto& pong = *add("pong").mutable_pong();
    pong.set_t1(1'000);
    pong.set_t2(1'500);
    pong.set_t3(1'600);
  }
  add("heartbeat").mutable_heartbeat()->set_sent_ns(std::numeric_limits<std::int64_t>::max());
  add("goodbye").mutable_goodbye()->set_reason("master shutting down");
  return out;
}

Bytes framed(const wire::Envelope& e) {
  Bytes out;
  net::append_envelope(out, e);
  return out;
}

Bytes header(std::uint32_t length) {
  Bytes out(net::kFrameHeaderBytes);
  net::write_frame_header(out.data(), length);
  return out;
}

Bytes concat(std::initializer_list<Bytes> parts) {
  Bytes out;
  for (const Bytes& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

// Byte 0 of a frames input picks the fragmentation.
Seed frame_seed(std::string name, std::uint8_t piece, const Bytes& stream) {
  Bytes bytes{piece};
  bytes.insert(bytes.end(), stream.begin(), stream.end());
  return {std::move(name), std::move(bytes)};
}

// --- deltas ---

wire::Snapshot base_snapshot() {
  wire::Snapshot s;
  *s.add_objects() = object(1, 0.0, 1.0, -0.5);
  *s.add_objects() = object(2, 1.0, 1.2, -0.7);
  *s.add_objects() = object(5, -1.0, 0.3, 0.1);
  set(*s.mutable_viewer()->mutable_eye_now(), 0.0, 1.6, 2.0);
  set(*s.mutable_viewer()->mutable_eye_next(), 0.0, 1.6, 2.0);
  s.add_lights_off(2);
  s.add_lights_off(7);
  return s;
}

Bytes join(const std::vector<Bytes>& chunks) {
  Bytes out;
  const auto* separator = reinterpret_cast<const std::uint8_t*>(kChunkSeparator.data());
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    if (std::search(chunks[i].begin(), chunks[i].end(), separator, separator + kChunkSeparator.size()) !=
        chunks[i].end()) {
      throw std::logic_error("a seed chunk contains the chunk separator");
    }
    if (i > 0) out.insert(out.end(), separator, separator + kChunkSeparator.size());
    out.insert(out.end(), chunks[i].begin(), chunks[i].end());
  }
  return out;
}

// A delta seed: base snapshot (unless given), then the deltas.
Seed delta_seed(std::string name, const std::vector<wire::StateDelta>& deltas,
                const wire::Snapshot& snapshot = base_snapshot()) {
  std::vector<Bytes> chunks{serialize(snapshot)};
  for (const auto& d : deltas) chunks.push_back(serialize(d));
  return {std::move(name), join(chunks)};
}

wire::StateDelta change(const wire::ObjectState& o) {
  wire::StateDelta d;
  *d.add_changed() = o;
  return d;
}

wire::StateDelta lights(std::initializer_list<std::uint32_t> off, std::initializer_list<std::uint32_t> on) {
  wire::StateDelta d;
  for (auto l : off) d.add_lights_off(l);
  for (auto l : on) d.add_lights_on(l);
  return d;
}

wire::StateDelta remove(std::initializer_list<std::uint32_t> ids) {
  wire::StateDelta d;
  for (auto id : ids) d.add_removed(id);
  return d;
}

wire::ObjectState with_rotation(wire::ObjectState o, double w, double x, double y, double z) {
  auto& q = *o.mutable_now()->mutable_rotation();
  q.set_w(w);
  q.set_x(x);
  q.set_y(y);
  q.set_z(z);
  return o;
}

}  // namespace

std::vector<Seed> frame_seeds() {
  std::vector<Seed> seeds;
  const auto bodies = one_of_each_body();
  Bytes all;
  for (const auto& [name, e] : bodies) {
    const Bytes frame = framed(e);
    seeds.push_back(frame_seed(name, 0, frame));
    all.insert(all.end(), frame.begin(), frame.end());
  }
  seeds.push_back(frame_seed("all_bodies_whole", 0, all));
  seeds.push_back(frame_seed("all_bodies_bytewise", 1, all));
  seeds.push_back(frame_seed("all_bodies_pieces_of_7", 7, all));
  seeds.push_back(frame_seed("all_bodies_pieces_of_200", 200, all));

  const Bytes hello = framed(bodies[1].second);
  wire::Envelope ping_envelope = envelope(99);
  ping_envelope.mutable_ping()->set_t1(-1);
  const Bytes ping = framed(ping_envelope);
  seeds.push_back(frame_seed("empty_stream", 0, {}));
  seeds.push_back(frame_seed("truncated_header", 0, {0x00, 0x00}));
  seeds.push_back(frame_seed("header_only", 3, header(100)));
  seeds.push_back(frame_seed("truncated_payload", 3, concat({header(100), noise(50, 3)})));
  seeds.push_back(frame_seed("good_then_truncated", 5, concat({hello, Bytes(hello.begin(), hello.end() - 3)})));
  seeds.push_back(frame_seed("oversized_header", 0, concat({header(0xFFFFFFFFu), noise(16, 4)})));
  seeds.push_back(frame_seed("one_byte_over_max", 2, concat({header(kMaxPayloadBytes + 1), noise(16, 5)})));
  seeds.push_back(frame_seed("zero_length", 0, header(0)));
  seeds.push_back(frame_seed("good_bad_good", 1, concat({hello, header(0), ping})));
  seeds.push_back(frame_seed("garbage_payload", 0, concat({header(32), noise(32, 6)})));
  seeds.push_back(frame_seed("garbage_stream", 9, noise(64, 7)));
  {
    wire::Envelope no_body = envelope(5);
    seeds.push_back(frame_seed("no_body", 0, framed(no_body)));
  }
  {
    // A field from a newer protocol: kept as an unknown field, body still there.
    Bytes payload = serialize(bodies[1].second);
    payload.insert(payload.end(), {0x98, 0x06, 0x2A});  // field 99, varint 42
    seeds.push_back(
        frame_seed("unknown_field", 4, concat({header(static_cast<std::uint32_t>(payload.size())), payload})));
  }
  {
    wire::Envelope old = bodies[1].second;
    old.set_protocol_version(net::kProtocolVersion - 1);
    seeds.push_back(frame_seed("old_protocol_version", 0, framed(old)));
  }
  return seeds;
}

std::vector<Seed> delta_seeds() {
  std::vector<Seed> seeds;
  seeds.push_back({"empty", {}});
  seeds.push_back(delta_seed("snapshot_only", {}));
  {
    // Live instances: a snapshot with a group, a move (the packed pose, once
    // when still and twice when moving), a removal, and a pose of 9 numbers.
    scene::SceneState placed;
    placed.instances["table"].asset = "torus";
    placed.instances["cup"].asset = "torus";
    placed.instances["cup"].parent = "table";
    placed.instances["cup"].animation = scene::AnimationTimes{1.0, 1.0};
    scene::SceneState moved = placed;
    moved.instances["table"].pose.now.position = {1.0, 0.0, 0.5};
    moved.instances["table"].pose.next.position = {1.0, 0.0, 0.75};
    moved.instances["cup"].pose = {{{0.0, 0.5, 0.0}, {0.0, 0.0, 1.0, 0.0}, {2.0, 2.0, 2.0}},
                                   {{0.0, 0.5, 0.0}, {0.0, 0.0, 1.0, 0.0}, {2.0, 2.0, 2.0}}};
    scene::SceneState gone = moved;
    gone.instances.erase("cup");
    wire::StateDelta short_pose = scene::make_delta(gone, moved);
    short_pose.mutable_instances_changed(0)->mutable_pose()->RemoveLast();
    seeds.push_back(delta_seed("instances_move_and_remove",
                               {scene::make_delta(placed, moved), scene::make_delta(moved, gone), short_pose},
                               scene::to_snapshot(placed)));
    // Moves only (id and pose), the form a frame that moves things takes: in
    // order, reversed, twice, and of an instance that is not there.
    scene::SceneState shifted = placed;
    for (auto& [id, instance] : shifted.instances) instance.pose.now.position.y += 0.5;
    const wire::StateDelta moves = scene::make_delta(placed, shifted);
    wire::StateDelta reversed = moves;
    std::reverse(reversed.mutable_instances_moved()->begin(), reversed.mutable_instances_moved()->end());
    wire::StateDelta twice = moves;
    if (twice.instances_moved_size() > 0) *twice.add_instances_moved() = twice.instances_moved(0);
    wire::StateDelta ghost = moves;
    if (ghost.instances_moved_size() > 0) ghost.mutable_instances_moved(0)->set_id("ghost");
    seeds.push_back(delta_seed("instances_moved_only",
                               {moves, scene::make_delta(shifted, placed), reversed, twice, ghost},
                               scene::to_snapshot(placed)));
  }
  {
    wire::StateDelta d = change(object(1, 0.5, 1.0, -0.5));
    *d.add_changed() = object(9, 3.0, 0.0, 0.0);
    d.add_removed(5);
    set(*d.mutable_viewer()->mutable_eye_now(), 0.0, 1.6, 2.0);
    set(*d.mutable_viewer()->mutable_eye_next(), 0.05, 1.6, 2.0);
    seeds.push_back(delta_seed("move_add_remove_view", {d}));
  }
  {
    wire::StateDelta d;
    set(*d.mutable_viewer()->mutable_eye_now(), 0.0, 1.6, 2.0);
    set(*d.mutable_viewer()->mutable_eye_next(), 0.0, 1.6, 2.0);
    for (wire::Pose* pose :
         {d.mutable_viewer()->mutable_navigation_now(), d.mutable_viewer()->mutable_navigation_next()}) {
      set(*pose->mutable_position(), 10.0, 0.0, -4.0);
      set(*pose->mutable_scale(), 2.0, 2.0, 2.0);
    }
    wire::StateDelta stretched = d;
    set(*stretched.mutable_viewer()->mutable_navigation_next()->mutable_scale(), 2.0, 1.0, 2.0);
    wire::StateDelta half = d;
    half.mutable_viewer()->clear_navigation_next();
    seeds.push_back(delta_seed("navigation", {d, stretched, half}));
  }
  {
    // Point lights added, moved, switched and removed; and what a node refuses.
    const auto point = [](std::uint32_t index, double x, double intensity) {
      wire::StateDelta d;
      auto& l = *d.add_point_lights_set();
      l.set_light(index);
      for (double v : {x, 1.5, 0.5}) l.add_position(v);
      for (double v : {1.0, 0.5, 0.25}) l.add_colour(v);
      l.set_intensity(intensity);
      return d;
    };
    wire::StateDelta removed;
    removed.add_point_lights_removed(21);
    wire::StateDelta both = point(20, 0.0, 1.0);
    both.add_point_lights_removed(20);
    seeds.push_back(delta_seed("point_lights", {point(20, 0.0, 1.0), point(21, 1.0, 2.0), lights({21}, {}),
                                                point(20, -1.0, 0.5), removed, point(22, 0.0, -1.0), both}));
  }
  seeds.push_back(delta_seed("lights_off_then_on", {lights({3}, {}), lights({}, {2}), lights({}, {3, 7})}));
  seeds.push_back(delta_seed("light_off_twice", {lights({2}, {})}));
  seeds.push_back(delta_seed("light_on_not_off", {lights({}, {4})}));
  seeds.push_back(delta_seed("light_off_and_on_in_one_delta", {lights({4}, {4})}));
  seeds.push_back(delta_seed("light_on_and_off_in_one_delta", {lights({2}, {2})}));
  seeds.push_back(delta_seed("same_light_off_twice_in_one_delta", {lights({4, 4}, {})}));
  seeds.push_back(delta_seed("all_lights_on", {lights({}, {2, 7}), lights({0, 1, 0xFFFFFFFFu}, {})}));
  {
    wire::ObjectState o = object(1, kNaN, 0.0, 0.0);
    seeds.push_back(delta_seed("nan_position", {change(o), change(object(1, 0.0, 0.0, 0.0))}));
  }
  {
    wire::ObjectState o = object(2, 0.0, 0.0, 0.0);
    o.mutable_next()->mutable_scale()->set_y(kInf);
    seeds.push_back(delta_seed("inf_scale", {change(o)}));
  }
  {
    wire::StateDelta d;
    set(*d.mutable_viewer()->mutable_eye_now(), 0.0, -kInf, 0.0);
    set(*d.mutable_viewer()->mutable_eye_next(), kNaN, 0.0, 0.0);
    seeds.push_back(delta_seed("nan_eye", {d}));
  }
  seeds.push_back(delta_seed("non_unit_quaternion", {change(with_rotation(object(1, 0, 0, 0), 2.0, 0.0, 0.0, 0.0))}));
  seeds.push_back(delta_seed("zero_quaternion", {change(with_rotation(object(1, 0, 0, 0), 0.0, 0.0, 0.0, 0.0))}));
  seeds.push_back(delta_seed("nan_quaternion", {change(with_rotation(object(1, 0, 0, 0), kNaN, 0.0, 0.0, 0.0))}));
  seeds.push_back(
      delta_seed("almost_unit_quaternion", {change(with_rotation(object(1, 0, 0, 0), 1.0 + 5e-7, 0, 0, 0)),
                                            change(with_rotation(object(1, 0, 0, 0), 1.0 + 2e-6, 0, 0, 0))}));
  seeds.push_back(delta_seed("rotated_quaternion", {change(with_rotation(object(1, 0, 0, 0), 0.5, 0.5, -0.5, 0.5)),
                                                    change(with_rotation(object(2, 0, 0, 0), 0.0, 0.0, 0.0, -1.0))}));
  seeds.push_back(delta_seed("remove_unknown_id", {remove({42}), remove({1, 42}), remove({1})}));
  seeds.push_back(delta_seed("remove_twice", {remove({5, 5}), remove({5})}));
  {
    wire::StateDelta d = change(object(1, 4.0, 4.0, 4.0));
    d.add_removed(1);
    seeds.push_back(delta_seed("change_and_remove_same_id", {d}));
  }
  {
    wire::StateDelta d = change(object(3, 1.0, 0.0, 0.0));
    *d.add_changed() = object(3, 2.0, 0.0, 0.0);
    seeds.push_back(delta_seed("same_id_changed_twice", {d}));
  }
  seeds.push_back(delta_seed("negative_zero", {change(object(1, -0.0, 0.0, -0.0)), change(object(1, 0.0, 0.0, 0.0))}));
  seeds.push_back(delta_seed("extreme_values", {change(object(1, 1e308, -1e308, 4.9e-324)),
                                                change(object(1, std::numeric_limits<double>::max(), 0.0, 0.0))}));
  {
    wire::ObjectState bare;
    bare.set_id(11);
    seeds.push_back(delta_seed("no_rotation_no_scale", {change(bare)}));
  }
  {
    const Bytes noise_chunk = noise(24, 8);
    std::vector<Bytes> chunks{serialize(base_snapshot()), serialize(lights({5}, {})), noise_chunk,
                              serialize(lights({}, {5}))};
    seeds.push_back({"garbage_between_deltas", join(chunks)});
  }
  seeds.push_back({"empty_deltas", join({serialize(base_snapshot()), {}, {}, {}})});
  {
    std::vector<wire::StateDelta> frames;
    for (int i = 0; i < 10; ++i) {
      wire::StateDelta d = change(object(1, 0.1 * i, 1.0, -0.5));
      if (i % 3 == 0) d.add_lights_off(10 + static_cast<std::uint32_t>(i));
      if (i % 3 == 1 && i > 1) d.add_lights_on(10 + static_cast<std::uint32_t>(i) - 4);
      frames.push_back(d);
    }
    seeds.push_back(delta_seed("ten_frames", frames));
  }
  {
    wire::Snapshot twice = base_snapshot();
    *twice.add_objects() = object(1, 9.0, 9.0, 9.0);
    seeds.push_back(delta_seed("snapshot_object_twice", {lights({1}, {})}, twice));
  }
  {
    wire::Snapshot twice = base_snapshot();
    twice.add_lights_off(2);
    seeds.push_back(delta_seed("snapshot_light_twice", {lights({1}, {})}, twice));
  }
  {
    wire::Snapshot nan = base_snapshot();
    nan.mutable_viewer()->mutable_eye_next()->set_z(kNaN);
    seeds.push_back(delta_seed("snapshot_nan_eye", {remove({1})}, nan));
  }
  seeds.push_back(delta_seed("empty_snapshot", {change(object(4, 1.0, 2.0, 3.0)), remove({4})}, wire::Snapshot{}));
  return seeds;
}

// --- the protocol cores ---

namespace {

// A prompt network, byte by byte: deliver what is there (7), now and then a timer (5).
Bytes prompt_steps(std::size_t rounds) {
  Bytes steps;
  for (std::size_t i = 0; i < rounds; ++i) {
    for (int k = 0; k < 6; ++k) steps.push_back(7);
    steps.push_back(5);
  }
  return steps;
}

Bytes with_header(std::uint8_t frames, std::uint8_t corrupt, const Bytes& steps) {
  Bytes out{frames, corrupt};
  out.insert(out.end(), steps.begin(), steps.end());
  return out;
}

// The step that does `kind` (see SimCluster::step) to node `node` of four.
std::uint8_t step_for(int kind, int node) { return static_cast<std::uint8_t>(kind + 8 * node); }

void join_chunks(Bytes& out, const Bytes& chunk) {
  if (!out.empty()) out.insert(out.end(), kChunkSeparator.begin(), kChunkSeparator.end());
  out.insert(out.end(), chunk.begin(), chunk.end());
}

wire::Welcome wall_welcome() {
  auto run = master::load_run_config(std::string(OPTIQUE_SOURCE_DIR) + "/configs/powerwall-2x2.json", {});
  if (!run) throw std::runtime_error(run.error());
  return protocol::encode_welcome(run.value().config.installation, 0, {}, 4, 16'666'666, nullptr);
}

Bytes frame_and_swap(std::uint64_t frame, const std::function<void(wire::FrameBegin&)>& change = {}) {
  wire::Envelope begin = envelope(frame * 2 + 1);
  begin.mutable_frame_begin()->set_frame_id(frame);
  begin.mutable_frame_begin()->set_state_hash(scene::state_hash(scene::SceneState{}));
  if (change) change(*begin.mutable_frame_begin());
  wire::Envelope swap = envelope(frame * 2 + 2);
  swap.mutable_swap()->set_frame_id(frame);
  Bytes out = serialize(begin);
  join_chunks(out, serialize(swap));
  return out;
}

Bytes node_seed(const wire::Welcome& welcome, const std::vector<Bytes>& messages) {
  Bytes out = serialize(welcome);
  for (const Bytes& m : messages) {
    out.insert(out.end(), kChunkSeparator.begin(), kChunkSeparator.end());
    out.insert(out.end(), m.begin(), m.end());
  }
  return out;
}

}  // namespace

std::vector<Seed> protocol_seeds() {
  std::vector<Seed> seeds;
  seeds.push_back({"prompt_ten_frames", with_header(5, 0, prompt_steps(200))});
  seeds.push_back({"corrupt_at_frame_three", with_header(10, 3, prompt_steps(300))});
  {
    Bytes steps = prompt_steps(150);
    steps.push_back(static_cast<std::uint8_t>(246));  // reset node 2's link
    const Bytes more = prompt_steps(300);
    steps.insert(steps.end(), more.begin(), more.end());
    seeds.push_back({"link_reset_midway", with_header(25, 0, steps)});
  }
  {
    Bytes steps = prompt_steps(100);
    steps.push_back(255);  // interrupt the master
    const Bytes more = prompt_steps(100);
    steps.insert(steps.end(), more.begin(), more.end());
    seeds.push_back({"interrupted", with_header(39, 0, steps)});
  }
  {
    // Everyone but node 3 hears from the master; timers run the barrier out.
    Bytes steps = prompt_steps(60);
    for (int round = 0; round < 200; ++round) {
      for (int node = 0; node < 3; ++node) {
        steps.push_back(step_for(0, node));
        steps.push_back(step_for(3, node));
      }
      steps.push_back(step_for(5, 0));
    }
    seeds.push_back({"one_node_starved", with_header(20, 0, steps)});
  }
  {
    // Assets loaded while the frames go on, one before and one after a link reset.
    std::vector<std::uint8_t> steps = prompt_steps(80);
    steps.push_back(247);
    const auto more = prompt_steps(80);
    steps.insert(steps.end(), more.begin(), more.end());
    steps.push_back(246);  // reset node 2's link
    steps.push_back(247);
    steps.insert(steps.end(), more.begin(), more.end());
    seeds.push_back({"assets_loaded", with_header(30, 0, steps)});
  }
  {
    // An application's edits at any moment (in a round or between), one node's link reset among them.
    std::vector<std::uint8_t> steps;
    for (int k = 0; k < 40; ++k) {
      const auto some = prompt_steps(7 + k % 5);
      steps.insert(steps.end(), some.begin(), some.end());
      steps.push_back(k % 2 == 0 ? 239 : 231);
      if (k == 20) steps.push_back(246);  // reset node 2's link
    }
    seeds.push_back({"edits_staged", with_header(30, 0, steps)});
  }
  seeds.push_back({"noise", noise(600, 7)});
  return seeds;
}

std::vector<Seed> node_seeds() {
  std::vector<Seed> seeds;
  const wire::Welcome welcome = wall_welcome();
  seeds.push_back(
      {"welcome_and_three_frames", node_seed(welcome, {frame_and_swap(0), frame_and_swap(1), frame_and_swap(2)})});
  {
    wire::Welcome bad = welcome;
    bad.mutable_projector()->set_width(0);
    for (auto& member : *bad.mutable_blend_group()) member.set_width(0);
    seeds.push_back({"welcome_zero_width", node_seed(bad, {frame_and_swap(0)})});
  }
  {
    wire::Welcome bad = welcome;
    for (auto& member : *bad.mutable_blend_group()) {
      member.clear_region();
      for (int k = 0; k < 9; ++k) member.add_homography(k == 0 ? kNaN : 1.0);
    }
    seeds.push_back({"welcome_nan_homography", node_seed(bad, {frame_and_swap(0)})});
  }
  {
    wire::Welcome bad = welcome;
    bad.set_frame_period_ns(0);
    seeds.push_back({"welcome_no_frame_period", node_seed(bad, {})});
  }
  // Behind: frames to skip (a share of the lights with one of them), then one to draw.
  seeds.push_back(
      {"frames_skipped_while_behind",
       node_seed(welcome, {frame_and_swap(0),
                           frame_and_swap(1,
                                          [](wire::FrameBegin& b) {
                                            b.set_skip(true);
                                            b.mutable_lights()->add_lights(1);
                                          }),
                           frame_and_swap(2, [](wire::FrameBegin& b) { b.set_skip(true); }), frame_and_swap(3)})});
  seeds.push_back(
      {"frame_light_out_of_range",
       node_seed(welcome, {frame_and_swap(0, [](wire::FrameBegin& b) { b.mutable_lights()->add_lights(1000); })})});
  seeds.push_back(
      {"frame_nan_focus",
       node_seed(welcome, {frame_and_swap(0, [](wire::FrameBegin& b) { b.mutable_focus()->set_depth(kNaN); })})});
  seeds.push_back({"frame_good_focus_and_lights", node_seed(welcome, {frame_and_swap(0, [](wire::FrameBegin& b) {
                                                              b.mutable_focus()->set_depth(2.0);
                                                              b.mutable_lights()->add_lights(1);
                                                              b.mutable_lights()->add_lights(3);
                                                            })})});
  seeds.push_back({"not_a_welcome", node_seed(wire::Welcome{}, {noise(40, 3), frame_and_swap(0)})});
  {
    // A glTF scene of two files (the second two 4 KiB chunks): fetched with one
    // chunk spoilt on the way and asked for again, then frames.
    const std::string gltf = R"({"asset":{"version":"2.0"}})";
    std::string bin(5000, '\0');
    for (std::size_t i = 0; i < bin.size(); ++i) bin[i] = static_cast<char>(i * 13);
    const scene::SceneManifest files{
        4096, {scene::describe_file("s.gltf", gltf, 4096), scene::describe_file("s.bin", bin, 4096)}};
    wire::Welcome with_files = welcome;
    with_files.set_scene_sha256(scene::manifest_sha256(files));
    *with_files.mutable_scene_files() = protocol::to_wire(files);
    std::uint64_t sequence = 100;
    const auto chunk = [&](std::uint32_t file, std::uint64_t index, std::string data) {
      wire::Envelope e = envelope(sequence++);
      e.mutable_scene_chunk()->set_file(file);
      e.mutable_scene_chunk()->set_chunk(index);
      e.mutable_scene_chunk()->set_data(std::move(data));
      return serialize(e);
    };
    std::string spoilt = bin.substr(0, 4096);
    spoilt[100] = static_cast<char>(spoilt[100] ^ 1);
    seeds.push_back({"scene_fetched_with_a_spoilt_chunk",
                     node_seed(with_files, {chunk(0, 0, gltf), chunk(1, 0, spoilt), chunk(1, 1, bin.substr(4096)),
                                            chunk(1, 0, bin.substr(0, 4096)), frame_and_swap(0), frame_and_swap(1)})});
    seeds.push_back({"scene_chunk_not_asked_for", node_seed(with_files, {chunk(1, 7, "x"), frame_and_swap(0)})});
    // The same files as an asset an application loaded, offered in the
    // frames and fetched beside them; then an offer that is not one.
    const auto offer = [&](const std::string& id, const std::string& sha256) {
      wire::Envelope e = envelope(sequence++);
      *e.mutable_asset_offer() = protocol::to_wire(protocol::AssetOffer{id, sha256, files, ""});
      return serialize(e);
    };
    const std::string sha256 = scene::manifest_sha256(files);
    seeds.push_back({"asset_offered_in_the_frames",
                     node_seed(welcome, {frame_and_swap(0), offer("duck", sha256), chunk(0, 0, gltf), frame_and_swap(1),
                                         chunk(1, 0, bin.substr(0, 4096)), chunk(1, 1, bin.substr(4096)),
                                         frame_and_swap(2), offer("goose", std::string(64, 'f')), frame_and_swap(3)})});
  }
  return seeds;
}

namespace {

// A tracker datagram after `gap_tenths` tenths of a millisecond.
Bytes datagram(std::uint8_t gap_tenths, const std::string& text) {
  Bytes out;
  out.reserve(text.size() + 1);
  out.push_back(gap_tenths);
  for (const char c : text) out.push_back(static_cast<std::uint8_t>(c));
  return out;
}

// Body 0 at x millimetres, turned `quarter` quarter turns about z, DTrack 2's way.
std::string frame_text(unsigned long long frame, double x, int quarter = 0) {
  static const char* const kTurns[] = {"1 0 0 0 1 0 0 0 1", "0 1 0 -1 0 0 0 0 1", "-1 0 0 0 -1 0 0 0 1",
                                       "0 -1 0 1 0 0 0 0 1"};
  return "fr " + std::to_string(frame) + "\r\nts2 1700000000 " + std::to_string(frame * 16667 % 1000000) +
         " 18000\r\n6dcal 1\r\n6d 1 [0 1.000][" + std::to_string(x) + " 1600.0 2000.0][" + kTurns[quarter & 3] +
         "]\r\n";
}

}  // namespace

std::vector<Seed> tracker_seeds() {
  std::vector<Seed> seeds;
  {
    std::vector<Bytes> walk;
    for (int i = 0; i < 12; ++i) walk.push_back(datagram(167, frame_text(100 + i, 10.0 * i, i / 3)));
    seeds.push_back({"walk", join(walk)});
  }
  seeds.push_back({"dtrack1_angles", join({datagram(167,
                                                    "fr 7\nts 39596.024831\n6d 1 [0 1.0][1 2 3 -160.4 -3.7 "
                                                    "-7.1][1 0 0 0 1 0 0 0 1]\n")})});
  seeds.push_back({"two_bodies_other_lines",
                   join({datagram(100,
                                  "fr 1\n6d 2 [3 0.5][0 0 0][1 0 0 0 1 0 0 0 1] [0 1][5 6 7][0 1 0 -1 0 0 0 0 "
                                  "1]\n6df 1 [0 1.000 0][1 2 3][1 0 0 0 1 0 0 0 1]\n3d 1 [7 1.0][1 2 3]\n")})});
  seeds.push_back({"garbage_nan_mirror",
                   join({datagram(50, "\x7f\x45\x4c\x46 elf"), datagram(50, "6d 1 [0 1][nan 0 0][1 0 0 0 1 0 0 0 1]"),
                         datagram(50, "6d 1 [0 1][0 0 0][-1 0 0 0 1 0 0 0 1]"), datagram(50, frame_text(1, 0.0))})});
  seeds.push_back(
      {"backwards_and_restart", join({datagram(167, frame_text(5000, 0.0)), datagram(167, frame_text(4999, 1.0)),
                                      datagram(167, frame_text(3, 2.0)), datagram(167, frame_text(4, 3.0))})});
  {
    std::vector<Bytes> flood{datagram(167, frame_text(1, 0.0))};
    for (int i = 0; i < 20; ++i) flood.push_back(datagram(1, frame_text(2 + i, 1.0 * i)));
    seeds.push_back({"flood", join(flood)});
  }
  seeds.push_back({"lost_and_back", join({datagram(167, frame_text(1, 0.0)), datagram(167, frame_text(2, 5.0)),
                                          datagram(255, "fr 3\n6d 0\n"), datagram(255, "fr 4\n6d 0\n"),
                                          datagram(255, "fr 5\n6d 0\n"), datagram(167, frame_text(6, 9.0))})});
  seeds.push_back({"stamps_too_close_far_apart",
                   join({datagram(100, "fr 1\nts2 0 0 0\n6d 1 [0 1][-99000 0 0][1 0 0 0 1 0 0 0 1]"),
                         datagram(5, "fr 2\nts2 0 0 499\n6d 1 [0 1][99000 0 0][1 0 0 0 1 0 0 0 1]"),
                         datagram(200, "fr 3\nts2 0 0 0\n6d 1 [0 1][99000 0 0][0 1 0 -1 0 0 0 0 1]")})});
  const std::string flysticks =
      "6df2 2 2 [0 1.000 6 2][100 200 300][1 0 0 0 1 0 0 0 1][5 0.5 -1.0] "
      "[1 -1.000 40 1][0 0 0][0 0 0 0 0 0 0 0 0][2147483649 2 0.25]\n";
  seeds.push_back({"flystick", join({datagram(167, frame_text(1, 0.0) + flysticks)})});
  seeds.push_back({"empty", {}});
  return seeds;
}

namespace {

// A scene session's request: one transaction of `edits` (text format of
// session.Edit, one per entry).
Bytes request(std::uint64_t id, const std::vector<std::function<void(session::Edit&)>>& edits) {
  wire::Envelope e;
  e.set_protocol_version(net::kProtocolVersion);
  e.mutable_session_request()->set_id(id);
  auto& transaction = *e.mutable_session_request()->mutable_transaction();
  for (const auto& edit : edits) edit(*transaction.add_edits());
  return serialize(e);
}

std::function<void(session::Edit&)> create(const std::string& id, const std::string& asset,
                                           const std::string& parent = "", double x = 0.0) {
  return [=](session::Edit& e) {
    auto& c = *e.mutable_create();
    c.set_instance(id);
    c.set_asset(asset);
    c.set_parent(parent);
    c.mutable_transform()->add_position(x);
    c.mutable_transform()->add_position(1.0);
    c.mutable_transform()->add_position(-x);
  };
}

std::function<void(session::Edit&)> move(const std::string& id, std::vector<double> position,
                                         std::vector<double> rotation = {}, std::vector<double> scale = {}) {
  return [=](session::Edit& e) {
    auto& t = *e.mutable_transform();
    t.set_instance(id);
    for (double v : position) t.mutable_transform()->add_position(v);
    for (double v : rotation) t.mutable_transform()->add_rotation(v);
    for (double v : scale) t.mutable_transform()->add_scale(v);
  };
}

std::function<void(session::Edit&)> reparent(const std::string& id, const std::string& parent) {
  return [=](session::Edit& e) {
    e.mutable_parent()->set_instance(id);
    e.mutable_parent()->set_parent(parent);
  };
}

std::function<void(session::Edit&)> remove(const std::string& id) {
  return [=](session::Edit& e) { e.mutable_remove()->set_instance(id); };
}

const Bytes kNextFrame{0};

Bytes subscribe(std::uint64_t id, bool frames) {
  wire::Envelope e;
  e.set_protocol_version(net::kProtocolVersion);
  e.mutable_session_request()->set_id(id);
  e.mutable_session_request()->mutable_subscribe()->set_frames(frames);
  e.mutable_session_request()->mutable_subscribe()->set_nodes(true);
  return serialize(e);
}

Bytes load_asset(std::uint64_t id, const std::string& asset, const std::string& path, const std::string& glb) {
  wire::Envelope e;
  e.set_protocol_version(net::kProtocolVersion);
  e.mutable_session_request()->set_id(id);
  auto& load = *e.mutable_session_request()->mutable_load_asset();
  load.set_asset(asset);
  if (!path.empty()) load.set_path(path);
  if (!glb.empty()) load.set_glb(glb);
  return serialize(e);
}

Bytes read_scene(std::uint64_t id) {
  wire::Envelope e;
  e.set_protocol_version(net::kProtocolVersion);
  e.mutable_session_request()->set_id(id);
  e.mutable_session_request()->mutable_read_scene();
  return serialize(e);
}

}  // namespace

std::vector<Seed> session_seeds() {
  std::vector<Seed> seeds;
  // Assets loaded from a path and uploaded, each answered usable or not by
  // the fuzz's shell; instances of them; and loads refused.
  seeds.push_back({"load_assets", join({load_asset(1, "duck", "models/duck.gltf", ""), kNextFrame,
                                        load_asset(2, "goose", "", "glTF" + std::string(20, '\2')), kNextFrame,
                                        request(3, {create("d1", "duck"), create("g1", "goose", "d1")}),
                                        load_asset(4, "a b", "x.gltf", ""), load_asset(5, "up", "../x.gltf", ""),
                                        load_asset(6, "junk", "", "not a glb at all"), load_asset(7, "none", "", ""),
                                        read_scene(8)})});
  seeds.push_back({"place_move_remove",
                   join({request(1, {create("table", "torus"), create("cup", "duck", "table", 0.5)}), kNextFrame,
                         request(2, {move("table", {1, 0, 0}, {0, 0, 1, 0}, {2}),
                                     [](session::Edit& e) {
                                       e.mutable_visible()->set_instance("cup");
                                       e.mutable_visible()->set_visible(false);
                                     },
                                     [](session::Edit& e) {
                                       e.mutable_factors()->set_instance("table");
                                       for (double v : {1.0, 0.5, 0.25, 1.0}) e.mutable_factors()->add_base_color(v);
                                       for (double v : {2.0, 0.0, 0.0}) e.mutable_factors()->add_emissive(v);
                                     }}),
                         kNextFrame, request(3, {remove("table")}), request(4, {create("table", "duck")})})});
  seeds.push_back({"read_the_scene", join({request(1, {create("table", "torus"), create("cup", "torus", "table", 0.5)}),
                                           read_scene(2), kNextFrame, request(3, {remove("cup")}), read_scene(4)})});
  seeds.push_back(
      {"navigate_and_switch", join({request(1, {[](session::Edit& e) {
                                                  auto& t = *e.mutable_navigation()->mutable_transform();
                                                  for (double v : {0.0, 0.0, -10.0}) t.add_position(v);
                                                  t.add_scale(2.0);
                                                },
                                                [](session::Edit& e) {
                                                  e.mutable_light()->set_light(1);
                                                  e.mutable_light()->set_on(false);
                                                }}),
                                    kNextFrame,
                                    request(2, {[](session::Edit& e) {
                                                  for (double v : {1.0, 2.0, 1.0}) {
                                                    e.mutable_navigation()->mutable_transform()->add_scale(v);
                                                  }
                                                },
                                                [](session::Edit& e) { e.mutable_light()->set_light(99); }}),
                                    read_scene(3)})});
  seeds.push_back({"subscribe", join({subscribe(1, true), kNextFrame, request(2, {create("a", "torus")}), kNextFrame,
                                      subscribe(3, false), kNextFrame})});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  seeds.push_back({"refusals", join({request(1, {create("a", "torus"), create("b", "teapot")}),
                                     request(2, {create("a", "torus"), move("a", {0, nan, 0})}),
                                     request(3, {create("a", "torus"), move("a", {0, 0, 0}, {0, 0, 0, 0})}),
                                     request(4, {create("a", "torus"), move("a", {0, 0, 0}, {}, {0})}),
                                     request(5, {create("a", "torus"), create("b", "torus", "a"), reparent("a", "b")}),
                                     request(6, {remove("ghost")}), request(7, {[](session::Edit&) {}}),
                                     request(8, {create("a b", "torus")}), request(9, {})})});
  {
    std::vector<std::function<void(session::Edit&)>> chain;
    for (int i = 0; i < 10; ++i)
      chain.push_back(create("c" + std::to_string(i), "torus", i ? "c" + std::to_string(i - 1) : ""));
    std::vector<std::function<void(session::Edit&)>> shallow(chain.begin(), chain.begin() + 5);
    seeds.push_back(
        {"deep_chain",
         join({request(1, chain), request(2, shallow), kNextFrame,
               request(3, {create("x", "torus", "c4"), reparent("c1", "c4")}), request(4, {reparent("c3", "")}),
               // d0 … d4 moved under c4: d4 would be 9 deep.
               request(5, {create("d0", "duck"), create("d1", "duck", "d0"), create("d2", "duck", "d1"),
                           create("d3", "duck", "d2"), create("d4", "duck", "d3")}),
               request(6, {reparent("c3", "c2"), reparent("d0", "c4")})})});
  }
  {
    std::vector<Bytes> chunks;
    for (int i = 0; i < 70; ++i) {
      chunks.push_back(request(static_cast<std::uint64_t>(i), {create("i" + std::to_string(i), "torus")}));
      if (i % 20 == 19) chunks.push_back(kNextFrame);
    }
    std::vector<std::function<void(session::Edit&)>> many;
    for (int i = 0; i < 300; ++i) many.push_back(move("i0", {static_cast<double>(i), 0, 0}));
    chunks.push_back(request(100, many));
    seeds.push_back({"limits", join(chunks)});
  }
  {
    wire::Envelope ready;
    ready.set_protocol_version(net::kProtocolVersion);
    ready.mutable_frame_ready()->set_frame_id(3);
    seeds.push_back({"noise_then_a_node_message", join({noise(40, 7), request(1, {create("a", "torus")}),
                                                        serialize(ready), request(2, {create("b", "torus")})})});
  }
  {
    const auto lamp = [](std::uint32_t light, std::vector<double> position) {
      return [=](session::Edit& e) {
        e.mutable_point_light()->set_light(light);
        e.mutable_point_light()->mutable_position()->Add(position.begin(), position.end());
      };
    };
    seeds.push_back(
        {"point_lights",
         join({request(1, {lamp(4, {0, 2, 1}), lamp(5, {1, 2, 1})}),
               request(2, {[](session::Edit& e) {
                             e.mutable_light()->set_light(5);
                             e.mutable_light()->set_on(false);
                           },
                           lamp(4, {0, 2.5, 1})}),
               kNextFrame, request(3, {[](session::Edit& e) { e.mutable_remove_point_light()->set_light(5); }}),
               request(4, {lamp(2, {0, 0, 0})}), request(5, {lamp(70, {0, 0, 0})}),
               request(6, {[](session::Edit& e) {
                         e.mutable_point_light()->set_light(6);
                         e.mutable_point_light()->set_intensity(-1);
                       }})})});
  }
  // As JSON, from the operator's WebSocket: well formed, and not; and an empty
  // chunk, which is neither JSON nor a frame, last (it once read past the input's end).
  const auto json = [](std::string_view text) { return Bytes(text.begin(), text.end()); };
  seeds.push_back(
      {"json", join({json(R"({"id": 1, "transaction": {"edits": [{"create": {"instance": "a", "asset": "torus",
                        "transform": {"position": [1, 2, 3], "rotation": [1, 0, 0, 0], "scale": [2]}}}]}})"),
                     json(R"({"id": "2", "readScene": {}})"), kNextFrame,
                     json(R"({"id": 3, "subscribe": {"frames": true, "head": true}})"),
                     json(R"({"id": 4, "transaction": {"edits": [{"factors": {"instance": "a",
                        "base_color": [1, 0.5, "NaN", 1]}}]}})"),
                     json(R"({"id": 5, "transaction": {"edits": [{"remove": {"instance": "a"}}, {"light":
                        {"light": 1, "on": false}}]}})"),
                     json(R"({"id": 55, "transaction": {"edits": [{"create": {"instance": "b", "asset": "duck"}},
                        {"animation": {"instance": "b", "playing": false, "seek": 2.5}}]}})"),
                     kNextFrame, json(R"({"id": 56, "transaction": {"edits": [{"animation": {"instance": "b",
                        "playing": true}}]}})"),
                     json(R"({"id": 58, "transaction": {"edits": [{"pointLight": {"light": 4, "position": [0, 2, 1],
                        "colour": [1, 0.5, 0], "intensity": 3}}, {"light": {"light": 4, "on": false}}]}})"),
                     json(R"({"id": 57, "transaction": {"edits": [{"animation": {"instance": "b", "seek": -1}}]}})"),
                     json(R"({"id": 6, "teleport": {}})"), json(R"({"id": -1})"), json("{"),
                     json(R"({"id": 7, "transaction": {"edits": [{"transform": {"instance": "a",
                        "transform": {"position": [1e400, 0, 0]}}}]}})"),
                     Bytes{}})});
  return seeds;
}

}  // namespace optique::fuzz
