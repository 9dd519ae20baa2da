#include "scene_load/gltf_source.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include <nlohmann/json.hpp>

#include "scene/relative_path.h"
#include "util/join.h"
#include "util/message_text.h"

namespace optique::scene {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr std::uint32_t kGlbMagic = 0x46546C67;     // "glTF"
constexpr std::uint32_t kJsonChunk = 0x4E4F534A;    // "JSON"
constexpr std::uint32_t kBinaryChunk = 0x004E4942;  // "BIN\0"

Result<std::string> read_file(const fs::path& path) {
  std::error_code error;
  const auto status = fs::status(path, error);
  if (!fs::exists(status)) return Error{"no such file"};
  if (!fs::is_regular_file(status)) return Error{"not a regular file"};
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{std::string("cannot open: ") + std::strerror(errno)};
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return Error{"read error"};
  return bytes;
}

std::uint32_t read_u32(const std::string& bytes, std::size_t at) {
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data() + at);
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

void append_u32(std::string& out, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xFF));
}

struct Glb {
  std::string json;
  std::optional<std::string> binary;  // the BIN chunk's data
};

// A GLB container (glTF 2.0 binary): its JSON chunk and its binary chunk.
Result<Glb> split_glb(const std::string& bytes) {
  if (bytes.size() < 20) return Error{"malformed GLB: " + std::to_string(bytes.size()) + " bytes, too short"};
  if (read_u32(bytes, 0) != kGlbMagic) return Error{"malformed GLB: no 'glTF' magic"};
  if (const std::uint32_t version = read_u32(bytes, 4); version != 2) {
    return Error{"GLB version " + std::to_string(version) + " is not supported (2 only)"};
  }
  const std::uint32_t length = read_u32(bytes, 8);
  if (length > bytes.size()) {
    return Error{"malformed GLB: the header says " + std::to_string(length) + " bytes, the file has " +
                 std::to_string(bytes.size()) + " (truncated?)"};
  }
  Glb glb;
  std::size_t at = 12;
  bool first = true;
  while (at + 8 <= length) {
    const std::uint32_t chunk_length = read_u32(bytes, at);
    const std::uint32_t type = read_u32(bytes, at + 4);
    if (chunk_length > length - at - 8) {
      return Error{"malformed GLB: a chunk at byte " + std::to_string(at) + " runs past the end (truncated?)"};
    }
    const std::string data = bytes.substr(at + 8, chunk_length);
    if (first && type != kJsonChunk) return Error{"malformed GLB: the first chunk is not JSON"};
    if (first) {
      glb.json = data;
    } else if (type == kBinaryChunk && !glb.binary) {
      glb.binary = data;
    }
    first = false;
    at += 8 + chunk_length;
  }
  if (first) return Error{"malformed GLB: no JSON chunk"};
  return glb;
}

std::string join_glb(const std::string& json_text, const std::optional<std::string>& binary) {
  std::string text = json_text;
  while (text.size() % 4 != 0) text.push_back(' ');
  std::string data = binary.value_or("");
  while (data.size() % 4 != 0) data.push_back('\0');
  std::string out;
  append_u32(out, kGlbMagic);
  append_u32(out, 2);
  append_u32(out, static_cast<std::uint32_t>(12 + 8 + text.size() + (binary ? 8 + data.size() : 0)));
  append_u32(out, static_cast<std::uint32_t>(text.size()));
  append_u32(out, kJsonChunk);
  out += text;
  if (binary) {
    append_u32(out, static_cast<std::uint32_t>(data.size()));
    append_u32(out, kBinaryChunk);
    out += data;
  }
  return out;
}

// Whether `file` (which exists) is inside `folder` once links are followed.
bool inside(const fs::path& folder, const fs::path& file) {
  std::error_code error;
  const fs::path real_folder = fs::canonical(folder, error);
  if (error) return false;
  const fs::path real_file = fs::canonical(file, error);
  if (error) return false;
  const fs::path relative = real_file.lexically_relative(real_folder);
  return !relative.empty() && *relative.begin() != "..";
}

class SourceReader {
 public:
  SourceReader(const std::string& path, GltfSource& source) : path_(path), source_(source) {
    folder_ = fs::path(path).parent_path();
    if (folder_.empty()) folder_ = ".";
  }

  // The file referenced by `uri` (element `index` of `kind`): its index in
  // source_.files, or nothing with the problem noted.
  std::optional<std::size_t> reference(const std::string& kind, std::size_t index, const std::string& uri,
                                       std::optional<std::uint64_t> least_bytes) {
    const std::string label = kind + " " + std::to_string(index) + " '" + util::shortened(uri) + "'";
    auto relative = relative_file_of_uri(uri);
    if (!relative) {
      problems_.push_back(label + ": its URI " + relative.error());
      return std::nullopt;
    }
    const auto known = std::find_if(source_.files.begin() + 1, source_.files.end(),
                                    [&](const auto& file) { return file.first == relative.value(); });
    std::size_t found = 0;
    if (known != source_.files.end()) {
      found = static_cast<std::size_t>(known - source_.files.begin());
    } else {
      const fs::path file = folder_ / relative.value();
      std::error_code error;
      if (!fs::exists(file, error)) {
        problems_.push_back(label + ": missing (no file " + file.string() + ")");
        return std::nullopt;
      }
      // Before reading: a link out may lead to anything (a device, a huge file).
      if (!inside(folder_, file)) {
        problems_.push_back(label + ": " + file.string() + " is a link to a file outside the glTF's folder");
        return std::nullopt;
      }
      auto bytes = read_file(file);
      if (!bytes) {
        problems_.push_back(label + ": " + file.string() + ": " + bytes.error());
        return std::nullopt;
      }
      source_.files.emplace_back(relative.value(), std::make_shared<const std::string>(std::move(bytes).value()));
      found = source_.files.size() - 1;
    }
    const std::uint64_t size = source_.files[found].second->size();
    if (least_bytes && size < *least_bytes) {
      problems_.push_back(label + " is truncated: " + std::to_string(size) + " bytes where its byteLength says " +
                          std::to_string(*least_bytes));
    }
    return found;
  }

  void note(std::string problem) { problems_.push_back(std::move(problem)); }

  Result<void> outcome() const {
    if (problems_.empty()) return {};
    std::string message = path_ + ": ";
    for (std::size_t i = 0; i < problems_.size(); ++i) message += (i == 0 ? "" : "; ") + problems_[i];
    return Error{message};
  }

 private:
  std::string path_;
  GltfSource& source_;
  fs::path folder_;
  std::vector<std::string> problems_;
};

std::optional<std::uint64_t> byte_length(const json& element) {
  const auto found = element.find("byteLength");
  if (found == element.end() || !found->is_number_unsigned()) return std::nullopt;
  return found->get<std::uint64_t>();
}

}  // namespace

std::string source_file_name(std::size_t index) { return "optique-file-" + std::to_string(index); }

SceneManifest GltfSource::manifest(std::uint32_t chunk_bytes) const {
  SceneManifest manifest;
  manifest.chunk_bytes = chunk_bytes;
  for (const auto& [name, bytes] : files) manifest.files.push_back(describe_file(name, *bytes, chunk_bytes));
  return manifest;
}

Result<GltfSource> read_gltf_source(const std::string& path, const std::vector<std::string>& supported_required) {
  auto bytes = read_file(path);
  if (!bytes) return Error{path + ": " + bytes.error()};
  if (bytes.value().size() > std::numeric_limits<std::uint32_t>::max()) return Error{path + ": too large for glTF"};

  GltfSource source;
  source.path = path;
  source.binary = bytes.value().size() >= 4 && bytes.value().compare(0, 4, "glTF") == 0;
  std::string json_text;
  std::optional<std::string> glb_binary;
  if (source.binary) {
    auto glb = split_glb(bytes.value());
    if (!glb) return Error{path + ": " + glb.error()};
    json_text = std::move(glb.value().json);
    glb_binary = std::move(glb.value().binary);
  } else {
    json_text = bytes.value();
  }
  const std::string name = fs::path(path).filename().string();
  source.files.emplace_back(name.empty() ? "scene.gltf" : name,
                            std::make_shared<const std::string>(std::move(bytes).value()));

  json doc;
  try {
    doc = json::parse(json_text);
  } catch (const json::parse_error& e) {
    return Error{path + ": malformed glTF: " + util::one_line(e.what())};
  }
  if (!doc.is_object()) return Error{path + ": malformed glTF: the document is not a JSON object"};

  // Required extensions first: a file that needs what we cannot draw is refused
  // as such, not for what that extension changes elsewhere.
  if (const auto required = doc.find("extensionsRequired"); required != doc.end()) {
    if (!required->is_array()) return Error{path + ": malformed glTF: extensionsRequired is not an array"};
    std::vector<std::string> unsupported;
    for (const json& extension : *required) {
      const std::string name_of = extension.is_string() ? extension.get<std::string>() : extension.dump();
      if (std::find(supported_required.begin(), supported_required.end(), name_of) == supported_required.end()) {
        unsupported.push_back(util::shortened(name_of));
      }
    }
    if (!unsupported.empty()) {
      return Error{path + ": requires " + (unsupported.size() == 1 ? "an extension" : "extensions") +
                   " that optique cannot draw: " + util::joined(unsupported) + " (it reads " +
                   util::joined(supported_required) + ")"};
    }
  }

  SourceReader reader(path, source);
  bool changed = false;
  if (const auto buffers = doc.find("buffers"); buffers != doc.end() && buffers->is_array()) {
    source.buffer_file.resize(buffers->size());
    for (std::size_t i = 0; i < buffers->size(); ++i) {
      json& buffer = (*buffers)[i];
      if (!buffer.is_object()) continue;  // tinygltf says what is wrong with it
      const auto uri = buffer.find("uri");
      if (uri == buffer.end() || !uri->is_string()) {
        if (source.binary && i == 0 && glb_binary) {
          if (const auto length = byte_length(buffer); length && glb_binary->size() < *length) {
            reader.note("buffer 0 (the GLB's binary chunk) is truncated: " + std::to_string(glb_binary->size()) +
                        " bytes where its byteLength says " + std::to_string(*length));
          }
        }
        continue;
      }
      const std::string text = uri->get<std::string>();
      if (is_data_uri(text)) continue;
      source.buffer_file[i] = reader.reference("buffer", i, text, byte_length(buffer));
      if (source.buffer_file[i]) {
        buffer["uri"] = source_file_name(*source.buffer_file[i]);
        changed = true;
      }
    }
  }
  if (const auto images = doc.find("images"); images != doc.end() && images->is_array()) {
    source.image_file.resize(images->size());
    for (std::size_t i = 0; i < images->size(); ++i) {
      const json& image = (*images)[i];
      if (!image.is_object()) continue;
      const auto uri = image.find("uri");
      if (uri == image.end() || !uri->is_string() || is_data_uri(uri->get<std::string>())) continue;
      source.image_file[i] = reader.reference("image", i, uri->get<std::string>(), std::nullopt);
    }
  }
  if (auto checked = reader.outcome(); !checked) return Error{checked.error()};

  if (const auto meshes = doc.find("meshes"); meshes != doc.end() && meshes->is_array()) {
    for (std::size_t m = 0; m < meshes->size(); ++m) {
      json& mesh = (*meshes)[m];
      const auto primitives = mesh.is_object() ? mesh.find("primitives") : mesh.end();
      if (!mesh.is_object() || primitives == mesh.end() || !primitives->is_array()) continue;
      for (std::size_t p = 0; p < primitives->size(); ++p) {
        json& primitive = (*primitives)[p];
        if (!primitive.is_object()) continue;
        const auto extensions = primitive.find("extensions");
        if (extensions == primitive.end() || !extensions->is_object() || !extensions->contains(kDracoExtension)) {
          continue;
        }
        // -1: none; an index no accessor has is kept as one, for the loader to refuse.
        std::int64_t indices = -1;
        if (const auto found = primitive.find("indices"); found != primitive.end()) {
          indices = found->is_number_integer()
                        ? std::clamp<std::int64_t>(found->get<std::int64_t>(), -2, std::numeric_limits<int>::max())
                        : -2;
          primitive.erase("indices");
          changed = true;
        }
        source.draco_indices[{m, p}] = indices;
      }
    }
  }

  if (!changed) {
    source.document = source.binary ? *source.files[0].second : json_text;
  } else {
    const std::string text = doc.dump();
    source.document = source.binary ? join_glb(text, glb_binary) : text;
  }
  return source;
}

}  // namespace optique::scene
