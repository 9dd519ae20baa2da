// Head prediction against tracker latency: the master's head tracker
// (common/tracking, the code the master runs) fed a walking head (HeadWalk:
// 1.2 m/s on a 2 m circle, bobbing) as DTrack would send it at 60 Hz with its
// latency in ts2 and 0.5 mm of jitter, and asked for the head at each 60 Hz frame's display time, one
// frame after the frame begins (as the master does); the eyes against the walk
// then. In-process, simulated time: what is measured is the prediction, not
// the network (the timing test tests/timing/test_tracked_head does that).
//
//   optique-bench-tracking --out docs/bench     (a second)


#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench_options.h"
#include "config/tracking.h"
#include "draw_plot.h"
#include "head_walk.h"
#include "tracking/head_tracker.h"

namespace optique::bench {
namespace {

using testing::HeadWalk;
using tracking::Nanos;

constexpr double kRate = 60.0;                     // tracker frames and display frames a second
constexpr double kSeconds = 20.0;                  // simulated per cell
constexpr double kSettle = 1.0;                    // seconds left out at the start
constexpr int kPhases = 8;                         // tracker frames against display frames
constexpr double kNoise = 0.0005;                  // m, each coordinate's (Gaussian, as a tracker's jitter)
const int kLatencies[] = {0, 10, 20, 30, 40, 50};  // ms

struct Method {
  std::string name;
  config::HeadPrediction prediction;
  double smoothing;
};

struct Cell {
  double median_mm = 0.0;
  double p99_mm = 0.0;
  double max_mm = 0.0;
};

double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

Nanos nanos(double seconds) { return static_cast<Nanos>(std::llround(seconds * 1e9)); }

Cell measure(const Method& method, double latency) {
  std::vector<double> errors;
  for (int phase = 0; phase < kPhases; ++phase) {
    config::Tracking settings;
    settings.prediction = method.prediction;
    settings.smoothing = method.smoothing;
    tracking::HeadTracker tracker(settings);
    std::mt19937 random(static_cast<unsigned>(phase + 1));
    std::normal_distribution<double> jitter(0.0, kNoise);
    const double offset = phase / (kPhases * kRate);  // the tracker's frames against the display's
    std::uint64_t sample = 0;
    std::vector<std::string> said;
    for (int frame = 0; frame < static_cast<int>(kSeconds * kRate); ++frame) {
      const double begin = frame / kRate;
      // Every sample that has arrived by the frame's beginning.
      while (true) {
        const double shows = offset + static_cast<double>(sample) / kRate;
        const double arrives = shows + latency;
        if (arrives > begin) break;
        const std::string text = testing::dtrack_frame(
            sample, latency,
            testing::dtrack_body(0, HeadWalk::eyes(shows) + glm::dvec3(jitter(random), jitter(random), jitter(random)),
                                 HeadWalk::head(shows)));
        (void)tracker.datagram(text, nanos(arrives));
        ++sample;
      }
      tracker.notice(nanos(begin), said);
      const double display = begin + 1.0 / kRate;
      const tracking::HeadAt head = tracker.at(nanos(display), HeadWalk::eyes(0.0));
      if (begin < kSettle || head.state != tracking::TrackerState::tracking) continue;
      errors.push_back(1000.0 * glm::distance(head.pose.position, HeadWalk::eyes(display)));
    }
  }
  return {quantile(errors, 0.5), quantile(errors, 0.99), quantile(errors, 1.0)};
}

}  // namespace
}  // namespace optique::bench

int main(int argc, char** argv) {
  using namespace optique;
  using namespace optique::bench;
  optique::bench::BenchOptions app{"head prediction against tracker latency"};
  std::string out;
  app.option("--out", out, "folder for tracking.md, .csv and .png (none: print only)");
  if (const std::optional<int> status = app.parse(argc, argv)) return *status;

  const std::vector<Method> methods{
      {"none", config::HeadPrediction::none, 0.5},
      {"constant-velocity", config::HeadPrediction::constant_velocity, 0.5},
      {"double-exponential α 0.3", config::HeadPrediction::double_exponential, 0.3},
      {"double-exponential α 0.5", config::HeadPrediction::double_exponential, 0.5},
      {"double-exponential α 0.7", config::HeadPrediction::double_exponential, 0.7},
      {"double-exponential α 0.9", config::HeadPrediction::double_exponential, 0.9},
  };
  std::ostringstream table;
  table << "| prediction |";
  for (int l : kLatencies) table << " " << l << " ms |";
  table << "\n|---|";
  for (std::size_t i = 0; i < std::size(kLatencies); ++i) table << "---|";
  table << "\n";
  std::ostringstream csv;
  csv << "method,smoothing,latency_ms,median_mm,p99_mm,max_mm\n";
  for (const Method& m : methods) {
    table << "| " << m.name << " |";
    for (int l : kLatencies) {
      const Cell c = measure(m, l / 1000.0);
      table << " " << std::fixed << std::setprecision(1) << c.median_mm << " (" << c.p99_mm << ") |";
      csv << m.name.substr(0, m.name.find(' ')) << "," << m.smoothing << "," << l << "," << c.median_mm << ","
          << c.p99_mm << "," << c.max_mm << "\n";
    }
    table << "\n";
  }
  std::cout << table.str();
  if (out.empty()) return 0;
  std::filesystem::create_directories(out);
  std::ofstream(out + "/tracking.csv") << csv.str();
  std::ofstream md(out + "/tracking.md");
  md << "# Head prediction against tracker latency\n\n"
     << "`optique-bench-tracking --out docs/bench` (about a second; simulated time, so the same on every machine). "
        "The master's head tracker — the code the master runs — is fed a head walking at 1.2 m/s around a 2 m "
        "circle, its eyes bobbing 1 cm at 1.8 Hz and facing its way (peak acceleration about 1.5 m/s²), as DTrack "
        "sends it: 60 frames a second, each with its latency in `ts2` and 0.5 mm of jitter (Gaussian, each "
        "coordinate). At every 60 Hz frame it predicts the eyes "
        "at the frame's display time, a frame after the frame begins; the table gives the distance to where the "
        "walking eyes then are, median (p99) in mm over "
     << kSeconds - kSettle << " s × " << kPhases
     << " phases of the tracker's frames against the display's. The horizon is the latency, plus up to a frame "
        "since the newest sample arrived, plus the frame to the display.\n\n"
     << table.str() << "\n![error against latency](tracking.png)\n";
  md.close();
  std::cout << "wrote " << out << "/tracking.md and .csv\n";
  return draw_plot(out, "tracking") ? 0 : 1;
}
