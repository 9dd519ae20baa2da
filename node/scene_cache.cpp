#include "node/scene_cache.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <vector>

#include "util/sha256.h"

namespace optique::node {

namespace fs = std::filesystem;

namespace {

// Room kept free on the disk beyond the scene itself.
constexpr std::uintmax_t kSpareBytes = 64u << 20;

std::string describe(const std::error_code& error) { return error.message(); }

// Whether `path` holds `size` bytes whose SHA-256 is `sha256`; what differs.
Result<void> check_file(const fs::path& path, const scene::SceneFile& file) {
  std::error_code error;
  const std::uintmax_t size = fs::file_size(path, error);
  if (error) return Error{path.string() + ": " + describe(error)};
  if (size != file.size) {
    return Error{path.string() + " has " + std::to_string(size) + " bytes, not " + std::to_string(file.size)};
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{path.string() + ": cannot open: " + std::strerror(errno)};
  util::Sha256 digest;
  std::vector<char> buffer(1u << 20);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    digest.update(std::string_view(buffer.data(), static_cast<std::size_t>(in.gcount())));
  }
  if (in.bad()) return Error{path.string() + ": read error"};
  if (digest.finish() != file.sha256) return Error{path.string() + " does not match its SHA-256"};
  return {};
}

Result<void> check_copy(const fs::path& copy, const scene::SceneManifest& manifest) {
  for (const scene::SceneFile& file : manifest.files) {
    if (auto checked = check_file(copy / file.path, file); !checked) return checked;
  }
  return {};
}

// The pid a partial copy's name ends with, if it is one of `sha256`'s.
std::optional<pid_t> partial_owner(const std::string& name, const std::string& sha256) {
  const std::string prefix = sha256 + ".partial-";
  if (!name.starts_with(prefix)) return std::nullopt;
  char* end = nullptr;
  const long pid = std::strtol(name.c_str() + prefix.size(), &end, 10);
  if (end == nullptr || (*end != '\0' && *end != '-') || pid <= 0) return std::nullopt;
  return static_cast<pid_t>(pid);
}

}  // namespace

SceneCache::SceneCache(const fs::path& cache_dir) : folder_(cache_dir / "scenes") {}

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
    if (!check_copy(copy, manifest)) {
      fs::remove_all(copy, error);
      return std::nullopt;
    }
    verified_ = sha256;
  }
  return (copy / manifest.files.front().path).string();
}

Result<void> SceneCache::begin(const scene::SceneManifest& manifest, const std::string& sha256) {
  abandon();
  std::error_code error;
  fs::create_directories(folder_, error);
  if (error) return Error{"cannot make the scene cache " + folder_.string() + ": " + describe(error)};
  // Partial copies of this scene whose node is gone.
  for (const auto& entry : fs::directory_iterator(folder_, error)) {
    const auto owner = partial_owner(entry.path().filename().string(), sha256);
    if (owner && kill(*owner, 0) != 0 && errno == ESRCH) fs::remove_all(entry.path(), error);
  }
  const fs::space_info space = fs::space(folder_, error);
  if (!error && space.available < manifest.total_bytes() + kSpareBytes) {
    return Error{"the scene cache " + folder_.string() + " has " + std::to_string(space.available >> 20) +
                 " MiB free, the scene needs " + std::to_string((manifest.total_bytes() + kSpareBytes) >> 20)};
  }
  // The process (for the clean-up above) and a random tag: two caches of one
  // process (tests) never share a partial copy either.
  partial_ = folder_ / (sha256 + ".partial-" + std::to_string(getpid()) + "-" + std::to_string(std::random_device{}()));
  fs::remove_all(partial_, error);
  for (const scene::SceneFile& file : manifest.files) {
    const fs::path path = partial_ / file.path;
    fs::create_directories(path.parent_path(), error);
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (error || !out) {
      const std::string why = error ? describe(error) : std::strerror(errno);
      abandon();
      return Error{"cannot write the scene cache " + folder_.string() + ": " + path.string() + ": " + why};
    }
  }
  manifest_ = manifest;
  sha256_ = sha256;
  return {};
}

Result<void> SceneCache::write(std::uint32_t file, std::uint64_t offset, std::string_view data) {
  if (!manifest_ || file >= manifest_->files.size()) return Error{"no scene is being written"};
  const fs::path path = partial_ / manifest_->files[file].path;
  std::fstream out(path, std::ios::binary | std::ios::in | std::ios::out);
  out.seekp(static_cast<std::streamoff>(offset));
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
  out.flush();
  if (!out) return Error{"cannot write " + path.string() + ": " + std::strerror(errno)};
  return {};
}

Result<std::string> SceneCache::commit() {
  if (!manifest_) return Error{"no scene is being written"};
  const scene::SceneManifest manifest = *manifest_;
  if (auto checked = check_copy(partial_, manifest); !checked) {
    abandon();
    return Error{"the scene's copy is not whole: " + checked.error()};
  }
  const fs::path copy = folder_ / sha256_;
  std::error_code error;
  fs::rename(partial_, copy, error);
  if (error) {
    // Another node of this machine put the same scene in place first: use it.
    abandon();
    if (auto found = find(manifest, sha256_)) return *found;
    return Error{"cannot put the scene in place at " + copy.string() + ": " + describe(error)};
  }
  verified_ = sha256_;
  manifest_.reset();
  return (copy / manifest.files.front().path).string();
}

void SceneCache::abandon() {
  if (!partial_.empty()) {
    std::error_code ignored;
    fs::remove_all(partial_, ignored);
  }
  partial_.clear();
  manifest_.reset();
}

}  // namespace optique::node
