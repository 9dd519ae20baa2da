#include "optics/projector_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace optique::optics {
namespace {

// As the config gives it: checked by config::parse_response, then modelled.
ProjectorModel model_of(const schema::Projector& projector) {
  auto response = config::parse_response(projector);
  EXPECT_TRUE(response) << (response ? "" : response.error());
  return response ? ProjectorModel(response.value()) : ProjectorModel{};
}

std::string error_of(const schema::Projector& projector) {
  auto response = config::parse_response(projector);
  return response ? std::string("(accepted)") : response.error();
}

TEST(ProjectorModel, DefaultIsEightBitSrgbWithoutBlack) {
  const ProjectorModel model;
  EXPECT_EQ(model.settings().bits, 8);
  EXPECT_EQ(model.levels(), 255);
  EXPECT_EQ(model.black(), 0.0);
  EXPECT_NEAR(model.response(0.5), 0.2140, 1e-4);  // sRGB 128/255 ≈ 0.2158; 0.5 → 0.2140
  EXPECT_NEAR(model.inverse_response(0.2140), 0.5, 1e-4);
}

// Round trips pass whatever the curve is, a gamma swapped for its inverse on
// both sides included: these are the curves' known values.
TEST(ProjectorModel, CurvesHaveTheirKnownValues) {
  const ProjectorModel srgb;
  // IEC 61966-2-1: the linear and the power segment meet at 0.04045 → 0.0031308.
  EXPECT_NEAR(srgb.response(0.04045), 0.0031308, 1e-7);
  EXPECT_NEAR(srgb.response(0.04), 0.04 / 12.92, 1e-9);
  EXPECT_NEAR(srgb.response(0.5), 0.2140411, 1e-7);
  EXPECT_NEAR(srgb.response(64 / 255.0), 0.0512695, 1e-7);
  EXPECT_NEAR(srgb.response(128 / 255.0), 0.2158605, 1e-7);
  EXPECT_DOUBLE_EQ(srgb.response(1.0), 1.0);
  EXPECT_NEAR(srgb.inverse_response(0.0031308), 0.04045, 1e-6);
  EXPECT_NEAR(srgb.inverse_response(0.2140411), 0.5, 1e-7);

  schema::Projector g;
  g.mutable_response()->set_gamma(2.2);
  const ProjectorModel gamma = model_of(g);
  EXPECT_NEAR(gamma.response(0.5), 0.2176376, 1e-7);  // 0.5^2.2, not 0.5^(1/2.2) = 0.7297
  EXPECT_NEAR(gamma.inverse_response(0.2176376), 0.5, 1e-7);
  EXPECT_NEAR(gamma.response(0.25), 0.0473661, 1e-7);

  schema::Projector t;
  for (const double v : {0.0, 0.1, 0.5, 1.0}) t.mutable_response()->add_table(v);
  const ProjectorModel table = model_of(t);
  EXPECT_NEAR(table.response(1.0 / 3.0), 0.1, 1e-12);  // on an entry
  EXPECT_NEAR(table.response(0.5), 0.3, 1e-12);        // halfway between 0.1 and 0.5
  EXPECT_NEAR(table.inverse_response(0.3), 0.5, 1e-12);

  // Black level and brightness: emitted = brightness · (black + (1 − black) · response).
  schema::Projector dim = g;
  dim.set_black_level(0.02);
  dim.set_brightness(0.7);
  const ProjectorModel d = model_of(dim);
  EXPECT_NEAR(d.emitted(0.0), 0.014, 1e-12);
  EXPECT_NEAR(d.emitted(0.5), 0.7 * (0.02 + 0.98 * 0.2176376), 1e-7);
  EXPECT_NEAR(d.emitted(1.0), 0.7, 1e-12);
}

TEST(ProjectorModel, EmittedLightIsBlackPlusWhatWasRendered) {
  for (const double gamma : {1.0, 1.8, 2.2, 2.6}) {
    schema::Projector p;
    p.mutable_response()->set_gamma(gamma);
    p.mutable_response()->set_bits(16);
    p.set_black_level(0.02);
    p.set_brightness(0.7);
    const ProjectorModel model = model_of(p);
    for (double light = 0.0; light <= model.headroom(); light += 0.01) {
      // 16-bit quantization: the step in light is at most slope · 2⁻¹⁶.
      EXPECT_NEAR(model.emitted(model.signal_for(light)), model.black() + light, 2e-4) << gamma << " " << light;
    }
    // Beyond the headroom the projector is at full white.
    EXPECT_NEAR(model.emitted(model.signal_for(2.0)), model.white(), 1e-12);
  }
}

TEST(ProjectorModel, MeasuredTableIsInvertedWhereItIsFlatAndSteep) {
  schema::Projector p;
  for (const double v : {0.0, 0.0, 0.05, 0.2, 0.2, 0.6, 1.0}) p.mutable_response()->add_table(v);
  p.mutable_response()->set_bits(16);
  const ProjectorModel model = model_of(p);
  EXPECT_EQ(model.settings().curve, ProjectorModel::Curve::table);
  EXPECT_DOUBLE_EQ(model.response(0.5), 0.2);  // signal 0.5 = table index 3
  EXPECT_NEAR(model.response(0.75), 0.4, 1e-12);
  for (double light = 0.0; light <= 1.0; light += 0.013) {
    EXPECT_NEAR(model.response(model.inverse_response(light)), light, 1e-9) << light;
  }
  // A flat stretch sends its smallest signal.
  EXPECT_NEAR(model.inverse_response(0.2), 0.5, 1e-12);
  EXPECT_EQ(model.inverse_response(0.0), 0.0);
}

TEST(ProjectorModel, QuantizationHasTwoToTheBitsLevels) {
  for (const int bits : {1, 4, 8, 10}) {
    schema::Projector p;
    p.mutable_response()->set_gamma(2.2);
    p.mutable_response()->set_bits(static_cast<unsigned>(bits));
    const ProjectorModel model = model_of(p);
    // Every level is reached by the light it emits, and nothing lies between levels.
    std::set<double> levels;
    for (int k = 0; k <= model.levels(); ++k) {
      const double signal = static_cast<double>(k) / model.levels();
      EXPECT_DOUBLE_EQ(model.signal_for(model.response(signal) * model.headroom()), signal) << bits << " " << k;
    }
    for (int i = 0; i <= 5000; ++i) levels.insert(model.signal_for(std::pow(i / 5000.0, 2.2)));
    EXPECT_EQ(static_cast<int>(levels.size()), std::min(1 << bits, 5001)) << bits;
    EXPECT_EQ(*levels.begin(), 0.0);
    EXPECT_EQ(*levels.rbegin(), 1.0);
  }
}

TEST(ProjectorModel, BadSettingsNameTheField) {
  schema::Projector p;
  p.mutable_response()->set_gamma(-1.0);
  EXPECT_NE(error_of(p).find("response.gamma"), std::string::npos) << error_of(p);
  p.mutable_response()->set_gamma(std::nan(""));
  EXPECT_NE(error_of(p).find("response.gamma"), std::string::npos);

  schema::Projector both;
  both.mutable_response()->set_gamma(2.2);
  both.mutable_response()->add_table(0.0);
  both.mutable_response()->add_table(1.0);
  EXPECT_NE(error_of(both).find("either gamma or table"), std::string::npos) << error_of(both);

  schema::Projector short_table;
  short_table.mutable_response()->add_table(0.0);
  EXPECT_NE(error_of(short_table).find("at least 2"), std::string::npos) << error_of(short_table);

  schema::Projector dips;
  for (const double v : {0.0, 0.5, 0.4, 1.0}) dips.mutable_response()->add_table(v);
  EXPECT_NE(error_of(dips).find("response.table[2]"), std::string::npos) << error_of(dips);

  schema::Projector unnormalized;
  for (const double v : {0.01, 0.5, 0.9}) unnormalized.mutable_response()->add_table(v);
  EXPECT_NE(error_of(unnormalized).find("from 0"), std::string::npos) << error_of(unnormalized);

  schema::Projector infinite;
  for (const double v : {0.0, static_cast<double>(INFINITY), 1.0}) infinite.mutable_response()->add_table(v);
  EXPECT_NE(error_of(infinite).find("response.table[1]"), std::string::npos) << error_of(infinite);

  schema::Projector bits;
  bits.mutable_response()->set_bits(17);
  EXPECT_NE(error_of(bits).find("response.bits"), std::string::npos) << error_of(bits);

  schema::Projector black;
  black.set_black_level(1.0);
  EXPECT_NE(error_of(black).find("black_level"), std::string::npos) << error_of(black);
  black.set_black_level(-0.1);
  EXPECT_NE(error_of(black).find("black_level"), std::string::npos);

  schema::Projector brightness;
  brightness.set_brightness(-2.0);
  EXPECT_NE(error_of(brightness).find("brightness"), std::string::npos) << error_of(brightness);
}

}  // namespace
}  // namespace optique::optics
