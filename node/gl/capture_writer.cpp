#include "node/gl/capture_writer.h"

#include <filesystem>

#include "image/frame_files.h"
#include "image/image_io.h"

namespace optique::node {
namespace {

Result<void> write_shown_file(const std::string& folder, std::uint64_t frame, const image::ByteImage& shown) {
  const std::string window = (std::filesystem::path(folder) / "window").string();
  std::error_code error;
  std::filesystem::create_directories(window, error);
  if (error) return Error{"cannot create " + window + ": " + error.message()};
  return image::write_png(image::frame_path(window, frame, "png"), shown);
}

constexpr const char* kSecondImageFolder = "second-image";

}  // namespace

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

void CaptureWriter::submit(std::uint64_t frame, int image, image::FloatImage linear, image::ByteImage encoded,
                           image::WordImage deep) {
  std::unique_lock lock(mutex_);
  if (jobs_.size() >= max_queued_) {
    log_.warn("capture writer is {} frames behind; waiting for it", jobs_.size());
    changed_.wait(lock, [this] { return jobs_.size() < max_queued_; });
  }
  jobs_.push_back({frame, image, std::move(linear), std::move(encoded), std::move(deep), {}});
  lock.unlock();
  changed_.notify_all();
}

void CaptureWriter::submit_shown(std::uint64_t frame, image::ByteImage shown) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return jobs_.size() < max_queued_; });
  jobs_.push_back({frame, 0, {}, {}, {}, std::move(shown)});
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
    Result<void> written;
    const std::string folder =
        job.image == 0 ? folder_ : (std::filesystem::path(folder_) / kSecondImageFolder).string();
    if (!job.shown.empty()) {
      written = write_shown_file(folder_, job.frame, job.shown);
    } else if (job.deep.empty()) {
      written = image::write_frame(folder, job.frame, job.linear, job.encoded);
    } else {
      written = image::write_frame(folder, job.frame, job.linear, job.deep);
    }
    if (!written) {
      log_.error("capture of frame {}{} lost: {}", job.frame, job.image == 0 ? "" : "'s second image", written.error());
    }
  }
}

}  // namespace optique::node
