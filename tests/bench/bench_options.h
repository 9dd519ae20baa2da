#pragma once
// A bench's command line. The parser (CLI11, header-only) is compiled once, in
// bench_options.cpp, rather than in every bench: about 8 s of build a file.

#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace optique::bench {

// What a number may be: more than `low` (`positive`), or within [low, high].
struct Bounds {
  double low = -std::numeric_limits<double>::infinity();
  double high = std::numeric_limits<double>::infinity();
  bool positive = false;

  [[nodiscard]] static Bounds more_than_zero() { return {0.0, std::numeric_limits<double>::infinity(), true}; }
  [[nodiscard]] static Bounds within(double low, double high) { return {low, high, false}; }
};

class BenchOptions {
 public:
  explicit BenchOptions(const std::string& description);
  ~BenchOptions();
  BenchOptions(const BenchOptions&) = delete;
  BenchOptions& operator=(const BenchOptions&) = delete;

  // --name VALUE, its default the value's when parse() is called.
  BenchOptions& option(const std::string& name, std::string& value, const std::string& help);
  BenchOptions& option(const std::string& name, int& value, const std::string& help, Bounds bounds = {});
  BenchOptions& option(const std::string& name, std::size_t& value, const std::string& help, Bounds bounds = {});
  BenchOptions& option(const std::string& name, double& value, const std::string& help, Bounds bounds = {});
  // --name A,B,C
  BenchOptions& list(const std::string& name, std::vector<std::size_t>& values, const std::string& help);
  BenchOptions& flag(const std::string& name, bool& value, const std::string& help);

  // nullopt: go on with the values set; else the bench exits with this status
  // (--help was printed, or what was wrong with the command line).
  [[nodiscard]] std::optional<int> parse(int argc, char** argv);

 private:
  std::unique_ptr<CLI::App> app_;
};

}  // namespace optique::bench
