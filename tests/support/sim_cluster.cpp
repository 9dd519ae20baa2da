#include "sim_cluster.h"

#include <algorithm>
#include <deque>
#include <limits>

#include "util/overloaded.h"

namespace optique::testing {

struct SimCluster::Link {
  master::PeerId peer = 0;
  std::size_t node = 0;
  std::deque<wire::Envelope> to_node;
  std::deque<wire::Envelope> to_master;
  bool eof_to_node = false;  // after what is queued, the node reads the end of the stream
  bool eof_to_master = false;
  bool node_open = true;  // each end until it has been told the link is gone
  bool master_open = true;
  std::string node_eof_reason;
  std::string master_eof_reason;
  // Each end's one-shot deadline and liveness timeout.
  std::optional<clock::Nanos> node_deadline;
  std::string node_deadline_reason;
  std::optional<clock::Nanos> master_deadline;
  std::string master_deadline_reason;
  clock::Nanos node_liveness = 0;  // 0: off
  clock::Nanos master_liveness = 0;
  clock::Nanos node_heard = 0;  // when each end last received something
  clock::Nanos master_heard = 0;
  std::set<std::uint64_t> readies;  // frames the node reported ready on this link
  int resyncs = 0;                  // the master's snapshots on this link: the first is the join
};

struct SimCluster::SimNode {
  explicit SimNode(node::NodeSettings settings) : protocol(std::move(settings)) {}
  node::NodeProtocol protocol;
  Link* link = nullptr;
  std::optional<clock::Nanos> ping_at;
  std::optional<clock::Nanos> present_at;
  std::optional<clock::Nanos> reconnect_at;
  std::vector<std::uint64_t> presented;
  std::uint64_t last_rendered = 0;
  std::optional<std::uint64_t> repaired_frame;  // the frame a repair snapshot precedes: its ready must match
  std::map<std::uint64_t, std::set<std::string>> instances_drawn;
  std::map<std::uint64_t, std::set<std::string>> instances_ahead;
};

SimCluster::SimCluster(const master::RunConfig& run, master::RunSettings settings, std::uint64_t corrupt_frame) {
  const config::Installation& installation = run.config.installation;
  std::vector<std::string> ids;
  for (const config::Projector& p : installation.projectors) ids.push_back(p.id);
  recorder_ = std::make_unique<master::RunRecorder>(ids);
  live_ = settings.live;
  corrupt_frame_ = corrupt_frame;
  master_ = std::make_unique<master::MasterProtocol>(installation, run.scene, std::move(settings), *recorder_);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    node::NodeSettings s;
    s.master = "sim:7400";
    s.id = ids[i];
    if (i == 0) s.faults.corrupt_state_at_frame = corrupt_frame;
    nodes_.push_back(std::make_unique<SimNode>(std::move(s)));
  }
}

SimCluster::~SimCluster() = default;

void SimCluster::violation(const std::string& what) {
  if (violations_.size() < 20) violations_.push_back(what);
}

const std::map<std::uint64_t, std::set<std::string>>& SimCluster::instances_drawn(std::size_t node) const {
  return nodes_.at(node)->instances_drawn;
}

const std::map<std::uint64_t, std::set<std::string>>& SimCluster::instances_ahead(std::size_t node) const {
  return nodes_.at(node)->instances_ahead;
}

const std::vector<std::uint64_t>& SimCluster::presented(std::size_t node) const { return nodes_[node]->presented; }

void SimCluster::start() {
  master_actions(master_->start(now_));
  for (std::size_t i = 0; i < nodes_.size(); ++i) connect(i);
}

void SimCluster::connect(std::size_t i) {
  SimNode& n = *nodes_[i];
  if (n.protocol.stopped()) return;
  if (!accepting_ || finished_) {
    node_actions(i, n.protocol.connect_failed("connection refused", now_));
    return;
  }
  auto link = std::make_unique<Link>();
  link->peer = next_peer_++;
  link->node = i;
  link->node_heard = link->master_heard = now_;
  Link* l = link.get();
  all_links_.push_back(std::move(link));
  links_[l->peer] = l;
  n.link = l;
  master_actions(master_->accepted(l->peer, "127.0.0.1:" + std::to_string(50000 + l->peer), true,
                                   std::vector<std::uint8_t>(32, static_cast<std::uint8_t>(l->peer)), now_));
  node_actions(i, n.protocol.connected(now_));
}

// ---------------------------------------------------------------- links

void SimCluster::close_link(Link& link, bool from_node, bool after_sending) {
  if (from_node) {
    if (!link.node_open) return;
    link.node_open = false;
    link.to_node.clear();
    link.eof_to_master = true;
    link.master_eof_reason = "the node closed the connection";
    (void)after_sending;  // what the node queued is on its way either way
  } else {
    if (!link.master_open) return;
    link.master_open = false;
    if (!after_sending) link.to_node.clear();  // what was not written yet is lost
    link.to_master.clear();
    link.eof_to_node = true;
    link.node_eof_reason = "the master closed the connection";
  }
}

bool SimCluster::deliver_to_node(std::size_t i) {
  SimNode& n = *nodes_[i];
  Link* link = n.link;
  if (link == nullptr || !link->node_open) return false;
  if (!link->to_node.empty()) {
    wire::Envelope message = std::move(link->to_node.front());
    link->to_node.pop_front();
    link->node_heard = now_;
    node_actions(i, n.protocol.message(message, now_));
    return true;
  }
  if (link->eof_to_node) {
    link->node_open = false;
    node_actions(i, n.protocol.closed(link->node_eof_reason, now_));
    return true;
  }
  return false;
}

bool SimCluster::deliver_to_master(std::size_t i) {
  // Any of the node's links that the master still reads (an old one may still
  // hold messages after the node reconnected).
  for (auto& owned : all_links_) {
    Link& link = *owned;
    if (link.node != i || !link.master_open) continue;
    if (!link.to_master.empty()) {
      wire::Envelope message = std::move(link.to_master.front());
      link.to_master.pop_front();
      link.master_heard = now_;
      if (message.has_frame_ready()) link.readies.insert(message.frame_ready().frame_id());
      master_actions(master_->message(link.peer, message, now_));
      return true;
    }
    if (link.eof_to_master) {
      link.master_open = false;
      links_.erase(link.peer);
      closed_peers_.insert(link.peer);
      master_actions(master_->closed(link.peer, link.master_eof_reason, now_));
      return true;
    }
  }
  return false;
}

void SimCluster::reset_link(std::size_t i) {
  Link* link = nodes_[i]->link;
  if (link == nullptr) return;
  link->to_node.clear();
  link->to_master.clear();
  if (link->master_open) {
    link->master_open = false;
    links_.erase(link->peer);
    closed_peers_.insert(link->peer);
    master_actions(master_->closed(link->peer, "connection reset by peer", now_));
  }
  if (link->node_open) {
    link->node_open = false;
    node_actions(i, nodes_[i]->protocol.closed("connection reset by peer", now_));
  }
}

void SimCluster::interrupt_master() { master_actions(master_->interrupted("Interrupt", now_)); }

// ---------------------------------------------------------------- actions

void SimCluster::master_actions(master::Actions actions) {
  for (master::Action& action : actions) {
    const auto peer_link = [&](master::PeerId peer, const char* what) -> Link* {
      if (closed_peers_.contains(peer)) {
        violation(std::string(what) + " for peer " + std::to_string(peer) + ", which the master knows is gone");
        return nullptr;
      }
      const auto found = links_.find(peer);
      return found == links_.end() || !found->second->master_open ? nullptr : found->second;
    };
    std::visit(
        util::Overloaded{
            [&](master::Send& a) {
              Link* link = peer_link(a.peer, "a send");
              if (link == nullptr) return;
              if (a.shared) a.message = *a.shared;  // the test's nodes each take their copy
              wire::Envelope& m = a.message;
              m.set_protocol_version(net::kProtocolVersion);
              if (m.has_pong()) m.mutable_pong()->set_t3(now_);
              if (m.has_frame_begin()) frame_hashes_[m.frame_begin().frame_id()] = m.frame_begin().state_hash();
              if (m.has_asset_offer() && !assets_offered_.emplace(a.peer, m.asset_offer().asset()).second) {
                violation("asset '" + m.asset_offer().asset() + "' offered twice to peer " + std::to_string(a.peer));
              }
              if (m.has_swap() && !link->readies.contains(m.swap().frame_id())) {
                violation("swap of frame " + std::to_string(m.swap().frame_id()) + " to peer " +
                          std::to_string(a.peer) + ", which did not say it was ready");
              }
              if (m.has_resync() && link->resyncs++ > 0) {
                nodes_[link->node]->repaired_frame = m.resync().next_frame_id();
              }
              link->to_node.push_back(std::move(m));
            },
            [&](master::Close& a) {
              Link* link = peer_link(a.peer, "a close");
              if (link == nullptr) return;
              close_link(*link, false, a.after_sending);
              links_.erase(a.peer);
              closed_peers_.insert(a.peer);
              master_actions(master_->closed(a.peer, a.reason, now_));
            },
            [&](master::SetDeadline& a) {
              if (Link* link = peer_link(a.peer, "a deadline")) {
                link->master_deadline = now_ + std::chrono::nanoseconds(a.after).count();
                link->master_deadline_reason = a.reason;
              }
            },
            [&](master::CancelDeadline& a) {
              if (Link* link = peer_link(a.peer, "a deadline")) link->master_deadline.reset();
            },
            [&](master::SetLiveness& a) {
              if (Link* link = peer_link(a.peer, "a liveness timeout")) {
                link->master_liveness = std::chrono::nanoseconds(a.timeout).count();
                link->master_heard = now_;
              }
            },
            [&](master::SetMaxPayload& a) { (void)peer_link(a.peer, "a payload limit"); },
            [&](master::Protect& a) { (void)peer_link(a.peer, "a session's keys"); },
            [&](master::Arm& a) { master_timers_[a.timer] = a.at; },
            [&](master::Disarm& a) { master_timers_.erase(a.timer); },
            [&](master::StopAccepting&) { accepting_ = false; },
            [&](master::SignalLocalNodes&) {},
            [&](master::HeadShown&) {},
            [&](master::FrameRows&) {},
            [&](master::Finish& a) { finished_ = a.exit_code; },
            [&](master::Log&) {},
            [&](master::AppEvent& a) { app_events_.push_back(std::move(a.event)); },
            [&](master::AssetUsable& a) {
              if (std::count(asset_news_.begin(), asset_news_.end(), "usable " + a.asset) > 0 ||
                  a.asset.rfind("asset-", 0) != 0) {
                violation("asset '" + a.asset + "' made usable twice, or never added");
              }
              asset_news_.push_back("usable " + a.asset);
            },
            [&](master::AssetFailed& a) { asset_news_.push_back("failed " + a.asset + ": " + a.reason); },
        },
        action);
  }
}

void SimCluster::node_actions(std::size_t i, node::Actions actions) {
  SimNode& n = *nodes_[i];
  for (node::Action& action : actions) {
    Link* link = n.link != nullptr && n.link->node_open ? n.link : nullptr;
    std::visit(
        util::Overloaded{
            [&](node::Send& a) {
              if (link == nullptr) return;
              wire::Envelope& m = a.message;
              if (m.protocol_version() == 0) m.set_protocol_version(net::kProtocolVersion);
              if (m.has_frame_ready() && n.repaired_frame == m.frame_ready().frame_id()) {
                n.repaired_frame.reset();
                if (m.frame_ready().state_hash() != frame_hashes_[m.frame_ready().frame_id()]) {
                  violation("node " + std::to_string(i) + "'s state is still wrong at frame " +
                            std::to_string(m.frame_ready().frame_id()) + ", after its repair");
                }
              }
              link->to_master.push_back(std::move(m));
            },
            [&](node::Close& a) {
              if (link == nullptr) return;
              close_link(*link, true, a.after_sending);
              node_actions(i, n.protocol.closed(a.reason, now_));
            },
            [&](node::SetDeadline& a) {
              if (link == nullptr) return;
              link->node_deadline = now_ + std::chrono::nanoseconds(a.after).count();
              link->node_deadline_reason = a.reason;
            },
            [&](node::CancelDeadline&) {
              if (link != nullptr) link->node_deadline.reset();
            },
            [&](node::SetLiveness& a) {
              if (link == nullptr) return;
              link->node_liveness = std::chrono::nanoseconds(a.timeout).count();
              link->node_heard = now_;
            },
            [&](node::Configure&) {
              node_actions(i, n.protocol.answer(node::Configured{{}, "sim", {}}, now_));
            },
            [&](node::Render& a) {
              n.last_rendered = a.frame.frame_id;
              for (const auto& instance : n.protocol.state().instances) {
                n.instances_drawn[a.frame.frame_id].insert(instance.first);
              }
              if (a.frame.ahead != nullptr) {
                auto& ahead = n.instances_ahead[a.frame.frame_id];
                for (const auto& instance : a.frame.ahead->instances) ahead.insert(instance.first);
              }
              node_actions(i,
                           n.protocol.answer(node::FrameRendered{a.frame.frame_id, clock::kNanosPerMilli, {}}, now_));
            },
            [&](node::Skip&) {},
            [&](node::Protect&) {},
            [&](node::PresentAt& a) { n.present_at = a.deadline; },
            [&](node::Present&) {
              if (std::find(n.presented.begin(), n.presented.end(), n.last_rendered) != n.presented.end()) {
                violation("node " + std::to_string(i) + " showed frame " + std::to_string(n.last_rendered) + " twice");
              } else if (!n.presented.empty() && n.last_rendered < n.presented.back()) {
                violation("node " + std::to_string(i) + " showed frame " + std::to_string(n.last_rendered) +
                          " after frame " + std::to_string(n.presented.back()));
              }
              n.presented.push_back(n.last_rendered);
              node_actions(i, n.protocol.answer(node::ImagePresented{}, now_));
            },
            [&](node::ShowBlack&) {},
            [&](node::PingIn& a) { n.ping_at = now_ + std::chrono::nanoseconds(a.after).count(); },
            [&](node::CancelPings&) { n.ping_at.reset(); },
            [&](node::Reconnect& a) { n.reconnect_at = now_ + std::chrono::nanoseconds(a.after).count(); },
            [&](node::Stop&) {
              n.ping_at.reset();
              n.present_at.reset();
              n.reconnect_at.reset();
            },
            [&](node::Log& a) {
              // A state that differs from the master's is a fault only where one was put in.
              const bool wrong_state = a.text.find("differs from the master's") != std::string::npos;
              if (a.text.find("frame ids jumped") != std::string::npos ||
                  a.text.find("an edit staged for frame") != std::string::npos ||
                  (wrong_state && corrupt_frame_ == 0)) {
                violation("node " + std::to_string(i) + ": " + a.text);
              }
            },
            // Simulated clusters show built-in scenes: no files to fetch.
            // An asset's files: a cache that holds them. The scene's: never (built in).
            [&](node::PrepareScene& a) {
              if (!asset_shas_.contains(a.sha256)) {
                violation("node " + std::to_string(i) + " was sent a scene's files");
                return;
              }
              node_actions(i, n.protocol.answer(node::SceneFound{"/sim/cache/" + a.sha256 + "/a.gltf"}, now_));
            },
            [&](node::RecheckScene&) {},
            [&](node::StoreSceneChunk&) {},
            [&](node::FinishScene&) {},
            [&](node::AbandonScene&) {},
            [&](node::ReadyAsset& a) {
              node_actions(i, n.protocol.answer(node::AssetLoaded{a.asset.asset, {}}, now_));
            },
        },
        action);
  }
}

// ---------------------------------------------------------------- time

bool SimCluster::fire_next_timer() {
  enum class Kind { master, ping, present, reconnect, node_deadline, master_deadline, node_silent, master_silent };
  clock::Nanos best = std::numeric_limits<clock::Nanos>::max();
  Kind kind = Kind::master;
  std::size_t index = 0;
  master::Timer which = master::Timer::startup;
  Link* link = nullptr;
  const auto consider = [&](clock::Nanos at, Kind k, std::size_t i, Link* l) {
    if (at < best) {
      best = at;
      kind = k;
      index = i;
      link = l;
    }
  };
  if (!finished_) {
    for (const auto& [timer, at] : master_timers_) {
      if (at < best) {
        best = at;
        kind = Kind::master;
        which = timer;
      }
    }
  }
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const SimNode& n = *nodes_[i];
    if (n.ping_at) consider(*n.ping_at, Kind::ping, i, nullptr);
    if (n.present_at) consider(*n.present_at, Kind::present, i, nullptr);
    if (n.reconnect_at) consider(*n.reconnect_at, Kind::reconnect, i, nullptr);
  }
  for (auto& owned : all_links_) {
    Link& l = *owned;
    if (l.node_open && l.node_deadline) consider(*l.node_deadline, Kind::node_deadline, l.node, &l);
    if (l.master_open && l.master_deadline) consider(*l.master_deadline, Kind::master_deadline, l.node, &l);
    if (l.node_open && l.node_liveness > 0) consider(l.node_heard + l.node_liveness, Kind::node_silent, l.node, &l);
    if (l.master_open && l.master_liveness > 0) {
      consider(l.master_heard + l.master_liveness, Kind::master_silent, l.node, &l);
    }
  }
  if (best == std::numeric_limits<clock::Nanos>::max()) return false;
  now_ = std::max(now_, best);
  SimNode& n = *nodes_[index];
  switch (kind) {
    case Kind::master:
      master_timers_.erase(which);
      master_actions(master_->timer(which, now_));
      break;
    case Kind::ping:
      n.ping_at.reset();
      node_actions(index, n.protocol.due(node::Due::ping, now_));
      break;
    case Kind::present:
      n.present_at.reset();
      node_actions(index, n.protocol.due(node::Due::present, now_));
      break;
    case Kind::reconnect:
      n.reconnect_at.reset();
      connect(index);
      break;
    case Kind::node_deadline:
    case Kind::node_silent: {
      const std::string reason = kind == Kind::node_deadline ? link->node_deadline_reason : "master silent";
      link->node_deadline.reset();
      close_link(*link, true, false);
      if (n.link == link) node_actions(index, n.protocol.closed(reason, now_));
      break;
    }
    case Kind::master_deadline:
    case Kind::master_silent: {
      const std::string reason = kind == Kind::master_deadline ? link->master_deadline_reason : "node silent";
      link->master_deadline.reset();
      close_link(*link, false, false);
      links_.erase(link->peer);
      closed_peers_.insert(link->peer);
      master_actions(master_->closed(link->peer, reason, now_));
      break;
    }
  }
  return true;
}

void SimCluster::run_promptly(clock::Nanos until) {
  while (!finished_ && now_ < until) {
    bool delivered = true;
    while (delivered) {
      delivered = false;
      for (std::size_t i = 0; i < nodes_.size(); ++i) {
        while (deliver_to_master(i) || deliver_to_node(i)) delivered = true;
      }
    }
    if (!fire_next_timer()) break;
  }
}

void SimCluster::add_asset() {
  if (assets_added_ >= 8) return;
  const std::string id = "asset-" + std::to_string(assets_added_++);
  auto asset = std::make_shared<scene::LoadedScene>();
  const std::string gltf = R"({"asset":{"version":"2.0"},"extras":")" + id + R"("})";
  asset->manifest = scene::SceneManifest{scene::kSceneChunkBytes, {scene::describe_file("a.gltf", gltf)}};
  asset->files = {std::make_shared<const std::string>(gltf)};
  asset->content_sha256 = scene::manifest_sha256(asset->manifest);
  asset->source = id + ".gltf";
  asset_shas_.insert(asset->content_sha256);
  master_actions(master_->add_asset(id, std::move(asset)));
}

void SimCluster::edit() {
  if (live_ == nullptr || live_->assets().empty()) return;
  // Each edit moves an instance, the fourth of them new.
  const std::string id = "e" + std::to_string(edits_ / 4);
  session::Transaction transaction;
  if (edits_ % 4 == 0) {
    auto& create = *transaction.add_edits()->mutable_create();
    create.set_instance(id);
    create.set_asset(*live_->assets().begin());
  } else {
    auto& move = *transaction.add_edits()->mutable_transform();
    move.set_instance(id);
    for (double x : {0.01 * static_cast<double>(edits_), 1.0, -1.0}) move.mutable_transform()->add_position(x);
  }
  ++edits_;
  if (live_->apply(transaction, master_->progress().next_frame)) return;
  scene_edited();
}

void SimCluster::scene_edited() { master_actions(master_->scene_edited()); }

void SimCluster::step(std::uint8_t choice) {
  const std::size_t node = (choice / 8u) % nodes_.size();
  switch (choice % 8u) {
    case 0:
    case 1:
    case 2:
      (void)deliver_to_node(node);
      break;
    case 3:
    case 4:
      (void)deliver_to_master(node);
      break;
    case 5:
      (void)fire_next_timer();
      break;
    case 6:
      if (choice >= 240) {
        reset_link(node);
      } else {
        (void)fire_next_timer();
      }
      break;
    default:
      if (choice == 255) {
        interrupt_master();
      } else if (choice == 247) {
        add_asset();
      } else if (choice == 239 || choice == 231) {
        edit();
      } else {
        for (std::size_t i = 0; i < nodes_.size(); ++i) {
          if (deliver_to_node(i) || deliver_to_master(i)) break;
        }
      }
      break;
  }
}

}  // namespace optique::testing
