// The scene session's rules: master/session/scene_sessions.h.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "master/session/journal.h"
#include "master/session/scene_sessions.h"
#include "master/session/session_json.h"
#include "net/envelope.h"

namespace optique::master {
namespace {

const std::vector<std::uint8_t> kNonce(net::kNonceBytes, 7);

wire::Envelope hello(const std::string& name, bool capable = true) {
  wire::Envelope e;
  e.set_protocol_version(net::kProtocolVersion);
  e.mutable_hello()->set_node_id(name);
  if (capable) e.mutable_hello()->add_capabilities(kSceneSessionCapability);
  return e;
}

wire::Envelope create(std::uint64_t id, const std::string& instance, const std::string& asset) {
  wire::Envelope e;
  e.set_protocol_version(net::kProtocolVersion);
  e.mutable_session_request()->set_id(id);
  auto& c = *e.mutable_session_request()->mutable_transaction()->add_edits()->mutable_create();
  c.set_instance(instance);
  c.set_asset(asset);
  return e;
}

template <class T>
std::vector<T> of(const SessionActions& actions) {
  std::vector<T> found;
  for (const SessionAction& a : actions) {
    if (const T* t = std::get_if<T>(&a)) found.push_back(*t);
  }
  return found;
}

std::string refusal_of(const SessionActions& actions) {
  const auto sends = of<session_action::Send>(actions);
  const auto closes = of<session_action::Close>(actions);
  if (sends.size() != 1 || !sends[0].message.has_refuse() || closes.size() != 1 || !closes[0].after_sending) {
    return "not refused";
  }
  return sends[0].message.refuse().reason();
}

class SceneSessionsTest : public ::testing::Test {
 protected:
  SceneSessionsTest() { live_.add_asset("torus"); }
  LiveScene live_;
};

TEST_F(SceneSessionsTest, AnApplicationIsChallengedSaysHelloAndItsEditsNameTheirFrame) {
  SceneSessions sessions(live_, {});
  const auto greeted = sessions.accepted(1, "127.0.0.1:5000", true, kNonce);
  ASSERT_EQ(of<session_action::Send>(greeted).size(), 1u);
  const wire::Envelope challenge = of<session_action::Send>(greeted)[0].message;
  ASSERT_TRUE(challenge.has_challenge());
  EXPECT_FALSE(challenge.challenge().secret_required());
  EXPECT_EQ(challenge.challenge().nonce(), std::string(kNonce.begin(), kNonce.end()));

  const auto admitted = sessions.message(1, hello("design-review"), 40);
  ASSERT_EQ(of<session_action::Log>(admitted).size(), 1u);
  EXPECT_EQ(of<session_action::Log>(admitted)[0].text, "application 'design-review' connected from 127.0.0.1:5000");
  EXPECT_TRUE(of<session_action::Send>(admitted).empty());
  ASSERT_EQ(of<session_action::SetMaxPayload>(admitted).size(), 1u)
      << "transactions may be as large as the master's messages";
  EXPECT_EQ(of<session_action::SetMaxPayload>(admitted)[0].bytes, SceneSessionSettings{}.max_message_bytes);

  const auto applied = sessions.message(1, create(9, "t1", "torus"), 41);
  ASSERT_EQ(of<session_action::Send>(applied).size(), 1u);
  const session::Reply ok = of<session_action::Send>(applied)[0].message.session_reply();
  EXPECT_EQ(ok.id(), 9u);
  ASSERT_TRUE(ok.has_applied());
  EXPECT_EQ(ok.applied().frame(), 41u);
  EXPECT_EQ(live_.instances().count("t1"), 1u);

  const auto refused = sessions.message(1, create(10, "t2", "teapot"), 42);
  const session::Reply no = of<session_action::Send>(refused)[0].message.session_reply();
  EXPECT_EQ(no.id(), 10u);
  ASSERT_TRUE(no.has_refused());
  EXPECT_EQ(no.refused().field(), "edits[0].create.asset");
  EXPECT_EQ(no.refused().reason(), "no asset 'teapot' is loaded");
  EXPECT_TRUE(of<session_action::Close>(refused).empty()) << "a refused edit keeps the session";

  wire::Envelope empty;
  empty.set_protocol_version(net::kProtocolVersion);
  empty.mutable_session_request()->set_id(11);
  const auto unknown = sessions.message(1, empty, 42);
  EXPECT_EQ(of<session_action::Send>(unknown)[0].message.session_reply().refused().field(), "request");

  const auto left = sessions.closed(1, "connection reset");
  EXPECT_EQ(of<session_action::Log>(left)[0].text,
            "application 'design-review' at 127.0.0.1:5000 left: connection reset");
  EXPECT_EQ(sessions.open(), 0u);
}

TEST_F(SceneSessionsTest, WhatIsNotAnApplicationIsRefused) {
  SceneSessions sessions(live_, {});
  (void)sessions.accepted(1, "a", true, kNonce);
  EXPECT_NE(refusal_of(sessions.message(1, hello("node-1", false), 0)).find("say \"scene-session\""),
            std::string::npos);
  (void)sessions.accepted(2, "b", true, kNonce);
  EXPECT_NE(refusal_of(sessions.message(2, hello("a b"), 0)).find("name the application"), std::string::npos);
  (void)sessions.accepted(3, "c", true, kNonce);
  EXPECT_EQ(refusal_of(sessions.message(3, create(1, "t", "torus"), 0)), "expected hello, got session_request");
  EXPECT_TRUE(live_.instances().empty());
  (void)sessions.accepted(4, "d", true, kNonce);
  wire::Envelope old = hello("app");
  old.set_protocol_version(net::kProtocolVersion - 1);
  EXPECT_NE(refusal_of(sessions.message(4, old, 0)).find("protocol version mismatch"), std::string::npos);
  // After its hello, a node's message closes the session.
  (void)sessions.accepted(5, "e", true, kNonce);
  (void)sessions.message(5, hello("app"), 0);
  wire::Envelope ready;
  ready.set_protocol_version(net::kProtocolVersion);
  ready.mutable_frame_ready()->set_frame_id(3);
  const auto closed = of<session_action::Close>(sessions.message(5, ready, 0));
  ASSERT_EQ(closed.size(), 1u);
  EXPECT_EQ(closed[0].reason, "unexpected frame_ready from an application");
}

TEST_F(SceneSessionsTest, FromAnotherMachineOnlyWithTheSecret) {
  SceneSessions open(live_, {});
  EXPECT_NE(refusal_of(open.accepted(1, "10.0.0.5:4000", false, kNonce)).find("only with the shared secret"),
            std::string::npos);

  SceneSessionSettings settings;
  settings.secret = net::Secret{std::vector<std::uint8_t>(32, 9)};
  SceneSessions guarded(live_, settings);
  const auto greeted = guarded.accepted(2, "10.0.0.5:4001", false, kNonce);
  EXPECT_TRUE(of<session_action::Send>(greeted)[0].message.challenge().secret_required());
  EXPECT_NE(refusal_of(guarded.message(2, hello("app"), 0)).find("requires the installation's shared secret"),
            std::string::npos);

  const std::vector<std::uint8_t> app_nonce(net::kNonceBytes, 3);
  std::vector<std::uint8_t> both = kNonce;
  both.insert(both.end(), app_nonce.begin(), app_nonce.end());
  const auto with_mac = [&](const net::Secret& secret) {
    wire::Envelope e = hello("app");
    const auto mac = net::hello_mac(secret, both, "app", net::kProtocolVersion);
    e.mutable_hello()->set_nonce_mac(std::string(mac.begin(), mac.end()));
    e.mutable_hello()->set_node_nonce(std::string(app_nonce.begin(), app_nonce.end()));
    return e;
  };
  (void)guarded.accepted(3, "10.0.0.5:4002", false, kNonce);
  EXPECT_NE(refusal_of(guarded.message(3, with_mac(net::Secret{std::vector<std::uint8_t>(32, 8)}), 0))
                .find("the application's secret does not match"),
            std::string::npos);
  (void)guarded.accepted(4, "10.0.0.5:4003", false, kNonce);
  const auto admitted = guarded.message(4, with_mac(*settings.secret), 0);
  EXPECT_EQ(of<session_action::Protect>(admitted).size(), 1u) << "everything after the hello is sealed";
  EXPECT_EQ(of<session_action::Send>(guarded.message(4, create(1, "t", "torus"), 5)).size(), 1u);
}

// With a journal (--record), an applied transaction is journalled, with its
// frame and the application's name, before the reply says it was applied; a
// refused one is not. Without, nothing is.
TEST_F(SceneSessionsTest, AppliedTransactionsAreJournalledBeforeTheReply) {
  for (const bool journal : {true, false}) {
    LiveScene live;
    live.add_asset("torus");
    SceneSessionSettings settings;
    settings.journal = journal;
    SceneSessions sessions(live, settings);
    (void)sessions.accepted(1, "127.0.0.1:5000", true, kNonce);
    (void)sessions.message(1, hello("design-review"), 0);
    const auto applied = sessions.message(1, create(4, "t1", "torus"), 12);
    ASSERT_EQ(applied.size(), journal ? 2u : 1u);
    if (journal) {
      const auto* entry = std::get_if<session_action::Journal>(&applied[0]);
      ASSERT_NE(entry, nullptr) << "the journal entry comes first";
      ASSERT_TRUE(std::holds_alternative<session_action::Send>(applied[1]));
      auto read = read_journal(std::string(kJournalMagic) + journal_start(0, "torus") + entry->entry);
      ASSERT_TRUE(read.ok()) << read.error();
      ASSERT_EQ(read.value().runs.size(), 1u);
      ASSERT_EQ(read.value().runs[0].transactions.size(), 1u);
      const auto& t = read.value().runs[0].transactions[0];
      EXPECT_EQ(t.frame(), 12u);
      EXPECT_EQ(t.application(), "design-review");
      EXPECT_EQ(t.transaction().edits(0).create().instance(), "t1");
    }
    const auto refused = sessions.message(1, create(5, "t2", "teapot"), 13);
    EXPECT_TRUE(of<session_action::Journal>(refused).empty());
    EXPECT_EQ(of<session_action::Send>(refused).size(), 1u);
  }
}

// An application that (re)connects reads the live scene as it is: the assets,
// and each instance with the values its edits gave it.
TEST_F(SceneSessionsTest, AnApplicationReadsTheSceneAsItIs) {
  SceneSessions sessions(live_, {});
  (void)sessions.accepted(1, "127.0.0.1:5000", true, kNonce);
  (void)sessions.message(1, hello("design-review"), 0);
  wire::Envelope edits = create(1, "table", "torus");
  auto& transaction = *edits.mutable_session_request()->mutable_transaction();
  auto& cup = *transaction.add_edits()->mutable_create();
  cup.set_instance("cup");
  cup.set_asset("torus");
  cup.set_parent("table");
  cup.set_hidden(true);
  for (double v : {1.0, 2.0, 3.0}) cup.mutable_transform()->add_position(v);
  for (double v : {0.0, 0.0, 2.0, 0.0}) cup.mutable_transform()->add_rotation(v);  // normalized: a half turn about y
  cup.mutable_transform()->add_scale(0.5);
  auto& factors = *transaction.add_edits()->mutable_factors();
  factors.set_instance("cup");
  for (double v : {0.5, 0.25, 1.0, 1.0}) factors.add_base_color(v);
  ASSERT_EQ(of<session_action::Send>(sessions.message(1, edits, 3))[0].message.session_reply().reply_case(),
            session::Reply::kApplied);

  wire::Envelope read;
  read.set_protocol_version(net::kProtocolVersion);
  read.mutable_session_request()->set_id(9);
  read.mutable_session_request()->mutable_read_scene();
  const auto sent = of<session_action::Send>(sessions.message(1, read, 4));
  ASSERT_EQ(sent.size(), 1u);
  const session::Reply& reply = sent[0].message.session_reply();
  EXPECT_EQ(reply.id(), 9u);
  ASSERT_TRUE(reply.has_scene());
  const session::SceneContents& scene = reply.scene();
  EXPECT_EQ(scene.frame(), 4u);
  ASSERT_EQ(scene.assets_size(), 1);
  EXPECT_EQ(scene.assets(0), "torus");
  ASSERT_EQ(scene.instances_size(), 2);
  const session::InstanceView& c = scene.instances(0);  // by id: "cup" before "table"
  EXPECT_EQ(c.instance(), "cup");
  EXPECT_EQ(c.parent(), "table");
  EXPECT_TRUE(c.hidden());
  EXPECT_EQ(std::vector<double>(c.transform().position().begin(), c.transform().position().end()),
            (std::vector<double>{1.0, 2.0, 3.0}));
  EXPECT_EQ(std::vector<double>(c.transform().rotation().begin(), c.transform().rotation().end()),
            (std::vector<double>{0.0, 0.0, 1.0, 0.0}));
  EXPECT_EQ(std::vector<double>(c.transform().scale().begin(), c.transform().scale().end()),
            (std::vector<double>{0.5, 0.5, 0.5}));
  EXPECT_EQ(std::vector<double>(c.base_color().begin(), c.base_color().end()),
            (std::vector<double>{0.5, 0.25, 1.0, 1.0}));
  EXPECT_EQ(std::vector<double>(c.emissive().begin(), c.emissive().end()), (std::vector<double>{1.0, 1.0, 1.0}));
  EXPECT_EQ(scene.instances(1).instance(), "table");
  EXPECT_EQ(scene.instances(1).parent(), "");
  EXPECT_FALSE(scene.instances(1).hidden());
}

wire::Envelope subscribe(std::uint64_t id, bool frames, bool head, bool run, bool nodes) {
  wire::Envelope e;
  e.set_protocol_version(net::kProtocolVersion);
  e.mutable_session_request()->set_id(id);
  auto& s = *e.mutable_session_request()->mutable_subscribe();
  s.set_frames(frames);
  s.set_head(head);
  s.set_run(run);
  s.set_nodes(nodes);
  return e;
}

// Each application gets the events of the kinds it subscribed to, and no
// other; one that has not said hello gets none.
TEST_F(SceneSessionsTest, EventsGoToTheirSubscribersOnly) {
  SceneSessions sessions(live_, {});
  for (SessionId id : {1, 2, 3}) (void)sessions.accepted(id, "127.0.0.1:500" + std::to_string(id), true, kNonce);
  (void)sessions.message(1, hello("frames-only"), 0);
  (void)sessions.message(2, hello("nodes-and-run"), 0);
  const auto answer = of<session_action::Send>(sessions.message(1, subscribe(7, true, false, false, false), 0));
  ASSERT_EQ(answer.size(), 1u);
  EXPECT_EQ(answer[0].message.session_reply().id(), 7u);
  EXPECT_TRUE(answer[0].message.session_reply().subscribed().frames());
  (void)sessions.message(2, subscribe(1, false, false, true, true), 0);

  const auto sent_to = [&](const session::Event& event) {
    std::vector<SessionId> to;
    for (const auto& send : of<session_action::Send>(sessions.publish(event))) {
      EXPECT_TRUE(send.message.has_session_event());
      to.push_back(send.session);
    }
    return to;
  };
  session::Event frame;
  frame.mutable_frame_begun()->set_frame(12);
  session::Event head;
  head.mutable_head()->set_frame(12);
  session::Event run;
  run.mutable_run()->set_state(session::RunChanged::PAUSED);
  session::Event node;
  node.mutable_node()->set_projector("top-left");
  EXPECT_EQ(sent_to(frame), std::vector<SessionId>{1});
  EXPECT_EQ(sent_to(head), std::vector<SessionId>{});
  EXPECT_EQ(sent_to(run), std::vector<SessionId>{2});
  EXPECT_EQ(sent_to(node), std::vector<SessionId>{2});
  (void)sessions.message(1, subscribe(8, false, false, false, false), 0);  // all off again
  EXPECT_EQ(sent_to(frame), std::vector<SessionId>{});
}

// An application with more than max_queued_bytes waiting for longer than
// stalled_for has stopped reading: it is closed, and sent nothing more. A
// queue that drains in time is no fault.
TEST_F(SceneSessionsTest, ASubscriberThatStopsReadingIsClosed) {
  SceneSessionSettings settings;
  settings.max_queued_bytes = 1000;
  settings.stalled_for = std::chrono::seconds(5);
  SceneSessions sessions(live_, settings);
  (void)sessions.accepted(1, "127.0.0.1:5000", true, kNonce);
  (void)sessions.message(1, hello("slow"), 0);
  (void)sessions.message(1, subscribe(1, true, false, false, false), 0);
  constexpr clock::Nanos kSecond = 1'000'000'000;
  EXPECT_TRUE(sessions.queued(1, 5000, 0).empty());
  EXPECT_TRUE(sessions.queued(1, 900, 4 * kSecond).empty()) << "drained in time";
  EXPECT_TRUE(sessions.queued(1, 5000, 6 * kSecond).empty()) << "over again from 6 s";
  EXPECT_TRUE(sessions.queued(1, 5000, 10 * kSecond).empty());
  const auto closed = sessions.queued(1, 6000, 11 * kSecond);
  ASSERT_EQ(of<session_action::Close>(closed).size(), 1u);
  EXPECT_EQ(of<session_action::Close>(closed)[0].reason, "it stopped reading: 6000 bytes have waited for it for 5 s");
  ASSERT_EQ(of<session_action::Log>(closed).size(), 1u);
  EXPECT_EQ(of<session_action::Log>(closed)[0].text,
            "closed application 'slow' at 127.0.0.1:5000: it stopped reading: 6000 bytes have waited for it for 5 s");
  session::Event frame;
  frame.mutable_frame_begun()->set_frame(1);
  EXPECT_TRUE(sessions.publish(frame).empty());
}

TEST_F(SceneSessionsTest, TheNumberOfSessionsIsBounded) {
  SceneSessionSettings settings;
  settings.max_sessions = 2;
  SceneSessions sessions(live_, settings);
  EXPECT_EQ(refusal_of(sessions.accepted(1, "a", true, kNonce)), "not refused");
  EXPECT_EQ(refusal_of(sessions.accepted(2, "b", true, kNonce)), "not refused");
  EXPECT_EQ(refusal_of(sessions.accepted(3, "c", true, kNonce)), "the master holds 2 scene sessions, the most it may");
  (void)sessions.closed(3, "refused");
  (void)sessions.closed(1, "gone");
  EXPECT_EQ(refusal_of(sessions.accepted(4, "d", true, kNonce)), "not refused");
}

// A WebSocket's application (opened by the operator's server, which checked
// who may): no challenge or hello, the same requests, the same bound on
// sessions; a message that is no request is answered, and the session goes on.
TEST_F(SceneSessionsTest, AnApplicationOpenedByTheOperatorsServerNeedsNoHello) {
  SceneSessionSettings settings;
  settings.max_sessions = 2;
  SceneSessions sessions(live_, settings);
  const SessionActions opened = sessions.opened(1, "127.0.0.1:1 (WebSocket)", "page");
  EXPECT_TRUE(of<session_action::Send>(opened).empty()) << "no challenge";
  ASSERT_EQ(of<session_action::Log>(opened).size(), 1u);
  EXPECT_EQ(of<session_action::Log>(opened)[0].text, "application 'page' connected from 127.0.0.1:1 (WebSocket)");
  auto answer = of<session_action::Send>(sessions.request(1, create(5, "t1", "torus").session_request(), 12));
  ASSERT_EQ(answer.size(), 1u);
  EXPECT_EQ(answer[0].message.session_reply().id(), 5u);
  EXPECT_EQ(answer[0].message.session_reply().applied().frame(), 12u);
  EXPECT_EQ(live_.instances().size(), 1u);
  answer = of<session_action::Send>(sessions.unreadable(1, "not a Request: x"));
  ASSERT_EQ(answer.size(), 1u);
  EXPECT_EQ(answer[0].message.session_reply().id(), 0u);
  EXPECT_EQ(answer[0].message.session_reply().refused().field(), "request");
  EXPECT_EQ(answer[0].message.session_reply().refused().reason(), "not a Request: x");

  EXPECT_EQ(refusal_of(sessions.opened(2, "b", "bad name!")),
            "name the application: 1 to 64 letters, digits, '-', '_' or '.'");
  EXPECT_TRUE(sessions.request(2, create(6, "t2", "torus").session_request(), 12).empty()) << "refused: nothing";
  EXPECT_TRUE(sessions.unreadable(2, "x").empty());
  (void)sessions.closed(2, "refused");
  EXPECT_EQ(refusal_of(sessions.accepted(3, "c", true, kNonce)), "not refused");
  EXPECT_EQ(refusal_of(sessions.opened(4, "d", "late")), "the master holds 2 scene sessions, the most it may");
  EXPECT_TRUE(sessions.request(3, create(7, "t3", "torus").session_request(), 12).empty()) << "no hello yet";
  EXPECT_EQ(live_.instances().size(), 1u);
}

TEST(SessionJson, ARequestIsReadFromItsJsonAndAnythingElseIsNamed) {
  auto read = request_from_json(
      R"({"id": 7, "transaction": {"edits": [{"create": {"instance": "a", "asset": "torus",
          "transform": {"position": [1, 2.5, -3], "scale": [2]}}}, {"visible": {"instance": "a"}}]}})");
  ASSERT_TRUE(read.ok()) << read.error();
  EXPECT_EQ(read.value().id(), 7u);
  ASSERT_EQ(read.value().transaction().edits_size(), 2);
  const auto& created = read.value().transaction().edits(0).create();
  EXPECT_EQ(created.asset(), "torus");
  EXPECT_EQ(created.transform().position(1), 2.5);
  EXPECT_EQ(created.transform().scale_size(), 1);
  EXPECT_TRUE(read.value().transaction().edits(1).has_visible());
  read = request_from_json(R"({"id": "18446744073709551615", "readScene": {}})");
  ASSERT_TRUE(read.ok()) << read.error() << " (64-bit numbers as strings, names in lowerCamelCase)";
  EXPECT_EQ(read.value().id(), 18446744073709551615u);
  EXPECT_TRUE(read.value().has_read_scene());

  read = request_from_json(R"({"id": 1, "teleport": {}})");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("teleport"), std::string::npos) << read.error();
  read = request_from_json(R"({"id": 1, "transaction": {"edits": [{"create": {"instance": 5}}]}})");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("instance"), std::string::npos) << read.error();
  for (const char* bad : {"", "[", "{\"id\": -1}", "\xff\xfe", "{\"id\": 1} trailing"}) {
    EXPECT_FALSE(request_from_json(bad).ok()) << bad;
  }
}

TEST(SessionJson, WhatAnApplicationHearsIsOneObjectNamingItsKind) {
  wire::Envelope applied;
  applied.mutable_session_reply()->set_id(3);
  applied.mutable_session_reply()->mutable_applied()->set_frame(40);
  EXPECT_EQ(to_application_json(applied), R"({"reply":{"id":"3","applied":{"frame":"40"}}})");
  wire::Envelope event;
  event.mutable_session_event()->mutable_run()->set_frame(9);
  EXPECT_EQ(to_application_json(event), R"({"event":{"run":{"state":"RUNNING","frame":"9","reason":""}}})")
      << "every field given, even at its default";
  EXPECT_EQ(to_application_json(net::refusal("full", true)), R"({"closing":{"reason":"full","retriable":true}})");
  wire::Envelope goodbye;
  goodbye.mutable_goodbye()->set_reason("the master is shutting down");
  EXPECT_EQ(to_application_json(goodbye), R"({"closing":{"reason":"the master is shutting down","retriable":false}})");
  wire::Envelope challenge;
  challenge.mutable_challenge()->set_nonce("n");
  EXPECT_EQ(to_application_json(challenge), "") << "nothing an application hears over JSON";
}

// LoadAsset: each source checked (a refusal names its field), then loaded by
// the shell (LoadAsset action) and answered when the master says it is
// usable, the journal told first; until then the id is taken and an instance
// of it is refused as still loading.
TEST_F(SceneSessionsTest, LoadAssetIsCheckedLoadedByTheShellAndAnsweredWhenUsable) {
  SceneSessionSettings settings;
  settings.journal = true;
  settings.assets_folder = "/srv/models";
  settings.max_loading = 2;
  SceneSessions sessions(live_, settings);
  (void)sessions.accepted(1, "127.0.0.1:5000", true, kNonce);
  (void)sessions.message(1, hello("loader"), 0);
  const auto load = [&](std::uint64_t id, const std::string& asset, const std::string* path, const std::string* glb) {
    wire::Envelope e;
    e.set_protocol_version(net::kProtocolVersion);
    e.mutable_session_request()->set_id(id);
    auto& l = *e.mutable_session_request()->mutable_load_asset();
    l.set_asset(asset);
    if (path) l.set_path(*path);
    if (glb) l.set_glb(*glb);
    return sessions.message(1, e, 7);
  };
  const auto refused = [](const SessionActions& a) {
    const auto sends = of<session_action::Send>(a);
    if (sends.size() != 1 || !sends[0].message.session_reply().has_refused()) return std::string("not refused");
    return sends[0].message.session_reply().refused().field() + ": " +
           sends[0].message.session_reply().refused().reason();
  };
  const std::string up = "../etc/passwd", absolute = "/etc/passwd", fine = "duck/duck.gltf", junk = "not a glb";
  const std::string glb = std::string("glTF") + std::string(20, '\0');
  EXPECT_EQ(refused(load(1, "a b", &fine, nullptr)),
            "load_asset.asset: must be 1 to 64 letters, digits, '-', '_' or '.'");
  EXPECT_EQ(refused(load(2, "torus", &fine, nullptr)),
            "load_asset.asset: 'torus' is loaded already (an id names one asset for good)");
  EXPECT_EQ(refused(load(3, "duck", &up, nullptr)), "load_asset.path: must not leave master.api.assets ('..')");
  EXPECT_EQ(refused(load(4, "duck", &absolute, nullptr)),
            "load_asset.path: must be a file inside master.api.assets, relative to it");
  EXPECT_EQ(refused(load(5, "duck", nullptr, &junk)),
            "load_asset.glb: is not a binary glTF (.glb): it does not begin with \"glTF\"");
  EXPECT_EQ(refused(load(6, "duck", nullptr, nullptr)),
            "load_asset: give the asset's path (inside master.api.assets) or its glb bytes");

  auto a = load(7, "duck", &fine, nullptr);
  EXPECT_TRUE(of<session_action::Send>(a).empty()) << "answered once loaded";
  ASSERT_EQ(of<session_action::LoadAsset>(a).size(), 1u);
  EXPECT_EQ(of<session_action::LoadAsset>(a)[0].path, "/srv/models/duck/duck.gltf");
  a = load(8, "goose", nullptr, &glb);
  ASSERT_EQ(of<session_action::LoadAsset>(a).size(), 1u);
  EXPECT_EQ(of<session_action::LoadAsset>(a)[0].glb, glb);
  EXPECT_EQ(refused(load(9, "swan", &fine, nullptr)),
            "load_asset: 2 assets are loading, the most at once: ask again once one is answered");
  EXPECT_EQ(refused(load(10, "duck", &fine, nullptr)),
            "load_asset.asset: 'duck' is loaded already (an id names one asset for good)");
  const auto still = sessions.message(1, create(11, "d1", "duck"), 7);
  EXPECT_EQ(of<session_action::Send>(still)[0].message.session_reply().refused().reason(),
            "'duck' is still loading (its LoadAsset has not been answered)");

  a = sessions.asset_loaded("duck", 12, true, "/srv/models/duck/duck.gltf", "abc");
  ASSERT_EQ(a.size(), 2u);
  ASSERT_TRUE(std::holds_alternative<session_action::Journal>(a[0])) << "the journal before the reply";
  auto journal = read_journal(std::string(kJournalMagic) + journal_start(0, "cubes") +
                              std::get<session_action::Journal>(a[0]).entry);
  ASSERT_TRUE(journal) << journal.error();
  ASSERT_EQ(journal.value().assets.size(), 1u);
  EXPECT_EQ(journal.value().assets[0].asset(), "duck");
  EXPECT_EQ(journal.value().assets[0].path(), "/srv/models/duck/duck.gltf");
  EXPECT_EQ(journal.value().assets[0].frame(), 12u);
  const session::Reply done = std::get<session_action::Send>(a[1]).message.session_reply();
  EXPECT_EQ(done.id(), 7u);
  EXPECT_EQ(done.applied().frame(), 12u);
  // Animated: each instance plays on its own clock from its frame.
  const auto placed = sessions.message(1, create(12, "d1", "duck"), 13);
  EXPECT_TRUE(of<session_action::Send>(placed)[0].message.session_reply().has_applied());
  ASSERT_TRUE(live_.instances().at("d1").animation.has_value());
  EXPECT_EQ(live_.instances().at("d1").animation->anchor, 13u);

  a = sessions.asset_failed("goose", "load_asset", "node 'x' cannot draw it: no");
  const auto failed = of<session_action::Send>(a);
  ASSERT_EQ(failed.size(), 1u);
  EXPECT_EQ(failed[0].message.session_reply().id(), 8u);
  EXPECT_EQ(failed[0].message.session_reply().refused().reason(), "node 'x' cannot draw it: no");
  EXPECT_FALSE(live_.is_loading("goose"));
  EXPECT_FALSE(live_.has_asset("goose"));

  // At most kMaxAssets besides the installation's own (what a node's welcome takes).
  for (std::size_t i = live_.assets().size(); i <= scene::kMaxAssets; ++i) live_.add_asset("a" + std::to_string(i));
  EXPECT_EQ(refused(load(13, "one-more", &fine, nullptr)),
            "load_asset: the live scene holds 256 assets an application loaded, the most it may");
}

}  // namespace
}  // namespace optique::master
