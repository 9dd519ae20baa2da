#include "local_capture.h"

#include <gtest/gtest.h>

#include <chrono>

#include "image/frame_files.h"
#include "image/image_io.h"
#include "process.h"

namespace optique::testing {

using namespace std::chrono_literals;

std::vector<std::string> capturing_master(const std::string& config, int frames, int capture_every,
                                          const std::string& out, const std::vector<std::string>& extra) {
  std::vector<std::string> command{std::string(OPTIQUE_BIN_DIR) + "/optique-master",
                                   "--config",
                                   config,
                                   "--local",
                                   "--frames",
                                   std::to_string(frames),
                                   "--capture-every",
                                   std::to_string(capture_every),
                                   "--out",
                                   out,
                                   "--no-status"};
  command.insert(command.end(), extra.begin(), extra.end());
  return command;
}

CapturedRun run_and_capture(const std::string& config, int frames, int capture_every,
                            const std::vector<std::string>& extra) {
  CapturedRun run{std::make_unique<ScratchDir>("optique-gl"), {}};
  const std::string dir = run.folder->string();
  Process master(capturing_master(config, frames, capture_every, dir + "/out", extra), dir + "/master.log");
  const auto status = master.wait(120s);
  EXPECT_TRUE(status.has_value()) << "master still running:\n" << master.output();
  EXPECT_EQ(status.value_or(-1), 0) << master.output();
  run.out = dir + "/out";
  return run;
}

image::FloatImage capture(const std::string& out, const std::string& projector, std::uint64_t frame) {
  auto loaded = image::read_image(image::frame_path(out + "/nodes/" + projector, frame, "png"));
  EXPECT_TRUE(loaded.ok()) << (loaded.ok() ? "" : loaded.error());
  return loaded.ok() ? std::move(loaded).value() : image::FloatImage();
}

}  // namespace optique::testing
