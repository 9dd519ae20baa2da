#include "util/background_thread.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace optique::util {

std::string lower_this_threads_priority(int steps) {
  // On Linux a thread's nice value is its own: setpriority on its thread id.
  const auto thread = static_cast<id_t>(syscall(SYS_gettid));
  errno = 0;
  const int now = getpriority(PRIO_PROCESS, thread);
  if (errno != 0) return std::strerror(errno);
  if (setpriority(PRIO_PROCESS, thread, std::min(now + steps, 19)) != 0) return std::strerror(errno);
  return {};
}

}  // namespace optique::util
