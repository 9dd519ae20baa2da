#pragma once
// A node's copies of the master's glTF scenes on disk, each under its identity
// (the SHA-256 of its manifest): <folder>/<sha256>/ holds the files by their
// paths. A scene being fetched is written into <sha256>.partial-<tag> beside it,
// whose owner holds a lock on <sha256>.partial-<tag>.lock, and renamed into
// place once every chunk is in, so a copy in place is complete (the loader checks
// its identity again) and a node that restarts does not fetch it again. Several
// nodes of one host may share a folder (even from several containers: the locks,
// not process ids, tell a partial copy whose node is gone): each writes its own
// partial copy, and the first to finish puts it in place. A partial copy whose
// node stopped midway (stopped, killed, or its master gone) is taken over by
// the next node that fetches the scene, with the chunks it holds; it is removed
// when a node begins to fetch another scene. When the disk runs
// short, the copies used longest ago make room, if removing them would; if not,
// none is removed and the scene is refused.

#include <spdlog/logger.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "scene/manifest.h"
#include "util/result.h"

namespace optique::node {

class SceneCache {
 public:
  // Room kept free on the disk beyond a scene being fetched.
  static constexpr std::uintmax_t kSpareBytes = 64u << 20;

  // Bytes free for this process on the file system that holds a folder.
  using FreeSpace = std::function<Result<std::uintmax_t>(const std::filesystem::path&)>;
  // statvfs(), through std::filesystem::space.
  [[nodiscard]] static Result<std::uintmax_t> disk_free_space(const std::filesystem::path& folder);

  // The copies go into `cache_dir`/scenes; `log` hears of copies found spoilt.
  // `free_space` is the disk's, or a test's.
  SceneCache(const std::filesystem::path& cache_dir, spdlog::logger& log, std::uintmax_t spare_bytes = kSpareBytes,
             FreeSpace free_space = disk_free_space);
  ~SceneCache();
  SceneCache(const SceneCache&) = delete;
  SceneCache& operator=(const SceneCache&) = delete;

  // The node's cache folder (the scenes go into its "scenes"):
  // $CACHE_DIRECTORY (systemd's CacheDirectory=), else $XDG_CACHE_HOME/optique,
  // else $HOME/.cache/optique, else the temporary folder's optique.
  [[nodiscard]] static std::filesystem::path default_cache_dir();
  [[nodiscard]] const std::filesystem::path& folder() const { return folder_; }

  // The glTF of scene `sha256` when the cache holds every file of `manifest`
  // whole (sizes and SHA-256 checked; once per process). A copy seen to differ
  // is removed, so that it is fetched again; one that cannot be read is left;
  // either is logged, naming the file and what was wrong with it.
  [[nodiscard]] std::optional<std::string> find(const scene::SceneManifest& manifest, const std::string& sha256);

  // For each file of the manifest, which chunks are in the copy being written.
  using Present = std::vector<std::vector<bool>>;
  // Another node (another process) is writing a copy of the scene into this
  // folder: wait for it rather than fetch the scene a second time.
  struct FetchedElsewhere {
    std::uint64_t bytes_there = 0;  // of its copy so far (the disk's blocks)
  };
  using Begun = std::variant<Present, FetchedElsewhere>;
  // Starts a copy, or goes on with an unfinished copy of the same scene (this
  // process's, its connection lost midway, or one a stopped node left): which
  // chunks it already holds, each checked against the manifest. Unless
  // `wait_for_others` is false, a copy that another live node is writing is
  // left to it: FetchedElsewhere (the look and the start of a copy are one step
  // for the nodes sharing the folder, so of two nodes that begin at once, one
  // fetches). Removes the other partial copies whose node is gone,
  // makes room by removing the copies used longest ago, and fails, naming the
  // folder, when it cannot be written or the disk has no room for the scene;
  // when removing every other copy would not make room either, it removes none
  // and says how much the scene needs and how much there is.
  [[nodiscard]] Result<Begun> begin(const scene::SceneManifest& manifest, const std::string& sha256,
                                    bool wait_for_others = true);
  [[nodiscard]] Result<void> write(std::uint32_t file, std::uint64_t offset, std::string_view data);
  // Every chunk is in (each was checked as it came): the copy put in place; the
  // path of its glTF.
  [[nodiscard]] Result<std::string> commit();
  // A fetch that will not go on (the node stops): its partial copy is removed.
  void abandon();

 private:
  void release_lock();
  void close_file();

  [[nodiscard]] Result<void> make_room(std::uintmax_t needed, const std::string& keep);
  [[nodiscard]] Error write_failed(const std::filesystem::path& path, int error);

  std::filesystem::path folder_;
  spdlog::logger& log_;
  std::uintmax_t spare_bytes_;
  FreeSpace free_space_;
  // The copy being written, and the lock that says its node is alive.
  std::optional<scene::SceneManifest> manifest_;
  std::string sha256_;
  std::filesystem::path partial_;
  int lock_fd_ = -1;
  // The file written last, kept open: chunks come file by file.
  std::int64_t open_file_ = -1;
  int file_fd_ = -1;
  std::optional<std::string> write_failed_;  // the first chunk that could not be written
  // Checked whole in this process already: not read again on a rejoin.
  std::string verified_;
};

}  // namespace optique::node
