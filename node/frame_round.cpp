// The node core's part in a frame's round (node/protocol.h): the swap, waiting
// for the present deadline, showing the frame's images, what came meanwhile;
// and the pings that measure the clock, which wait while a round is open.
#include <fmt/format.h>

#include <algorithm>

#include "node/protocol.h"

namespace optique::node {

void NodeProtocol::on_swap(const wire::FrameSwap& swap, clock::Nanos now, Actions& out) {
  if (!rendered_any_ || swap.frame_id() != last_rendered_) {
    log(out, spdlog::level::warn,
        "swap for frame " + std::to_string(swap.frame_id()) + " but the last rendered frame is " +
            std::to_string(last_rendered_) + "; not presenting");
    end_round(now, out);
    return;
  }
  const std::optional<clock::ClockEstimate> estimate = estimator_.at(settings_.clock.to_local(now));
  const clock::Nanos to_master = estimate ? estimate->offset : 0;
  clock::Nanos deadline = settings_.clock.to_monotonic(swap.present_deadline_ns() - to_master);
  // Never wait on a deadline from a broken or hostile master for longer than a
  // few frames.
  const clock::Nanos longest = std::max<clock::Nanos>(4 * frame_period_, 100 * clock::kNanosPerMilli);
  if (deadline > now + longest) {
    log(out, spdlog::level::warn,
        fmt::format("swap for frame {} asks to present {:.1f} ms from now; presenting in {:.1f} ms", swap.frame_id(),
                    static_cast<double>(deadline - now) / 1e6, static_cast<double>(longest) / 1e6));
    deadline = now + longest;
  }
  pending_ = Pending{swap.frame_id(), deadline, swap.present_deadline_ns(), false};
  wait_for_pending(now, out);
}

// Checked when the swap comes and again when the deadline does: a stop can
// stretch the wait too. An image is stale once the next one's time has come.
bool NodeProtocol::stale(clock::Nanos now, Actions& out) const {
  if (now <= pending_->deadline + frame_period_ / images_) return false;
  log(out, spdlog::level::warn,
      fmt::format("frame {}{}'s present deadline passed {:.1f} ms ago: not showing a stale frame", pending_->frame_id,
                  images_ > 1 ? fmt::format(" image {}", pending_->image) : "",
                  static_cast<double>(now - pending_->deadline) / 1e6));
  return true;
}

bool NodeProtocol::next_image() {
  if (pending_->image + 1 >= images_) return false;
  const clock::Nanos later = frame_period_ / images_;
  pending_->image += 1;
  pending_->deadline += later;
  pending_->master_deadline += later;
  pending_->due = false;
  return true;
}

void NodeProtocol::wait_for_pending(clock::Nanos now, Actions& out) {
  do {
    if (!stale(now, out)) {
      out.push_back(PresentAt{pending_->frame_id, pending_->deadline});
      return;
    }
  } while (next_image());
  pending_.reset();
  end_round(now, out);
}

// The frame's next image, its share of the frame later, while what came
// meanwhile waits for it; or, after the last, the frame is over and that goes on.
void NodeProtocol::image_done(clock::Nanos now, Actions& out) {
  if (next_image()) {
    wait_for_pending(now, out);
  } else {
    pending_.reset();
    end_round(now, out);
  }
  if (!pending_) release_held(now, out);
}

void NodeProtocol::on_present_due(clock::Nanos now, Actions& out) {
  if (!pending_ || pending_->due) return;
  if (!stale(now, out)) {
    pending_->due = true;
    out.push_back(Present{pending_->image});
    return;
  }
  image_done(now, out);  // not shown
}

// What came while a frame waited for its deadline, in order, until one of them
// waits again.
void NodeProtocol::release_held(clock::Nanos now, Actions& out) {
  while (!held_.empty() && !pending_) {
    wire::Envelope next = std::move(held_.front());
    held_.pop_front();
    if (next.has_staged_edit()) {  // its turn, whatever is held behind it
      on_staged_edit(next.staged_edit(), out);
      continue;
    }
    Actions more = message(next, now);
    out.insert(out.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
  }
}

void NodeProtocol::on_presented(clock::Nanos now, Actions& out) {
  if (!pending_ || !pending_->due) return;
  const Pending shown = *pending_;
  const clock::Nanos local = settings_.clock.to_local(now);
  // The offset drifts while the node waits for the deadline: convert at this instant.
  const std::optional<clock::ClockEstimate> estimate = estimator_.at(local);
  const clock::Nanos offset = estimate ? estimate->offset : 0;
  const clock::Nanos presented_at = local + offset;
  if (connection_open_ && phase_ == Phase::joined) {
    // The frame's first image is what the master's deadline is for, and what
    // it measures sync by: one report per frame.
    if (shown.image == 0) {
      wire::Envelope envelope;
      auto& report = *envelope.mutable_presented();
      report.set_frame_id(shown.frame_id);
      report.set_presented_ns(presented_at);
      report.set_content_frame_id(last_content_frame_);
      report.set_clock_offset_ns(offset);
      if (estimate) {
        report.set_clock_rtt_ns(estimate->round_trip);
        report.set_clock_drift_ppm(estimate->drift_ppm);
        report.set_clock_error_bound_ns(estimate->error_bound);
      }
      if (settings_.clock.skewed()) {
        report.set_clock_truth_known(true);
        report.set_clock_true_error_ns(offset - (now - local));
      }
      out.push_back(Send{std::move(envelope)});
    }
    log(out, spdlog::level::debug,
        fmt::format("presented frame {}{} at master time {} ns ({:+.1f} µs from the deadline)", shown.frame_id,
                    images_ > 1 ? fmt::format(" image {}", shown.image) : "", presented_at,
                    static_cast<double>(presented_at - shown.master_deadline) / 1e3));
  }
  image_done(now, out);
}

// ---------------------------------------------------------------- clock

void NodeProtocol::send_ping(clock::Nanos now, Actions& out) {
  ping_owed_ = false;
  if (phase_ != Phase::joined || !connection_open_) return;
  wire::Envelope envelope;
  envelope.mutable_ping()->set_t1(settings_.clock.to_local(now));
  out.push_back(Send{std::move(envelope)});
  if (pings_in_burst_ > 0) --pings_in_burst_;
  out.push_back(PingIn{pings_in_burst_ > 0 ? kBurstInterval : std::min(heartbeat_, kPingInterval)});
}

void NodeProtocol::on_ping_due(clock::Nanos now, Actions& out) {
  if (!ping_owed_ && pings_in_burst_ == 0 && in_round(now)) {
    ping_owed_ = true;
    out.push_back(PingIn{kPingDeferral});  // in case the round never ends here (no swap comes)
    return;
  }
  send_ping(now, out);
}

bool NodeProtocol::in_round(clock::Nanos now) const {
  if (round_open_) return true;
  if (!last_begin_ || frame_period_ <= 0) return false;
  const clock::Nanos next_begin = *last_begin_ + frame_period_;
  const clock::Nanos guard = std::chrono::nanoseconds(kRoundGuard).count();
  return now >= next_begin - guard && now < next_begin + guard;
}

void NodeProtocol::end_round(clock::Nanos now, Actions& out) {
  round_open_ = false;
  if (ping_owed_) send_ping(now, out);
}

void NodeProtocol::on_pong(const wire::Pong& pong, clock::Nanos now, Actions& out) {
  const clock::PingSample sample{pong.t1(), pong.t2(), pong.t3(), settings_.clock.to_local(now)};
  if (!estimator_.add(sample)) log(out, spdlog::level::debug, "dropped an impossible clock sample");
}

}  // namespace optique::node
