#pragma once
// Writes captured frames on a worker thread, so encoding and disk I/O do not stall
// the frame loop. The read-back from the GPU happens before (it must); if the
// writer falls more than a few frames behind, submit() waits rather than drop a
// capture.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>

#include <spdlog/logger.h>

#include "image/image.h"

namespace optique::node {

class CaptureWriter {
 public:
  CaptureWriter(std::string folder, spdlog::logger& log, std::size_t max_queued = 4);
  ~CaptureWriter();  // writes what is queued, then stops
  CaptureWriter(const CaptureWriter&) = delete;
  CaptureWriter& operator=(const CaptureWriter&) = delete;

  // `encoded` is the signal: 8 bits, or 16 (`deep`, non-empty) for deeper
  // projectors. Image 1 of a frame (a projector that shows two per frame) goes
  // to FOLDER/second-image/frame-NNNNNN.{exr,png}.
  void submit(std::uint64_t frame, int image, image::FloatImage linear, image::ByteImage encoded,
              image::WordImage deep = {});
  // What the projector's window showed for `frame` (read back from the window):
  // FOLDER/window/frame-NNNNNN.png.
  void submit_shown(std::uint64_t frame, image::ByteImage shown);
  [[nodiscard]] const std::string& folder() const { return folder_; }

 private:
  struct Job {
    std::uint64_t frame;
    int image;
    image::FloatImage linear;
    image::ByteImage encoded;
    image::WordImage deep;
    image::ByteImage shown;  // set for a window's read-back, alone
  };
  void run();

  std::string folder_;
  spdlog::logger& log_;
  std::size_t max_queued_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> jobs_;
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace optique::node
