#pragma once
// Internal to node: a scene cache's folder on the disk (node/scene_cache.h
// decides; this reads and writes). Copies checked against their manifest,
// partial copies and the locks their writers hold, the lock under which a
// node begins a copy, how much a copy holds, the copies by age.

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "scene/manifest.h"

namespace optique::node::cache_folder {

namespace fs = std::filesystem;

inline constexpr char kPartial[] = ".partial-";  // <sha256>.partial-<random>: a copy being written
inline constexpr char kLock[] = ".lock";         // beside it, held by its writer

[[nodiscard]] inline std::string describe(const std::error_code& error) { return error.message(); }

enum class Check { whole, differs, unreadable };

struct FileCheck {
  Check outcome = Check::whole;
  std::string problem;
};

// Reads `path` in pieces of `piece_bytes`, handing each to `piece`; false on a read error.
template <class Piece>
bool read_pieces(const fs::path& path, std::uint64_t piece_bytes, Piece&& piece) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::vector<char> buffer(piece_bytes);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto got = static_cast<std::size_t>(in.gcount());
    if (got > 0) piece(std::string_view(buffer.data(), got));
  }
  return !in.bad();
}

// Whether every file of `manifest` in `copy` is whole (its size and SHA-256).
[[nodiscard]] FileCheck check_copy(const fs::path& copy, const scene::SceneManifest& manifest);

// Partial copies whose node is gone: nobody holds their lock (or they have none).
void remove_abandoned_partials(const fs::path& folder);

// A partial copy of scene `sha256` whose node stopped midway (nobody holds its
// lock), with its lock now held: the chunks it holds need not come again.
// One without a lock file is left to remove_abandoned_partials (its node died
// before it began, or while it removed the copy).
struct Adopted {
  fs::path partial;
  int lock_fd = -1;
};
[[nodiscard]] std::optional<Adopted> adopt_abandoned(const fs::path& folder, const std::string& sha256);

// The copy of scene `sha256` another live process is writing into `folder`:
// the bytes its files hold on the disk so far.
[[nodiscard]] std::optional<std::uint64_t> being_fetched(const fs::path& folder, const std::string& sha256);

// Held while a node looks for another's copy and starts its own, so that of
// nodes sharing the folder that begin at once one fetches: an flock on
// <folder>/.begin, let go when this goes.
class BeginLock {
 public:
  explicit BeginLock(const fs::path& folder)
      : fd_(open((folder / ".begin").c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644)) {
    while (fd_ >= 0 && flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
    }
  }
  ~BeginLock() {
    if (fd_ >= 0) close(fd_);
  }
  BeginLock(const BeginLock&) = delete;
  BeginLock& operator=(const BeginLock&) = delete;

 private:
  int fd_;
};

// Every file of `manifest` in `copy`, its folders made: empty (`whole`
// false), or at its size, what it holds kept; what went wrong, naming the file.
[[nodiscard]] std::optional<std::string> make_files(const fs::path& copy, const scene::SceneManifest& manifest,
                                                    bool whole);

// How much of a copy is in: chunks, of how many, and their bytes.
struct Held {
  std::size_t chunks = 0;
  std::size_t of = 0;
  std::uint64_t bytes = 0;
};
[[nodiscard]] Held held_in(const std::vector<std::vector<bool>>& present, const scene::SceneManifest& manifest);

struct CachedCopy {
  fs::file_time_type used;
  fs::path path;
  std::uintmax_t bytes = 0;  // its files' sizes: about what removing it frees
};

// The copies in place but `keep`, used longest ago first.
[[nodiscard]] std::vector<CachedCopy> copies_by_age(const fs::path& folder, const std::string& keep);

}  // namespace optique::node::cache_folder
