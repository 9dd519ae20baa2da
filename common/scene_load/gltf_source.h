#pragma once
// A glTF file and every file it references, read and checked before tinygltf
// parses anything (scene_load/gltf.cpp then builds the scene from it):
// - required extensions that optique cannot draw are refused first, all named
//   in one message;
// - each buffer and image URI that is not a data: URI must name a file inside
//   the glTF's own folder (scene/relative_path.h: no '..', no absolute path, no
//   scheme, no link leading out), which must exist and, for a buffer, hold its
//   byteLength; every such problem is listed at once;
// - the files are read once, here: what is parsed, hashed (scene/manifest.h)
//   and sent to nodes are the same bytes, even if a file changes meanwhile.
// What tinygltf gets is the document with each external buffer's URI replaced
// by a name only this reader answers to, and the indices of Draco-compressed
// primitives set aside (tinygltf would want a buffer view for them; they are in
// the compressed data).

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "scene/manifest.h"
#include "util/result.h"

namespace optique::scene {

inline constexpr char kDracoExtension[] = "KHR_draco_mesh_compression";

struct GltfSource {
  std::string path;  // as given, for messages
  // [0] the glTF itself, then each referenced file once, in order of first
  // reference (buffers, then images); bytes shared with whoever keeps them.
  std::vector<std::pair<std::string, std::shared_ptr<const std::string>>> files;
  std::string document;  // what tinygltf parses: JSON text, or a whole GLB
  bool binary = false;
  std::vector<std::optional<std::size_t>> buffer_file;  // per buffer: its file, if external
  std::vector<std::optional<std::size_t>> image_file;   // per image: its file, if external
  // (mesh, primitive) → the indices accessor of a Draco-compressed primitive
  // (-1: none; -2: not a valid index, refused when the primitive is read).
  std::map<std::pair<std::size_t, std::size_t>, std::int64_t> draco_indices;

  [[nodiscard]] SceneManifest manifest(std::uint32_t chunk_bytes = kSceneChunkBytes) const;
};

// The name tinygltf is given for file `index` (a buffer's URI), and the folder
// it is looked for in.
inline constexpr char kSourceFolder[] = "optique-source";
[[nodiscard]] std::string source_file_name(std::size_t index);

// Reads `path` and what it references; `supported_required`: the extensions a
// file may require. Every error message starts with `path`.
[[nodiscard]] Result<GltfSource> read_gltf_source(const std::string& path,
                                                  const std::vector<std::string>& supported_required);

}  // namespace optique::scene
