// The master core's staged edits (master/protocol.h): the instances an
// application changed go to the nodes as soon as no barrier round is under
// way, so that a node takes them in while it waits for the next frame, and
// the next FrameBegin carries only what changed after them. A thousand
// instances moved a frame cost each node its decoding and checking; in the
// round, every frame would wait for the slowest node's share of it.
//
// The master's own state follows the live scene the same way, instance by
// instance: a frame takes the instances staged, with the edits since and the
// animation clocks that play, and no frame copies or compares them all.

#include <cassert>

#include "master/protocol.h"

namespace optique::master {

wire::StateDelta MasterProtocol::take_live_instances(const std::set<std::string>& ids, std::uint64_t frame) {
  // As frame `frame` shows them, by id: walked beside the live scene's, not searched.
  std::map<std::string, std::optional<scene::InstanceState>> after;
  const auto& live = settings_.live->instances();
  auto in_live = live.begin();
  for (const std::string& id : ids) {
    while (in_live != live.end() && in_live->first < id) ++in_live;
    after.emplace_hint(after.end(), id,
                       in_live != live.end() && in_live->first == id
                           ? std::optional(instance_state(*settings_.live, in_live->second, frame))
                           : std::nullopt);
  }
  wire::StateDelta delta = scene::make_instance_delta(current_state_, after);
  // Into the state as every node takes it in (the same function), its instances' hash kept.
  [[maybe_unused]] const auto applied = scene::apply_delta(current_state_, delta, current_instances_hash_);
  assert(applied && "the master's delta from its own state applies to it");
  return delta;
}

Actions MasterProtocol::scene_edited() {
  Actions out;
  if (!barrier_.active()) stage_edits(out);
  return out;
}

void MasterProtocol::stage_edits(Actions& out) {
  // Before the frames (and once they end), the next FrameBegin or snapshot has them all.
  if (settings_.live == nullptr || state_ != RunState::running) return;
  const std::set<std::string> edited = settings_.live->take_edited();
  if (edited.empty()) return;
  auto envelope = std::make_shared<wire::Envelope>();
  auto& staged = *envelope->mutable_staged_edit();
  staged.set_frame_id(next_frame_);
  // As the next frame will show them: its FrameBegin then has nothing of them.
  *staged.mutable_delta() = take_live_instances(edited, next_frame_);
  const wire::StateDelta& delta = staged.delta();
  if (delta.instances_changed_size() == 0 && delta.instances_moved_size() == 0 && delta.instances_removed_size() == 0) {
    return;  // a refused transaction's edits, undone
  }
  for (const auto& [peer, session] : sessions_) {
    // Every node sent a snapshot (a resync); one still setting up gets one with these in it.
    if (session.phase == Phase::joined || session.phase == Phase::in_barrier ||
        session.phase == Phase::out_of_barrier) {
      out.push_back(Send{peer, {}, envelope});
    }
  }
  recorder_.staged(envelope->ByteSizeLong());
}

}  // namespace optique::master
