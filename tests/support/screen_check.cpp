#include "screen_check.h"

#include <gtest/gtest.h>

#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "config/load.h"
#include "config/to_schema.h"
#include "image/compare.h"
#include "image/frame_files.h"
#include "image/image_io.h"
#include "optics/projector_model.h"
#include "process.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;

image::FloatImage read(const std::string& path) {
  auto image = image::read_image(path);
  EXPECT_TRUE(image.ok()) << (image.ok() ? "" : image.error());
  return image.ok() ? image.value() : image::FloatImage{};
}

}  // namespace

ScreenMatch compare_with_reference(const ScreenCheck& check, std::uint64_t frame) {
  const std::string k = std::to_string(frame);
  const std::string log_dir = check.out_dir;
  std::filesystem::create_directories(log_dir);
  Process compose({check.master_binary, "compose", "--config", check.config, "--frame", k, "--captures",
                   check.captures_dir, "--out", check.out_dir},
                  log_dir + "/compose-" + k + ".log");
  EXPECT_EQ(compose.wait(60s).value_or(-1), 0) << compose.output();
  std::vector<std::string> reference_argv{
      check.master_binary, "render-reference", "--config", check.config, "--frame", k, "--out", check.out_dir};
  reference_argv.insert(reference_argv.end(), check.reference_args.begin(), check.reference_args.end());
  Process reference(reference_argv, log_dir + "/reference-" + k + ".log");
  EXPECT_EQ(reference.wait(60s).value_or(-1), 0) << reference.output();

  auto loaded = config::load_installation(check.config);
  EXPECT_TRUE(loaded) << (loaded ? "" : loaded.error());
  if (!loaded) return {};
  double black = 0.0;
  const config::Installation& installation = loaded.value().installation;
  for (const config::Projector& p : installation.projectors) {
    if (installation.screen_of(p).id == check.screen) black += optics::ProjectorModel(p.response).black();
  }
  image::FloatImage composite = read(image::frame_path(check.out_dir + "/screens/" + check.screen, frame, "exr"));
  const image::FloatImage expected =
      read(image::frame_path(check.out_dir + "/reference/" + check.screen, frame, "exr"));
  if (composite.pixels.empty() || composite.width != expected.width || composite.height != expected.height) {
    ADD_FAILURE() << "frame " << frame << ": the composite and the reference differ in size or did not come";
    return {};
  }
  for (std::size_t i = 0; i < composite.pixels.size(); ++i) {
    if (i % 4 != 3) composite.pixels[i] -= static_cast<float>(black);
  }
  const int w = composite.width;
  const int h = composite.height;
  const auto shown = [&](int x, int y) {
    if (x < 2 || y < 2 || x >= w - 2 || y >= h - 2) return false;
    return std::max({expected.at(x, y, 0), expected.at(x, y, 1), expected.at(x, y, 2)}) <= 0.6f;
  };
  ScreenMatch match;
  match.psnr_db = image::psnr_luma_where(composite, expected, shown);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (shown(x, y) && std::abs(image::luma(composite, x, y) - image::luma(expected, x, y)) > 0.01) {
        ++match.pixels_off;
      }
    }
  }
  return match;
}

std::string write_config_variant(const std::string& config, const std::function<void(schema::Installation&)>& change,
                                 const std::string& path) {
  auto loaded = config::load_installation(config);
  EXPECT_TRUE(loaded) << (loaded ? "" : loaded.error());
  // Written out resolved (config/to_schema.h): the copy need not sit beside the
  // original's calibration files.
  schema::Installation installation = loaded ? config::to_schema(loaded.value().installation) : schema::Installation{};
  change(installation);
  google::protobuf::util::JsonPrintOptions print;
  print.preserve_proto_field_names = true;
  std::string json;
  EXPECT_TRUE(google::protobuf::util::MessageToJsonString(installation, &json, print).ok());
  std::ofstream(path) << json;
  return path;
}

}  // namespace optique::testing
