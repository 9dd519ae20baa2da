#pragma once
// A master process on 127.0.0.1 with an ephemeral port the test reads back, and
// nodes pointed at it: the cluster as a user runs it, for integration tests.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "process.h"
#include "scratch.h"

namespace optique::testing {

[[nodiscard]] std::string master_binary();
// A port nothing listens on (bound, then released): for a master restarted on the same port.
[[nodiscard]] std::string free_port();
[[nodiscard]] std::string node_binary();

struct ExternalMaster {
  ScratchDir scratch{"optique-it"};  // kept when the test fails
  std::string dir = scratch.string();
  std::unique_ptr<Process> process;
  std::string port;  // empty if the master never wrote its port file

  // Starts `optique-master --config CONFIG --listen 127.0.0.1 --port 0 --out DIR/out
  // --no-status EXTRA...` and waits up to 10 s for its port.
  ExternalMaster(const std::string& config, const std::vector<std::string>& extra);

  // A node for projector `id`, its log in DIR/node-ID.log.
  [[nodiscard]] std::unique_ptr<Process> node(const std::string& id, const std::vector<std::string>& extra = {}) const;
};

// One null-render node per projector of `config`, in config order; `extra(i)`
// adds arguments for the i-th.
struct NullNodes {
  std::vector<std::string> ids;
  std::vector<std::unique_ptr<Process>> processes;
};
[[nodiscard]] NullNodes start_null_nodes(const ExternalMaster& master, const std::string& config,
                                         const std::function<std::vector<std::string>(std::size_t)>& extra = {});

}  // namespace optique::testing
