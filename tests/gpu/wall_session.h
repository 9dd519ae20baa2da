#pragma once
// What the gpu tests of the live scene share on configs/powerwall-2x2.json:
// an application's session on the master's api port (once its port file is
// written), the four tiles of a captured frame stitched as the wall shows
// them (each projector 320×180 of the 640×360 screen) and compared with a
// reference, and two runs' captures compared.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "clients/cpp/session.h"
#include "cluster_run.h"
#include "image/compare.h"
#include "image/frame_files.h"
#include "image/image.h"
#include "image/image_io.h"
#include "local_capture.h"
#include "process.h"
#include "scratch.h"

namespace optique::testing {

// A master on the wall with local GL nodes for `frames` frames, capturing every
// `capture_every`-th, recording its journal into DIR/session.journal, its
// output in DIR/live, its log in DIR/live.log, its api port in DIR/api.port;
// `extra` arguments after those.
inline std::unique_ptr<Process> recording_wall(const ScratchDir& dir, int frames, int capture_every,
                                               const std::vector<std::string>& extra = {}) {
  std::vector<std::string> more{"--api-port",         "0",        "--api-port-file",
                                dir.file("api.port"), "--record", dir.file("session.journal")};
  more.insert(more.end(), extra.begin(), extra.end());
  return std::make_unique<Process>(
      capturing_master(OPTIQUE_SOURCE_DIR "/configs/powerwall-2x2.json", frames, capture_every, dir.file("live"), more),
      dir.file("live.log"));
}

// The session, subscribed to the frames, once the first has begun (every node
// is in the frames); or null (the test has failed) when the port file is not
// written within 30 s, the session does not open, or no frame begins in 60 s.
inline std::unique_ptr<client::Session> wall_session(const std::string& port_file, const std::string& name,
                                                     const Process& master) {
  using namespace std::chrono_literals;
  if (!wait_for_file(port_file, 30s)) {
    ADD_FAILURE() << "no api port: " << master.output();
    return nullptr;
  }
  client::Options options;
  options.port = static_cast<std::uint16_t>(std::stoi(read_file(port_file)));
  options.name = name;
  auto session = client::Session::connect(options);
  if (!session) {
    ADD_FAILURE() << session.error();
    return nullptr;
  }
  session::Subscribe frames;
  frames.set_frames(true);
  auto first = session.value()->subscribe(frames) ? session.value()->next_event(60s)
                                                  : Result<std::optional<session::Event>>{Error{"cannot subscribe"}};
  if (!first || !first.value()) {
    ADD_FAILURE() << "no frame began: " << (first ? "" : first.error()) << master.output();
    return nullptr;
  }
  return std::move(session).value();
}

inline image::FloatImage stitched_wall(const std::string& out, std::uint64_t frame) {
  image::FloatImage wall(640, 360, 4);
  image::paste(wall, capture(out, "top-left", frame), 0, 0);
  image::paste(wall, capture(out, "top-right", frame), 320, 0);
  image::paste(wall, capture(out, "bottom-left", frame), 0, 180);
  image::paste(wall, capture(out, "bottom-right", frame), 320, 180);
  return wall;
}

// The master ends cleanly, every node of the wall having shown every one of
// `frames` frames (but at most `may_miss`) in the master's state.
inline void expect_whole_run(Process& master, const std::string& out, int frames, int may_miss = 0) {
  using namespace std::chrono_literals;
  ASSERT_EQ(master.wait(300s), 0) << master.output();
  const ClusterRun run = read_cluster_run(out);
  ASSERT_EQ(run.error, "");
  ASSERT_EQ(run.report.nodes_size(), 4);
  for (const auto& node : run.report.nodes()) {
    EXPECT_GE(node.frames_presented(), static_cast<std::uint64_t>(frames - may_miss)) << node.id();
    EXPECT_EQ(node.hash_mismatches(), 0u) << node.id() << ": its state left the master's";
  }
}

// The worst channel's PSNR of the stitched tiles against a reference; under
// `least_db`, a failure, with both images and their difference (×10) kept in
// a scratch folder named `kept`.
inline double expect_near_reference(const image::FloatImage& tiles, const image::FloatImage& reference, double least_db,
                                    const std::string& kept) {
  auto comparison = image::compare(tiles, reference);
  if (!comparison) {
    ADD_FAILURE() << comparison.error();
    return 0.0;
  }
  const auto& c = comparison.value();
  const double worst = std::min({c.psnr_r, c.psnr_g, c.psnr_b});
  if (worst < least_db) {
    const ScratchDir folder(kept);
    (void)image::write_exr(folder.string() + "/stitched.exr", tiles);
    (void)image::write_exr(folder.string() + "/reference.exr", reference);
    (void)image::write_exr(folder.string() + "/difference.exr", image::difference(tiles, reference, 10.0f));
    ADD_FAILURE() << "the stitched tiles are " << worst << " dB from the reference, under " << least_db
                  << "; images and the difference (×10) in " << folder.string();
  }
  return worst;
}

// Every projector's capture of each of `frames`, byte for byte the same in two runs.
inline void expect_same_captures(const std::string& out, const std::string& other_out,
                                 const std::vector<std::uint64_t>& frames) {
  for (const char* projector : {"top-left", "top-right", "bottom-left", "bottom-right"}) {
    for (std::uint64_t frame : frames) {
      const std::string a = read_file(image::frame_path(out + "/nodes/" + projector, frame, "png"));
      const std::string b = read_file(image::frame_path(other_out + "/nodes/" + projector, frame, "png"));
      EXPECT_FALSE(a.empty()) << projector << " frame " << frame;
      EXPECT_TRUE(a == b) << projector << " frame " << frame << ": the other run's capture differs";
    }
  }
}

}  // namespace optique::testing
