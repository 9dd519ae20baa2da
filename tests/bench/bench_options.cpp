#include "bench_options.h"

#include <CLI/CLI.hpp>

namespace optique::bench {

namespace {

// `whole`: a count, whose bounds are said as whole numbers.
void check(CLI::Option* option, const Bounds& bounds, bool whole) {
  if (bounds.positive) {
    option->check(CLI::PositiveNumber);
  } else if (bounds.low > -std::numeric_limits<double>::infinity() ||
             bounds.high < std::numeric_limits<double>::infinity()) {
    if (whole) {
      option->check(CLI::Range(static_cast<long long>(bounds.low), static_cast<long long>(bounds.high)));
    } else {
      option->check(CLI::Range(bounds.low, bounds.high));
    }
  }
}

}  // namespace

BenchOptions::BenchOptions(const std::string& description) : app_(std::make_unique<CLI::App>(description)) {}

BenchOptions::~BenchOptions() = default;

BenchOptions& BenchOptions::option(const std::string& name, std::string& value, const std::string& help) {
  app_->add_option(name, value, help);
  return *this;
}

BenchOptions& BenchOptions::option(const std::string& name, int& value, const std::string& help, Bounds bounds) {
  check(app_->add_option(name, value, help), bounds, true);
  return *this;
}

BenchOptions& BenchOptions::option(const std::string& name, std::size_t& value, const std::string& help,
                                   Bounds bounds) {
  check(app_->add_option(name, value, help), bounds, true);
  return *this;
}

BenchOptions& BenchOptions::option(const std::string& name, double& value, const std::string& help, Bounds bounds) {
  check(app_->add_option(name, value, help), bounds, false);
  return *this;
}

BenchOptions& BenchOptions::list(const std::string& name, std::vector<std::size_t>& values, const std::string& help) {
  app_->add_option(name, values, help)->delimiter(',');
  return *this;
}

BenchOptions& BenchOptions::flag(const std::string& name, bool& value, const std::string& help) {
  app_->add_flag(name, value, help);
  return *this;
}

std::optional<int> BenchOptions::parse(int argc, char** argv) {
  try {
    app_->parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app_->exit(error);
  }
  return std::nullopt;
}

}  // namespace optique::bench
