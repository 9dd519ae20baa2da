// Calibration benchmark: the time to fit a projector's homography for 4, 20 and
// 200 points, for the DLT alone, the DLT + Levenberg–Marquardt refinement and
// robust mode (RANSAC + refinement), side by side in one run, each with the
// transfer error it reaches against the noise-limited optimum. Clean points
// (σ = 0.5 px on the pixels) and points with 10 % gross outliers.
//
//   optique-bench-calib [--out DIR] [--trials T] [--repeats R]

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <thread>

#include "bench_options.h"
#include "calib/fit.h"
#include "clock/clock.h"
#include "draw_plot.h"
#include "pinhole_projector.h"
#include "spread.h"

namespace {

using namespace optique;

constexpr double kSigma = 0.5;

enum class Method { kDlt, kRefined, kRobust };
constexpr Method kMethods[] = {Method::kDlt, Method::kRefined, Method::kRobust};

const char* method_name(Method m) {
  switch (m) {
    case Method::kDlt:
      return "DLT only";
    case Method::kRefined:
      return "DLT + refinement";
    case Method::kRobust:
      return "robust (RANSAC + refinement)";
  }
  return "";
}

struct Case {
  int columns;
  int rows;
  double outlier_fraction;
  [[nodiscard]] int points() const { return columns * rows; }
  [[nodiscard]] int outliers() const { return static_cast<int>(std::round(outlier_fraction * points())); }
};

// The points of one trial: noisy pixels, and gross outliers (60–300 px off) at
// random indices.
struct Trial {
  std::vector<geometry::Correspondence> points;
  std::vector<bool> outlier;
};

Trial make_trial(const testing::PinholeProjector& p, const Case& c, std::mt19937_64& random) {
  Trial t;
  t.points = testing::with_pixel_noise(testing::grid_points(p.homography(), p.width, p.height, c.columns, c.rows),
                                       kSigma, random);
  t.outlier.assign(t.points.size(), false);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * std::numbers::pi);
  std::uniform_real_distribution<double> distance(60.0, 300.0);
  for (int k = 0; k < c.outliers();) {
    const std::size_t i = std::uniform_int_distribution<std::size_t>(0, t.points.size() - 1)(random);
    if (t.outlier[i]) continue;
    t.outlier[i] = true;
    const double a = angle(random);
    t.points[i].pixel += distance(random) * glm::dvec2(std::cos(a), std::sin(a));
    ++k;
  }
  return t;
}

struct Sample {
  double microseconds_per_fit = 0.0;
  double transfer_sq = 0.0;  // Σ over trials of ε² at the inliers
  double image_sq = 0.0;     // Σ over trials of ε² over a grid across the image
  int trials = 0;
  int failures = 0;
};

// One repeat: `trials` fits of fresh data; the data are made before the clock starts.
Sample run_repeat(const testing::PinholeProjector& p, const Case& c, Method m, int trials, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  std::vector<Trial> data;
  for (int t = 0; t < trials; ++t) data.push_back(make_trial(p, c, random));
  calib::FitOptions options;
  options.refine = m != Method::kDlt;
  options.robust = m == Method::kRobust;
  std::vector<Result<calib::HomographyFit>> fits;
  fits.reserve(data.size());
  const clock::Nanos start = clock::monotonic_now();
  for (const auto& t : data) fits.push_back(calib::fit_homography(t.points, options));
  const clock::Nanos end = clock::monotonic_now();

  Sample s;
  s.microseconds_per_fit = static_cast<double>(end - start) / 1e3 / trials;
  const glm::dmat3 truth = p.homography();
  const auto image_grid = testing::grid_points(truth, p.width, p.height, 9, 9);
  const auto exact = testing::grid_points(truth, p.width, p.height, c.columns, c.rows);
  for (std::size_t t = 0; t < data.size(); ++t) {
    if (!fits[t].ok()) {
      ++s.failures;
      continue;
    }
    std::vector<geometry::Correspondence> inliers;
    for (std::size_t i = 0; i < exact.size(); ++i) {
      if (!data[t].outlier[i]) inliers.push_back(exact[i]);
    }
    const double e = testing::transfer_error(fits[t].value().homography, truth, inliers);
    const double g = testing::transfer_error(fits[t].value().homography, truth, image_grid);
    s.transfer_sq += e * e;
    s.image_sq += g * g;
    ++s.trials;
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  optique::bench::BenchOptions app{"optique calibration benchmark"};
  std::string out = "docs/bench";
  int trials = 100;
  int repeats = 7;
  app.option("--out", out, "folder for calibration.md, .csv and .png");
  app.option("--trials", trials, "fits of fresh noisy data per repeat (timed together)");
  app.option("--repeats", repeats, "repeats per row; the table shows the median and the min–max over repeats");
  if (const std::optional<int> status = app.parse(argc, argv)) return *status;

  const testing::PinholeProjector projector = testing::projector_cases()[1];  // strong oblique
  const std::vector<Case> cases{{2, 2, 0.0}, {5, 4, 0.0}, {20, 10, 0.0}, {5, 4, 0.1}, {20, 10, 0.1}};
  std::filesystem::create_directories(out);
  std::ofstream csv(out + "/calibration.csv");
  csv << "projector,points,outliers,method,repeat,trials,failures,us_per_fit,transfer_rms_px,optimum_px,"
         "image_rms_px\n";
  std::ostringstream table;
  table << "| points | gross outliers | method | time per fit µs | transfer error at the points px | optimum px | "
           "ratio | transfer error over the image px |\n"
        << "|---:|---:|---|---:|---:|---:|---:|---:|\n";

  std::uint64_t seed = 1000;
  for (const Case& c : cases) {
    const int inliers = c.points() - c.outliers();
    const double optimum = kSigma * std::sqrt(8.0 / (2.0 * inliers));
    for (const Method m : kMethods) {
      std::vector<double> times;
      double transfer_sq = 0.0;
      double image_sq = 0.0;
      int fitted = 0;
      int failures = 0;
      for (int r = 0; r < repeats; ++r) {
        const Sample s = run_repeat(projector, c, m, trials, seed + static_cast<std::uint64_t>(r));
        times.push_back(s.microseconds_per_fit);
        transfer_sq += s.transfer_sq;
        image_sq += s.image_sq;
        fitted += s.trials;
        failures += s.failures;
        csv << '"' << projector.name << "\"," << c.points() << ',' << c.outliers() << ",\"" << method_name(m) << "\","
            << r << ',' << trials << ',' << s.failures << ',' << s.microseconds_per_fit << ','
            << (s.trials ? std::sqrt(s.transfer_sq / s.trials) : 0.0) << ',' << optimum << ','
            << (s.trials ? std::sqrt(s.image_sq / s.trials) : 0.0) << '\n';
      }
      const double transfer = fitted ? std::sqrt(transfer_sq / fitted) : 0.0;
      const double over_image = fitted ? std::sqrt(image_sq / fitted) : 0.0;
      const bench::Spread time = bench::spread(times);
      char row[512];
      std::snprintf(row, sizeof row, "| %d | %d | %s | %s | %.3f | %.3f | %.2f | %.3f |%s\n", c.points(), c.outliers(),
                    method_name(m), bench::cell(time, 1).c_str(), transfer, optimum, transfer / optimum, over_image,
                    failures ? (" " + std::to_string(failures) + " fits failed").c_str() : "");
      table << row;
      std::cout << row << std::flush;
    }
    seed += 100;
  }

  std::ofstream md(out + "/calibration.md");
  md << "Calibration benchmark: fitting the homography of a " << projector.name << " projector (" << projector.width
     << "×" << projector.height << ", " << static_cast<int>(std::round(projector.incidence_deg()))
     << "° from the screen normal) from points spread over its image, σ = " << kSigma
     << " px Gaussian noise on the pixels. Each row: " << repeats << " repeats of " << trials
     << " fits of fresh data, timed together (data made before the clock starts); the time cell is the median "
        "over repeats with the min–max in brackets. Transfer error: √(Σ|Ĥ(sᵢ) − H(sᵢ)|² / 2n) per coordinate, at "
        "the inliers' true screen points, as an RMS over all fits; the optimum is the noise-limited σ·√(8 / 2n) "
        "(Hartley & Zisserman, result 5.2, n = inliers); \"over the image\" is the same error on a 9×9 grid across "
        "the whole image. Gross outliers move a pixel 60–300 px. Robust mode with 4 points is the plain fit "
        "(nothing to vote on). One thread, on a machine with "
     << std::thread::hardware_concurrency() << " hardware threads (shared with other work: the min–max shows it).\n\n"
     << table.str()
     << "\n![time per fit on clean points, and transfer error ÷ optimum with 10 % gross outliers, against the "
        "number of points](calibration.png)\n";
  md.close();
  csv.close();
  std::cout << "wrote " << out << "/calibration.md, .csv\n";
  return bench::draw_plot(out, "calibration") ? 0 : 1;
}
