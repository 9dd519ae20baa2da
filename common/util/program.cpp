#include "util/program.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

extern char** environ;

namespace optique::util {
namespace {

// execv wants char* const*; the strings outlive the call.
std::vector<char*> argv_of(const std::string& name, std::span<const std::string> args,
                           std::vector<std::string>& storage) {
  storage.assign(1, name);
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  return argv;
}

std::string cannot_run(const std::string& path, int error) {
  return "cannot run " + path + ": " + std::strerror(error) +
         (error == ENOENT ? " (it is built and installed beside this program)" : "");
}

}  // namespace

std::string sibling_program(const std::string& name) {
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return name;
  return (self.parent_path() / name).string();
}

Error replace_process(const std::string& path, const std::string& name, std::span<const std::string> args) {
  std::vector<std::string> storage;
  const std::vector<char*> argv = argv_of(name, args, storage);
  execv(path.c_str(), argv.data());
  return Error{cannot_run(path, errno)};
}

Result<int> run_program(const std::string& path, const std::vector<std::string>& args) {
  std::vector<std::string> storage;
  const std::vector<char*> argv = argv_of(path, args, storage);
  pid_t pid = 0;
  if (const int error = posix_spawn(&pid, path.c_str(), nullptr, nullptr, argv.data(), environ); error != 0) {
    return Error{cannot_run(path, error)};
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return Error{"waiting for " + path + ": " + std::strerror(errno)};
  }
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return WEXITSTATUS(status);
}

}  // namespace optique::util
