#include "master/session/scene_sessions.h"

#include <algorithm>
#include <filesystem>

#include "log/escape.h"
#include "master/session/journal.h"
#include "net/envelope.h"
#include "net/hello_proof.h"

namespace optique::master {
namespace {

using session_action::Close;
using session_action::Log;
using session_action::Protect;
using session_action::Send;

wire::Envelope reply(std::uint64_t id) {
  wire::Envelope envelope;
  envelope.mutable_session_reply()->set_id(id);
  return envelope;
}

}  // namespace

SessionActions SceneSessions::accepted(SessionId id, const std::string& peer_text, bool loopback,
                                       const std::vector<std::uint8_t>& nonce) {
  SessionActions out;
  Session& session = sessions_[id];
  session.peer_text = peer_text;
  session.nonce = nonce;
  if (!loopback && !settings_.secret) {
    refuse(id, session, "this master takes applications from other machines only with the shared secret", false, out);
    return out;
  }
  if (!admit(id, session, out)) return out;
  wire::Envelope challenge;
  challenge.set_protocol_version(net::kProtocolVersion);
  challenge.mutable_challenge()->set_nonce(std::string(nonce.begin(), nonce.end()));
  challenge.mutable_challenge()->set_secret_required(settings_.secret.has_value());
  out.push_back(Send{id, std::move(challenge)});
  return out;
}

SessionActions SceneSessions::opened(SessionId id, const std::string& peer_text, const std::string& application) {
  SessionActions out;
  Session& session = sessions_[id];
  session.peer_text = peer_text;
  if (!admit(id, session, out)) return out;
  if (!scene::is_instance_id(application)) {
    refuse(id, session, "name the application: 1 to 64 letters, digits, '-', '_' or '.'", false, out);
    return out;
  }
  connected(session, application, out);
  return out;
}

bool SceneSessions::answerable(SessionId id) const {
  const auto found = sessions_.find(id);
  return found != sessions_.end() && !found->second.refused && !found->second.application.empty();
}

SessionActions SceneSessions::request(SessionId id, const session::Request& request, std::uint64_t next_frame) {
  SessionActions out;
  if (answerable(id)) on_request(id, request, next_frame, out);
  return out;
}

SessionActions SceneSessions::unreadable(SessionId id, const std::string& reason) const {
  SessionActions out;
  if (!answerable(id)) return out;
  wire::Envelope answer = reply(0);  // its id could not be read
  answer.mutable_session_reply()->mutable_refused()->set_field("request");
  answer.mutable_session_reply()->mutable_refused()->set_reason(reason);
  out.push_back(Send{id, std::move(answer)});
  return out;
}

bool SceneSessions::admit(SessionId id, Session& session, SessionActions& out) {
  if (sessions_.size() <= settings_.max_sessions) return true;
  refuse(id, session, "the master holds " + std::to_string(settings_.max_sessions) + " scene sessions, the most it may",
         true, out);
  return false;
}

void SceneSessions::connected(Session& session, const std::string& application, SessionActions& out) {
  session.application = application;
  out.push_back(
      Log{spdlog::level::info, "application '" + session.application + "' connected from " + session.peer_text});
}

SessionActions SceneSessions::message(SessionId id, const wire::Envelope& message, std::uint64_t next_frame) {
  SessionActions out;
  const auto found = sessions_.find(id);
  if (found == sessions_.end() || found->second.refused) return out;
  Session& session = found->second;
  if (session.application.empty()) {
    on_hello(id, session, message, out);
    return out;
  }
  if (message.protocol_version() != net::kProtocolVersion) {
    out.push_back(Close{id, "protocol version changed mid-connection"});
    return out;
  }
  switch (message.body_case()) {
    case wire::Envelope::kSessionRequest:
      on_request(id, message.session_request(), next_frame, out);
      break;
    case wire::Envelope::kHeartbeat:
      break;
    case wire::Envelope::kGoodbye:
      out.push_back(Close{id, "the application said goodbye"});
      break;
    default:
      out.push_back(Close{id, std::string("unexpected ") + net::body_name(message) + " from an application"});
      break;
  }
  return out;
}

SessionActions SceneSessions::closed(SessionId id, const std::string& reason) {
  SessionActions out;
  const auto found = sessions_.find(id);
  if (found == sessions_.end()) return out;
  if (!found->second.application.empty()) {
    out.push_back(Log{spdlog::level::info, "application '" + found->second.application + "' at " +
                                               found->second.peer_text + " left: " + reason});
  }
  sessions_.erase(found);
  return out;
}

SessionActions SceneSessions::publish(const session::Event& event) const {
  // Which subscription takes this kind of event (none: a kind not set).
  bool (session::Subscribe::*wants)() const = nullptr;
  switch (event.event_case()) {
    case session::Event::kFrameBegun:
      wants = &session::Subscribe::frames;
      break;
    case session::Event::kHead:
      wants = &session::Subscribe::head;
      break;
    case session::Event::kRun:
      wants = &session::Subscribe::run;
      break;
    case session::Event::kNode:
      wants = &session::Subscribe::nodes;
      break;
    case session::Event::kFlystick:
      wants = &session::Subscribe::flysticks;
      break;
    case session::Event::EVENT_NOT_SET:
      break;
  }
  SessionActions out;
  if (wants == nullptr) return out;
  wire::Envelope envelope;
  *envelope.mutable_session_event() = event;
  for (const auto& [id, session] : sessions_) {
    if (session.application.empty() || session.refused || !(session.subscribed.*wants)()) continue;
    out.push_back(Send{id, envelope});
  }
  return out;
}

SessionActions SceneSessions::queued(SessionId id, std::size_t bytes, clock::Nanos now) {
  SessionActions out;
  const auto found = sessions_.find(id);
  if (found == sessions_.end() || found->second.refused) return out;
  Session& session = found->second;
  if (bytes <= settings_.max_queued_bytes) {
    session.over_since.reset();
    return out;
  }
  if (!session.over_since) session.over_since = now;
  if (now - *session.over_since < settings_.stalled_for.count()) return out;
  const std::string reason =
      "it stopped reading: " + std::to_string(bytes) + " bytes have waited for it for " +
      std::to_string(std::chrono::duration_cast<std::chrono::seconds>(settings_.stalled_for).count()) + " s";
  out.push_back(Log{spdlog::level::warn,
                    "closed application '" + session.application + "' at " + session.peer_text + ": " + reason});
  session.refused = true;  // nothing more is sent to it
  out.push_back(Close{id, reason});
  return out;
}

void SceneSessions::refuse(SessionId id, Session& session, const std::string& reason, bool retriable,
                           SessionActions& out) {
  out.push_back(Log{spdlog::level::warn, "refused an application at " + session.peer_text + ": " + reason});
  session.refused = true;
  out.push_back(Send{id, net::refusal(reason, retriable)});
  out.push_back(Close{id, "refused: " + reason, true});
}

void SceneSessions::on_hello(SessionId id, Session& session, const wire::Envelope& message, SessionActions& out) {
  if (message.body_case() != wire::Envelope::kHello) {
    refuse(id, session, std::string("expected hello, got ") + net::body_name(message), false, out);
    return;
  }
  const wire::Hello& hello = message.hello();
  if (message.protocol_version() != net::kProtocolVersion) {
    refuse(id, session,
           "protocol version mismatch: the application speaks v" + std::to_string(message.protocol_version()) +
               ", the master v" + std::to_string(net::kProtocolVersion),
           false, out);
    return;
  }
  const auto& capabilities = hello.capabilities();
  if (std::find(capabilities.begin(), capabilities.end(), kSceneSessionCapability) == capabilities.end()) {
    refuse(id, session,
           std::string("this port is the scene session: say \"") + kSceneSessionCapability +
               "\" among the hello's capabilities",
           false, out);
    return;
  }
  // Its name goes into logs and the operator's page as it is.
  if (!scene::is_instance_id(hello.node_id())) {
    refuse(id, session, "name the application in the hello: 1 to 64 letters, digits, '-', '_' or '.'", false, out);
    return;
  }
  if (settings_.secret) {
    auto keys = net::check_hello(*settings_.secret, session.nonce, hello, message.protocol_version(), "application",
                                 "give the application the installation's secret file");
    if (!keys) {
      refuse(id, session, keys.error(), false, out);
      return;
    }
    out.push_back(Protect{id, keys.value()});
  }
  out.push_back(session_action::SetMaxPayload{id, settings_.max_message_bytes});
  connected(session, hello.node_id(), out);
}

void SceneSessions::on_request(SessionId id, const session::Request& request, std::uint64_t next_frame,
                               SessionActions& out) {
  wire::Envelope answer = reply(request.id());
  switch (request.request_case()) {
    case session::Request::kTransaction:
      if (auto refusal = live_.apply(request.transaction(), next_frame)) {
        auto& refused = *answer.mutable_session_reply()->mutable_refused();
        refused.set_edit(static_cast<std::uint32_t>(refusal->edit));
        refused.set_field(refusal->field);
        refused.set_reason(refusal->reason);
      } else {
        if (settings_.journal) {
          out.push_back(session_action::Journal{
              journal_transaction(next_frame, sessions_.at(id).application, request.transaction())});
        }
        answer.mutable_session_reply()->mutable_applied()->set_frame(next_frame);
      }
      break;
    case session::Request::kSubscribe:
      sessions_.at(id).subscribed = request.subscribe();
      *answer.mutable_session_reply()->mutable_subscribed() = request.subscribe();
      break;
    case session::Request::kReadScene:
      *answer.mutable_session_reply()->mutable_scene() = scene_contents(live_, next_frame);
      break;
    case session::Request::kLoadAsset: {
      const session::LoadAsset& load = request.load_asset();
      if (auto problem = load_problem(load)) {
        answer.mutable_session_reply()->mutable_refused()->set_field(problem->first);
        answer.mutable_session_reply()->mutable_refused()->set_reason(problem->second);
        break;
      }
      live_.set_loading(load.asset(), true);
      loading_[load.asset()] = Asking{id, request.id()};
      const bool from_file = load.source_case() == session::LoadAsset::kPath;
      out.push_back(Log{spdlog::level::info,
                        "application '" + sessions_.at(id).application + "' loads asset '" + load.asset() + "' " +
                            (from_file ? "from " + log::escape_for_log(load.path())
                                       : "from " + std::to_string(load.glb().size()) + " bytes it sent")});
      out.push_back(session_action::LoadAsset{
          load.asset(),
          from_file ? (std::filesystem::path(settings_.assets_folder) / load.path()).lexically_normal().string() : "",
          from_file ? "" : load.glb()});
      return;  // answered once it is loaded
    }
    case session::Request::REQUEST_NOT_SET:
      answer.mutable_session_reply()->mutable_refused()->set_field("request");
      answer.mutable_session_reply()->mutable_refused()->set_reason("is empty or of a kind this master does not know");
      break;
  }
  out.push_back(Send{id, std::move(answer)});
}

std::optional<std::pair<std::string, std::string>> SceneSessions::load_problem(const session::LoadAsset& load) const {
  const auto wrong = [](std::string field, std::string reason) {
    return std::make_optional(std::make_pair(std::move(field), std::move(reason)));
  };
  if (!scene::is_instance_id(load.asset())) {
    return wrong("load_asset.asset", "must be 1 to 64 letters, digits, '-', '_' or '.'");
  }
  if (live_.has_asset(load.asset()) || live_.is_loading(load.asset())) {
    return wrong("load_asset.asset", "'" + load.asset() + "' is loaded already (an id names one asset for good)");
  }
  if (live_.assets().size() + loading_.size() >= scene::kMaxAssets + 1) {  // the installation's own scene is one
    return wrong("load_asset", "the live scene holds " + std::to_string(scene::kMaxAssets) +
                                   " assets an application loaded, the most it may");
  }
  if (loading_.size() >= settings_.max_loading) {
    return wrong("load_asset", std::to_string(settings_.max_loading) +
                                   " assets are loading, the most at once: ask again once one is answered");
  }
  switch (load.source_case()) {
    case session::LoadAsset::kPath: {
      const std::filesystem::path path(load.path());
      if (load.path().empty() || path.is_absolute()) {
        return wrong("load_asset.path", "must be a file inside master.api.assets, relative to it");
      }
      for (const auto& part : path.lexically_normal()) {
        if (part == "..") return wrong("load_asset.path", "must not leave master.api.assets ('..')");
      }
      return std::nullopt;
    }
    case session::LoadAsset::kGlb:
      // A binary glTF begins with its magic, "glTF".
      if (load.glb().size() < 12 || load.glb().compare(0, 4, "glTF") != 0) {
        return wrong("load_asset.glb", "is not a binary glTF (.glb): it does not begin with \"glTF\"");
      }
      return std::nullopt;
    case session::LoadAsset::SOURCE_NOT_SET:
      break;
  }
  return wrong("load_asset", "give the asset's path (inside master.api.assets) or its glb bytes");
}

SessionActions SceneSessions::asset_loaded(const std::string& asset, std::uint64_t frame, bool animated,
                                           const std::string& path, const std::string& sha256) {
  SessionActions out;
  live_.add_asset(asset, animated);
  if (settings_.journal) out.push_back(session_action::Journal{journal_asset(frame, asset, path, sha256)});
  const auto asking = loading_.find(asset);
  if (asking == loading_.end()) return out;  // from the journal, at the start
  if (answerable(asking->second.session)) {
    wire::Envelope answer = reply(asking->second.request);
    answer.mutable_session_reply()->mutable_applied()->set_frame(frame);
    out.push_back(Send{asking->second.session, std::move(answer)});
  }
  loading_.erase(asking);
  return out;
}

SessionActions SceneSessions::asset_failed(const std::string& asset, const std::string& field,
                                           const std::string& reason) {
  SessionActions out;
  live_.set_loading(asset, false);
  out.push_back(Log{spdlog::level::warn, "asset '" + asset + "' could not be loaded: " + reason});
  const auto asking = loading_.find(asset);
  if (asking == loading_.end()) return out;
  if (answerable(asking->second.session)) {
    wire::Envelope answer = reply(asking->second.request);
    answer.mutable_session_reply()->mutable_refused()->set_field(field);
    answer.mutable_session_reply()->mutable_refused()->set_reason(reason);
    out.push_back(Send{asking->second.session, std::move(answer)});
  }
  loading_.erase(asking);
  return out;
}

}  // namespace optique::master
