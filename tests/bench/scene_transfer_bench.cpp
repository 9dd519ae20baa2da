// A large glTF scene sent from the master to a node with an empty cache, over
// loopback: real processes (optique-master, optique-node-gl), the rate the node
// reports for its fetch (chunks asked for, checked against the manifest, stored,
// the copy put in place). Side by side in each run, on the
// same bytes and the same disk:
//   - raw TCP: the bytes through a loopback socket, read and dropped (the link);
//   - TCP, checked and stored: received in 1 MiB pieces, each hashed (SHA-256)
//     and written to a file — the least a node that checks what it stores must
//     do;
//   - the cached copy checked again (what a restarted node does instead of a
//     fetch: every file's SHA-256), in-process through node::SceneCache.
//
//   optique-bench-scene-transfer --out docs/bench [--mib 200] [--runs 5]

#include <arpa/inet.h>
#include <netinet/in.h>
#include <spdlog/sinks/null_sink.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_options.h"
#include "draw_plot.h"
#include "external_master.h"
#include "node/scene_cache.h"
#include "process.h"
#include "scene_load/gltf.h"
#include "spread.h"
#include "util/sha256.h"

namespace optique::bench {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

constexpr std::size_t kPiece = 1u << 20;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// The torus with a buffer of `bytes` beside it (unused by its mesh, part of the
// scene), in `dir`/scene; returns the glTF's path.
std::string make_scene(const fs::path& dir, std::size_t bytes) {
  const fs::path scene = dir / "scene";
  fs::create_directories(scene);
  const std::string torus = std::string(OPTIQUE_SOURCE_DIR) + "/configs/assets/torus/";
  for (const char* name : {"torus.gltf", "torus.bin", "torus.png"}) fs::copy_file(torus + name, scene / name);
  {
    std::ofstream big(scene / "big.bin", std::ios::binary);
    std::string piece(kPiece, '\0');
    for (std::size_t done = 0; done < bytes; done += piece.size()) {
      for (std::size_t i = 0; i < piece.size(); ++i) piece[i] = static_cast<char>(((done + i) * 2654435761u) >> 13);
      big.write(piece.data(), static_cast<std::streamsize>(std::min(piece.size(), bytes - done)));
    }
  }
  std::ifstream in(scene / "torus.gltf");
  nlohmann::json gltf = nlohmann::json::parse(in);
  gltf["buffers"].push_back({{"uri", "big.bin"}, {"byteLength", bytes}});
  std::ofstream(scene / "torus.gltf") << gltf.dump(1);
  return (scene / "torus.gltf").string();
}

std::string make_config(const fs::path& dir, const std::string& gltf) {
  std::ifstream in(std::string(OPTIQUE_SOURCE_DIR) + "/configs/gltf-torus.json");
  nlohmann::json config = nlohmann::json::parse(in);
  config["scene"]["gltf"] = gltf;
  config["master"]["listen"] = "127.0.0.1";
  config["master"]["port"] = 0;
  const fs::path path = dir / "config.json";
  std::ofstream(path) << config.dump(1);
  return path.string();
}

// The SHA-256 of a file read back in 1 MiB pieces, as node::SceneCache checks one.
std::string sha256_of_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  util::Sha256 digest;
  std::vector<char> piece(kPiece);
  while (in) {
    in.read(piece.data(), static_cast<std::streamsize>(piece.size()));
    digest.update(std::string_view(piece.data(), static_cast<std::size_t>(in.gcount())));
  }
  return digest.finish();
}

// `bytes` through a loopback TCP connection, the receiver doing `take` with each
// piece it reads; the seconds from connect to the last byte taken.
double through_loopback(const std::string& bytes, const std::function<void(const char*, std::size_t)>& take) {
  const int listener = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(listener, reinterpret_cast<sockaddr*>(&address), sizeof address);
  listen(listener, 1);
  socklen_t length = sizeof address;
  getsockname(listener, reinterpret_cast<sockaddr*>(&address), &length);
  const auto start = Clock::now();
  std::thread sender([&] {
    const int fd = socket(AF_INET, SOCK_STREAM, 0);
    if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0) {
      for (std::size_t sent = 0; sent < bytes.size();) {
        const ssize_t n = send(fd, bytes.data() + sent, std::min(kPiece, bytes.size() - sent), 0);
        if (n <= 0) break;
        sent += static_cast<std::size_t>(n);
      }
    }
    close(fd);
  });
  const int fd = accept(listener, nullptr, nullptr);
  std::vector<char> buffer(kPiece);
  std::size_t filled = 0;
  std::size_t received = 0;
  while (received < bytes.size()) {
    const ssize_t n = recv(fd, buffer.data() + filled, buffer.size() - filled, 0);
    if (n <= 0) break;
    filled += static_cast<std::size_t>(n);
    received += static_cast<std::size_t>(n);
    if (filled == buffer.size() || received == bytes.size()) {
      take(buffer.data(), filled);
      filled = 0;
    }
  }
  const double took = seconds_since(start);
  close(fd);
  close(listener);
  sender.join();
  if (received != bytes.size()) throw std::runtime_error("the loopback baseline lost bytes");
  return took;
}

struct Measured {
  std::string method;
  double seconds = 0.0;
};

// One fetch by a real node; the seconds it reports.
double optique_fetch(const std::string& config, const fs::path& cache, const fs::path& dir) {
  testing::Process master({testing::master_binary(), "--config", config, "--port-file", (dir / "port").string(),
                           "--frames", "3", "--no-status", "--out", (dir / "out").string()},
                          (dir / "master.log").string());
  const std::string port = testing::wait_for_port((dir / "port").string(), 20s);
  if (port.empty()) throw std::runtime_error("the master wrote no port");
  testing::Process node({testing::node_binary(), "--master", "127.0.0.1:" + port, "--id", "wall", "--cache-dir",
                         cache.string(), "--capture-dir", (dir / "captures").string()},
                        (dir / "node.log").string());
  if (master.wait(300s) != 0 || node.wait(60s) != 0) {
    throw std::runtime_error("the run failed:\n" + master.output() + node.output());
  }
  const std::string log = node.output();
  std::smatch match;
  if (!std::regex_search(log, match, std::regex(R"(fetched the scene: ([0-9.]+) MiB in ([0-9.]+) s)"))) {
    throw std::runtime_error("the node reported no fetch:\n" + log);
  }
  return std::stod(match[2]);
}

int run(const std::string& out, std::size_t mib, int runs) {
  const testing::ScratchDir work_folder("optique-bench-transfer");
  const fs::path work = work_folder.path();
  const std::size_t big = mib << 20;
  const std::string gltf = make_scene(work, big);
  const std::string config = make_config(work, gltf);
  auto loaded = scene::load_gltf(gltf, {});
  if (!loaded) throw std::runtime_error(loaded.error());
  const scene::SceneManifest& manifest = loaded.value().manifest;
  const std::string identity = loaded.value().content_sha256;
  const std::uint64_t total = manifest.total_bytes();
  const std::string bytes = optique::testing::read_file(fs::path(gltf).parent_path() / "big.bin");
  std::cout << "scene: " << manifest.files.size() << " files, " << total / double(1 << 20) << " MiB\n";

  std::vector<Measured> rows;
  for (int r = 0; r < runs; ++r) {
    const fs::path dir = work / ("run-" + std::to_string(r));
    fs::create_directories(dir);
    // Each row starts with nothing left to write back from the one before (a
    // 200 MiB write-back beside a measurement halves it on this machine).
    sync();
    rows.push_back({"raw TCP", through_loopback(bytes, [](const char*, std::size_t) {})});
    {
      sync();
      const auto start = Clock::now();
      std::ofstream file(dir / "stored.bin", std::ios::binary);
      (void)through_loopback(bytes, [&](const char* data, std::size_t size) {
        (void)util::sha256_raw(std::string_view(data, size));
        file.write(data, static_cast<std::streamsize>(size));
      });
      file.close();
      rows.push_back({"TCP, checked and stored", seconds_since(start)});
      if (sha256_of_file(dir / "stored.bin") != util::sha256_raw(bytes)) {  // untimed: the baseline is honest
        throw std::runtime_error("the stored baseline differs");
      }
      fs::remove(dir / "stored.bin");
    }
    const fs::path cache = dir / "cache";
    sync();
    rows.push_back({"optique fetch", optique_fetch(config, cache, dir)});
    {
      sync();
      spdlog::logger quiet("bench", std::make_shared<spdlog::sinks::null_sink_mt>());
      node::SceneCache restarted(cache, quiet);
      const auto start = Clock::now();
      if (!restarted.find(manifest, identity)) throw std::runtime_error("the fetched copy is not in the cache");
      rows.push_back({"cached copy checked", seconds_since(start)});
    }
    // Left until the end: removing 400 MiB makes the file system busy for a
    // while, which slowed the next run's fetch to half.
    std::cout << "run " << r + 1 << "/" << runs << " done\n";
  }
  fs::remove_all(work);

  const std::vector<std::string> methods{"raw TCP", "TCP, checked and stored", "optique fetch", "cached copy checked"};
  fs::create_directories(out);
  std::ofstream csv(fs::path(out) / "scene-transfer.csv");
  csv << "run,method,mib,seconds,mib_per_s\n";
  std::map<std::string, std::vector<double>> rates;
  std::map<std::string, std::vector<double>> times;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double scene_mib = rows[i].method == "optique fetch" || rows[i].method == "cached copy checked"
                                 ? static_cast<double>(total) / (1 << 20)
                                 : static_cast<double>(big) / (1 << 20);
    const double rate = scene_mib / rows[i].seconds;
    csv << i / methods.size() << ",\"" << rows[i].method << "\"," << scene_mib << "," << rows[i].seconds << "," << rate
        << "\n";
    rates[rows[i].method].push_back(rate);
    times[rows[i].method].push_back(rows[i].seconds);
  }
  csv.close();
  std::ofstream md(fs::path(out) / "scene-transfer.md");
  md << "# A scene sent to a node with an empty cache\n\n"
     << "`optique-bench-scene-transfer --out docs/bench --mib " << mib << " --runs " << runs << "`: the textured torus "
     << "with a " << mib << " MiB buffer beside it (" << manifest.files.size() << " files, "
     << static_cast<double>(total) / (1 << 20) << " MiB), from optique-master to optique-node-gl over loopback on "
     << "this machine (2 cores, shared); median over " << runs << " runs (min–max). Each run measures every row "
     << "side by side on the same bytes and disk.\n\n"
     << "| | MiB/s | seconds | of raw TCP |\n|---|---|---|---|\n";
  const double raw = spread(rates["raw TCP"]).median;
  for (const std::string& method : methods) {
    const Spread r = spread(rates[method]);
    md << "| " << method << " | " << cell(r, 0) << " | " << cell(spread(times[method]), 2) << " | "
       << cell({r.median / raw, r.low / raw, r.high / raw}, 2) << " |\n";
  }
  std::vector<double> against_floor;
  for (std::size_t i = 0; i < rates["optique fetch"].size(); ++i) {
    against_floor.push_back(rates["optique fetch"][i] / rates["TCP, checked and stored"][i]);
  }
  md << "\nThe optique fetch against TCP that checks and stores, run by run (both measured in the same run): "
     << cell(spread(against_floor), 2) << ". This machine's disk makes both rows vary by 2x from run to run and "
     << "from one invocation to the next.\n";
  md << "\n- **raw TCP**: the bytes through a loopback socket in 1 MiB writes, read and dropped.\n"
     << "- **TCP, checked and stored**: the same, each 1 MiB hashed (SHA-256) and written to a file: the least a "
     << "node that checks what it keeps must do.\n"
     << "- **optique fetch**: what the node reports (`fetched the scene: … MiB/s` in its log): from the first "
     << "request to the copy put in place; four 1 MiB chunks in flight, each checked against the manifest (SHA-256) "
     << "before it is written.\n"
     << "- **cached copy checked**: what a restarted node does instead of fetching: every file's SHA-256 (the rate "
     << "is the scene's size over that time).\n";
  md.close();
  std::cout << optique::testing::read_file(fs::path(out) / "scene-transfer.md");
  (void)draw_plot(out, "scene-transfer");
  return 0;
}

}  // namespace
}  // namespace optique::bench

int main(int argc, char** argv) {
  optique::bench::BenchOptions app{
      "optique-bench-scene-transfer: a large scene from the master to a node with an empty cache"};
  std::string out = "docs/bench";
  std::size_t mib = 200;
  int runs = 5;
  app.option("--out", out, "where scene-transfer.{md,csv,png} go");
  app.option("--mib", mib, "the scene's extra buffer, MiB", optique::bench::Bounds::within(1, 4096));
  app.option("--runs", runs, "runs (each measures every row)", optique::bench::Bounds::within(1, 50));
  if (const std::optional<int> status = app.parse(argc, argv)) return *status;
  try {
    return optique::bench::run(out, mib, runs);
  } catch (const std::exception& e) {
    std::cerr << "optique-bench-scene-transfer: " << e.what() << "\n";
    return 1;
  }
}
