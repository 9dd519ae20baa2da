#pragma once
// A node's copies of the master's glTF scenes on disk, each under its identity
// (the SHA-256 of its manifest): <folder>/<sha256>/ holds the files by their
// paths. A scene being fetched is written into <sha256>.partial-<pid>-<tag> beside it
// and renamed into place once every file is whole, so a copy in place is complete
// (it is checked again when used) and a node that restarts does not fetch it
// again. Several nodes of one machine may share a folder: each writes its own
// partial copy, and the first to finish puts it in place.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "scene/manifest.h"
#include "util/result.h"

namespace optique::node {

class SceneCache {
 public:
  // The copies go into `cache_dir`/scenes.
  explicit SceneCache(const std::filesystem::path& cache_dir);

  // The node's cache folder (the scenes go into its "scenes"):
  // $CACHE_DIRECTORY (systemd's CacheDirectory=), else $XDG_CACHE_HOME/optique,
  // else $HOME/.cache/optique, else the temporary folder's optique.
  [[nodiscard]] static std::filesystem::path default_cache_dir();
  [[nodiscard]] const std::filesystem::path& folder() const { return folder_; }

  // The glTF of scene `sha256` when the cache holds every file of `manifest`
  // whole (sizes and SHA-256 checked); a copy that fails the check is removed,
  // so that it is fetched again.
  [[nodiscard]] std::optional<std::string> find(const scene::SceneManifest& manifest, const std::string& sha256);
  // Starts a copy: its partial folder, every file made; fails, naming the folder,
  // when it cannot be written or the disk has too little room for it. Partial
  // copies left by nodes that are gone are removed.
  [[nodiscard]] Result<void> begin(const scene::SceneManifest& manifest, const std::string& sha256);
  [[nodiscard]] Result<void> write(std::uint32_t file, std::uint64_t offset, std::string_view data);
  // Every file checked whole against the manifest, then the copy put in place;
  // the path of its glTF.
  [[nodiscard]] Result<std::string> commit();
  // A fetch that will not finish: its partial copy is removed.
  void abandon();

 private:
  std::filesystem::path folder_;
  // The copy being written.
  std::optional<scene::SceneManifest> manifest_;
  std::string sha256_;
  std::filesystem::path partial_;
  // Checked whole in this process already: not read again on a rejoin.
  std::string verified_;
};

}  // namespace optique::node
