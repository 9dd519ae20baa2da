// The node's side of the protocol without sockets (node/protocol.h): each rule the
// process tests once checked by starting processes, as events in and actions out.

#include "node/protocol.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "actions.h"
#include "config/load.h"
#include "envelopes.h"
#include "net/auth.h"
#include "protocol/welcome.h"
#include "scene/manifest.h"
#include "scene/state.h"

namespace optique::node {
namespace {

constexpr clock::Nanos kMs = clock::kNanosPerMilli;
constexpr clock::Nanos kPeriod = 16'666'666;

using testing::all_of;
using testing::first;

// The messages the actions send, of one kind.
std::vector<wire::Envelope> sent(const Actions& actions, wire::Envelope::BodyCase kind) {
  std::vector<wire::Envelope> out;
  for (const Send* s : all_of<Send>(actions)) {
    if (s->message.body_case() == kind) out.push_back(s->message);
  }
  return out;
}

bool logged(const Actions& actions, const std::string& fragment) { return testing::logged<Log>(actions, fragment); }

using testing::envelope;

config::Installation wall() {
  auto loaded = config::load_installation(std::string(OPTIQUE_SOURCE_DIR) + "/configs/powerwall-2x2.json");
  EXPECT_TRUE(loaded) << (loaded ? "" : loaded.error());
  return loaded ? loaded.value().installation : config::Installation{};
}

// A node and its master's side of the conversation, by hand.
class NodeTest : public ::testing::Test {
 protected:
  NodeSettings settings() {
    NodeSettings s;
    s.master = "127.0.0.1:7400";
    s.id = "bottom-left";
    return s;
  }

  // Through the handshake to joined at frame `next`, with the scene state `state`.
  void join(NodeProtocol& node, std::uint64_t next = 0) {
    Actions a = node.connected(now_);
    ASSERT_NE(first<SetDeadline>(a), nullptr);
    wire::Envelope challenge = envelope();
    challenge.mutable_challenge()->set_nonce(std::string(32, 'n'));
    a = node.message(challenge, now_);
    ASSERT_EQ(sent(a, wire::Envelope::kHello).size(), 1u);
    wire::Envelope welcome = envelope();
    *welcome.mutable_welcome() = protocol::encode_welcome(wall_, 0, {}, 4, kPeriod, nullptr);
    a = node.message(welcome, now_);
    ASSERT_NE(first<Configure>(a), nullptr);
    a = node.answer(Configured{{}, "test renderer", {}}, now_);
    ASSERT_EQ(sent(a, wire::Envelope::kConfigured).size(), 1u);
    wire::Envelope resync = envelope();
    *resync.mutable_resync()->mutable_snapshot() = scene::to_snapshot(state_);
    resync.mutable_resync()->set_next_frame_id(next);
    resync.mutable_resync()->set_state_hash(scene::state_hash(state_));
    a = node.message(resync, now_);
    ASSERT_TRUE(node.joined());
    ASSERT_NE(first<SetLiveness>(a), nullptr);
    ASSERT_EQ(sent(a, wire::Envelope::kPing).size(), 1u);
  }

  // The master answers a ping `one_way` later, holding it `hold`; the pong comes back `one_way` after that.
  void pong(NodeProtocol& node, clock::Nanos one_way, clock::Nanos hold, clock::Nanos master_ahead) {
    Actions a = node.due(Due::ping, now_);
    const auto pings = sent(a, wire::Envelope::kPing);
    ASSERT_EQ(pings.size(), 1u);
    wire::Envelope reply = envelope();
    auto& p = *reply.mutable_pong();
    p.set_t1(pings.front().ping().t1());
    p.set_t2(now_ + one_way + master_ahead);
    p.set_t3(now_ + one_way + hold + master_ahead);
    now_ += 2 * one_way + hold;
    (void)node.message(reply, now_);
  }

  Actions begin(NodeProtocol& node, std::uint64_t frame) {
    wire::Envelope e = envelope();
    auto& b = *e.mutable_frame_begin();
    b.set_frame_id(frame);
    b.set_simulation_time_ns(static_cast<clock::Nanos>(frame) * kPeriod);
    b.set_state_hash(scene::state_hash(state_));
    return node.message(e, now_);
  }

  Actions swap(NodeProtocol& node, std::uint64_t frame, clock::Nanos master_deadline) {
    wire::Envelope e = envelope();
    e.mutable_swap()->set_frame_id(frame);
    e.mutable_swap()->set_present_deadline_ns(master_deadline);
    return node.message(e, now_);
  }

  // The node of configs/dlp-stereo-as-mono.json, two images per frame, in place of the wall.
  NodeSettings stereo_as_mono() {
    auto loaded = config::load_installation(std::string(OPTIQUE_SOURCE_DIR) + "/configs/dlp-stereo-as-mono.json");
    EXPECT_TRUE(loaded) << (loaded ? "" : loaded.error());
    if (loaded) wall_ = loaded.value().installation;
    NodeSettings s = settings();
    s.id = "dlp";
    return s;
  }

  config::Installation wall_ = wall();
  scene::SceneState state_;
  clock::Nanos now_ = 1'000'000 * kMs;
};

TEST_F(NodeTest, HandshakeAnswersTheChallengeWithItsMacAndJoinsOnTheState) {
  NodeSettings s = settings();
  s.secret = net::Secret{std::vector<std::uint8_t>(32, 7)};
  NodeProtocol node(s);
  const std::vector<std::uint8_t> own(32, 6);
  (void)node.connected(now_, own);
  wire::Envelope challenge = envelope();
  const std::string nonce(32, 'x');
  challenge.mutable_challenge()->set_nonce(nonce);
  challenge.mutable_challenge()->set_secret_required(true);
  const Actions a = node.message(challenge, now_);
  const auto hello = sent(a, wire::Envelope::kHello);
  ASSERT_EQ(hello.size(), 1u);
  EXPECT_EQ(hello.front().hello().node_id(), "bottom-left");
  EXPECT_EQ(hello.front().hello().node_nonce(), std::string(own.begin(), own.end()));
  const std::string& mac = hello.front().hello().nonce_mac();
  std::vector<std::uint8_t> both(nonce.begin(), nonce.end());
  both.insert(both.end(), own.begin(), own.end());
  EXPECT_TRUE(net::verify_hello_mac(*s.secret, both, "bottom-left", net::kProtocolVersion,
                                    std::span(reinterpret_cast<const std::uint8_t*>(mac.data()), mac.size())));
  // Everything after the hello is sealed, each way with its own key.
  const Protect* protect = first<Protect>(a);
  ASSERT_NE(protect, nullptr);
  const net::SessionKeys keys =
      net::derive_session_keys(*s.secret, std::span(both).first(32), own, "bottom-left", net::kProtocolVersion);
  EXPECT_EQ(protect->send, keys.to_master);
  EXPECT_EQ(protect->receive, keys.to_node);
  // A second challenge is a broken master.
  EXPECT_NE(first<Close>(node.message(challenge, now_)), nullptr);
}

// A node with the installation's secret does not join a master that asks for
// none: anyone could be that master (and would be sent this node's pictures'
// scene requests, and cached).
TEST_F(NodeTest, ANodeWithASecretRefusesAMasterWithout) {
  NodeSettings s = settings();
  s.secret = net::Secret{std::vector<std::uint8_t>(32, 7)};
  NodeProtocol node(s);
  (void)node.connected(now_, std::vector<std::uint8_t>(32, 6));
  wire::Envelope challenge = envelope();
  challenge.mutable_challenge()->set_nonce(std::string(32, 'x'));
  const Actions a = node.message(challenge, now_);
  EXPECT_TRUE(sent(a, wire::Envelope::kHello).empty());
  ASSERT_NE(first<Stop>(a), nullptr);
  EXPECT_EQ(first<Stop>(a)->exit_code, kExitRefused);
  EXPECT_TRUE(logged(a, "asked for no secret, but this node has one"));
}

TEST_F(NodeTest, ASecretTheNodeLacksStopsIt) {
  NodeProtocol node(settings());
  (void)node.connected(now_);
  wire::Envelope challenge = envelope();
  challenge.mutable_challenge()->set_secret_required(true);
  const Actions a = node.message(challenge, now_);
  ASSERT_NE(first<Stop>(a), nullptr);
  EXPECT_EQ(first<Stop>(a)->exit_code, kExitRefused);
  EXPECT_TRUE(logged(a, "--secret-file"));
}

TEST_F(NodeTest, ABadWelcomeStopsTheNodeNamingTheField) {
  NodeProtocol node(settings());
  (void)node.connected(now_);
  wire::Envelope challenge = envelope();
  challenge.mutable_challenge();
  ASSERT_EQ(sent(node.message(challenge, now_), wire::Envelope::kHello).size(), 1u);
  wire::Envelope welcome = envelope();
  *welcome.mutable_welcome() = protocol::encode_welcome(wall_, 0, {}, 4, kPeriod, nullptr);
  welcome.mutable_welcome()->mutable_screen()->set_width(-2.0);
  const Actions a = node.message(welcome, now_);
  ASSERT_NE(first<Stop>(a), nullptr);
  EXPECT_EQ(first<Stop>(a)->exit_code, kExitRefused);
  EXPECT_TRUE(logged(a, "screens[0].width: must be > 0")) << "the message names the field";
  EXPECT_EQ(first<Configure>(a), nullptr);
}

TEST_F(NodeTest, RefusalsGoodbyesAndOtherVersions) {
  {
    NodeProtocol node(settings());
    (void)node.connected(now_);
    wire::Envelope refuse = envelope();
    refuse.mutable_refuse()->set_reason("projector 'bottom-left' is already driven");
    refuse.mutable_refuse()->set_retriable(true);
    Actions a = node.message(refuse, now_);
    ASSERT_NE(first<Close>(a), nullptr);
    EXPECT_EQ(first<Stop>(a), nullptr);
    refuse.mutable_refuse()->set_retriable(false);
    (void)node.connected(now_);
    a = node.message(refuse, now_);
    ASSERT_NE(first<Stop>(a), nullptr);
    EXPECT_EQ(first<Stop>(a)->exit_code, kExitRefused);
  }
  {
    NodeProtocol node(settings());
    join(node);
    wire::Envelope goodbye = envelope();
    goodbye.mutable_goodbye()->set_reason("ran 300 frames");
    const Actions a = node.message(goodbye, now_);
    ASSERT_NE(first<Stop>(a), nullptr);
    EXPECT_EQ(first<Stop>(a)->exit_code, kExitOk);
    EXPECT_TRUE(node.stopped());
    EXPECT_TRUE(node.message(goodbye, now_).empty()) << "a stopped node does nothing";
  }
  {
    NodeProtocol node(settings());
    join(node);
    wire::Envelope other = envelope();
    other.set_protocol_version(net::kProtocolVersion + 1);
    other.mutable_heartbeat();
    const Actions a = node.message(other, now_);
    ASSERT_NE(first<Stop>(a), nullptr);
    EXPECT_EQ(first<Stop>(a)->exit_code, kExitRefused);
  }
}

TEST_F(NodeTest, AFrameIsRenderedReportedAndShownAtItsDeadline) {
  NodeProtocol node(settings());
  join(node, 5);
  // The master's clock is 3 s ahead; loopback takes 20 µs each way.
  for (int i = 0; i < 8; ++i) pong(node, 20'000, 5'000, 3'000 * kMs);
  Actions a = begin(node, 5);
  const Render* render = first<Render>(a);
  ASSERT_NE(render, nullptr);
  EXPECT_EQ(render->frame.frame_id, 5u);
  EXPECT_EQ(render->frame.state, &node.state());
  a = node.answer(FrameRendered{5, 3 * kMs, {}}, now_);
  const auto ready = sent(a, wire::Envelope::kFrameReady);
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_EQ(ready.front().frame_ready().state_hash(), scene::state_hash(state_));
  EXPECT_EQ(ready.front().frame_ready().render_ns(), 3 * kMs);

  // Present 2 ms from now on the master's clock: 2 ms from now on the node's.
  const clock::Nanos master_deadline = now_ + 3'000 * kMs + 2 * kMs;
  a = swap(node, 5, master_deadline);
  const PresentAt* at = first<PresentAt>(a);
  ASSERT_NE(at, nullptr);
  EXPECT_NEAR(static_cast<double>(at->deadline - now_), 2e6, 1e3) << "the offset estimate converts the deadline";
  now_ = at->deadline;
  a = node.due(Due::present, now_);
  ASSERT_NE(first<Present>(a), nullptr);
  a = node.answer(ImagePresented{}, now_ + 10'000);
  const auto reports = sent(a, wire::Envelope::kPresented);
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports.front().presented().frame_id(), 5u);
  EXPECT_NEAR(static_cast<double>(reports.front().presented().presented_ns() - master_deadline), 10e3, 1e3);
  EXPECT_TRUE(node.answer(ImagePresented{}, now_).empty()) << "shown once";
}

// An edit staged between rounds goes into the state the next FrameBegin
// applies to at once (a frame waiting for its deadline has its images), or
// after a FrameBegin held before it: its hash is the master's.
// One that cannot be applied closes the connection, as a bad FrameBegin does.
TEST_F(NodeTest, AnEditStagedBetweenRoundsIsInTheNextFrame) {
  state_.instances["cup"].asset = "cubes";
  NodeProtocol node(settings());
  join(node, 5);
  ASSERT_NE(first<Render>(begin(node, 5)), nullptr);
  (void)node.answer(FrameRendered{5, kMs, {}}, now_);
  ASSERT_NE(first<PresentAt>(swap(node, 5, now_ + 2 * kMs)), nullptr);

  scene::SceneState next = state_;
  next.instances["cup"].pose.now.position.x = 1.5;
  next.instances["saucer"].asset = "cubes";
  wire::Envelope staged = envelope();
  staged.mutable_staged_edit()->set_frame_id(6);
  *staged.mutable_staged_edit()->mutable_delta() =
      scene::make_instance_delta(state_, {{"cup", next.instances.at("cup")}, {"saucer", next.instances.at("saucer")}});
  Actions a = node.message(staged, now_);
  EXPECT_TRUE(a.empty());
  EXPECT_EQ(node.state(), next) << "applied at once: frame 5's image is drawn already";
  now_ += 2 * kMs;
  ASSERT_NE(first<Present>(node.due(Due::present, now_)), nullptr);
  (void)node.answer(ImagePresented{}, now_);

  state_ = next;
  ASSERT_NE(first<Render>(begin(node, 6)), nullptr);  // an empty delta, the hash of the staged state
  a = node.answer(FrameRendered{6, kMs, {}}, now_);
  const auto ready = sent(a, wire::Envelope::kFrameReady);
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_EQ(ready.front().frame_ready().state_hash(), scene::state_hash(next));

  // Behind a FrameBegin held for frame 6's deadline, it waits its turn.
  ASSERT_NE(first<PresentAt>(swap(node, 6, now_ + 2 * kMs)), nullptr);
  EXPECT_EQ(first<Render>(begin(node, 7)), nullptr) << "held";
  scene::SceneState later = next;
  later.instances["saucer"].visible = false;
  staged.mutable_staged_edit()->set_frame_id(8);
  *staged.mutable_staged_edit()->mutable_delta() =
      scene::make_instance_delta(next, {{"saucer", later.instances.at("saucer")}});
  EXPECT_TRUE(node.message(staged, now_).empty());
  EXPECT_EQ(node.state(), next) << "behind the held frame";
  now_ += 2 * kMs;
  (void)node.due(Due::present, now_);
  a = node.answer(ImagePresented{}, now_);
  const Render* seventh = first<Render>(a);
  ASSERT_NE(seventh, nullptr);
  EXPECT_EQ(seventh->frame.frame_id, 7u);
  EXPECT_EQ(node.state(), later) << "frame 7 began, then the edit staged for 8";
  (void)node.answer(FrameRendered{7, kMs, {}}, now_);
  wire::Envelope bad = envelope();
  bad.mutable_staged_edit()->set_frame_id(8);
  bad.mutable_staged_edit()->mutable_delta()->add_instances_removed("ghost");
  a = node.message(bad, now_);
  const Close* closed = first<Close>(a);
  ASSERT_NE(closed, nullptr);
  EXPECT_NE(closed->reason.find("cannot apply the edit staged for frame 8"), std::string::npos) << closed->reason;
}

// A 2×60 Hz stereo projector used as mono shows two images per frame: the second
// half a frame after the first, the next frame held back until it is shown, and
// only the first reported (the master's deadline and sync are for it).
TEST_F(NodeTest, AStereoProjectorUsedAsMonoShowsItsSecondImageHalfAFrameLater) {
  const NodeSettings s = stereo_as_mono();
  ASSERT_EQ(wall_.projectors.front().color_fields.images, 2);
  NodeProtocol node(s);
  join(node);
  (void)begin(node, 0);
  (void)node.answer(FrameRendered{0, kMs, {}}, now_);
  const clock::Nanos deadline = now_ + 2 * kMs;
  Actions a = swap(node, 0, deadline);
  const PresentAt* at = first<PresentAt>(a);
  ASSERT_NE(at, nullptr);
  now_ = at->deadline;
  a = node.due(Due::present, now_);
  ASSERT_NE(first<Present>(a), nullptr);
  EXPECT_EQ(first<Present>(a)->image, 0);
  // Frame 1 comes meanwhile: it waits for both images of frame 0.
  now_ += kMs;
  EXPECT_EQ(first<Render>(begin(node, 1)), nullptr);
  a = node.answer(ImagePresented{}, now_);
  ASSERT_EQ(sent(a, wire::Envelope::kPresented).size(), 1u) << "the first image is reported";
  EXPECT_EQ(first<Render>(a), nullptr) << "the second image is not shown yet";
  at = first<PresentAt>(a);
  ASSERT_NE(at, nullptr);
  EXPECT_EQ(at->deadline - (deadline), kPeriod / 2) << "half a frame after the first";
  now_ = at->deadline;
  a = node.due(Due::present, now_);
  ASSERT_NE(first<Present>(a), nullptr);
  EXPECT_EQ(first<Present>(a)->image, 1);
  a = node.answer(ImagePresented{}, now_);
  EXPECT_TRUE(sent(a, wire::Envelope::kPresented).empty()) << "one report per frame";
  const Render* render = first<Render>(a);
  ASSERT_NE(render, nullptr) << "frame 1 is drawn once frame 0's second image is shown";
  EXPECT_EQ(render->frame.frame_id, 1u);
  // An image is stale once the next one's time has come: a first image shown
  // late is followed by its second only if that is not late too.
  (void)node.answer(FrameRendered{1, kMs, {}}, now_);
  a = swap(node, 1, now_ + kMs);
  at = first<PresentAt>(a);
  ASSERT_NE(at, nullptr);
  now_ = at->deadline;
  (void)node.due(Due::present, now_);
  a = node.answer(ImagePresented{}, now_ + kPeriod + kMs);
  EXPECT_EQ(first<PresentAt>(a), nullptr);
  EXPECT_TRUE(logged(a, "frame 1 image 1's present deadline passed"));
  // And a first image woken too late gives way to the second.
  now_ += kPeriod;
  (void)begin(node, 2);
  (void)node.answer(FrameRendered{2, kMs, {}}, now_);
  a = swap(node, 2, now_ + kMs);
  at = first<PresentAt>(a);
  ASSERT_NE(at, nullptr);
  now_ = at->deadline + kPeriod / 2 + kMs;
  a = node.due(Due::present, now_);
  EXPECT_TRUE(logged(a, "frame 2 image 0's present deadline passed"));
  EXPECT_EQ(first<Present>(a), nullptr);
  at = first<PresentAt>(a);
  ASSERT_NE(at, nullptr) << "the second image's time has not passed";
  const clock::Nanos second = at->deadline;
  a = node.due(Due::present, second);
  ASSERT_NE(first<Present>(a), nullptr);
  EXPECT_EQ(first<Present>(a)->image, 1);
}

// Between the two images: the master lost (nothing more is shown of that frame,
// the projector goes black), or the second image's wake-up late (skipped, and the
// frame that waited behind it goes on).
TEST_F(NodeTest, BetweenTheTwoImagesALostMasterOrALateWakeUpEndsTheFrame) {
  const NodeSettings s = stereo_as_mono();
  for (const bool lose_master : {true, false}) {
    NodeProtocol node(s);
    join(node);
    (void)begin(node, 0);
    (void)node.answer(FrameRendered{0, kMs, {}}, now_);
    Actions a = swap(node, 0, now_ + kMs);
    ASSERT_NE(first<PresentAt>(a), nullptr);
    now_ = first<PresentAt>(a)->deadline;
    ASSERT_NE(first<Present>(node.due(Due::present, now_)), nullptr);
    a = node.answer(ImagePresented{}, now_);
    ASSERT_NE(first<PresentAt>(a), nullptr);
    const clock::Nanos second = first<PresentAt>(a)->deadline;
    if (lose_master) {
      a = node.closed("reset by peer", now_);
      EXPECT_NE(first<ShowBlack>(a), nullptr);
      EXPECT_TRUE(node.due(Due::present, second).empty()) << "the frame's second image is not shown";
      continue;
    }
    EXPECT_EQ(first<Render>(begin(node, 1)), nullptr) << "frame 1 waits for the second image";
    now_ = second + kPeriod / 2 + kMs;
    a = node.due(Due::present, now_);
    EXPECT_EQ(first<Present>(a), nullptr);
    EXPECT_TRUE(logged(a, "frame 0 image 1's present deadline passed"));
    const Render* render = first<Render>(a);
    ASSERT_NE(render, nullptr) << "frame 1 goes on once frame 0 is given up";
    EXPECT_EQ(render->frame.frame_id, 1u);
  }
}

TEST_F(NodeTest, AFrameThatComesWhileOneWaitsForItsDeadlineWaitsForIt) {
  NodeProtocol node(settings());
  join(node);
  (void)begin(node, 0);
  (void)node.answer(FrameRendered{0, kMs, {}}, now_);
  Actions a = swap(node, 0, now_ + 2 * kMs);
  ASSERT_NE(first<PresentAt>(a), nullptr);
  // Frame 1 arrives early (a master behind schedule): not drawn over frame 0.
  a = begin(node, 1);
  EXPECT_EQ(first<Render>(a), nullptr);
  // A pong meanwhile is taken at once: the clock estimate does not wait.
  pong(node, 20'000, 5'000, 0);
  EXPECT_GE(node.estimator().size(), 1u);
  now_ += 2 * kMs;
  a = node.due(Due::present, now_);
  ASSERT_NE(first<Present>(a), nullptr);
  a = node.answer(ImagePresented{}, now_);
  ASSERT_EQ(sent(a, wire::Envelope::kPresented).size(), 1u);
  const Render* render = first<Render>(a);
  ASSERT_NE(render, nullptr) << "frame 1 is drawn once frame 0 is shown";
  EXPECT_EQ(render->frame.frame_id, 1u);
}

TEST_F(NodeTest, AStaleFrameIsNotShown) {
  NodeProtocol node(settings());
  join(node);
  (void)begin(node, 0);
  (void)node.answer(FrameRendered{0, kMs, {}}, now_);
  // The deadline passed more than a frame ago already (the process was stopped).
  Actions a = swap(node, 0, now_ - 2 * kPeriod);
  EXPECT_EQ(first<PresentAt>(a), nullptr);
  EXPECT_TRUE(logged(a, "not showing a stale frame"));
  // Or the wait itself was stretched past the next frame's time.
  (void)begin(node, 1);
  (void)node.answer(FrameRendered{1, kMs, {}}, now_);
  a = swap(node, 1, now_ + 2 * kMs);
  ASSERT_NE(first<PresentAt>(a), nullptr);
  now_ += 2 * kMs + kPeriod + kMs;
  a = node.due(Due::present, now_);
  EXPECT_EQ(first<Present>(a), nullptr);
  EXPECT_TRUE(logged(a, "not showing a stale frame"));
}

// The guard's edge, to the microsecond: a frame is still shown a whole frame
// period after its deadline, and not a microsecond later.
TEST_F(NodeTest, AFrameIsStaleOneFramePeriodAfterItsDeadline) {
  for (const clock::Nanos late : {kPeriod - 1000, kPeriod + 1000}) {
    NodeProtocol node(settings());
    join(node);
    (void)begin(node, 0);
    (void)node.answer(FrameRendered{0, kMs, {}}, now_);
    const clock::Nanos deadline = now_ + 2 * kMs;
    ASSERT_NE(first<PresentAt>(swap(node, 0, deadline)), nullptr);
    const Actions a = node.due(Due::present, deadline + late);
    if (late < kPeriod) {
      EXPECT_NE(first<Present>(a), nullptr) << late << " ns late is still this frame's time";
    } else {
      EXPECT_EQ(first<Present>(a), nullptr) << late << " ns late is the next frame's time";
      EXPECT_TRUE(logged(a, "not showing a stale frame"));
    }
  }
}

TEST_F(NodeTest, ASwapForAFrameNotRenderedIsNotShown) {
  NodeProtocol node(settings());
  join(node);
  (void)begin(node, 0);
  (void)node.answer(FrameRendered{0, kMs, {}}, now_);
  const Actions a = swap(node, 7, now_ + 2 * kMs);
  EXPECT_EQ(first<PresentAt>(a), nullptr);
  EXPECT_TRUE(logged(a, "swap for frame 7 but the last rendered frame is 0"));
}

TEST_F(NodeTest, ADeadlineFarAwayIsCutToFourFrames) {
  NodeProtocol node(settings());
  join(node);
  (void)begin(node, 0);
  (void)node.answer(FrameRendered{0, kMs, {}}, now_);
  const Actions a = swap(node, 0, now_ + 60'000 * kMs);
  const PresentAt* at = first<PresentAt>(a);
  ASSERT_NE(at, nullptr);
  EXPECT_EQ(at->deadline - now_, 100 * kMs);  // four frames at 60 Hz are less than the 100 ms floor
  EXPECT_TRUE(logged(a, "presenting in 100.0 ms"));
}

TEST_F(NodeTest, BadFrameInputClosesTheConnection) {
  NodeProtocol node(settings());
  join(node);
  wire::Envelope e = envelope();
  auto& b = *e.mutable_frame_begin();
  b.set_frame_id(0);
  // The welcome said the scene has 4 lights (0-3): 64 more may be added (4-67).
  b.mutable_lights()->add_lights(68);
  Actions a = node.message(e, now_);
  ASSERT_NE(first<Close>(a), nullptr);
  EXPECT_NE(first<Close>(a)->reason.find("light 68 does not exist"), std::string::npos) << first<Close>(a)->reason;
  EXPECT_EQ(first<Render>(a), nullptr);

  NodeProtocol other(settings());
  join(other);
  wire::Envelope nan = envelope();
  nan.mutable_frame_begin()->mutable_focus()->set_depth(std::numeric_limits<double>::quiet_NaN());
  a = other.message(nan, now_);
  ASSERT_NE(first<Close>(a), nullptr);
  EXPECT_NE(first<Close>(a)->reason.find("focus depth"), std::string::npos);
}

// A node that interpolates gets a later frame's scene with a frame: checked and
// handed to the renderer beside the frame's own; how the frame was drawn goes
// back in FrameReady. A scene for a frame not ahead, or beyond what the largest
// ratio with spread key frames needs, or not a valid snapshot, closes the connection by name.
TEST_F(NodeTest, TheSceneSentAheadReachesTheRendererAndHowTheFrameWasDrawnGoesBack) {
  NodeProtocol node(settings());
  join(node);
  scene::SceneState later = state_;
  later.eye_now.x += 0.25;
  wire::Envelope e = envelope();
  auto& b = *e.mutable_frame_begin();
  b.set_frame_id(0);
  b.set_state_hash(scene::state_hash(state_));
  *b.mutable_ahead() = scene::to_snapshot(later);
  b.set_ahead_frame(3);
  Actions a = node.message(e, now_);
  const Render* render = first<Render>(a);
  ASSERT_NE(render, nullptr);
  ASSERT_NE(render->frame.ahead, nullptr);
  EXPECT_EQ(*render->frame.ahead, later);
  EXPECT_EQ(render->frame.ahead_frame, 3u);
  a = node.answer(FrameRendered{0, kMs, {up::FrameKind::between, true}}, now_);
  const auto ready = sent(a, wire::Envelope::kFrameReady);
  ASSERT_EQ(ready.size(), 1u);
  EXPECT_EQ(ready.front().frame_ready().drawn_as(), wire::DRAWN_BETWEEN_AND_KEY_AHEAD);

  const auto refused = [&](std::uint64_t frame, std::uint64_t ahead, double x, const std::string& says) {
    NodeProtocol other(settings());
    join(other);
    wire::Envelope bad = envelope();
    auto& begin = *bad.mutable_frame_begin();
    begin.set_frame_id(frame);
    scene::SceneState odd = state_;
    odd.eye_now.x = x;
    *begin.mutable_ahead() = scene::to_snapshot(odd);
    begin.set_ahead_frame(ahead);
    Actions closed = other.message(bad, now_);
    ASSERT_NE(first<Close>(closed), nullptr) << says;
    EXPECT_NE(first<Close>(closed)->reason.find(says), std::string::npos) << first<Close>(closed)->reason;
    EXPECT_EQ(first<Render>(closed), nullptr);
  };
  refused(0, 0, 0.0, "the scene sent ahead is for frame 0, not 1…31 frames on");
  refused(0, 32, 0.0, "not 1…31 frames on");
  refused(0, 2, std::numeric_limits<double>::quiet_NaN(), "the scene sent ahead:");
}

// --give-up-after-ms 10000 once gave up after 11.1 s: the backoff ran past it.
TEST_F(NodeTest, GivingUpKeepsToTheLimitWhateverTheBackoff) {
  for (const long limit : {10000L, 150L, 2500L, 7777L}) {
    NodeSettings s = settings();
    s.give_up_after = std::chrono::milliseconds(limit);
    NodeProtocol node(s);
    const clock::Nanos lost = now_;
    Actions a = node.closed("connection refused", lost);
    clock::Nanos t = lost;
    int tries = 0;
    while (first<Stop>(a) == nullptr && tries < 1000) {
      const Reconnect* r = first<Reconnect>(a);
      ASSERT_NE(r, nullptr) << "limit " << limit;
      t += r->after.count() * kMs;  // each try is refused at once
      a = node.connect_failed("connection refused", t);
      ++tries;
    }
    ASSERT_NE(first<Stop>(a), nullptr) << "limit " << limit;
    EXPECT_EQ((t - lost) / kMs, limit) << "gave up " << (t - lost) / kMs << " ms after the loss, " << tries << " tries";
  }
}

TEST_F(NodeTest, LosingTheMasterShowsBlackAndReconnectsWithBackoffThenGivesUp) {
  NodeProtocol node(settings());
  join(node);
  Actions a = node.closed("master silent for 3000 ms", now_);
  EXPECT_NE(first<ShowBlack>(a), nullptr);
  ASSERT_NE(first<Reconnect>(a), nullptr);
  EXPECT_EQ(first<Reconnect>(a)->after, std::chrono::milliseconds(100));
  std::vector<long> waits;
  for (int i = 0; i < 8; ++i) {
    now_ += 500 * kMs;
    a = node.connect_failed("connection refused", now_);
    if (const Reconnect* r = first<Reconnect>(a)) waits.push_back(r->after.count());
  }
  EXPECT_EQ(waits, (std::vector<long>{200, 400, 800, 1600, 2000, 2000, 2000, 2000}));
  now_ += 7 * 1000 * kMs;  // 10.5 s unreachable in all
  a = node.connect_failed("connection refused", now_);
  ASSERT_NE(first<Stop>(a), nullptr);
  EXPECT_EQ(first<Stop>(a)->exit_code, kExitNoMaster);
  EXPECT_TRUE(logged(a, "gave up: the master at 127.0.0.1:7400 was not reachable"));

  NodeSettings hold = settings();
  hold.hold_last_frame = true;
  NodeProtocol holding(hold);
  join(holding);
  a = holding.closed("reset", now_);
  EXPECT_EQ(first<ShowBlack>(a), nullptr);
  EXPECT_TRUE(logged(a, "holding the last frame"));
}

TEST_F(NodeTest, ALaggingNodeShowsAnOlderFramesContent) {
  NodeSettings s = settings();
  s.faults.lag_frames = 2;
  NodeProtocol node(s);
  join(node);
  for (std::uint64_t frame = 0; frame < 4; ++frame) {
    const Actions a = begin(node, frame);
    const Render* render = first<Render>(a);
    ASSERT_NE(render, nullptr);
    EXPECT_EQ(render->frame.simulation_time, static_cast<clock::Nanos>(frame >= 2 ? frame - 2 : 0) * kPeriod);
    (void)node.answer(FrameRendered{frame, kMs, {}}, now_);
  }
}

TEST_F(NodeTest, InterruptedSaysGoodbye) {
  NodeProtocol node(settings());
  join(node);
  const Actions a = node.interrupted("Terminated");
  const auto goodbye = sent(a, wire::Envelope::kGoodbye);
  ASSERT_EQ(goodbye.size(), 1u);
  EXPECT_EQ(goodbye.front().goodbye().reason(), "node Terminated");
  ASSERT_NE(first<Close>(a), nullptr);
  EXPECT_TRUE(first<Close>(a)->after_sending);
  ASSERT_NE(first<Stop>(a), nullptr);
  EXPECT_EQ(first<Stop>(a)->exit_code, kExitOk);
}

TEST_F(NodeTest, PingsComeInABurstOnJoiningThenFortyASecond) {
  NodeProtocol node(settings());
  join(node);
  std::vector<long> intervals;
  for (int i = 0; i < 10; ++i) {
    const Actions a = node.due(Due::ping, now_);
    ASSERT_NE(first<PingIn>(a), nullptr);
    intervals.push_back(first<PingIn>(a)->after.count());
  }
  EXPECT_EQ(intervals, (std::vector<long>{5, 5, 5, 5, 5, 5, 25, 25, 25, 25}));
}

TEST_F(NodeTest, APingDueDuringARoundWaitsUntilTheFrameIsShown) {
  NodeProtocol node(settings());
  join(node);
  for (int i = 1; i < NodeProtocol::kPingBurst; ++i) (void)node.due(Due::ping, now_);  // the burst is over
  (void)begin(node, 0);
  Actions a = node.due(Due::ping, now_);
  EXPECT_TRUE(sent(a, wire::Envelope::kPing).empty()) << "not while the master waits for this node's ready";
  ASSERT_NE(first<PingIn>(a), nullptr);
  EXPECT_EQ(first<PingIn>(a)->after, NodeProtocol::kPingDeferral);
  (void)node.answer(FrameRendered{0, kMs, {}}, now_);
  a = swap(node, 0, now_ + 2 * kMs);
  now_ = first<PresentAt>(a)->deadline;
  (void)node.due(Due::present, now_);
  a = node.answer(ImagePresented{}, now_);
  const auto presented = std::find_if(a.begin(), a.end(), [](const Action& x) {
    return std::holds_alternative<Send>(x) && std::get<Send>(x).message.has_presented();
  });
  const auto ping = std::find_if(a.begin(), a.end(), [](const Action& x) {
    return std::holds_alternative<Send>(x) && std::get<Send>(x).message.has_ping();
  });
  ASSERT_NE(ping, a.end()) << "the ping goes once the frame is shown";
  EXPECT_LT(presented, ping) << "after the report";
  ASSERT_NE(first<PingIn>(a), nullptr);
  EXPECT_EQ(first<PingIn>(a)->after, NodeProtocol::kPingInterval);

  // Mid-frame: sent at once.
  now_ += 5 * kMs;
  EXPECT_EQ(sent(node.due(Due::ping, now_), wire::Envelope::kPing).size(), 1u);
  // Half a millisecond before the next FrameBegin is expected: held back.
  now_ += kPeriod - 2 * kMs - 5 * kMs - kMs / 2;
  EXPECT_TRUE(sent(node.due(Due::ping, now_), wire::Envelope::kPing).empty());

  // A round that never ends here (the master dropped the frame: no swap comes)
  // holds a ping back once, not forever.
  (void)begin(node, 1);
  (void)node.answer(FrameRendered{1, kMs, {}}, now_);
  now_ += NodeProtocol::kPingDeferral.count() * kMs;
  EXPECT_EQ(sent(node.due(Due::ping, now_), wire::Envelope::kPing).size(), 1u);
}

// --- a glTF scene's files, fetched from the master when this node has no copy

// A scene of two files: a small glTF, and a binary of two 4 KiB chunks.
struct TwoFileScene {
  std::string gltf = R"({"asset":{"version":"2.0"}})";
  std::string bin = std::string(5000, '\x42');
  scene::SceneManifest files{
      4096, {scene::describe_file("s.gltf", gltf, 4096), scene::describe_file("maps/s.bin", bin, 4096)}};
  std::string sha256 = scene::manifest_sha256(files);
};

class SceneFetchTest : public NodeTest {
 protected:
  // Through the challenge to the welcome of a glTF scene.
  Actions welcome_with_files(NodeProtocol& node) { return welcomed(node, welcome_of(scene_.files)); }
  // Through the challenge to `welcome`.
  Actions welcomed(NodeProtocol& node, const wire::Envelope& welcome) {
    (void)node.connected(now_);
    wire::Envelope challenge = envelope();
    challenge.mutable_challenge();
    (void)node.message(challenge, now_);
    return node.message(welcome, now_);
  }
  wire::Envelope welcome_of(const scene::SceneManifest& files, std::span<const protocol::AssetOffer> assets = {}) {
    wire::Envelope welcome = envelope();
    *welcome.mutable_welcome() = protocol::encode_welcome(wall_, 0, files, 4, kPeriod, nullptr, assets);
    return welcome;
  }
  wire::Envelope chunk(std::uint32_t file, std::uint64_t index, std::string data) {
    wire::Envelope e = envelope();
    e.mutable_scene_chunk()->set_file(file);
    e.mutable_scene_chunk()->set_chunk(index);
    e.mutable_scene_chunk()->set_data(std::move(data));
    return e;
  }
  TwoFileScene scene_;
};

TEST_F(SceneFetchTest, ACopyInTheCacheIsUsedWithoutAFetch) {
  NodeProtocol node(settings());
  Actions a = welcome_with_files(node);
  const PrepareScene* prepare = first<PrepareScene>(a);
  ASSERT_NE(prepare, nullptr);
  EXPECT_EQ(prepare->sha256, scene_.sha256);
  EXPECT_EQ(prepare->manifest.files.size(), 2u);
  EXPECT_EQ(first<Configure>(a), nullptr);
  a = node.answer(SceneFound{"/cache/scenes/abc/s.gltf"}, now_);
  ASSERT_NE(first<Configure>(a), nullptr);
  EXPECT_EQ(first<Configure>(a)->job.scene_path, "/cache/scenes/abc/s.gltf");
  EXPECT_TRUE(sent(a, wire::Envelope::kSceneRequest).empty());
}

TEST_F(SceneFetchTest, AMissingSceneIsFetchedChunkByChunkAndCheckedThenConfigured) {
  NodeProtocol node(settings());
  (void)welcome_with_files(node);
  Actions a = node.answer(SceneCopyStarted{protocol::SceneFetch::Present{}}, now_);
  auto requests = sent(a, wire::Envelope::kSceneRequest);
  ASSERT_EQ(requests.size(), 3u);  // every chunk there is, up to four at once
  EXPECT_EQ(requests[0].scene_request().scene_sha256(), scene_.sha256);
  EXPECT_EQ(requests[1].scene_request().file(), 1u);
  EXPECT_EQ(requests[2].scene_request().chunk(), 1u);
  ASSERT_NE(first<SetDeadline>(a), nullptr);
  EXPECT_TRUE(logged(a, "fetching the scene"));

  a = node.message(chunk(0, 0, scene_.gltf), now_);
  ASSERT_NE(first<StoreSceneChunk>(a), nullptr);
  EXPECT_EQ(first<StoreSceneChunk>(a)->data, scene_.gltf);
  // A chunk spoilt on the way is not stored but asked for again.
  std::string spoilt = scene_.bin.substr(0, 4096);
  spoilt[7] = 'x';
  a = node.message(chunk(1, 0, spoilt), now_);
  EXPECT_EQ(first<StoreSceneChunk>(a), nullptr);
  EXPECT_TRUE(logged(a, "does not match its SHA-256; asking for it again"));
  requests = sent(a, wire::Envelope::kSceneRequest);
  ASSERT_EQ(requests.size(), 1u);
  EXPECT_EQ(requests[0].scene_request().chunk(), 0u);
  a = node.message(chunk(1, 1, scene_.bin.substr(4096)), now_);
  ASSERT_NE(first<StoreSceneChunk>(a), nullptr);
  EXPECT_EQ(first<StoreSceneChunk>(a)->offset, 4096u);
  EXPECT_EQ(first<FinishScene>(a), nullptr);
  a = node.message(chunk(1, 0, scene_.bin.substr(0, 4096)), now_ + 20 * kMs);
  ASSERT_NE(first<StoreSceneChunk>(a), nullptr);
  ASSERT_NE(first<FinishScene>(a), nullptr);

  a = node.answer(SceneCopyFinished{std::string("/cache/scenes/x/s.gltf")}, now_ + 30 * kMs);
  EXPECT_TRUE(logged(a, "fetched the scene: 0.0 MiB in 0.03 s"));
  EXPECT_TRUE(logged(a, "1 chunk(s) asked for again"));
  ASSERT_NE(first<Configure>(a), nullptr);
  EXPECT_EQ(first<Configure>(a)->job.scene_path, "/cache/scenes/x/s.gltf");
}

TEST_F(SceneFetchTest, AChunkNotAskedForClosesAndAFailedCopyStopsTheNode) {
  {
    NodeProtocol node(settings());
    (void)welcome_with_files(node);
    (void)node.answer(SceneCopyStarted{protocol::SceneFetch::Present{}}, now_);
    const Actions a = node.message(chunk(1, 9, "x"), now_);
    ASSERT_NE(first<Close>(a), nullptr);
    EXPECT_NE(first<Close>(a)->reason.find("not asked for"), std::string::npos);
    // The connection goes; the partial copy stays, for the fetch to go on from.
    EXPECT_EQ(first<AbandonScene>(node.closed("gone", now_)), nullptr);
    // Stopping while it reconnects keeps it too, for the next node to fetch
    // the scene (this one restarted) to go on from.
    EXPECT_EQ(first<AbandonScene>(node.interrupted("SIGTERM")), nullptr);
  }
  {
    NodeProtocol node(settings());
    (void)welcome_with_files(node);
    const Actions a = node.answer(SceneCopyStarted{Error{"no room"}}, now_);
    ASSERT_NE(first<Stop>(a), nullptr);
    EXPECT_EQ(first<Stop>(a)->exit_code, kExitRefused);
    EXPECT_TRUE(logged(a, "no room"));
  }
  {
    NodeProtocol node(settings());
    (void)welcome_with_files(node);
    (void)node.answer(SceneCopyStarted{protocol::SceneFetch::Present{}}, now_);
    const Actions a = node.answer(SceneStoreFailed{"disk full"}, now_);
    ASSERT_NE(first<Stop>(a), nullptr);
    EXPECT_NE(first<AbandonScene>(a), nullptr);
  }
  {
    // The same chunk spoilt on every try: the fetch gives the connection up.
    NodeProtocol node(settings());
    (void)welcome_with_files(node);
    (void)node.answer(SceneCopyStarted{protocol::SceneFetch::Present{}}, now_);
    Actions a;
    for (int i = 0; i < protocol::SceneFetch::kMostTries; ++i) a = node.message(chunk(0, 0, "{}"), now_);
    ASSERT_NE(first<Close>(a), nullptr);
    EXPECT_NE(first<Close>(a)->reason.find("after 4 tries"), std::string::npos) << first<Close>(a)->reason;
  }
}

TEST_F(SceneFetchTest, AFetchCutShortGoesOnFromWhatIsHere) {
  NodeProtocol node(settings());
  (void)welcome_with_files(node);
  // The glTF and the binary's first chunk came before the connection went.
  const protocol::SceneFetch::Present present{{true}, {true, false}};
  Actions a = node.answer(SceneCopyStarted{present}, now_);
  EXPECT_TRUE(logged(a, "fetching the rest of the scene"));
  const auto requests = sent(a, wire::Envelope::kSceneRequest);
  ASSERT_EQ(requests.size(), 1u);
  EXPECT_EQ(requests[0].scene_request().file(), 1u);
  EXPECT_EQ(requests[0].scene_request().chunk(), 1u);
  a = node.message(chunk(1, 1, scene_.bin.substr(4096)), now_);
  EXPECT_NE(first<FinishScene>(a), nullptr);
  // Everything here already: put in place at once.
  NodeProtocol whole(settings());
  (void)welcome_with_files(whole);
  a = whole.answer(SceneCopyStarted{protocol::SceneFetch::Present{{true}, {true, true}}}, now_);
  EXPECT_TRUE(sent(a, wire::Envelope::kSceneRequest).empty());
  EXPECT_NE(first<FinishScene>(a), nullptr);
}

// Another node of this host is fetching the scene into the shared cache: this
// one waits for its copy, looking again every kSceneRecheck and telling the
// master about once a second, while the copy grows; the copy in place is used.
TEST_F(SceneFetchTest, ANodeWaitsForTheCopyAnotherNodeOfItsHostIsFetching) {
  NodeProtocol node(settings());
  (void)welcome_with_files(node);
  Actions a = node.answer(SceneFetchedElsewhere{100}, now_);
  EXPECT_TRUE(logged(a, "another node of this host is fetching the scene")) << "logged";
  EXPECT_TRUE(sent(a, wire::Envelope::kSceneRequest).empty());
  auto waits = sent(a, wire::Envelope::kSceneWait);
  ASSERT_EQ(waits.size(), 1u);
  EXPECT_EQ(waits[0].scene_wait().scene_sha256(), scene_.sha256);
  EXPECT_EQ(waits[0].scene_wait().bytes_there(), 100u);
  ASSERT_NE(first<RecheckScene>(a), nullptr);
  EXPECT_EQ(first<RecheckScene>(a)->after, NodeProtocol::kSceneRecheck);
  ASSERT_NE(first<SetDeadline>(a), nullptr);
  EXPECT_GT(first<SetDeadline>(a)->after, NodeProtocol::kSceneStall);

  // The recheck asks the cache again, still waiting for others.
  const clock::Nanos recheck = NodeProtocol::kSceneRecheck.count() * kMs;
  now_ += recheck;
  a = node.due(Due::scene_recheck, now_);
  ASSERT_NE(first<PrepareScene>(a), nullptr);
  EXPECT_TRUE(first<PrepareScene>(a)->wait_for_others);
  // The copy grows: not logged again, the master not told again within the second.
  a = node.answer(SceneFetchedElsewhere{500}, now_);
  EXPECT_FALSE(logged(a, "another node"));
  EXPECT_TRUE(sent(a, wire::Envelope::kSceneWait).empty());
  now_ += NodeProtocol::kSceneWaitWord.count() * kMs;
  a = node.answer(SceneFetchedElsewhere{600}, now_);
  waits = sent(a, wire::Envelope::kSceneWait);
  ASSERT_EQ(waits.size(), 1u);
  EXPECT_EQ(waits[0].scene_wait().bytes_there(), 600u);
  // It grew until just now: waited for well past kSceneStall from the start.
  now_ += NodeProtocol::kSceneStall.count() * kMs - recheck;
  a = node.answer(SceneFetchedElsewhere{900}, now_);
  EXPECT_EQ(first<PrepareScene>(a), nullptr);
  ASSERT_NE(first<RecheckScene>(a), nullptr);

  a = node.answer(SceneFound{"/cache/scenes/abc/s.gltf"}, now_);
  ASSERT_NE(first<Configure>(a), nullptr);
  EXPECT_TRUE(logged(a, "fetched by another node of this host"));
  EXPECT_TRUE(node.due(Due::scene_recheck, now_ + recheck).empty()) << "no longer waiting";
}

// A copy that stops growing for kSceneStall is not waited for any longer: the
// node fetches the scene itself (not waiting for others).
TEST_F(SceneFetchTest, ACopyThatStopsGrowingIsNotWaitedForAndTheNodeFetches) {
  NodeProtocol node(settings());
  (void)welcome_with_files(node);
  (void)node.answer(SceneFetchedElsewhere{100}, now_);
  now_ += NodeProtocol::kSceneStall.count() * kMs - kMs;
  Actions a = node.answer(SceneFetchedElsewhere{100}, now_);
  EXPECT_EQ(first<PrepareScene>(a), nullptr) << "a millisecond short of the stall";
  now_ += kMs;
  a = node.answer(SceneFetchedElsewhere{100}, now_);
  ASSERT_NE(first<PrepareScene>(a), nullptr);
  EXPECT_FALSE(first<PrepareScene>(a)->wait_for_others);
  EXPECT_EQ(first<RecheckScene>(a), nullptr);
  EXPECT_TRUE(logged(a, "has not grown for 10 s"));
  EXPECT_TRUE(logged(a, "fetching the scene from the master"));
  a = node.answer(SceneCopyStarted{protocol::SceneFetch::Present{}}, now_);
  EXPECT_EQ(sent(a, wire::Envelope::kSceneRequest).size(), 3u);

  // The connection lost while waiting: a recheck due afterwards does nothing.
  NodeProtocol lost(settings());
  (void)welcome_with_files(lost);
  (void)lost.answer(SceneFetchedElsewhere{0}, now_);
  (void)lost.closed("gone", now_);
  EXPECT_TRUE(lost.due(Due::scene_recheck, now_).empty());
}

TEST_F(SceneFetchTest, ANodeWithoutARendererOrTooSmallALimitFetchesNothing) {
  {
    NodeSettings s = settings();
    s.needs_scene_files = false;
    NodeProtocol node(s);
    const Actions a = welcome_with_files(node);
    EXPECT_NE(first<Configure>(a), nullptr);
    EXPECT_EQ(first<PrepareScene>(a), nullptr);
  }
  {
    NodeSettings s = settings();
    s.most_scene_bytes = 1000;
    NodeProtocol node(s);
    const Actions a = welcome_with_files(node);
    ASSERT_NE(first<Stop>(a), nullptr);
    EXPECT_EQ(first<Stop>(a)->exit_code, kExitRefused);
    EXPECT_TRUE(logged(a, "--max-scene-mb"));
  }
}

TEST_F(SceneFetchTest, AWelcomeWhoseManifestDoesNotHashToTheSceneIsRefused) {
  NodeProtocol node(settings());
  wire::Envelope welcome = welcome_of(scene_.files);
  welcome.mutable_welcome()->mutable_scene_files()->mutable_files(1)->set_size(4999);
  Actions a = welcomed(node, welcome);
  ASSERT_NE(first<Stop>(a), nullptr);
  EXPECT_TRUE(logged(a, "does not hash to its SHA-256")) << "the manifest is the scene's identity";

  NodeProtocol other(settings());
  welcome = welcome_of(scene_.files);
  welcome.mutable_welcome()->mutable_scene_files()->mutable_files(1)->set_path("../../etc/s.bin");
  a = welcomed(other, welcome);
  ASSERT_NE(first<Stop>(a), nullptr);
  EXPECT_TRUE(logged(a, "leaves the scene's folder"));
}

}  // namespace
}  // namespace optique::node

namespace optique::node {
namespace {

// Behind (the master no longer waits for it): frames it is told to skip change
// the state and pass on what they carry, but are neither drawn nor answered;
// the first frame it is told to draw again is drawn.
TEST_F(NodeTest, AFrameToSkipIsAppliedButNotDrawnOrAnswered) {
  NodeProtocol node(settings());
  join(node, 3);
  const scene::SceneState before = state_;
  state_.eye_now.x += 0.25;  // what the skipped frame changes
  wire::Envelope e = envelope();
  auto& b = *e.mutable_frame_begin();
  b.set_frame_id(3);
  *b.mutable_delta() = scene::make_delta(before, state_);
  b.set_state_hash(scene::state_hash(state_));
  b.set_skip(true);
  Actions a = node.message(e, now_);
  EXPECT_EQ(first<Render>(a), nullptr);
  const Skip* skip = first<Skip>(a);
  ASSERT_NE(skip, nullptr);
  EXPECT_EQ(skip->frame.frame_id, 3u);
  EXPECT_EQ(node.state(), state_) << "the skipped frame's change is applied";
  EXPECT_TRUE(sent(a, wire::Envelope::kFrameReady).empty());
  EXPECT_TRUE(logged(a, "behind: skipping frames from frame 3"));
  // A ping falling due now is not held back for a round that never ends.
  a = node.due(Due::ping, now_);
  EXPECT_EQ(sent(a, wire::Envelope::kPing).size(), 1u);

  b.set_frame_id(4);
  b.clear_delta();
  a = node.message(e, now_);
  EXPECT_NE(first<Skip>(a), nullptr);
  EXPECT_FALSE(logged(a, "behind")) << "said once";

  a = begin(node, 5);
  const Render* render = first<Render>(a);
  ASSERT_NE(render, nullptr);
  EXPECT_EQ(render->frame.frame_id, 5u);
  EXPECT_TRUE(logged(a, "caught up: drawing frame 5 after skipping 2 frame(s)"));
  a = node.answer(FrameRendered{5, 3 * kMs, {}}, now_);
  EXPECT_EQ(sent(a, wire::Envelope::kFrameReady).size(), 1u);
}

TEST_F(NodeTest, ConfiguredSaysHowLongTheWarmUpFrameTook) {
  NodeProtocol node(settings());
  (void)node.connected(now_);
  wire::Envelope challenge = envelope();
  challenge.mutable_challenge()->set_nonce(std::string(32, 'n'));
  (void)node.message(challenge, now_);
  wire::Envelope welcome = envelope();
  *welcome.mutable_welcome() = protocol::encode_welcome(wall_, 0, {}, 4, kPeriod, nullptr);
  (void)node.message(welcome, now_);
  const Actions a = node.answer(Configured{{}, "test renderer", {420 * kMs, 130 * kMs}}, now_);
  const auto configured = sent(a, wire::Envelope::kConfigured);
  ASSERT_EQ(configured.size(), 1u);
  EXPECT_EQ(configured.front().configured().warm_up_ns(), 420 * kMs);
  EXPECT_EQ(configured.front().configured().capture_ns(), 130 * kMs);
  EXPECT_TRUE(logged(a, "warm-up frame 420.0 ms, 130.0 ms more when captured"));
}

// --- assets an application loads while the frames go on

class AssetTest : public SceneFetchTest {
 protected:
  wire::Envelope offer(const std::string& id) {
    wire::Envelope e = envelope();
    *e.mutable_asset_offer() = protocol::to_wire(protocol::AssetOffer{id, scene_.sha256, scene_.files, ""});
    return e;
  }
  static std::vector<std::string> readies(const Actions& a) {
    std::vector<std::string> out;
    for (const wire::Envelope& e : sent(a, wire::Envelope::kAssetReady)) {
      out.push_back(e.asset_ready().asset() +
                    (e.asset_ready().problem().empty() ? "" : ": " + e.asset_ready().problem()));
    }
    return out;
  }
};

// Offered in the frames: its files fetched beside them (no other node's copy
// waited for), given to the renderer, and the master told; the frames go on
// throughout, and a second offer waits for the first.
TEST_F(AssetTest, AnAssetOfferedInTheFramesIsFetchedReadiedAndAnswered) {
  NodeProtocol node(settings());
  join(node);
  Actions a = node.message(offer("duck"), now_);
  const PrepareScene* prepare = first<PrepareScene>(a);
  ASSERT_NE(prepare, nullptr);
  EXPECT_EQ(prepare->sha256, scene_.sha256);
  EXPECT_FALSE(prepare->wait_for_others);
  EXPECT_TRUE(node.joined());
  a = node.message(offer("goose"), now_);
  EXPECT_EQ(first<PrepareScene>(a), nullptr) << "one at a time";

  a = node.answer(SceneCopyStarted{protocol::SceneFetch::Present{}}, now_);
  EXPECT_EQ(sent(a, wire::Envelope::kSceneRequest).size(), 3u);
  EXPECT_TRUE(logged(a, "fetching the asset 'duck' from the master"));
  // A frame comes meanwhile, and is drawn.
  a = begin(node, 0);
  ASSERT_NE(first<Render>(a), nullptr);
  (void)node.message(chunk(0, 0, scene_.gltf), now_);
  (void)node.message(chunk(1, 0, scene_.bin.substr(0, 4096)), now_);
  a = node.message(chunk(1, 1, scene_.bin.substr(4096)), now_);
  ASSERT_NE(first<FinishScene>(a), nullptr);
  a = node.answer(SceneCopyFinished{std::string("/cache/scenes/d/s.gltf")}, now_);
  ASSERT_NE(first<ReadyAsset>(a), nullptr);
  EXPECT_EQ(first<ReadyAsset>(a)->asset.asset, "duck");
  EXPECT_EQ(first<ReadyAsset>(a)->asset.path, "/cache/scenes/d/s.gltf");
  EXPECT_NE(first<CancelDeadline>(a), nullptr) << "the fetch's stall deadline goes with it";
  EXPECT_TRUE(readies(a).empty()) << "not before the renderer has it";

  a = node.answer(AssetLoaded{"duck", {}}, now_);
  EXPECT_EQ(readies(a), std::vector<std::string>{"duck"});
  ASSERT_NE(first<PrepareScene>(a), nullptr) << "then the next";
  a = node.answer(SceneFound{"/cache/scenes/d/s.gltf"}, now_);
  ASSERT_NE(first<ReadyAsset>(a), nullptr);
  a = node.answer(AssetLoaded{"goose", Error{"texture 3 is not a PNG"}}, now_);
  EXPECT_EQ(readies(a), std::vector<std::string>{"goose: texture 3 is not a PNG"});
  EXPECT_TRUE(node.joined()) << "an asset that cannot be drawn costs the asset, not the node";
}

// Offered while the node sets up: readied once it is in the frames. A node
// that draws nothing (the null renderer) needs no files: ready at once. An
// offer of an id it has, or one the master cannot have meant, closes.
TEST_F(AssetTest, OffersWaitForTheFramesNeedNoFilesWithoutARendererAndAreChecked) {
  NodeSettings without = settings();
  without.needs_scene_files = false;
  NodeProtocol null_node(without);
  ASSERT_NE(first<Configure>(welcomed(null_node, welcome_of({}))), nullptr);
  EXPECT_TRUE(readies(null_node.message(offer("duck"), now_)).empty()) << "not in the frames yet";
  (void)null_node.answer(Configured{{}, "null", {}}, now_);
  wire::Envelope resync = envelope();
  *resync.mutable_resync()->mutable_snapshot() = scene::to_snapshot(state_);
  resync.mutable_resync()->set_state_hash(scene::state_hash(state_));
  Actions a = null_node.message(resync, now_);
  ASSERT_TRUE(null_node.joined());
  EXPECT_EQ(readies(a), std::vector<std::string>{"duck"});
  EXPECT_EQ(first<PrepareScene>(a), nullptr);
  // Offered again (it failed on another node and was loaded again): readied again.
  EXPECT_EQ(readies(null_node.message(offer("duck"), now_)), std::vector<std::string>{"duck"});

  NodeProtocol node(settings());
  join(node);
  (void)node.message(offer("swan"), now_);
  ASSERT_NE(first<Close>(node.message(offer("swan"), now_)), nullptr) << "offered twice while it is readied";
  wire::Envelope bad = offer("duck");
  bad.mutable_asset_offer()->set_scene_sha256(std::string(64, '0'));
  a = node.message(bad, now_);
  ASSERT_NE(first<Close>(a), nullptr);
  EXPECT_NE(first<Close>(a)->reason.find("does not hash to its SHA-256"), std::string::npos) << first<Close>(a)->reason;
  wire::Envelope unnamed = offer("no such id!");
  EXPECT_NE(first<Close>(node.message(unnamed, now_)), nullptr);
}

// A welcome that names assets: each is fetched after the scene, before the
// renderer is configured, which gets their paths.
TEST_F(AssetTest, AWelcomesAssetsAreFetchedBeforeTheNodeIsConfigured) {
  NodeProtocol node(settings());
  const std::vector<protocol::AssetOffer> assets{{"duck", scene_.sha256, scene_.files, ""}};
  const wire::Envelope welcome = welcome_of({}, assets);
  Actions a = welcomed(node, welcome);
  ASSERT_NE(first<PrepareScene>(a), nullptr);
  EXPECT_TRUE(first<PrepareScene>(a)->wait_for_others) << "setting up, another node's copy is waited for";
  EXPECT_EQ(first<Configure>(a), nullptr);
  a = node.answer(SceneFound{"/cache/scenes/d/s.gltf"}, now_);
  ASSERT_NE(first<Configure>(a), nullptr);
  ASSERT_EQ(first<Configure>(a)->job.assets.size(), 1u);
  EXPECT_EQ(first<Configure>(a)->job.assets[0].path, "/cache/scenes/d/s.gltf");
  // A cache that cannot hold it stops the node, as for the scene.
  NodeProtocol full(settings());
  (void)welcomed(full, welcome);
  a = full.answer(SceneCopyStarted{Error{"no room"}}, now_);
  ASSERT_NE(first<Stop>(a), nullptr);
  EXPECT_TRUE(logged(a, "cannot keep the asset 'duck' here: no room"));
}

}  // namespace
}  // namespace optique::node
