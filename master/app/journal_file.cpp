#include "master/app/journal_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "util/read_file.h"

namespace optique::master {
namespace {

std::string system_reason() { return std::strerror(errno); }

}  // namespace

Result<JournalFile> JournalFile::open(const std::string& path, Journal& journal) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) return Error{"cannot open " + path + " for writing: " + system_reason()};
  JournalFile file(fd, path);
  auto bytes = util::read_file(path, "journal");
  if (!bytes) return Error{bytes.error()};
  auto read = read_journal(bytes.value());
  if (!read) return Error{path + ": " + read.error()};
  journal = std::move(read).value();
  if (journal.whole_bytes < bytes.value().size() && ::ftruncate(fd, static_cast<off_t>(journal.whole_bytes)) != 0) {
    return Error{"cannot cut the torn end off " + path + ": " + system_reason()};
  }
  if (journal.whole_bytes == 0) {
    if (auto begun = file.append(kJournalMagic); !begun) return Error{begun.error()};
  }
  return file;
}

JournalFile::~JournalFile() {
  if (fd_ >= 0) ::close(fd_);
}

JournalFile::JournalFile(JournalFile&& other) noexcept : fd_(other.fd_), path_(std::move(other.path_)) {
  other.fd_ = -1;
}

JournalFile& JournalFile::operator=(JournalFile&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = other.fd_;
    path_ = std::move(other.path_);
    other.fd_ = -1;
  }
  return *this;
}

Result<void> JournalFile::append(std::string_view entry) {
  while (!entry.empty()) {
    const ssize_t wrote = ::write(fd_, entry.data(), entry.size());
    if (wrote < 0 && errno == EINTR) continue;
    if (wrote <= 0) return Error{"cannot append to " + path_ + ": " + system_reason()};
    entry.remove_prefix(static_cast<std::size_t>(wrote));
  }
  return {};
}

}  // namespace optique::master
