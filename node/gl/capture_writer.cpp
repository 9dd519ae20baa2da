#include "node/gl/capture_writer.h"

#include "image/frame_files.h"

namespace optique::node {

CaptureWriter::CaptureWriter(std::string folder, spdlog::logger& log, std::size_t max_queued)
    : folder_(std::move(folder)), log_(log), max_queued_(max_queued), worker_([this] { run(); }) {}

CaptureWriter::~CaptureWriter() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  worker_.join();
}

void CaptureWriter::submit(std::uint64_t frame, image::FloatImage linear, image::ByteImage encoded,
                           image::WordImage deep) {
  std::unique_lock lock(mutex_);
  if (jobs_.size() >= max_queued_) {
    log_.warn("capture writer is {} frames behind; waiting for it", jobs_.size());
    changed_.wait(lock, [this] { return jobs_.size() < max_queued_; });
  }
  jobs_.push_back({frame, std::move(linear), std::move(encoded), std::move(deep)});
  lock.unlock();
  changed_.notify_all();
}

void CaptureWriter::run() {
  for (;;) {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [this] { return stopping_ || !jobs_.empty(); });
    if (jobs_.empty()) return;  // stopping, and nothing left to write
    Job job = std::move(jobs_.front());
    jobs_.pop_front();
    lock.unlock();
    changed_.notify_all();
    const auto written = job.deep.empty() ? image::write_frame(folder_, job.frame, job.linear, job.encoded)
                                          : image::write_frame(folder_, job.frame, job.linear, job.deep);
    if (!written) {
      log_.error("capture of frame {} lost: {}", job.frame, written.error());
    }
  }
}

}  // namespace optique::node
