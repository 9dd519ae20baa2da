// The live scene (master.api) on real processes: a master and null nodes on
// loopback, an application through the C++ client (clients/cpp).
//
// Throughput: the application moves 1, 100, 1,000 or 10,000 instances every
// frame, each time a frame begins; right before each, the same cluster with
// no application, so that each is held against a run a minute apart at most
// (this machine's barrier round drifted by half between runs minutes apart).
// The barrier round, the achieved frame rate and the bytes of the scene every
// node is sent a frame (its FrameBegin and the edits staged for it between
// rounds) and of the FrameBegin alone, against a snapshot of the whole state
// (run.json: frame_state_bytes, frame_begin_bytes, snapshot_bytes).
//
// Latency, edit to display: from the moment the application sends a
// transaction to the display time of the frame its reply names (the first
// frame every node shows it in; the master's FrameBegun events say when that
// is, one period after the frame begins), and to when the last node presented
// that frame (frames.csv: at the Swap's deadline), all on this machine's
// monotonic clock. Three ways to send: right when
// a frame begins (an application that answers each frame), at any moment
// (uniformly through the period), and just before the next frame begins
// (FrameBegun says when: its display time).
//
// Writes live-scene.md, live-scene.csv (one row per run) and live-scene.png.
//
//   optique-bench-live-scene [--out DIR] [--frames N] [--rate HZ] [--nodes N] [--repeats R]
//                            [--counts 1,100,1000,10000] [--lead-us US]

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <thread>

#include "bench_options.h"
#include "clients/cpp/session.h"
#include "cluster_run.h"
#include "draw_plot.h"
#include "metrics/distribution.h"
#include "process.h"
#include "scratch.h"
#include "spread.h"
#include "strip_wall.h"

namespace {

using namespace optique;
using Clock = std::chrono::steady_clock;

// When the application sends its transaction of each frame.
enum class Send { none, at_begin, any_moment, before_next };

const char* name_of(Send send) {
  switch (send) {
    case Send::none:
      return "none";
    case Send::at_begin:
      return "at-begin";
    case Send::any_moment:
      return "any-moment";
    case Send::before_next:
      return "before-next";
  }
  return "?";
}

struct Case {
  Send send = Send::none;
  std::size_t moved = 0;  // instances moved in each transaction
};

struct Sample {
  double barrier_median = 0, barrier_p99 = 0;
  double frame_rate = 0;
  double begin_bytes_median = 0;
  double state_bytes_median = 0;
  double snapshot_bytes = 0;
  double latency_median_ms = 0, latency_p99_ms = 0;  // to the display time
  double present_median_ms = 0, present_p99_ms = 0;  // to the last node's present
  double transactions = 0;
  std::size_t refused = 0;
  std::uint64_t missing = 0, mismatches = 0;
};

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
}

// What the application saw: each applied transaction's send time and the
// frame its reply named, and each frame's display time (FrameBegun).
struct Driven {
  std::map<std::uint64_t, std::int64_t> display;             // frame → display time, ns
  std::vector<std::pair<std::int64_t, std::uint64_t>> sent;  // send time, the frame the reply names
};

// The application: creates `moved` instances, then moves them all in one
// transaction a frame, sent as `send` says, until the master stops.
Driven drive(std::uint16_t port, const Case& c, std::int64_t lead_ns, Sample& s) {
  client::Options options;
  options.port = port;
  options.name = "bench";
  auto connected = client::Session::connect(options);
  if (!connected) throw std::runtime_error("the bench could not connect: " + connected.error());
  client::Session& app = *connected.value();
  const auto name = [](std::size_t i) { return "i" + std::to_string(i); };
  client::Transaction create;
  for (std::size_t i = 0; i < c.moved; ++i) {
    create.create(name(i), "cubes",
                  {{{0.001 * static_cast<double>(i % 1000), 1.0, -0.01 * static_cast<double>(i / 1000)}},
                   std::nullopt,
                   {{0.01, 0.01, 0.01}}});
  }
  auto created = app.apply(create);
  if (!created || !created.value().applied()) {
    throw std::runtime_error("creating the instances failed: " +
                             (created ? created.value().refused->reason() : created.error()));
  }
  session::Subscribe kinds;
  kinds.set_frames(true);
  kinds.set_run(true);
  if (auto subscribed = app.subscribe(kinds); !subscribed) throw std::runtime_error(subscribed.error());

  std::mt19937_64 random(42);
  Driven driven;
  auto& display = driven.display;
  auto& sent = driven.sent;
  bool stopping = false;
  while (!stopping) {
    // The newest frame begun: what came while the last transaction was answered first.
    std::optional<session::FrameBegun> newest;
    auto event = app.next_event(std::chrono::seconds(5));
    while (event && event.value()) {
      if (event.value()->has_frame_begun()) {
        newest = event.value()->frame_begun();
        display[newest->frame()] = newest->display_ns();
      }
      if (event.value()->has_run() && event.value()->run().state() == session::RunChanged::STOPPING) stopping = true;
      event = app.next_event(std::chrono::milliseconds(0));
    }
    if (!event) break;  // the master closed the session: the run is over
    if (!newest || stopping) continue;
    const std::int64_t period = newest->period_ns();
    std::int64_t at = now_ns();
    if (c.send == Send::any_moment) {
      at = newest->display_ns() - period + std::uniform_int_distribution<std::int64_t>(0, period - 1)(random);
    } else if (c.send == Send::before_next) {
      at = newest->display_ns() - lead_ns;  // the next frame begins about when this one is shown
    }
    if (at > now_ns()) std::this_thread::sleep_for(std::chrono::nanoseconds(at - now_ns()));
    client::Transaction move;
    const double t = static_cast<double>(newest->frame()) / 60.0;
    for (std::size_t i = 0; i < c.moved; ++i) {
      move.move(name(i), {{{0.001 * static_cast<double>(i % 1000) + 0.1 * std::sin(t), 1.0 + 0.1 * std::cos(t),
                            -0.01 * static_cast<double>(i / 1000)}},
                          std::nullopt,
                          std::nullopt});
    }
    const std::int64_t sent_at = now_ns();
    auto outcome = app.apply(move);
    if (!outcome) break;  // the run ended while it was answered
    ++s.transactions;
    if (!outcome.value().applied()) {
      ++s.refused;
      continue;
    }
    sent.emplace_back(sent_at, outcome.value().frame);
  }
  return driven;
}

// Milliseconds from each send to its frame's time in `at` (frames without one left out).
std::vector<double> latencies_to(const Driven& driven, const std::map<std::uint64_t, std::int64_t>& at) {
  std::vector<double> latencies;
  for (const auto& [sent, frame] : driven.sent) {
    const auto shown = at.find(frame);
    if (shown != at.end()) latencies.push_back(static_cast<double>(shown->second - sent) / 1e6);
  }
  return latencies;
}

Sample run_once(const std::string& master_bin, const std::string& work, std::size_t nodes, std::size_t frames,
                double rate, const Case& c, std::int64_t lead_ns) {
  const std::string config = work + "/live-" + std::to_string(nodes) + ".json";
  std::ofstream(config) << bench::strip_wall_json(nodes, rate);
  const std::string out = work + "/run";
  const std::string port_file = work + "/api.port";
  std::filesystem::remove_all(out);
  std::filesystem::remove(port_file);
  testing::Process master(
      {master_bin, "--config", config, "--local", "--frames", std::to_string(frames), "--out", out, "--no-status",
       "--log-level", "warn", "--node-arg=--renderer=null", "--api-port", "0", "--api-port-file", port_file},
      work + "/master.log");
  Sample s;
  Driven driven;
  if (c.send != Send::none) {
    if (!testing::wait_for_file(port_file, std::chrono::seconds(30))) {
      throw std::runtime_error("the master wrote no api port:\n" + master.output());
    }
    driven = drive(static_cast<std::uint16_t>(std::stoi(testing::read_file(port_file))), c, lead_ns, s);
  }
  const auto status = master.wait(std::chrono::seconds(180));
  if (status != 0) throw std::runtime_error("master failed:\n" + master.output());
  const auto run = testing::read_cluster_run(out);
  if (!run.error.empty()) throw std::runtime_error(run.error);
  const auto& sync = run.report.sync();
  s.barrier_median = sync.barrier_round_us().median();
  s.barrier_p99 = sync.barrier_round_us().p99();
  s.frame_rate = sync.achieved_frame_rate();
  s.missing = sync.frames_with_missing_node();
  s.begin_bytes_median = run.report.frame_begin_bytes().median();
  s.state_bytes_median = run.report.frame_state_bytes().median();
  s.snapshot_bytes = static_cast<double>(run.report.snapshot_bytes());
  for (const auto& node : run.report.nodes()) s.mismatches += node.hash_mismatches();
  // A frame is on the screen when its last node presents it (frames every node presented only).
  std::map<std::uint64_t, std::int64_t> presented;
  std::map<std::uint64_t, std::size_t> presenters;
  for (const testing::FrameRow& row : run.rows) {
    if (row.presented == 0) continue;
    presented[row.frame] = std::max(presented[row.frame], row.presented);
    ++presenters[row.frame];
  }
  std::erase_if(presented, [&](const auto& entry) { return presenters[entry.first] != nodes; });
  if (auto to_display = latencies_to(driven, driven.display); !to_display.empty()) {
    const auto summary = metrics::summarize(std::move(to_display));
    s.latency_median_ms = summary.median();
    s.latency_p99_ms = summary.p99();
  }
  if (auto to_present = latencies_to(driven, presented); !to_present.empty()) {
    const auto summary = metrics::summarize(std::move(to_present));
    s.present_median_ms = summary.median();
    s.present_p99_ms = summary.p99();
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  bench::BenchOptions app{"optique live scene benchmark"};
  std::string out = "docs/bench";
  // 5 s at 60 Hz; moving 10,000 instances a frame on 2 cores the same frames take 100 s.
  std::size_t frames = 300;
  double rate = 60.0;
  std::size_t nodes = 8;
  std::size_t repeats = 5;
  double lead_us = 2000.0;
  std::vector<std::size_t> counts{1, 100, 1000, 10000};
  std::string master_bin = std::string(OPTIQUE_BIN_DIR) + "/optique-master";
  app.option("--out", out, "folder for live-scene.md, live-scene.csv and live-scene.png");
  app.option("--frames", frames, "frames per run", bench::Bounds::more_than_zero());
  app.option("--rate", rate, "frame rate in Hz", bench::Bounds::more_than_zero());
  app.option("--nodes", nodes, "null nodes", bench::Bounds::more_than_zero());
  app.option("--repeats", repeats, "runs of each case; the table shows the median and the min–max",
             bench::Bounds::more_than_zero());
  app.list("--counts", counts, "instances moved per frame");
  app.option("--lead-us", lead_us, "before-next: how long before the next frame begins the application sends",
             bench::Bounds::more_than_zero());
  app.option("--master", master_bin, "optique-master binary");
  if (const std::optional<int> status = app.parse(argc, argv)) return *status;
  if (counts.empty() || std::find(counts.begin(), counts.end(), 0u) != counts.end()) {
    std::cerr << "optique-bench-live-scene: --counts needs one or more counts, each at least 1\n";
    return 2;
  }

  // One repeat runs every case once, so that each sees the same machine.
  std::vector<Case> cases{{Send::none, 0}};
  for (const std::size_t n : counts) cases.push_back({Send::at_begin, n});
  cases.push_back({Send::any_moment, 1});
  cases.push_back({Send::before_next, 1});

  const testing::ScratchDir work_scratch("optique-bench-live");
  const std::string work = work_scratch.string();
  std::filesystem::create_directories(out);
  std::ofstream csv(out + "/live-scene.csv");
  csv << "case,send,moved,repeat,nodes,frames,rate_hz,barrier_median_us,barrier_p99_us,achieved_hz,"
         "frame_begin_bytes_median,frame_state_bytes_median,snapshot_bytes,latency_median_ms,latency_p99_ms,"
         "transactions,refused,"
         "frames_with_missing_node,hash_mismatches,present_latency_median_ms,present_latency_p99_ms\n";
  std::vector<std::vector<Sample>> samples(cases.size());
  // For each throughput run, the run without an application just before it.
  std::vector<std::vector<Sample>> paired_none(cases.size());
  for (std::size_t r = 0; r < repeats; ++r) {
    for (std::size_t i = 0; i < cases.size(); ++i) {
      // The run without an application goes before each run it is held against, not once.
      if (cases[i].send == Send::none) continue;
      std::vector<std::size_t> runs{i};
      if (cases[i].send == Send::at_begin) runs.insert(runs.begin(), 0);
      for (const std::size_t run : runs) {
        const Case& c = cases[run];
        const Sample s = run_once(master_bin, work, nodes, frames, rate, c, static_cast<std::int64_t>(lead_us * 1e3));
        samples[run].push_back(s);
        if (run == 0) paired_none[i].push_back(s);
        csv << run << ',' << name_of(c.send) << ',' << c.moved << ',' << r << ',' << nodes << ',' << frames << ','
            << rate << ',' << s.barrier_median << ',' << s.barrier_p99 << ',' << s.frame_rate << ','
            << s.begin_bytes_median << ',' << s.state_bytes_median << ',' << s.snapshot_bytes << ','
            << s.latency_median_ms << ',' << s.latency_p99_ms << ',' << s.transactions << ',' << s.refused << ','
            << s.missing << ',' << s.mismatches << ',' << s.present_median_ms << ',' << s.present_p99_ms << '\n'
            << std::flush;
        std::cerr << name_of(c.send) << " " << c.moved << " repeat " << r << ": barrier " << s.barrier_median << " µs, "
                  << s.frame_rate << " Hz, FrameBegin " << s.begin_bytes_median << " B (snapshot " << s.snapshot_bytes
                  << " B), latency " << s.latency_median_ms << " ms (p99 " << s.latency_p99_ms << "), "
                  << s.transactions << " transactions, " << s.mismatches << " hash mismatches\n";
      }
    }
  }

  using bench::cell;
  using bench::spread;
  const double period_ms = 1e3 / rate;
  const auto column = [&](std::size_t i, double Sample::*field) {
    std::vector<double> values;
    for (const Sample& s : samples[i]) values.push_back(s.*field);
    return spread(values);
  };
  // The barrier round of each run against the run without an application just before it.
  const auto against_none = [&](std::size_t i) {
    std::vector<double> ratios;
    if (i == 0) return spread({1.0});
    for (std::size_t r = 0; r < repeats; ++r)
      ratios.push_back(samples[i][r].barrier_median / paired_none[i][r].barrier_median);
    return spread(ratios);
  };
  std::ostringstream table;
  table << "| application | instances moved a frame | barrier round median µs | p99 µs | against none (median) | "
           "achieved Hz | scene bytes a frame (median) | of which FrameBegin | snapshot bytes | hash mismatches |\n"
        << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  std::size_t all_mismatches = 0;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    if (cases[i].send != Send::none && cases[i].send != Send::at_begin) continue;
    std::size_t mismatches = 0;
    for (const Sample& s : samples[i]) mismatches += s.mismatches;
    all_mismatches += mismatches;
    table << "| " << (cases[i].send == Send::none ? "none" : "moves every instance each frame") << " | "
          << cases[i].moved << " | " << cell(column(i, &Sample::barrier_median), 0) << " | "
          << cell(column(i, &Sample::barrier_p99), 0) << " | " << cell(against_none(i), 2) << " | "
          << cell(column(i, &Sample::frame_rate), 1) << " | " << cell(column(i, &Sample::state_bytes_median), 0)
          << " | " << cell(column(i, &Sample::begin_bytes_median), 0) << " | "
          << cell(column(i, &Sample::snapshot_bytes), 0) << " | " << mismatches << " |\n";
  }
  std::ostringstream latency;
  latency << "| sent | instances moved | to the display time: median ms | p99 ms | median / period | to the last "
             "present: median ms | p99 ms | median / (period + barrier round) | transactions a run |\n"
          << "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (std::size_t i = 1; i < cases.size(); ++i) {
    std::vector<double> in_periods;
    std::vector<double> against_goal;  // the bar: the median at most a period and the run's barrier round
    for (const Sample& s : samples[i]) {
      in_periods.push_back(s.latency_median_ms / period_ms);
      against_goal.push_back(s.present_median_ms / (period_ms + s.barrier_median / 1e3));
    }
    latency << "| " << name_of(cases[i].send) << " | " << cases[i].moved << " | "
            << cell(column(i, &Sample::latency_median_ms), 2) << " | " << cell(column(i, &Sample::latency_p99_ms), 2)
            << " | " << cell(spread(in_periods), 2) << " | " << cell(column(i, &Sample::present_median_ms), 2) << " | "
            << cell(column(i, &Sample::present_p99_ms), 2) << " | " << cell(spread(against_goal), 2) << " | "
            << cell(column(i, &Sample::transactions), 0) << " |\n";
  }

  std::ofstream md(out + "/live-scene.md");
  md << "# Live scene: edits from an application to the screen\n\n"
     << "Generated by `optique-bench-live-scene` (tests/bench/live_scene_bench.cpp): a master and " << nodes
     << " null nodes (`--renderer=null`) on loopback, " << frames << " frames at " << rate
     << " Hz a run, and an application on the C++ client; every case once in each of " << repeats
     << " repeats, each throughput run right after a run without an application, so that they share the "
        "machine. Cells: median over the repeats (min–max).\n\n"
     << "## Throughput: instances moved every frame\n\n"
     << "The application moves every instance in one transaction each time a frame begins. The barrier round "
        "(FrameBegin sent → Swap sent) against the run without an application just before it (the none row: all of "
        "those runs). The master "
        "reads no request and sends no event while a round is under way, and sends the instances an application "
        "moved to the nodes between rounds (staged edits), so that the FrameBegin carries only what changed after "
        "them. The scene every node is sent a frame (its FrameBegin and the edits staged for it), and the "
        "FrameBegin alone, against a snapshot of the whole state (what a node that joins is sent). Hash "
        "mismatches: frames a node's state differed from the master's, all runs.\n\n"
     << table.str() << "\n"
     << "## Latency: from the send to the frame that shows it\n\n"
     << "The frame the reply names is the first every node shows the edit in. Two times of that frame: its display "
        "time, in the master's FrameBegun event, which the master's schedule puts one period after the frame "
        "begins (what the tracked head is predicted to, and what applications time their sends by); and when the "
        "last node presented it (frames.csv, on the master's clock: the Swap's deadline, the barrier round and "
        "the present lead after the frame begins). To the display time an edit waits for the next frame to begin "
        "and then one period: sent when a frame begins, about two periods; at any moment, about 1.5; just before "
        "the next frame begins ("
     << lead_us / 1e3
     << " ms before), about one period plus that lead. To the present it waits for the next frame to begin and "
        "then the barrier round and the present lead. The period is "
     << period_ms << " ms; the last column holds the present against the goal, a period and the run's barrier "
     << "round (≤ 1 meets it).\n\n"
     << latency.str() << "\n"
     << "![barrier round and scene bytes a frame against the instances moved a frame](live-scene.png)\n";
  csv.close();
  (void)bench::draw_plot(out, "live-scene");  // says itself what failed; the tables are written
  if (all_mismatches != 0) {
    std::cerr << "optique-bench-live-scene: " << all_mismatches << " hash mismatches (see live-scene.csv)\n";
    return 1;
  }
  return 0;
}
