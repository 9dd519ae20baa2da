#include "external_master.h"

#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>

#include "config/load.h"

namespace optique::testing {

using namespace std::chrono_literals;

std::string master_binary() { return std::string(OPTIQUE_BIN_DIR) + "/optique-master"; }
std::string node_binary() { return std::string(OPTIQUE_BIN_DIR) + "/optique-node"; }

std::string free_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  socklen_t length = sizeof address;
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  close(fd);
  return std::to_string(ntohs(address.sin_port));
}

ExternalMaster::ExternalMaster(const std::string& config, const std::vector<std::string>& extra) {
  std::vector<std::string> argv{master_binary(), "--config",    config,  "--listen",   "127.0.0.1",  "--port", "0",
                                "--port-file",   dir + "/port", "--out", dir + "/out", "--no-status"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  process = std::make_unique<Process>(argv, dir + "/master.log");
  port = wait_for_port(dir + "/port", 10s);
}

std::unique_ptr<Process> ExternalMaster::node(const std::string& id, const std::vector<std::string>& extra) const {
  std::vector<std::string> argv{node_binary(), "--master", "127.0.0.1:" + port, "--id", id};
  argv.insert(argv.end(), extra.begin(), extra.end());
  return std::make_unique<Process>(argv, dir + "/node-" + id + ".log");
}

NullNodes start_null_nodes(const ExternalMaster& master, const std::string& config,
                           const std::function<std::vector<std::string>(std::size_t)>& extra) {
  NullNodes nodes;
  auto loaded = config::load_installation(config);
  EXPECT_TRUE(loaded) << (loaded ? "" : loaded.error());
  if (!loaded) return nodes;
  for (const auto& p : loaded.value().installation.projectors) {
    std::vector<std::string> arguments{"--renderer", "null"};
    if (extra) {
      const std::vector<std::string> more = extra(nodes.ids.size());
      arguments.insert(arguments.end(), more.begin(), more.end());
    }
    nodes.ids.push_back(p.id);
    nodes.processes.push_back(master.node(p.id, arguments));
  }
  return nodes;
}

}  // namespace optique::testing
