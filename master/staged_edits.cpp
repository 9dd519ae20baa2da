// The master core's staged edits (master/protocol.h): the instances an
// application changed go to the nodes as soon as no barrier round is under
// way, so that a node takes them in while it waits for the next frame, and
// the next FrameBegin carries only what changed after them. A thousand
// instances moved a frame cost each node its decoding and checking; in the
// round, every frame would wait for the slowest node's share of it.

#include "master/protocol.h"

namespace optique::master {

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
  // As the next frame will show them: begin_frame's state then holds the same.
  std::map<std::string, std::optional<scene::InstanceState>> after;
  for (const std::string& id : edited) after.emplace(id, instance_state(*settings_.live, id, next_frame_));
  auto envelope = std::make_shared<wire::Envelope>();
  auto& staged = *envelope->mutable_staged_edit();
  staged.set_frame_id(next_frame_);
  *staged.mutable_delta() = scene::make_instance_delta(current_state_, after);
  const wire::StateDelta& delta = staged.delta();
  if (delta.instances_changed_size() == 0 && delta.instances_moved_size() == 0 && delta.instances_removed_size() == 0) {
    return;  // a refused transaction's edits, undone
  }
  // What every node has from now on (a snapshot for a node that joins, the
  // state the next FrameBegin's delta applies to).
  for (auto& [id, instance] : after) {
    if (instance) {
      current_state_.instances.insert_or_assign(id, std::move(*instance));
    } else {
      current_state_.instances.erase(id);
    }
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
