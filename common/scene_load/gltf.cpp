#include "scene_load/gltf.h"

#include <exception>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "scene_load/draco_primitive.h"
#include "scene_load/gltf_error.h"
#include "scene_load/gltf_loader.h"
#include "scene_load/gltf_source.h"
#include "scene_load/tinygltf.h"
#include "util/message_text.h"

namespace optique::scene {
namespace {

// Extensions a file may require: we read the first and the third, and the
// second only scales a factor we read.
const std::vector<std::string> kSupportedRequiredExtensions{"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                                            kDracoExtension};

// ---------------------------------------------------------------------------
// File access for tinygltf: only the files scene_load/gltf_source.h read, by the
// names it gave their buffers (source_file_name) in the folder kSourceFolder.

std::optional<std::size_t> source_index(const std::string& path, const GltfSource& source) {
  const std::string prefix = std::string(kSourceFolder) + "/";
  if (!path.starts_with(prefix)) return std::nullopt;
  for (std::size_t i = 1; i < source.files.size(); ++i) {
    if (path.compare(prefix.size(), std::string::npos, source_file_name(i)) == 0) return i;
  }
  return std::nullopt;
}

bool fs_file_exists(const std::string& path, void* user) {
  return source_index(path, *static_cast<const GltfSource*>(user)).has_value();
}

std::string fs_expand_path(const std::string& path, void*) { return path; }

bool fs_read_whole_file(std::vector<unsigned char>* out, std::string* error, const std::string& path, void* user) {
  const auto& source = *static_cast<const GltfSource*>(user);
  const auto index = source_index(path, source);
  if (!index) {
    if (error != nullptr) *error = "not a file the glTF references";
    return false;
  }
  const std::string& bytes = *source.files[*index].second;
  out->assign(bytes.begin(), bytes.end());
  return true;
}

bool fs_write_whole_file(std::string* error, const std::string&, const std::vector<unsigned char>&, void*) {
  if (error != nullptr) *error = "writing is disabled";
  return false;
}

// tinygltf hands over every image's encoded bytes while parsing. Decoding
// waits until a material uses the image as its base colour (normal maps and the
// like are never decoded), so an image embedded as a data URI keeps its encoded
// bytes in Image::image (width and height stay 0) until then; an image in a
// buffer view is read from its buffer then, with bounds checks. Never fails: an
// image that cannot be decoded costs a warning, not the load.
bool keep_encoded_image(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                        const unsigned char* bytes, int size, void*) {
  if (image->bufferView < 0 && bytes != nullptr && size > 0) {
    image->image.assign(bytes, bytes + size);
  }
  return true;
}

using util::one_line;
using util::shortened;

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) lines.push_back(shortened(line));
  }
  return lines;
}

Result<LoadedGltf> load(const std::string& path, const ImageDecoder& decode) {
  auto read = read_gltf_source(path, kSupportedRequiredExtensions);
  if (!read) return Error{read.error()};
  const GltfSource& source = read.value();

  tinygltf::TinyGLTF reader;
  reader.SetImageLoader(&keep_encoded_image, nullptr);
  reader.SetFsCallbacks(
      {&fs_file_exists, &fs_expand_path, &fs_read_whole_file, &fs_write_whole_file, const_cast<GltfSource*>(&source)});
  tinygltf::Model model;
  std::string load_error;
  std::string load_warning;
  const auto* bytes = reinterpret_cast<const unsigned char*>(source.document.data());
  const auto size = static_cast<unsigned int>(source.document.size());
  const bool loaded =
      source.binary
          ? reader.LoadBinaryFromMemory(&model, &load_error, &load_warning, bytes, size, kSourceFolder)
          : reader.LoadASCIIFromString(&model, &load_error, &load_warning, source.document.data(), size, kSourceFolder);
  if (!loaded) return Error{path + ": malformed glTF: " + one_line(load_error.empty() ? "unknown error" : load_error)};

  LoadedGltf loaded_gltf;
  for (const auto& line : lines_of(load_warning)) loaded_gltf.warnings.push_back(path + ": " + line);
  Loader loader(source, model, decode, loaded_gltf.warnings);
  loaded_gltf.scene = loader.build();
  loaded_gltf.manifest = source.manifest();
  // As every node will check it: a file name a node would refuse is refused here.
  if (auto sendable = check_manifest(loaded_gltf.manifest, kLargestScene); !sendable) {
    return Error{path + ": " + sendable.error()};
  }
  loaded_gltf.content_sha256 = manifest_sha256(loaded_gltf.manifest);
  for (const auto& file : source.files) loaded_gltf.files.push_back(file.second);
  return loaded_gltf;
}

}  // namespace

Result<LoadedGltf> load_gltf(const std::string& path, const ImageDecoder& decode) {
  try {
    return load(path, decode);
  } catch (const GltfError& e) {
    return Error{e.what()};
  } catch (const std::exception& e) {
    return Error{path + ": " + e.what()};
  }
}

}  // namespace optique::scene
