#pragma once
// A child process for integration tests: started with its output in files, waited
// for with a deadline (never forever), killed if the test ends first.

#include <sys/types.h>

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "scratch.h"

namespace optique::testing {

class Process {
 public:
  // Starts `argv[0]` with `argv`; stdout and stderr go to `log_path`.
  Process(std::vector<std::string> argv, std::string log_path);
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;
  ~Process();  // SIGKILL if still running

  // Exit code, or 128 + signal; nullopt if still running after `timeout`.
  [[nodiscard]] std::optional<int> wait(std::chrono::milliseconds timeout);
  void signal(int signal) const;
  [[nodiscard]] bool running();
  [[nodiscard]] pid_t pid() const { return pid_; }
  [[nodiscard]] std::string output() const;  // everything it wrote so far
  // Polls the output until it contains `needle`, or the timeout passes.
  [[nodiscard]] bool wait_for_output(const std::string& needle, std::chrono::milliseconds timeout) const;
  [[nodiscard]] const std::string& log_path() const { return log_path_; }

 private:
  pid_t pid_ = -1;
  std::string log_path_;
  std::optional<int> status_;
};

// Checks `done` every 10 ms until it holds (true) or the timeout passes (false).
[[nodiscard]] bool poll_until(const std::function<bool()>& done, std::chrono::milliseconds timeout);
// Polls until `path` exists and is non-empty, or the timeout passes.
[[nodiscard]] bool wait_for_file(const std::string& path, std::chrono::milliseconds timeout);
// The port a master wrote to its --port-file once it listens (without the line
// break); empty when it wrote none within the timeout.
[[nodiscard]] std::string wait_for_port(const std::string& port_file, std::chrono::milliseconds timeout);
// How many times slower than a plain build the processes under test run:
// OPTIQUE_TEST_TIME_SCALE (scripts/sanitize.sh sets it), else 1. Bounds on how
// late something may be are multiplied by it; bounds on what happened are not.
[[nodiscard]] double timing_scale();
// `bound` · timing_scale(): for a bound on how late something may happen.
[[nodiscard]] std::chrono::milliseconds scaled(std::chrono::milliseconds bound);
// Processes whose command line contains `needle` (from /proc), excluding this one.
[[nodiscard]] std::vector<pid_t> processes_matching(const std::string& needle);

}  // namespace optique::testing
