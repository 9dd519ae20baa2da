#pragma once
// Starts one optique-node process per projector on this machine (--local), keeps
// track of them, and makes sure none outlives the master.

#include <sys/types.h>

#include <string>
#include <vector>

#include "util/result.h"

namespace optique::master {

struct ChildExit {
  std::string id;
  pid_t pid = 0;
  int status = 0;                              // raw waitpid status
  [[nodiscard]] std::string describe() const;  // "exited with status 2", "killed by signal 9"
  [[nodiscard]] bool clean() const;
};

class LocalLauncher {
 public:
  explicit LocalLauncher(std::string node_binary) : node_binary_(std::move(node_binary)) {}
  LocalLauncher(const LocalLauncher&) = delete;
  LocalLauncher& operator=(const LocalLauncher&) = delete;
  ~LocalLauncher();  // kills whatever is still running

  // Starts the node binary with `args`; its stdout and stderr go to `log_file`
  // (or stay the master's when empty).
  [[nodiscard]] Result<pid_t> spawn(const std::string& id, const std::vector<std::string>& args,
                                    const std::string& log_file);

  // Collects children that have exited, without blocking.
  [[nodiscard]] std::vector<ChildExit> reap();

  void signal_all(int signal) const;
  [[nodiscard]] std::size_t running() const { return children_.size(); }

 private:
  struct Child {
    std::string id;
    pid_t pid;
  };
  std::string node_binary_;
  std::vector<Child> children_;
};

}  // namespace optique::master
