#pragma once
// A whole cluster in one thread and no sockets: the master's protocol core and
// one node core per projector, joined by simulated links (each direction a FIFO
// of messages, closed by an end-of-stream mark, as TCP delivers them), on one
// virtual clock. A test or a fuzzer picks what happens next — which message
// arrives, which timer fires, which link breaks — and the cluster checks, after
// every step, what must hold whatever the order: no action for a peer the
// master knows is gone, no frame shown twice, no frame skipped after a join,
// every repaired state right on the next frame, no swap without a ready.

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "master/protocol.h"
#include "master/run/run_config.h"
#include "master/run_recorder.h"
#include "node/protocol.h"

namespace optique::testing {

class SimCluster {
 public:
  // `run` must outlive the cluster. One node per projector; `corrupt_frame`
  // nudges the first node's state at that frame (0: never).
  SimCluster(const master::RunConfig& run, master::RunSettings settings, std::uint64_t corrupt_frame = 0);
  ~SimCluster();

  // The master starts and every node connects.
  void start();

  // One step each; false when there was nothing to do.
  bool deliver_to_node(std::size_t node);
  bool deliver_to_master(std::size_t node);
  // The earliest timer of anyone (master, nodes, connection deadlines); the clock
  // moves to it.
  bool fire_next_timer();
  // Breaks node's link (a reset: both ends see it closed, queued messages lost).
  void reset_link(std::size_t node);
  void interrupt_master();
  // An application loads an asset (up to eight, "asset-0" on): the master
  // offers it to every node (which, drawing nothing, readies it at once).
  void add_asset();
  // An application's transaction on the live scene (settings.live; none:
  // nothing): an instance created, or moved; what it changed is staged to the
  // nodes as the master's shell does (MasterProtocol::scene_edited).
  void edit();
  // The shell's call after an application's request (MasterProtocol::scene_edited).
  void scene_edited();

  // A prompt network: every message delivered as soon as it is sent, timers in
  // order, until the master has finished or `until` (virtual time) is reached.
  void run_promptly(clock::Nanos until);

  // One fuzz step from one byte (what happens next, to which node).
  void step(std::uint8_t choice);

  [[nodiscard]] const std::vector<std::string>& violations() const { return violations_; }
  [[nodiscard]] bool master_finished() const { return finished_.has_value(); }
  [[nodiscard]] std::optional<int> exit_code() const { return finished_; }
  [[nodiscard]] clock::Nanos now() const { return now_; }
  [[nodiscard]] std::size_t nodes() const { return nodes_.size(); }
  // Frames node i showed, in order.
  [[nodiscard]] const std::vector<std::uint64_t>& presented(std::size_t node) const;
  // The live scene's instances in the state node i drew each frame with (none: not listed).
  [[nodiscard]] const std::map<std::uint64_t, std::set<std::string>>& instances_drawn(std::size_t node) const;
  // The same in the state sent ahead with each frame (a node that interpolates).
  [[nodiscard]] const std::map<std::uint64_t, std::set<std::string>>& instances_ahead(std::size_t node) const;
  // The events the master raised for applications (AppEvent), in order.
  [[nodiscard]] const std::vector<session::Event>& app_events() const { return app_events_; }
  // What the master said of assets: "usable ID" or "failed ID: reason", in order.
  [[nodiscard]] const std::vector<std::string>& asset_news() const { return asset_news_; }
  [[nodiscard]] const master::MasterProtocol& master() const { return *master_; }
  [[nodiscard]] const master::RunRecorder& recorder() const { return *recorder_; }

 private:
  struct Link;
  struct SimNode;

  void master_actions(master::Actions actions);
  void node_actions(std::size_t node, node::Actions actions);
  void connect(std::size_t node);
  void close_link(Link& link, bool from_node, bool after_sending);
  void violation(const std::string& what);

  std::unique_ptr<master::RunRecorder> recorder_;
  std::unique_ptr<master::MasterProtocol> master_;
  std::vector<std::unique_ptr<SimNode>> nodes_;
  std::map<master::PeerId, Link*> links_;  // open from the master's side
  std::vector<std::unique_ptr<Link>> all_links_;
  std::map<master::Timer, clock::Nanos> master_timers_;
  std::set<master::PeerId> closed_peers_;                // the master was told they are gone
  std::map<std::uint64_t, std::uint64_t> frame_hashes_;  // the master's hash per frame begun
  bool accepting_ = true;
  std::optional<int> finished_;
  master::PeerId next_peer_ = 1;
  clock::Nanos now_ = 1'000'000'000'000;
  std::vector<std::string> violations_;
  std::vector<session::Event> app_events_;
  std::vector<std::string> asset_news_;
  std::set<std::pair<master::PeerId, std::string>> assets_offered_;
  int assets_added_ = 0;
  master::LiveScene* live_ = nullptr;
  std::uint64_t corrupt_frame_ = 0;
  std::uint64_t edits_ = 0;
  std::set<std::string> asset_shas_;  // the assets' identities, whose files a node may ask for
};

}  // namespace optique::testing
