// Barrier benchmark: optique's frame barrier (null renderer, real master and node
// processes on loopback) for 1 … 64 nodes, side by side in one run with a plain
// ready/go barrier at the same pacing. Writes a Markdown table, a CSV and a plot
// (barrier.png: barrier round and present skew against the node count). Then
// what sealing every message costs: runs with and without the shared secret,
// alternating, for a few node counts (barrier-secret.md, barrier-secret.csv).
//
//   optique-bench-barrier [--out DIR] [--frames N] [--rate HZ] [--repeats R] [--nodes 1,2,4]
//                         [--secret-nodes 1,8]

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "bench_options.h"
#include "cluster_run.h"
#include "draw_plot.h"
#include "metrics/distribution.h"
#include "process.h"
#include "ready_go_baseline.h"
#include "spread.h"
#include "strip_wall.h"

namespace {

using namespace optique;

struct Sample {
  double barrier_median = 0, barrier_p99 = 0, skew_median = 0, skew_p99 = 0;
  double baseline_median = 0, baseline_p99 = 0;
  std::uint64_t missing = 0;
  double presented_by_all = 0;  // fraction of the frames every node presented
};

// The fraction of frames [0, frames) that all `nodes` of the run presented.
double presented_by_all(const testing::ClusterRun& run, std::size_t nodes, std::size_t frames) {
  std::vector<std::size_t> presenters(frames, 0);
  for (const auto& row : run.rows) {
    if (row.presented != 0 && row.frame < frames) ++presenters[row.frame];
  }
  const auto complete = std::count(presenters.begin(), presenters.end(), nodes);
  return static_cast<double>(complete) / static_cast<double>(frames);
}

Sample run_once(const std::string& master_bin, const std::string& work, std::size_t nodes, std::size_t frames,
                double rate, bool sealed = false) {
  const std::string config = work + "/bench-" + std::to_string(nodes) + ".json";
  std::ofstream(config) << bench::strip_wall_json(nodes, rate, sealed);
  const std::string out = work + "/run-" + std::to_string(nodes);
  std::filesystem::remove_all(out);
  testing::Process master({master_bin, "--config", config, "--local", "--frames", std::to_string(frames), "--out", out,
                           "--no-status", "--log-level", "warn", "--node-arg=--renderer=null"},
                          work + "/master.log");
  const auto status = master.wait(std::chrono::seconds(120));
  if (status != 0) throw std::runtime_error("master failed:\n" + master.output());
  const auto run = testing::read_cluster_run(out);
  if (!run.error.empty()) throw std::runtime_error(run.error);
  Sample s;
  const auto& sync = run.report.sync();
  s.barrier_median = sync.barrier_round_us().median();
  s.barrier_p99 = sync.barrier_round_us().p99();
  s.skew_median = sync.present_skew_us().median();
  s.skew_p99 = sync.present_skew_us().p99();
  s.missing = sync.frames_with_missing_node();
  s.presented_by_all = presented_by_all(run, nodes, frames);
  auto baseline = bench::ready_go_rounds(nodes, frames, rate);
  const auto summary = metrics::summarize(std::move(baseline));
  s.baseline_median = summary.median();
  s.baseline_p99 = summary.p99();
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  optique::bench::BenchOptions app{"optique barrier benchmark"};
  std::string out = "docs/bench";
  std::size_t frames = 600;  // 10 s at 60 Hz
  double rate = 60.0;
  std::size_t repeats = 3;
  std::vector<std::size_t> node_counts{1, 2, 4, 8, 16, 32, 64};
  std::string master_bin = std::string(OPTIQUE_BIN_DIR) + "/optique-master";
  app.option("--out", out, "folder for barrier.md, barrier.csv and barrier.png");
  app.option("--frames", frames, "frames (and baseline rounds) per run", optique::bench::Bounds::more_than_zero());
  app.option("--rate", rate, "frame rate in Hz (both barriers are paced at it)",
             optique::bench::Bounds::more_than_zero());
  app.option("--repeats", repeats, "runs per node count; the table shows the median and the min–max",
             optique::bench::Bounds::more_than_zero());
  app.list("--nodes", node_counts, "node counts");
  std::vector<std::size_t> secret_nodes{1, 8};
  app.list("--secret-nodes", secret_nodes, "node counts run with and without the shared secret (none: skip)");
  app.option("--master", master_bin, "optique-master binary");
  if (const std::optional<int> status = app.parse(argc, argv)) return *status;
  if (node_counts.empty() || std::find(node_counts.begin(), node_counts.end(), 0u) != node_counts.end()) {
    std::cerr << "optique-bench-barrier: --nodes needs one or more node counts, each at least 1\n";
    return 2;
  }
  std::sort(node_counts.begin(), node_counts.end());

  const testing::ScratchDir work_scratch("optique-bench");

  const std::string work = work_scratch.string();
  std::filesystem::create_directories(out);
  std::ofstream csv(out + "/barrier.csv");
  csv << "nodes,repeat,frames,rate_hz,barrier_median_us,barrier_p99_us,present_skew_median_us,present_skew_p99_us,"
         "ready_go_median_us,ready_go_p99_us,frames_with_missing_node,presented_by_all\n";
  std::ostringstream table;
  table << "| nodes | optique barrier round median µs | p99 µs | present skew median µs | p99 µs | "
           "ready/go baseline median µs | p99 µs | optique / baseline (median) | frames presented by all nodes % |\n"
        << "|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (std::size_t nodes : node_counts) {
    std::vector<double> bm, bp, sm, sp, gm, gp, ratio, all;
    for (std::size_t r = 0; r < repeats; ++r) {
      const Sample s = run_once(master_bin, work, nodes, frames, rate);
      csv << nodes << ',' << r << ',' << frames << ',' << rate << ',' << s.barrier_median << ',' << s.barrier_p99 << ','
          << s.skew_median << ',' << s.skew_p99 << ',' << s.baseline_median << ',' << s.baseline_p99 << ',' << s.missing
          << ',' << s.presented_by_all << '\n'
          << std::flush;
      bm.push_back(s.barrier_median);
      bp.push_back(s.barrier_p99);
      sm.push_back(s.skew_median);
      sp.push_back(s.skew_p99);
      gm.push_back(s.baseline_median);
      gp.push_back(s.baseline_p99);
      ratio.push_back(s.barrier_median / s.baseline_median);
      all.push_back(100.0 * s.presented_by_all);
      std::cerr << "nodes " << nodes << " repeat " << r << ": barrier " << s.barrier_median << " µs, skew "
                << s.skew_median << " µs, ready/go " << s.baseline_median << " µs, presented by all "
                << 100.0 * s.presented_by_all << " %\n";
    }
    using bench::cell;
    using bench::spread;
    const bench::Spread barrier_median = spread(bm), barrier_p99 = spread(bp);
    const bench::Spread skew_median = spread(sm), skew_p99 = spread(sp);
    table << "| " << nodes << " | " << cell(barrier_median, 0) << " | " << cell(barrier_p99, 0) << " | "
          << cell(skew_median, 0) << " | " << cell(skew_p99, 0) << " | " << cell(spread(gm), 0) << " | "
          << cell(spread(gp), 0) << " | " << cell(spread(ratio), 2) << " | " << cell(spread(all), 1) << " |\n";
  }

  // Sealed sessions against plain ones, alternating so that both see the same
  // machine.
  std::ofstream secret_csv(out + "/barrier-secret.csv");
  secret_csv << "nodes,repeat,sealed,barrier_median_us,barrier_p99_us,present_skew_median_us,present_skew_p99_us\n";
  std::ostringstream secret_table;
  secret_table << "| nodes | plain: barrier median µs | p99 µs | sealed: barrier median µs | p99 µs | sealed / plain "
                  "(median) | plain: skew median µs | sealed: skew median µs |\n"
               << "|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  {
    const std::string secret = work + "/secret";
    std::ofstream(secret) << "a secret for the barrier bench, 32 bytes or so\n";
    std::filesystem::permissions(secret, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  }
  for (std::size_t nodes : secret_nodes) {
    std::vector<double> pm, pp, qm, qp, ratio, ps, qs;
    for (std::size_t r = 0; r < repeats; ++r) {
      for (const bool sealed : {false, true}) {
        const Sample s = run_once(master_bin, work, nodes, frames, rate, sealed);
        secret_csv << nodes << ',' << r << ',' << sealed << ',' << s.barrier_median << ',' << s.barrier_p99 << ','
                   << s.skew_median << ',' << s.skew_p99 << '\n'
                   << std::flush;
        (sealed ? qm : pm).push_back(s.barrier_median);
        (sealed ? qp : pp).push_back(s.barrier_p99);
        (sealed ? qs : ps).push_back(s.skew_median);
        std::cerr << "nodes " << nodes << " repeat " << r << (sealed ? " sealed" : " plain") << ": barrier "
                  << s.barrier_median << " µs, skew " << s.skew_median << " µs\n";
      }
      ratio.push_back(qm.back() / pm.back());
    }
    using bench::cell;
    using bench::spread;
    secret_table << "| " << nodes << " | " << cell(spread(pm), 0) << " | " << cell(spread(pp), 0) << " | "
                 << cell(spread(qm), 0) << " | " << cell(spread(qp), 0) << " | " << cell(spread(ratio), 2) << " | "
                 << cell(spread(ps), 0) << " | " << cell(spread(qs), 0) << " |\n";
  }
  std::ofstream secret_md(out + "/barrier-secret.md");
  secret_md << "What sealing every message costs (master.secret_file: AES-256-GCM per message after the hello): "
            << frames << " frames at " << rate << " Hz, " << repeats
            << " pairs of runs per row, plain and sealed alternating; each cell is the median over runs with the "
               "min–max in brackets. Null-render nodes, all on this machine.\n\n"
            << secret_table.str();
  secret_md.close();
  secret_csv.close();
  std::cout << secret_table.str();

  std::ofstream md(out + "/barrier.md");
  md << "Barrier benchmark: " << frames << " frames at " << rate << " Hz, " << repeats
     << " runs per row; each cell is the median over runs with the min–max in brackets. "
        "Null-render nodes, all on this machine; a frame counts as presented by all nodes when every node reported "
        "its present.\n\n"
     << table.str() << "\n![barrier round and present skew against the node count](barrier.png)\n";
  md.close();
  csv.close();
  std::cout << table.str();
  std::filesystem::remove_all(work);
  return bench::draw_plot(out, "barrier") ? 0 : 1;
}
