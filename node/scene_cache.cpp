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

#include "util/sha256.h"

namespace optique::node {

namespace fs = std::filesystem;

namespace {

constexpr char kPartial[] = ".partial-";
constexpr char kLock[] = ".lock";

std::string describe(const std::error_code& error) { return error.message(); }

enum class Check { whole, differs, unreadable };

struct FileCheck {
  Check outcome = Check::whole;
  std::string problem;
};

// Reads `path` in 1 MiB pieces, handing each to `piece`; false on a read error.
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

FileCheck check_copy(const fs::path& copy, const scene::SceneManifest& manifest) {
  for (const scene::SceneFile& file : manifest.files) {
    FileCheck checked = check_file(copy / file.path, file);
    if (checked.outcome != Check::whole) return checked;
  }
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

// A partial copy of scene `sha256` whose node stopped midway (nobody holds its
// lock), with its lock now held: the chunks it holds need not come again.
// One without a lock file is left to remove_abandoned_partials (its node died
// before it began, or while it removed the copy).
struct Adopted {
  fs::path partial;
  int lock_fd = -1;
};
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

// How much of a copy is in: chunks, of how many, and their bytes.
struct Held {
  std::size_t chunks = 0;
  std::size_t of = 0;
  std::uint64_t bytes = 0;
};
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

struct CachedCopy {
  fs::file_time_type used;
  fs::path path;
  std::uintmax_t bytes = 0;  // its files' sizes: about what removing it frees
};

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
  std::sort(copies.begin(), copies.end(),
            [](const CachedCopy& a, const CachedCopy& b) { return std::tie(a.used, a.path) < std::tie(b.used, b.path); });
  return copies;
}

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
      if (const std::optional<std::uint64_t> bytes = being_fetched(folder_, sha256)) return Begun{FetchedElsewhere{*bytes}};
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
  const std::string wants = "the scene needs " + mib(needed) + " (" + mib(scene_bytes) + " and " + mib(spare_bytes_) +
                            " kept free)";
  if (free.value() + freed < needed) {
    return Error{"the scene cache " + folder_.string() + " has " + mib(free.value()) + " free, and removing every other copy (" +
                 std::to_string(copies.size()) + ") would free " + mib(freed) + " more; " + wants +
                 ": none was removed"};
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
