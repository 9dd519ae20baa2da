#include "master/app/tracker_receiver.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cstring>
#include <string>
#include <vector>

#include "net/stamped_receive.h"
#include "tracking/dtrack.h"

namespace optique::master {
namespace {

// What has come is read at once on each wake-up, up to this many: then the
// batch is handed over, so samples do not wait behind a flood.
constexpr int kMostPerWake = 256;

}  // namespace

TrackerReceiver::TrackerReceiver(int fd, tracking::DTrackReader reader, std::function<void()> ready)
    : fd_(fd), stop_fd_(::eventfd(0, EFD_CLOEXEC)), reader_(std::move(reader)), ready_(std::move(ready)) {
  thread_ = std::thread([this] { run(); });
}

TrackerReceiver::~TrackerReceiver() {
  stop();
  if (stop_fd_ >= 0) ::close(stop_fd_);
}

void TrackerReceiver::stop() {
  if (!thread_.joinable()) return;
  stopping_ = true;
  const std::uint64_t one = 1;
  if (stop_fd_ >= 0) (void)!::write(stop_fd_, &one, sizeof one);
  thread_.join();
}

tracking::TrackerInput TrackerReceiver::take() {
  const std::lock_guard lock(mutex_);
  announced_ = false;
  return std::exchange(waiting_, {});
}

bool TrackerReceiver::hand_over(tracking::TrackerInput& batch, clock::Nanos now) {
  const std::lock_guard lock(mutex_);
  waiting_.counted += batch.counted;
  for (std::string& text : batch.said) waiting_.said.push_back(std::move(text));
  for (tracking::DTrackSample& sample : batch.samples) {
    if (waiting_.samples.size() < kMostSamplesWaiting) {
      waiting_.samples.push_back(std::move(sample));
    } else {
      ++waiting_.counted.flood;
    }
  }
  for (tracking::FlystickSample& flystick : batch.flysticks) waiting_.newest(std::move(flystick));
  if (announced_ || waiting_.empty()) return false;
  if (waiting_.samples.empty() && waiting_.flysticks.empty() && waiting_.said.empty() &&
      now - last_announced_ < kCountsEvery)
    return false;
  announced_ = true;
  return true;
}

void TrackerReceiver::run() {
  std::vector<std::uint8_t> buffer(tracking::kMaxDTrackDatagram + 1);
  const int wait_ms = static_cast<int>(kCountsEvery / clock::kNanosPerMilli);
  while (!stopping_) {
    pollfd fds[2] = {{fd_, POLLIN, 0}, {stop_fd_, POLLIN, 0}};
    const int ready = ::poll(fds, 2, wait_ms);
    if (stopping_ || (ready < 0 && errno != EINTR)) return;
    tracking::TrackerInput batch;
    for (int i = 0; i < kMostPerWake && (fds[0].revents & POLLIN) != 0; ++i) {
      const net::StampedDatagram got = net::read_datagram_stamped(fd_, buffer);
      if (got.read.status == net::StampedRead::Status::would_block) break;
      if (got.read.status != net::StampedRead::Status::data) {
        if (!error_said_) {
          batch.said.push_back(std::string("tracking: receiving failed: ") + std::strerror(got.read.error) +
                               " (going on)");
        }
        error_said_ = true;
        break;
      }
      reader_.read(std::string_view(reinterpret_cast<const char*>(buffer.data()), got.read.count), got.read.received,
                   got.sender, batch);
    }
    const clock::Nanos now = clock::monotonic_now();
    if (hand_over(batch, now)) {
      last_announced_ = now;
      ready_();
    }
  }
}

}  // namespace optique::master
