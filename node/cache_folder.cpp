#include "node/cache_folder.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <tuple>

#include "util/sha256.h"

namespace optique::node::cache_folder {
namespace {

// Whether `path` holds the file `file` describes: its size and SHA-256.
FileCheck check_file(const fs::path& path, const scene::SceneFile& file) {
  std::error_code error;
  const std::uintmax_t size = fs::file_size(path, error);
  if (error) {
    return {error == std::errc::no_such_file_or_directory ? Check::differs : Check::unreadable,
            path.string() + ": " + describe(error)};
  }
  if (size != file.size) {
    return {Check::differs,
            path.string() + " has " + std::to_string(size) + " bytes, not " + std::to_string(file.size)};
  }
  util::Sha256 digest;
  if (!read_pieces(path, 1u << 20, [&](std::string_view piece) { digest.update(piece); })) {
    return {Check::unreadable, path.string() + ": " + std::strerror(errno)};
  }
  if (digest.finish() != file.sha256) return {Check::differs, path.string() + " does not match its SHA-256"};
  return {};
}

bool is_identity(const std::string& name) {
  return name.size() == 64 && std::all_of(name.begin(), name.end(), [](char c) {
           return std::isdigit(static_cast<unsigned char>(c)) || (c >= 'a' && c <= 'f');
         });
}

// Whether the node writing partial copy `partial` is alive: its lock file is
// there and held (by another open file than any of this cache's). Taking the
// lock to test it, and letting it go, is how a live holder is told from a gone
// one; where the lock cannot be taken at all, the holder is taken for alive.
bool writer_alive(const fs::path& partial) {
  const int fd = open((partial.string() + kLock).c_str(), O_RDWR | O_CLOEXEC);
  const bool alive = fd >= 0 && flock(fd, LOCK_EX | LOCK_NB) != 0;
  if (fd >= 0) close(fd);
  return alive;
}

// The bytes of the files under `folder`: their sizes, or what the disk holds
// of them (a copy being written: its files may be sized, or written out of
// order, before their bytes are in).
enum class Measure { sizes, on_disk };
std::uintmax_t bytes_under(const fs::path& folder, Measure measure = Measure::sizes) {
  std::uintmax_t bytes = 0;
  std::error_code error;
  for (fs::recursive_directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
    struct stat file {};
    if (stat(it->path().c_str(), &file) != 0 || !S_ISREG(file.st_mode)) continue;
    const auto size = static_cast<std::uintmax_t>(file.st_size);
    bytes += measure == Measure::sizes ? size : std::min(size, static_cast<std::uintmax_t>(file.st_blocks) * 512);
  }
  return bytes;
}

}  // namespace

FileCheck check_copy(const fs::path& copy, const scene::SceneManifest& manifest) {
  for (const scene::SceneFile& file : manifest.files) {
    FileCheck checked = check_file(copy / file.path, file);
    if (checked.outcome != Check::whole) return checked;
  }
  return {};
}

// Partial copies whose node is gone: nobody holds their lock (or they have none).
void remove_abandoned_partials(const fs::path& folder) {
  std::error_code error;
  std::vector<fs::path> partials;
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (name.find(kPartial) != std::string::npos && !name.ends_with(kLock)) partials.push_back(entry.path());
  }
  for (const fs::path& partial : partials) {
    if (!writer_alive(partial)) {
      fs::remove_all(partial, error);
      fs::remove(partial.string() + kLock, error);
    }
  }
}

std::optional<Adopted> adopt_abandoned(const fs::path& folder, const std::string& sha256) {
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with(sha256 + kPartial) || name.ends_with(kLock) || !entry.is_directory(error)) continue;
    const fs::path lock = entry.path().string() + kLock;
    const int fd = open(lock.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) continue;
    // Held: its node is alive. Taken: the lock must still be the file at its
    // path (a node clearing abandoned copies may have removed both meanwhile).
    struct stat held {};
    struct stat named {};
    if (flock(fd, LOCK_EX | LOCK_NB) != 0 || fstat(fd, &held) != 0 || stat(lock.c_str(), &named) != 0 ||
        held.st_ino != named.st_ino || held.st_dev != named.st_dev || !fs::is_directory(entry.path(), error)) {
      close(fd);
      continue;
    }
    return Adopted{entry.path(), fd};
  }
  return std::nullopt;
}

// The copy of scene `sha256` another live process is writing into `folder`:
// the bytes its files hold on the disk so far.
std::optional<std::uint64_t> being_fetched(const fs::path& folder, const std::string& sha256) {
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (!name.starts_with(sha256 + kPartial) || name.ends_with(kLock) || !entry.is_directory(error)) continue;
    if (writer_alive(entry.path())) return bytes_under(entry.path(), Measure::on_disk);
  }
  return std::nullopt;
}

// Every file of `manifest` in `copy`, its folders made: empty (`whole`
// false), or at its size, what it holds kept; what went wrong, naming the file.
std::optional<std::string> make_files(const fs::path& copy, const scene::SceneManifest& manifest, bool whole) {
  for (const scene::SceneFile& file : manifest.files) {
    const fs::path path = copy / file.path;
    std::error_code error;
    fs::create_directories(path.parent_path(), error);
    if (error) return path.string() + ": " + describe(error);
    const int fd = open(path.c_str(), O_CREAT | O_WRONLY | O_CLOEXEC, 0644);
    const bool sized = fd >= 0 && ftruncate(fd, whole ? static_cast<off_t>(file.size) : 0) == 0;
    const std::string why = std::strerror(errno);
    if (fd >= 0) close(fd);
    if (!sized) return path.string() + ": " + why;
  }
  return std::nullopt;
}

Held held_in(const std::vector<std::vector<bool>>& present, const scene::SceneManifest& manifest) {
  Held held;
  for (std::size_t f = 0; f < present.size(); ++f) {
    for (std::size_t c = 0; c < present[f].size(); ++c) {
      if (present[f][c]) {
        ++held.chunks;
        held.bytes += manifest.chunk_length(f, c);
      }
    }
    held.of += present[f].size();
  }
  return held;
}

// The copies in place but `keep`, used longest ago first.
std::vector<CachedCopy> copies_by_age(const fs::path& folder, const std::string& keep) {
  std::error_code error;
  std::vector<CachedCopy> copies;
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (is_identity(name) && name != keep) {
      copies.push_back({fs::last_write_time(entry.path(), error), entry.path(), bytes_under(entry.path())});
    }
  }
  std::sort(copies.begin(), copies.end(), [](const CachedCopy& a, const CachedCopy& b) {
    return std::tie(a.used, a.path) < std::tie(b.used, b.path);
  });
  return copies;
}

}  // namespace optique::node::cache_folder
