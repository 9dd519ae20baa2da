#pragma once
// The scene session's C++ client: a blocking connection to the master's
// master.api (docs/applications.md). Connects, answers the challenge (with the
// installation's shared secret where the master requires it, sealing every
// message after the hello), then sends requests one at a time and waits for
// each reply. Expected failures (the master refuses, goes away, sends what is
// not a reply) come back as errors with a message; a transaction the master
// refuses is an outcome, not an error.

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>

#include "clients/cpp/transaction.h"
#include "optique/session.pb.h"
#include "util/result.h"

namespace optique::client {

struct Options {
  std::string host = "127.0.0.1";
  std::uint16_t port = 7490;
  std::string name = "cpp";                  // in the master's log: 1 to 64 of a-z A-Z 0-9 - _ .
  std::string secret_file;                   // the installation's shared secret, where the master requires it
  std::chrono::milliseconds timeout{10000};  // for each reply
};

// What became of a transaction: the frame from which every node shows it, or
// the master's refusal (its first edit that could not be applied; nothing of
// the transaction was).
struct Outcome {
  std::uint64_t frame = 0;
  std::optional<session::Refused> refused;
  [[nodiscard]] bool applied() const { return !refused.has_value(); }
};

class Session {
 public:
  // Opens the session and reads the scene as it is (scene()).
  [[nodiscard]] static Result<std::unique_ptr<Session>> connect(const Options& options);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  [[nodiscard]] Result<Outcome> apply(const Transaction& transaction);
  // Loads a glTF asset that instances may then name: `path` a file inside the
  // master's master.api.assets folder (relative to it), or `glb` the bytes of
  // a binary glTF this application sends. The outcome's frame is the first
  // from which every node can draw it (the reply waits until every node has
  // it: the timeout is the options' or `timeout`, whichever is longer), or
  // why not.
  [[nodiscard]] Result<Outcome> load_asset(const std::string& asset, const std::string& path,
                                           std::chrono::milliseconds timeout = std::chrono::seconds(60));
  [[nodiscard]] Result<Outcome> upload_asset(const std::string& asset, std::string glb,
                                             std::chrono::milliseconds timeout = std::chrono::seconds(60));
  [[nodiscard]] Result<session::SceneContents> read_scene();
  // From now on the master sends these kinds of events (all off at first);
  // read them with next_event. An application that stops reading them is
  // closed by the master after a while.
  [[nodiscard]] Result<void> subscribe(const session::Subscribe& kinds);
  // The next event, or nullopt when none came within `timeout` (0: only what
  // has come already, without waiting).
  [[nodiscard]] Result<std::optional<session::Event>> next_event(std::chrono::milliseconds timeout);
  // The scene as it was when the session opened.
  [[nodiscard]] const session::SceneContents& scene() const { return scene_; }
  // Says goodbye and closes.
  void close();

 private:
  struct Link;  // the socket, the framing and the seal (session.cpp)
  explicit Session(std::unique_ptr<Link> link);
  [[nodiscard]] Result<session::Reply> ask(session::Request request);
  [[nodiscard]] Result<Outcome> outcome_of(session::Request request, std::chrono::milliseconds timeout);

  std::unique_ptr<Link> link_;
  std::deque<session::Event> events_;  // those that came while a reply was awaited
  session::SceneContents scene_;
  std::chrono::milliseconds timeout_{10000};  // for replies (Options::timeout)
  std::uint64_t next_request_ = 1;
};

}  // namespace optique::client
