// What check-config says of a DLP projector's fields (tools/check_config.h): the
// velocity threshold's effect told per method, as the pipeline applies it.

#include "tools/check_config.h"

#include <gtest/gtest.h>

#include <string>

#include "config/load.h"

namespace optique::tools {
namespace {

config::LoadedConfig pinball() {
  auto loaded = config::load_installation(OPTIQUE_SOURCE_DIR "/configs/dlp-pinball.json");
  EXPECT_TRUE(loaded) << (loaded ? "" : loaded.error());
  return loaded ? std::move(loaded).value() : config::LoadedConfig{};
}

TEST(CheckConfig, SaysWhatTheVelocityThresholdDoesWithEachMethod) {
  config::LoadedConfig config = pinball();
  ASSERT_FALSE(config.installation.projectors.empty());
  config::ColorFields& fields = config.installation.projectors.front().color_fields;
  ASSERT_EQ(fields.velocity_threshold, 24.0);
  const auto said = [&](config::FieldMethod method) {
    fields.method = method;
    return summarize(config);
  };
  EXPECT_NE(said(config::FieldMethod::gather)
                .find("velocity_threshold 24 px per frame: faster pixels get motion "
                      "blur over the frame instead"),
            std::string::npos)
      << said(config::FieldMethod::gather);
  EXPECT_NE(said(config::FieldMethod::per_field).find("instead (from one more render, with velocity)"),
            std::string::npos)
      << said(config::FieldMethod::per_field);
  EXPECT_NE(said(config::FieldMethod::off).find("has no effect with method off"), std::string::npos)
      << said(config::FieldMethod::off);
}

TEST(CheckConfig, SaysThatAnUpConvertingDlpProjectorBuildsEveryField) {
  config::LoadedConfig config = pinball();
  ASSERT_FALSE(config.installation.projectors.empty());
  config::Projector& p = config.installation.projectors.front();
  p.color_fields.method = config::FieldMethod::up_conversion;
  p.color_fields.velocity_threshold = 0.0;
  p.up_conversion.ratio = 4;
  const std::string said = summarize(config);
  EXPECT_NE(said.find("up-conversion: a key frame every 4 frames"), std::string::npos) << said;
  EXPECT_NE(said.find("; every colour field built from the key frames at its own moment"), std::string::npos) << said;
}

}  // namespace
}  // namespace optique::tools

namespace optique::tools {
namespace {

// Port 0 is not an address anyone can open: check-config says the master picks one.
TEST(CheckConfig, AnEphemeralStatusPortIsNotGivenAsAnAddress) {
  config::LoadedConfig config = pinball();
  config.installation.master.status = config::StatusServer{};
  config.installation.master.status->port = 0;
  const std::string said = summarize(config);
  EXPECT_EQ(said.find("127.0.0.1:0/"), std::string::npos) << said;
  EXPECT_NE(said.find("an ephemeral port the master logs when it starts"), std::string::npos) << said;
  config.installation.master.status->port = 7480;
  EXPECT_NE(summarize(config).find("http://127.0.0.1:7480/"), std::string::npos) << summarize(config);
}

// With master.api, where applications' models are read from.
TEST(CheckConfig, SaysWhereApplicationsLoadModelsFrom) {
  config::LoadedConfig config = pinball();
  config.installation.master.api = config::ApiServer{};
  config.installation.master.api->assets = "/srv/wall/models";
  const std::string said = summarize(config);
  EXPECT_NE(said.find("edits a frame; models loaded from /srv/wall/models; an edit made before frame k"),
            std::string::npos)
      << said;
}

}  // namespace
}  // namespace optique::tools
