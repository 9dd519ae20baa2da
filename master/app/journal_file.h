#pragma once
// The --record file (master/session/journal.h) on disk: read once when the
// master starts, a torn last entry (a write a crash cut short, never
// acknowledged) cut away, then appended to. Each entry is handed to the kernel
// whole before the application hears that its transaction was applied: a
// crash of the master (kill -9 included) loses nothing it acknowledged; a
// crash of the machine loses what the kernel had not yet written to disk
// (Linux writes dirty pages back within about 30 s).

#include <string>
#include <string_view>

#include "master/session/journal.h"
#include "util/result.h"

namespace optique::master {

class JournalFile {
 public:
  // Opens `path` for appending, created if missing; what it already holds is
  // read and returned in `journal` (the live scene to restore), its torn tail
  // cut away. Fails when it cannot be read or written, or is not a journal.
  [[nodiscard]] static Result<JournalFile> open(const std::string& path, Journal& journal);
  ~JournalFile();
  JournalFile(JournalFile&& other) noexcept;
  JournalFile& operator=(JournalFile&& other) noexcept;
  JournalFile(const JournalFile&) = delete;
  JournalFile& operator=(const JournalFile&) = delete;

  // Writes `entry` whole, or fails with the system's reason.
  [[nodiscard]] Result<void> append(std::string_view entry);
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  JournalFile(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  int fd_ = -1;
  std::string path_;
};

}  // namespace optique::master
