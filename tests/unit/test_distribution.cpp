// Nearest-rank percentiles and summaries: common/metrics/distribution.h.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "metrics/distribution.h"

namespace optique::metrics {
namespace {

std::vector<double> one_to(int n) {
  std::vector<double> v;
  for (int i = 1; i <= n; ++i) v.push_back(i);
  return v;
}

std::vector<double> shuffled(std::vector<double> v) {
  std::mt19937 rng(12345);
  std::shuffle(v.begin(), v.end(), rng);
  return v;
}

TEST(Percentile, NearestRankOnOneToHundred) {
  std::vector<double> v = shuffled(one_to(100));
  EXPECT_DOUBLE_EQ(percentile(v, 50.0), 50.0);
  EXPECT_DOUBLE_EQ(percentile(v, 99.0), 99.0);
  EXPECT_DOUBLE_EQ(percentile(v, 100.0), 100.0);
  EXPECT_DOUBLE_EQ(percentile(v, 0.0), 1.0);  // rank clamps to the first value
  EXPECT_DOUBLE_EQ(percentile(v, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(percentile(v, 25.5), 26.0);      // ceil(25.5) = 26th value
  EXPECT_TRUE(std::is_sorted(v.begin(), v.end()));  // sorted in place, as documented
}

TEST(Percentile, NearestRankOnSmallSets) {
  // Nearest rank: the ceil(p/100·n)-th smallest value.
  std::vector<double> v{15, 20, 35, 40, 50};
  EXPECT_DOUBLE_EQ(percentile(v, 5.0), 15.0);
  EXPECT_DOUBLE_EQ(percentile(v, 30.0), 20.0);
  EXPECT_DOUBLE_EQ(percentile(v, 40.0), 20.0);
  EXPECT_DOUBLE_EQ(percentile(v, 50.0), 35.0);
  EXPECT_DOUBLE_EQ(percentile(v, 100.0), 50.0);

  std::vector<double> even{4.0, 1.0, 3.0, 2.0};
  EXPECT_DOUBLE_EQ(percentile(even, 50.0), 2.0);  // a measured value, not the mean 2.5
  EXPECT_DOUBLE_EQ(percentile(even, 50.1), 3.0);
}

TEST(Percentile, EmptyIsZero) {
  std::vector<double> v;
  EXPECT_DOUBLE_EQ(percentile(v, 50.0), 0.0);
}

TEST(Percentile, SingleValue) {
  for (double p : {0.0, 1.0, 50.0, 99.0, 100.0}) {
    std::vector<double> v{-3.5};
    EXPECT_DOUBLE_EQ(percentile(v, p), -3.5) << "p" << p;
  }
}

// Nearest rank must not be pushed up by rounding: 7 / 100.0 * 100 is just above 7.
TEST(Percentile, IntegerPercentilesOfOneToHundredAreExact) {
  std::vector<double> v = one_to(100);
  for (int p = 1; p <= 100; ++p) {
    EXPECT_DOUBLE_EQ(percentile(v, p), static_cast<double>(p)) << "p" << p;
  }
}

TEST(Summarize, OneToHundred) {
  const report::Distribution d = summarize(shuffled(one_to(100)));
  EXPECT_EQ(d.count(), 100u);
  EXPECT_DOUBLE_EQ(d.median(), 50.0);
  EXPECT_DOUBLE_EQ(d.p99(), 99.0);
  EXPECT_DOUBLE_EQ(d.max(), 100.0);
}

TEST(Summarize, OneToThousand) {
  const report::Distribution d = summarize(shuffled(one_to(1000)));
  EXPECT_EQ(d.count(), 1000u);
  EXPECT_DOUBLE_EQ(d.median(), 500.0);
  EXPECT_DOUBLE_EQ(d.p99(), 990.0);
  EXPECT_DOUBLE_EQ(d.max(), 1000.0);
}

TEST(Summarize, SingleValue) {
  const report::Distribution d = summarize({42.25});
  EXPECT_EQ(d.count(), 1u);
  EXPECT_DOUBLE_EQ(d.median(), 42.25);
  EXPECT_DOUBLE_EQ(d.p99(), 42.25);
  EXPECT_DOUBLE_EQ(d.max(), 42.25);
}

TEST(Summarize, EmptyHasCountZero) {
  const report::Distribution d = summarize({});
  EXPECT_EQ(d.count(), 0u);
  EXPECT_DOUBLE_EQ(d.median(), 0.0);
  EXPECT_DOUBLE_EQ(d.p99(), 0.0);
  EXPECT_DOUBLE_EQ(d.max(), 0.0);
}

TEST(Summarize, OutlierShowsInMaxNotMedian) {
  std::vector<double> v(99, 10.0);
  v.push_back(5000.0);
  const report::Distribution d = summarize(v);
  EXPECT_DOUBLE_EQ(d.median(), 10.0);
  EXPECT_DOUBLE_EQ(d.p99(), 10.0);
  EXPECT_DOUBLE_EQ(d.max(), 5000.0);
}

}  // namespace
}  // namespace optique::metrics
