#include "master/app/local_launcher.h"

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>

namespace optique::master {

std::string ChildExit::describe() const {
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status))
    return "was killed by signal " + std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")";
  return "stopped (status " + std::to_string(status) + ")";
}

bool ChildExit::clean() const { return WIFEXITED(status) && WEXITSTATUS(status) == 0; }

LocalLauncher::~LocalLauncher() {
  signal_all(SIGKILL);
  for (const Child& c : children_) {
    int status = 0;
    waitpid(c.pid, &status, 0);
  }
}

Result<pid_t> LocalLauncher::spawn(const std::string& id, const std::vector<std::string>& args,
                                   const std::string& log_file) {
  if (access(node_binary_.c_str(), X_OK) != 0) {
    return Error{"cannot run the node binary '" + node_binary_ + "': " + std::strerror(errno)};
  }
  int log_fd = -1;
  if (!log_file.empty()) {
    log_fd = open(log_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (log_fd < 0) return Error{"cannot create node log '" + log_file + "': " + std::strerror(errno)};
  }
  // Everything the child needs is prepared before fork: after it, only
  // async-signal-safe calls.
  std::vector<std::string> argv_storage;
  argv_storage.push_back(node_binary_);
  argv_storage.insert(argv_storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t parent = getpid();

  const pid_t pid = fork();
  if (pid < 0) {
    const int error = errno;
    if (log_fd >= 0) ::close(log_fd);
    return Error{std::string("fork failed: ") + std::strerror(error)};
  }
  if (pid == 0) {
    // Own process group: a Ctrl-C on the terminal reaches the master only, which
    // then says goodbye to its nodes in order. And die with the master.
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(125);
    if (log_fd >= 0) {
      dup2(log_fd, STDOUT_FILENO);
      dup2(log_fd, STDERR_FILENO);
    }
    execv(argv[0], argv.data());
    _exit(127);
  }
  if (log_fd >= 0) ::close(log_fd);
  children_.push_back({id, pid});
  return pid;
}

std::vector<ChildExit> LocalLauncher::reap() {
  std::vector<ChildExit> exits;
  for (auto it = children_.begin(); it != children_.end();) {
    int status = 0;
    if (waitpid(it->pid, &status, WNOHANG) == it->pid) {
      exits.push_back({it->id, it->pid, status});
      it = children_.erase(it);
    } else {
      ++it;
    }
  }
  return exits;
}

void LocalLauncher::signal_all(int signal) const {
  for (const Child& c : children_) kill(c.pid, signal);
}

}  // namespace optique::master
