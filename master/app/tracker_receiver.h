#pragma once
// The head tracker's datagrams, read and parsed on a thread of their own, so
// that the frame loop's thread never spends a frame parsing: each datagram is
// read with the kernel's receive stamp, put through the reader's rules
// (tracking/dtrack_reader.h: the tracker's address, each sender's flood rule,
// the read budget), and what comes of it (samples, counts, log lines) is handed
// over through a mutex. The head tracker on the frame loop's thread still
// decides what a sample means.

#include <atomic>
#include <functional>
#include <mutex>
#include <thread>

#include "clock/clock.h"
#include "tracking/dtrack_reader.h"

namespace optique::master {

// Samples waiting to be taken beyond this are dropped (counted as flood): a
// frame loop that stalls does not let the queue grow without bound.
inline constexpr std::size_t kMostSamplesWaiting = 1024;
// Counts alone (everything dropped) are announced at most this often.
inline constexpr clock::Nanos kCountsEvery = 100'000'000;

class TrackerReceiver {
 public:
  // Reads `fd` (a bound, non-blocking UDP socket that asked for receive stamps;
  // the caller's, open until stop()) through `reader`. `ready` is called on the
  // receive thread when there is something to take() and the last call has
  // been answered by a take(): samples or a log line at once, counts alone
  // after kCountsEvery.
  TrackerReceiver(int fd, tracking::DTrackReader reader, std::function<void()> ready);
  ~TrackerReceiver();  // stop()
  TrackerReceiver(const TrackerReceiver&) = delete;
  TrackerReceiver& operator=(const TrackerReceiver&) = delete;

  // What came since the last take (any thread).
  [[nodiscard]] tracking::TrackerInput take();
  // Stops and joins the receive thread; take() still hands over what it left.
  void stop();

 private:
  void run();
  // `batch` joined to what waits; whether to announce it.
  [[nodiscard]] bool hand_over(tracking::TrackerInput& batch, clock::Nanos now);

  int fd_;
  std::atomic<bool> stopping_{false};
  int stop_fd_;  // an eventfd, written to wake the thread to stop (without one it sees stopping_ within kCountsEvery)
  tracking::DTrackReader reader_;  // the receive thread's
  std::function<void()> ready_;
  std::mutex mutex_;
  tracking::TrackerInput waiting_;   // guarded by mutex_
  bool announced_ = false;           // guarded by mutex_: ready_ called, not yet taken
  clock::Nanos last_announced_ = 0;  // the receive thread's
  bool error_said_ = false;          // the receive thread's
  std::thread thread_;
};

}  // namespace optique::master
