// A thread lowered for background work runs at a lesser priority (a higher
// nice value), its own only: the thread that asked nothing keeps its own.
#include "util/background_thread.h"

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <thread>

namespace optique::util {
namespace {

int nice_of_this_thread() { return getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid))); }

TEST(BackgroundThread, OnlyTheThreadThatAsksIsLowered) {
  const int before = nice_of_this_thread();
  int lowered = 0;
  std::string why = "not run";
  std::thread worker([&] {
    why = lower_this_threads_priority(5);
    lowered = nice_of_this_thread();
  });
  worker.join();
  EXPECT_EQ(why, "");
  EXPECT_EQ(lowered, std::min(before + 5, 19));
  EXPECT_EQ(nice_of_this_thread(), before);
}

}  // namespace
}  // namespace optique::util
