#include "master/live_status.h"

#include <algorithm>

#include "metrics/distribution.h"

namespace optique::master {

std::string_view to_string(NodeLink link) {
  switch (link) {
    case NodeLink::absent:
      return "absent";
    case NodeLink::connecting:
      return "connecting";
    case NodeLink::configuring:
      return "configuring";
    case NodeLink::up:
      return "up";
    case NodeLink::behind:
      return "behind";
    case NodeLink::gone:
      return "gone";
  }
  return "unknown";
}

void summarize_recent(const std::deque<RecentFrame>& recent, clock::Nanos now, LiveStatus& status) {
  constexpr clock::Nanos kRateWindow = 2 * clock::kNanosPerSecond;
  std::size_t begun = 0;
  clock::Nanos first = 0;
  clock::Nanos last = 0;
  std::vector<double> skews;
  std::vector<double> intervals;
  std::vector<std::vector<double>> renders(status.nodes.size());
  for (std::size_t i = 0; i < recent.size(); ++i) {
    const RecentFrame& f = recent[i];
    if (f.skew_us) skews.push_back(*f.skew_us);
    if (i + 1 < recent.size()) intervals.push_back(static_cast<double>(recent[i + 1].begin_sent - f.begin_sent) / 1e6);
    for (std::size_t n = 0; n < renders.size() && n < f.render_us.size(); ++n) {
      if (f.render_us[n] >= 0.0F) renders[n].push_back(static_cast<double>(f.render_us[n]) / 1e3);
    }
    if (now - f.begin_sent <= kRateWindow) {
      if (begun == 0) first = f.begin_sent;
      last = f.begin_sent;
      ++begun;
    }
  }
  // n frames begun over the window: n − 1 intervals between the first and the last.
  if (begun >= 2 && last > first)
    status.frame_rate_hz = static_cast<double>(begun - 1) * 1e9 / static_cast<double>(last - first);
  const std::size_t chart_from = recent.size() > kChartFrames ? recent.size() - kChartFrames : 0;
  for (std::size_t i = chart_from; i < recent.size(); ++i) {
    LivePoint point{recent[i].id, recent[i].skew_us, std::nullopt};
    if (i + 1 < recent.size()) point.frame_ms = intervals[i];
    status.history.push_back(point);
  }
  if (!skews.empty()) {
    status.skew_us_median = metrics::percentile(skews, 50);
    status.skew_us_p99 = metrics::percentile(skews, 99);
  }
  if (!intervals.empty()) status.frame_ms_median = metrics::percentile(intervals, 50);
  for (std::size_t n = 0; n < renders.size(); ++n) {
    if (renders[n].empty()) continue;
    status.nodes[n].render_ms_median = metrics::percentile(renders[n], 50);
    status.nodes[n].render_ms_p99 = metrics::percentile(renders[n], 99);
  }
}

}  // namespace optique::master
