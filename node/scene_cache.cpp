#include "node/scene_cache.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <tuple>
#include <utility>

#include "node/cache_folder.h"
#include "util/sha256.h"

namespace optique::node {

namespace fs = std::filesystem;

using namespace cache_folder;  // the folder's own files: node/cache_folder.h

namespace {

std::string mib(std::uintmax_t bytes) { return fmt::format("{:.1f} MiB", static_cast<double>(bytes) / (1 << 20)); }

}  // namespace

SceneCache::SceneCache(const fs::path& cache_dir, spdlog::logger& log, std::uintmax_t spare_bytes, FreeSpace free_space)
    : folder_(cache_dir / "scenes"), log_(log), spare_bytes_(spare_bytes), free_space_(std::move(free_space)) {}

Result<std::uintmax_t> SceneCache::disk_free_space(const fs::path& folder) {
  std::error_code error;
  const fs::space_info space = fs::space(folder, error);
  if (error) return Error{"cannot tell the free space of " + folder.string() + ": " + describe(error)};
  return space.available;
}

// The partial copy and its lock file stay (the lock released): the next node
// to fetch this scene goes on from the chunks in it.
SceneCache::~SceneCache() {
  close_file();
  if (lock_fd_ >= 0) close(lock_fd_);
}

fs::path SceneCache::default_cache_dir() {
  const auto variable = [](const char* name) -> std::string {
    const char* value = std::getenv(name);
    return value != nullptr ? value : "";
  };
  fs::path base;
  if (const std::string systemd = variable("CACHE_DIRECTORY"); !systemd.empty()) {
    base = systemd.substr(0, systemd.find(':'));  // the first of several
  } else if (const std::string xdg = variable("XDG_CACHE_HOME"); !xdg.empty()) {
    base = fs::path(xdg) / "optique";
  } else if (const std::string home = variable("HOME"); !home.empty()) {
    base = fs::path(home) / ".cache" / "optique";
  } else {
    base = fs::temp_directory_path() / "optique";
  }
  return base;
}

std::optional<std::string> SceneCache::find(const scene::SceneManifest& manifest, const std::string& sha256) {
  const fs::path copy = folder_ / sha256;
  std::error_code error;
  if (!fs::is_directory(copy, error)) return std::nullopt;
  if (verified_ != sha256) {
    const FileCheck checked = check_copy(copy, manifest);
    if (checked.outcome == Check::differs) {
      log_.warn("the cached copy of the scene {}… is spoilt ({}): removed, it is fetched again", sha256.substr(0, 12),
                checked.problem);
      fs::remove_all(copy, error);
    } else if (checked.outcome == Check::unreadable) {
      log_.warn("the cached copy of the scene {}… cannot be read ({}): left as it is, the scene is fetched",
                sha256.substr(0, 12), checked.problem);
    }
    if (checked.outcome != Check::whole) return std::nullopt;
    verified_ = sha256;
  }
  fs::last_write_time(copy, fs::file_time_type::clock::now(), error);  // used now: evicted last
  return (copy / manifest.files.front().path).string();
}

Result<SceneCache::Begun> SceneCache::begin(const scene::SceneManifest& manifest, const std::string& sha256,
                                            bool wait_for_others) {
  Present present(manifest.files.size());
  for (std::size_t f = 0; f < manifest.files.size(); ++f)
    present[f].assign(manifest.files[f].chunks(manifest.chunk_bytes), false);
  // The chunks of an unfinished copy that check against the manifest.
  const auto mark_present = [&] {
    for (std::size_t f = 0; f < manifest.files.size(); ++f) {
      std::uint64_t index = 0;
      (void)read_pieces(partial_ / manifest.files[f].path, manifest.chunk_bytes, [&](std::string_view piece) {
        if (index < present[f].size() && piece.size() == manifest.chunk_length(f, index) &&
            util::sha256_raw(piece) == manifest.files[f].chunk_digest(index)) {
          present[f][index] = true;
        }
        ++index;
      });
    }
  };
  std::error_code error;
  if (manifest_ && sha256_ == sha256 && fs::is_directory(partial_, error)) {
    mark_present();  // this process's unfinished copy (its connection went)
    return Begun{std::move(present)};
  }
  abandon();
  fs::create_directories(folder_, error);
  if (error) return Error{"cannot make the scene cache " + folder_.string() + ": " + describe(error)};
  // A fresh copy, seen by the nodes that begin after this one: its lock first
  // (a partial copy without one is taken for abandoned), then its folder.
  const auto start_fresh = [&]() -> Result<void> {
    partial_ = folder_ / (sha256 + kPartial + std::to_string(std::random_device{}()) + "-" +
                          std::to_string(std::random_device{}()));
    lock_fd_ = open((partial_.string() + kLock).c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
    if (lock_fd_ < 0 || flock(lock_fd_, LOCK_EX | LOCK_NB) != 0 || !fs::create_directory(partial_, error)) {
      const std::string why = error ? describe(error) : std::strerror(errno);
      abandon();
      return Error{"cannot write the scene cache " + folder_.string() + ": " + why};
    }
    return {};
  };
  std::uint64_t held_bytes = 0;  // in a copy taken over
  {
    const BeginLock begin_lock(folder_);
    if (wait_for_others) {
      if (const std::optional<std::uint64_t> bytes = being_fetched(folder_, sha256))
        return Begun{FetchedElsewhere{*bytes}};
    }
    if (std::optional<Adopted> adopted = adopt_abandoned(folder_, sha256)) {
      // A node stopped midway (this one, restarted, or another of this host):
      // what it fetched is kept; every file is there, at its size, to be
      // written into. Anything amiss, and a fresh copy is begun instead.
      partial_ = adopted->partial;
      lock_fd_ = adopted->lock_fd;
      if (make_files(partial_, manifest, true)) {
        abandon();
      } else {
        mark_present();
        manifest_ = manifest;
        sha256_ = sha256;
        const Held held = held_in(present, manifest);
        held_bytes = held.bytes;
        log_.info("going on with the copy of the scene {}… that a stopped node left: {} of its {} chunks are in",
                  sha256.substr(0, 12), held.chunks, held.of);
      }
    }
    if (!manifest_) {
      if (auto started = start_fresh(); !started) return Error{started.error()};
    }
  }
  remove_abandoned_partials(folder_);
  // Room for what is still to come.
  if (auto room = make_room(manifest.total_bytes() - held_bytes, sha256); !room) {
    abandon();
    return Error{room.error()};
  }
  if (manifest_) return Begun{std::move(present)};  // taken over
  if (const std::optional<std::string> problem = make_files(partial_, manifest, false)) {
    abandon();
    return Error{"cannot write the scene cache " + folder_.string() + ": " + *problem};
  }
  manifest_ = manifest;
  sha256_ = sha256;
  return Begun{std::move(present)};
}

Result<void> SceneCache::write(std::uint32_t file, std::uint64_t offset, std::string_view data) {
  if (!manifest_ || file >= manifest_->files.size()) return Error{"no scene is being written"};
  const fs::path path = partial_ / manifest_->files[file].path;
  if (open_file_ != file) {
    close_file();
    file_fd_ = open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (file_fd_ < 0) return write_failed(path, errno);
    open_file_ = file;
  }
  for (std::size_t done = 0; done < data.size();) {
    const ssize_t n = pwrite(file_fd_, data.data() + done, data.size() - done, static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return write_failed(path, errno);
    done += static_cast<std::size_t>(n);
  }
  return {};
}

// Remembered: the copy's files have their full size from the start, so a chunk
// that did not reach the disk leaves a hole that commit() must not put in place.
Error SceneCache::write_failed(const std::filesystem::path& path, int error) {
  Error failed{"cannot write " + path.string() + ": " + std::strerror(error)};
  if (!write_failed_) write_failed_ = failed.message;
  return failed;
}

void SceneCache::close_file() {
  if (file_fd_ >= 0) close(file_fd_);
  file_fd_ = -1;
  open_file_ = -1;
}

Result<std::string> SceneCache::commit() {
  if (!manifest_) return Error{"no scene is being written"};
  close_file();
  if (write_failed_) {
    const std::string problem = "the scene's copy is not whole: " + *write_failed_;
    abandon();  // clears write_failed_: the message first
    return Error{problem};
  }
  const scene::SceneManifest manifest = *manifest_;
  // Each chunk was checked against the manifest as it came; what the disk did
  // with them the loader sees (it checks the scene's identity again).
  for (const scene::SceneFile& file : manifest.files) {
    std::error_code error;
    const std::uintmax_t size = fs::file_size(partial_ / file.path, error);
    if (error || size != file.size) {
      const std::string problem =
          "the scene's copy is not whole: " + (partial_ / file.path).string() + " has " +
          (error ? describe(error) : std::to_string(size) + " bytes, not " + std::to_string(file.size));
      abandon();  // clears partial_: the message first
      return Error{problem};
    }
  }
  const fs::path copy = folder_ / sha256_;
  std::error_code error;
  fs::rename(partial_, copy, error);
  if (error) {
    // Another node of this host put the same scene in place first: use it.
    abandon();
    if (auto found = find(manifest, sha256_)) return *found;
    return Error{"cannot put the scene in place at " + copy.string() + ": " + describe(error)};
  }
  release_lock();
  partial_.clear();
  manifest_.reset();
  fs::last_write_time(copy, fs::file_time_type::clock::now(), error);
  return (copy / manifest.files.front().path).string();
}

// Decided before anything is removed: a scene that would not fit even with every
// other copy gone costs the node none of them.
Result<void> SceneCache::make_room(std::uintmax_t scene_bytes, const std::string& keep) {
  const std::uintmax_t needed = scene_bytes + spare_bytes_;
  const Result<std::uintmax_t> free = free_space_(folder_);
  if (!free || free.value() >= needed) return {};  // unknown: nothing removed on a guess
  const std::vector<CachedCopy> copies = copies_by_age(folder_, keep);
  std::uintmax_t freed = 0;
  std::size_t removing = 0;
  while (removing < copies.size() && free.value() + freed < needed) freed += copies[removing++].bytes;
  const std::string wants =
      "the scene needs " + mib(needed) + " (" + mib(scene_bytes) + " and " + mib(spare_bytes_) + " kept free)";
  if (free.value() + freed < needed) {
    return Error{"the scene cache " + folder_.string() + " has " + mib(free.value()) +
                 " free, and removing every other copy (" + std::to_string(copies.size()) + ") would free " +
                 mib(freed) + " more; " + wants + ": none was removed"};
  }
  std::error_code error;
  for (std::size_t i = 0; i < removing; ++i) fs::remove_all(copies[i].path, error);
  const Result<std::uintmax_t> after = free_space_(folder_);
  if (after && after.value() < needed) {
    return Error{"the scene cache " + folder_.string() + " has " + mib(after.value()) + " free after removing the " +
                 std::to_string(removing) + " copies used longest ago; " + wants};
  }
  return {};
}

void SceneCache::abandon() {
  close_file();
  if (!partial_.empty()) {
    std::error_code ignored;
    fs::remove_all(partial_, ignored);
    fs::remove(partial_.string() + kLock, ignored);
  }
  release_lock();
  partial_.clear();
  manifest_.reset();
  write_failed_.reset();
}

void SceneCache::release_lock() {
  if (lock_fd_ >= 0) {
    if (!partial_.empty()) {
      std::error_code ignored;
      fs::remove(partial_.string() + kLock, ignored);
    }
    close(lock_fd_);
  }
  lock_fd_ = -1;
}

}  // namespace optique::node
