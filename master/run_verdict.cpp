#include "master/run_verdict.h"

#include <fmt/format.h>

namespace optique::master {
namespace {

// "median 140 µs p99 260 µs", or why there is no number: a median over no
// samples is not 0.
std::string median_p99(const report::Distribution& d, const char* why_none) {
  if (d.count() == 0) return fmt::format("n/a ({})", why_none);
  return fmt::format("median {:.0f} µs p99 {:.0f} µs", d.median(), d.p99());
}

std::string percent(double share) { return fmt::format("{:.1f} %", 100.0 * share); }

}  // namespace

double shown_by_all_share(std::uint64_t frames, std::uint64_t with_missing_node) {
  if (frames == 0) return 0.0;
  return static_cast<double>(frames - std::min(with_missing_node, frames)) / static_cast<double>(frames);
}

double shown_by_all_share(const report::RunReport& report) {
  return shown_by_all_share(report.frames(), report.sync().frames_with_missing_node());
}

std::optional<std::string> too_few_shown(const report::RunReport& report, std::optional<double> min_presented) {
  if (report.frames() == 0) return std::nullopt;
  if (min_presented) {
    const double share = shown_by_all_share(report);
    if (share >= *min_presented) return std::nullopt;
    return fmt::format("{} of the {} frames were shown by every projector, less than master.min_presented ({})",
                       percent(share), report.frames(), percent(*min_presented));
  }
  if (report.sync().frames_shown_by_none() < report.frames()) return std::nullopt;
  return fmt::format("no projector showed any of the {} frames", report.frames());
}

std::string summary_line(const report::RunReport& report) {
  const report::SyncReport& sync = report.sync();
  const std::string rate = report.frames() > 1 ? fmt::format("{:.1f}", sync.achieved_frame_rate()) : "n/a";
  return fmt::format(
      "{} frames at {} of {} Hz; {} shown by every projector; barrier round {}; present skew {}; {} frame(s) with a "
      "node missing",
      report.frames(), rate, report.frame_rate(), percent(shown_by_all_share(report)),
      median_p99(sync.barrier_round_us(), "no frame ran"),
      median_p99(sync.present_skew_us(), "no frame was presented by two nodes"), sync.frames_with_missing_node());
}

}  // namespace optique::master
