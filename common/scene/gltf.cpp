#include "scene/gltf.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec4.hpp>

#include "scene/draco_primitive.h"
#include "scene/gltf_source.h"
#include "util/finite.h"
#include "util/message_text.h"
#include "util/sha256.h"

// TinyGLTF's implementation lives here (Debian ships a shared library too, but
// building it in keeps the link line as it is). It uses nlohmann/json; tinygltf
// decodes no images itself (no stb_image: base colour images go to the caller's
// ImageDecoder) and reads no external image files.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

namespace optique::scene {
namespace {

// glTF point lights are in candela; our scenes are not photometric: a light's
// irradiance is colour·intensity / r² in the renderer's own units, and the
// built-in scenes use intensities of about 1 to 3. So 100 cd ↦ 1.
constexpr double kCandelaToIntensity = 1.0 / 100.0;

// Extensions a file may require: we read the first and the third, and the
// second only scales a factor we read.
const std::vector<std::string> kSupportedRequiredExtensions{"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                                            kDracoExtension};

// Thrown inside the loader, caught in load_gltf: the message already starts with
// the path.
class GltfError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// ---------------------------------------------------------------------------
// File access for tinygltf: only the files scene/gltf_source.h read, by the
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

// ---------------------------------------------------------------------------
// Small helpers.

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

std::string labelled(const std::string& kind, std::size_t index, const std::string& name) {
  std::string label = kind + " " + std::to_string(index);
  if (!name.empty()) label += " '" + name + "'";
  return label;
}

std::string type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "type " + std::to_string(type);
  }
}

std::string component_type_name(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_INT:
      return "INT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return "FLOAT";
    case TINYGLTF_COMPONENT_TYPE_DOUBLE:
      return "DOUBLE";
    default:
      return "component type " + std::to_string(component_type);
  }
}

std::size_t component_count(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    case TINYGLTF_TYPE_MAT2:
      return 4;
    case TINYGLTF_TYPE_MAT3:
      return 9;
    case TINYGLTF_TYPE_MAT4:
      return 16;
    default:
      return 0;
  }
}

std::size_t component_size(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

// One component at `p`, as a double; normalized integers map to [0, 1] or [−1, 1].
double read_component(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float v = 0.0f;
      std::memcpy(&v, p, sizeof v);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      const std::uint8_t v = *p;
      return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      std::int8_t v = 0;
      std::memcpy(&v, p, sizeof v);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t v = 0;
      std::memcpy(&v, p, sizeof v);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t v = 0;
      std::memcpy(&v, p, sizeof v);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      std::uint32_t v = 0;
      std::memcpy(&v, p, sizeof v);
      return v;
    }
    default:
      return 0.0;
  }
}

using util::finite;

bool finite(const Pose& pose) { return finite(pose.position) && finite(pose.scale) && finite(pose.rotation); }

glm::dquat canonical(glm::dquat q) {
  q = glm::normalize(q);
  if (q.w < 0.0) q = -q;
  return q;
}

// The rotation taking unit vector `from` to unit vector `to`.
glm::dquat rotation_between(const glm::dvec3& from, const glm::dvec3& to) {
  const double d = glm::dot(from, to);
  if (d < -1.0 + 1e-12) {
    const glm::dvec3 other = std::abs(from.x) < 0.9 ? glm::dvec3(1.0, 0.0, 0.0) : glm::dvec3(0.0, 1.0, 0.0);
    return glm::angleAxis(std::numbers::pi, glm::normalize(glm::cross(from, other)));
  }
  const glm::dvec3 c = glm::cross(from, to);
  return glm::normalize(glm::dquat(1.0 + d, c.x, c.y, c.z));
}

// The pose whose model matrix is `m`, assuming `m` has no shear. A negative
// determinant becomes a negative x scale; an axis scaled to 0 takes its
// direction from the other two, or, where only one is left, the rotation is the
// shortest one onto that one.
Pose decompose(const glm::dmat4& m) {
  Pose pose;
  pose.position = glm::dvec3(m[3]);
  glm::dvec3 axes[3] = {glm::dvec3(m[0]), glm::dvec3(m[1]), glm::dvec3(m[2])};
  glm::dvec3 scale(glm::length(axes[0]), glm::length(axes[1]), glm::length(axes[2]));
  if (glm::dot(axes[0], glm::cross(axes[1], axes[2])) < 0.0) scale.x = -scale.x;
  const double largest = std::max({std::abs(scale.x), std::abs(scale.y), std::abs(scale.z)});
  const double tiny = 1e-12 * largest;
  int collapsed = -1;
  int collapsed_count = 0;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(scale[i]) > tiny && largest > 0.0) {
      axes[i] /= scale[i];
    } else {
      collapsed = i;
      ++collapsed_count;
    }
  }
  if (collapsed_count == 1) {
    const auto& a = axes[(collapsed + 1) % 3];
    const auto& b = axes[(collapsed + 2) % 3];
    axes[collapsed] = glm::normalize(glm::cross(a, b));
  }
  if (collapsed_count <= 1) {
    pose.rotation = canonical(glm::quat_cast(glm::dmat3(axes[0], axes[1], axes[2])));
  } else if (collapsed_count == 2) {
    for (int i = 0; i < 3; ++i) {
      if (std::abs(scale[i]) > tiny && largest > 0.0) {
        glm::dvec3 unit(0.0);
        unit[i] = 1.0;
        pose.rotation = canonical(rotation_between(unit, glm::normalize(axes[i])));
      }
    }
  }
  pose.scale = scale;
  return pose;
}

// Whether `pose` reproduces `m`: the same linear part (to a millionth of its
// largest element: no shear) and an affine bottom row.
bool reproduces(const Pose& pose, const glm::dmat4& m) {
  const glm::dmat4 back = model_matrix(pose);
  double largest = 0.0;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) largest = std::max(largest, std::abs(m[c][r]));
  }
  const double tolerance = 1e-6 * largest;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) {
      if (!(std::abs(back[c][r] - m[c][r]) <= tolerance)) return false;
    }
  }
  for (int c = 0; c < 4; ++c) {
    if (!(std::abs(m[c][3] - (c == 3 ? 1.0 : 0.0)) <= 1e-9)) return false;
  }
  return true;
}

// ---------------------------------------------------------------------------
// Animation data, self-contained so that pose_at can own a copy.

enum class Interpolation { kStep, kLinear, kCubicSpline };

struct Sampler {
  Interpolation interpolation = Interpolation::kLinear;
  bool rotation = false;       // quaternions (x, y, z, w), else 3-vectors
  std::vector<double> times;   // strictly increasing
  std::vector<double> values;  // per key one element, or in-tangent, value, out-tangent for cubic splines

  [[nodiscard]] std::size_t width() const { return rotation ? 4 : 3; }

  [[nodiscard]] glm::dvec4 element(std::size_t i) const {
    const double* v = values.data() + i * width();
    return {v[0], v[1], v[2], rotation ? v[3] : 0.0};
  }

  [[nodiscard]] glm::dvec4 key(std::size_t k) const {
    return element(interpolation == Interpolation::kCubicSpline ? 3 * k + 1 : k);
  }

  // The value at `t`: before the first key the first value, after the last the
  // last. Quaternions come back unit length.
  [[nodiscard]] glm::dvec4 at(double t) const {
    const std::size_t n = times.size();
    if (n == 1 || t <= times.front()) return key(0);
    if (t >= times.back()) return key(n - 1);
    const auto upper = std::upper_bound(times.begin(), times.end(), t);
    const auto k = static_cast<std::size_t>(upper - times.begin()) - 1;  // times[k] <= t < times[k + 1]
    const double span = times[k + 1] - times[k];
    const double u = (t - times[k]) / span;
    switch (interpolation) {
      case Interpolation::kStep:
        return key(k);
      case Interpolation::kLinear: {
        if (!rotation) return glm::mix(key(k), key(k + 1), u);
        const glm::dvec4 a = key(k);
        const glm::dvec4 b = key(k + 1);
        const glm::dquat q =
            glm::normalize(glm::slerp(glm::dquat(a.w, a.x, a.y, a.z), glm::dquat(b.w, b.x, b.y, b.z), u));
        return {q.x, q.y, q.z, q.w};
      }
      case Interpolation::kCubicSpline: {
        const double u2 = u * u;
        const double u3 = u2 * u;
        const glm::dvec4 value =
            (2.0 * u3 - 3.0 * u2 + 1.0) * element(3 * k + 1) + (u3 - 2.0 * u2 + u) * span * element(3 * k + 2) +
            (-2.0 * u3 + 3.0 * u2) * element(3 * (k + 1) + 1) + (u3 - u2) * span * element(3 * (k + 1));
        if (!rotation) return value;
        const double length = glm::length(value);
        if (!(length > 1e-12) || !std::isfinite(length)) return u < 0.5 ? key(k) : key(k + 1);
        return value / length;
      }
    }
    return key(k);
  }
};

// A node's local transform: fixed, or translation/rotation/scale with any of
// them animated.
struct Link {
  bool animated = false;
  glm::dmat4 fixed{1.0};
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
  glm::dvec3 scale{1.0};
  std::optional<Sampler> translation_track;
  std::optional<Sampler> rotation_track;
  std::optional<Sampler> scale_track;

  [[nodiscard]] glm::dmat4 local_at(double t) const {
    if (!animated) return fixed;
    glm::dvec3 position = translation;
    glm::dquat turn = rotation;
    glm::dvec3 size = scale;
    if (translation_track) position = glm::dvec3(translation_track->at(t));
    if (rotation_track) {
      const glm::dvec4 q = rotation_track->at(t);
      turn = glm::dquat(q.w, q.x, q.y, q.z);
    }
    if (scale_track) size = glm::dvec3(scale_track->at(t));
    return glm::translate(glm::dmat4(1.0), position) * glm::mat4_cast(turn) * glm::scale(glm::dmat4(1.0), size);
  }

  // The key times of its tracks.
  void key_times(std::vector<double>& out) const {
    for (const auto* track : {&translation_track, &rotation_track, &scale_track}) {
      if (*track) out.insert(out.end(), (*track)->times.begin(), (*track)->times.end());
    }
  }
};

// Everything an animated object's pose needs: the world matrix of its nearest
// static ancestor and the local transforms from there down to the node.
struct Track {
  glm::dmat4 base{1.0};
  std::vector<Link> links;
  double duration = 0.0;  // all animations loop over this
  Pose fallback;          // the pose at t = 0, checked finite at load

  [[nodiscard]] double wrap(double t) const {
    if (!std::isfinite(t) || !(duration > 0.0)) return 0.0;
    double local = std::fmod(t, duration);
    if (local < 0.0) local += duration;
    if (!(local < duration) || local < 0.0) local = 0.0;
    return local;
  }

  [[nodiscard]] glm::dmat4 world_at(double local_time) const {
    glm::dmat4 world = base;
    for (const auto& link : links) world = world * link.local_at(local_time);
    return world;
  }

  [[nodiscard]] Pose pose_at(double t) const {
    const Pose pose = decompose(world_at(wrap(t)));
    return finite(pose) ? pose : fallback;
  }
};

// ---------------------------------------------------------------------------

class Loader {
 public:
  Loader(const GltfSource& source, const tinygltf::Model& model, const ImageDecoder& decode,
         std::vector<std::string>& warnings)
      : path_(source.path), source_(source), model_(model), decode_(decode), warnings_(warnings) {}

  SceneDefinition build() {
    check_version();
    check_skins();
    read_animations();
    walk_scene();
    read_links();
    SceneDefinition scene;
    scene.name = scene_name();
    add_instances(scene);
    add_lights(scene);
    return scene;
  }

 private:
  struct Part {
    std::uint32_t mesh = 0;
    std::uint32_t material = 0;
  };

  [[noreturn]] void fail(const std::string& what) const { throw GltfError(path_ + ": " + what); }
  void warn(const std::string& what) { warnings_.push_back(path_ + ": " + what); }

  std::string node_label(std::size_t index) const { return labelled("node", index, model_.nodes[index].name); }

  // --- checks on the whole file

  void check_version() const {
    const auto& version = model_.asset.version;
    if (!version.starts_with("2.")) fail("glTF version '" + version + "' is not supported (2.x only)");
  }

  void check_skins() const {
    if (!model_.skins.empty()) fail("skinned meshes are not supported (the file has skins)");
    for (std::size_t i = 0; i < model_.nodes.size(); ++i) {
      if (model_.nodes[i].skin >= 0) fail("skinned meshes are not supported (" + node_label(i) + " has a skin)");
    }
  }

  // --- accessors

  struct Located {
    const unsigned char* data = nullptr;
    std::size_t stride = 0;
    std::size_t count = 0;
  };

  std::string accessor_label(int index, const std::string& what) const {
    return "accessor " + std::to_string(index) + " (" + what + ")";
  }

  const tinygltf::Accessor& accessor(int index, const std::string& what) const {
    if (index < 0 || static_cast<std::size_t>(index) >= model_.accessors.size()) {
      fail(accessor_label(index, what) + " is out of range: the file has " + std::to_string(model_.accessors.size()) +
           " accessors");
    }
    return model_.accessors[static_cast<std::size_t>(index)];
  }

  // The bytes of buffer view `index` (for `label`), after checking that the view
  // and its buffer exist and that the view lies inside the buffer.
  std::span<const unsigned char> view_bytes(int index, const std::string& label) const {
    const std::string view_label = "buffer view " + std::to_string(index);
    if (index < 0 || static_cast<std::size_t>(index) >= model_.bufferViews.size()) {
      fail(label + ": " + view_label + " is out of range");
    }
    const auto& view = model_.bufferViews[static_cast<std::size_t>(index)];
    if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model_.buffers.size()) {
      fail(label + ": " + view_label + " names buffer " + std::to_string(view.buffer) + ", which is out of range");
    }
    const auto& buffer = model_.buffers[static_cast<std::size_t>(view.buffer)];
    if (view.byteOffset > buffer.data.size() || view.byteLength > buffer.data.size() - view.byteOffset) {
      fail(label + ": " + view_label + " (bytes " + std::to_string(view.byteOffset) + " + " +
           std::to_string(view.byteLength) + ") is out of range of buffer " + std::to_string(view.buffer) + " (" +
           std::to_string(buffer.data.size()) + " bytes)");
    }
    return {buffer.data.data() + view.byteOffset, view.byteLength};
  }

  // Where the elements of accessor `index` are, each `element_size` bytes, after
  // checking that all of them lie inside their buffer view and buffer.
  Located locate(int index, const std::string& what, std::size_t element_size) const {
    const auto& acc = accessor(index, what);
    const std::string label = accessor_label(index, what);
    if (acc.sparse.isSparse) fail(label + ": sparse accessors are not supported");
    if (acc.count == 0) return {};
    if (acc.bufferView < 0) fail(label + ": accessors without a buffer view are not supported");
    const std::span<const unsigned char> bytes = view_bytes(acc.bufferView, label);
    const auto& view = model_.bufferViews[static_cast<std::size_t>(acc.bufferView)];
    const std::string view_label = "buffer view " + std::to_string(acc.bufferView);
    const std::size_t stride = view.byteStride != 0 ? view.byteStride : element_size;
    if (stride < element_size) {
      fail(label + ": byteStride " + std::to_string(stride) + " is smaller than an element (" +
           std::to_string(element_size) + " bytes)");
    }
    if (acc.byteOffset > view.byteLength || element_size > view.byteLength - acc.byteOffset ||
        (acc.count - 1) > (view.byteLength - acc.byteOffset - element_size) / stride) {
      fail(label + ": " + std::to_string(acc.count) + " elements from byte " + std::to_string(acc.byteOffset) +
           " are out of range of " + view_label + " (" + std::to_string(view.byteLength) + " bytes)");
    }
    return {bytes.data() + acc.byteOffset, stride, acc.count};
  }

  // The components of accessor `index`, which must be of `type` and FLOAT (or,
  // where `normalized_ok`, normalized integers), all finite.
  std::vector<double> read_floats(int index, const std::string& what, int type, bool normalized_ok = false) const {
    const auto& acc = accessor(index, what);
    const std::string label = accessor_label(index, what);
    if (acc.type != type) fail(label + " must be " + type_name(type) + ", not " + type_name(acc.type));
    const bool is_float = acc.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
    const bool normalized_int = normalized_ok && acc.normalized &&
                                (acc.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
                                 acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                 acc.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
                                 acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
    if (!is_float && !normalized_int) {
      fail(label + ": component type " + component_type_name(acc.componentType) +
           (acc.normalized ? " (normalized)" : "") + " is not supported here (FLOAT only" +
           (normalized_ok ? ", or normalized integers" : "") + ")");
    }
    const std::size_t components = component_count(type);
    const std::size_t size = component_size(acc.componentType);
    const Located where = locate(index, what, components * size);
    std::vector<double> out;
    out.reserve(where.count * components);
    for (std::size_t i = 0; i < where.count; ++i) {
      const unsigned char* element = where.data + i * where.stride;
      for (std::size_t c = 0; c < components; ++c) {
        const double v = read_component(element + c * size, acc.componentType, acc.normalized);
        if (!std::isfinite(v)) fail(label + ": element " + std::to_string(i) + " is not a finite number");
        out.push_back(v);
      }
    }
    return out;
  }

  std::vector<std::uint32_t> read_indices(int index, const std::string& what) const {
    const auto& acc = accessor(index, what);
    const std::string label = accessor_label(index, what);
    if (acc.type != TINYGLTF_TYPE_SCALAR) fail(label + " must be SCALAR, not " + type_name(acc.type));
    if (acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
      fail(label + ": component type " + component_type_name(acc.componentType) +
           " is not an index type (UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT)");
    }
    const Located where = locate(index, what, component_size(acc.componentType));
    std::vector<std::uint32_t> out;
    out.reserve(where.count);
    for (std::size_t i = 0; i < where.count; ++i) {
      out.push_back(
          static_cast<std::uint32_t>(read_component(where.data + i * where.stride, acc.componentType, false)));
    }
    return out;
  }

  // --- animations

  void read_animations() {
    for (std::size_t a = 0; a < model_.animations.size(); ++a) {
      const auto& animation = model_.animations[a];
      const std::string animation_label = labelled("animation", a, animation.name);
      for (std::size_t c = 0; c < animation.channels.size(); ++c) {
        const auto& channel = animation.channels[c];
        const std::string label = animation_label + " channel " + std::to_string(c);
        if (channel.target_path == "weights") fail(label + ": morph targets are not supported (it animates weights)");
        if (channel.target_path != "translation" && channel.target_path != "rotation" &&
            channel.target_path != "scale") {
          fail(label + ": animating '" + channel.target_path + "' is not supported");
        }
        if (channel.target_node < 0) {
          warn(label + " has no target node; ignored");
          continue;
        }
        if (static_cast<std::size_t>(channel.target_node) >= model_.nodes.size()) {
          fail(label + ": target node " + std::to_string(channel.target_node) + " is out of range");
        }
        if (channel.sampler < 0 || static_cast<std::size_t>(channel.sampler) >= animation.samplers.size()) {
          fail(label + ": sampler " + std::to_string(channel.sampler) + " is out of range");
        }
        const auto& source = animation.samplers[static_cast<std::size_t>(channel.sampler)];
        const std::string sampler_label = animation_label + " sampler " + std::to_string(channel.sampler);
        Sampler sampler = read_sampler(source, sampler_label, channel.target_path == "rotation");
        duration_ = std::max(duration_, sampler.times.back());

        auto& tracks = channels_[static_cast<std::size_t>(channel.target_node)];
        auto& slot = channel.target_path == "translation" ? tracks.translation
                     : channel.target_path == "rotation"  ? tracks.rotation
                                                          : tracks.scale;
        if (slot) {
          warn(node_label(static_cast<std::size_t>(channel.target_node)) + ": several channels animate its " +
               channel.target_path + "; the first one is used");
          continue;
        }
        slot = std::move(sampler);
      }
    }
  }

  Sampler read_sampler(const tinygltf::AnimationSampler& source, const std::string& label, bool rotation) const {
    Sampler sampler;
    sampler.rotation = rotation;
    if (source.interpolation == "LINEAR" || source.interpolation.empty()) {
      sampler.interpolation = Interpolation::kLinear;
    } else if (source.interpolation == "STEP") {
      sampler.interpolation = Interpolation::kStep;
    } else if (source.interpolation == "CUBICSPLINE") {
      sampler.interpolation = Interpolation::kCubicSpline;
    } else {
      fail(label + ": interpolation '" + source.interpolation + "' is not supported");
    }
    sampler.times = read_floats(source.input, label + " input", TINYGLTF_TYPE_SCALAR);
    if (sampler.times.empty()) fail(label + ": the input has no key times");
    for (std::size_t k = 1; k < sampler.times.size(); ++k) {
      if (!(sampler.times[k] > sampler.times[k - 1])) {
        fail(label + ": input times must increase (key " + std::to_string(k) + ")");
      }
    }
    sampler.values = read_floats(source.output, label + " output", rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3,
                                 /*normalized_ok=*/rotation);
    const std::size_t per_key = sampler.interpolation == Interpolation::kCubicSpline ? 3 : 1;
    const std::size_t expected = sampler.times.size() * per_key;
    if (sampler.values.size() != expected * sampler.width()) {
      fail(label + ": the output has " + std::to_string(sampler.values.size() / sampler.width()) + " elements where " +
           std::to_string(expected) + " were expected");
    }
    if (rotation) {
      // Key values must be unit quaternions; make them exactly so (tangents stay).
      for (std::size_t k = 0; k < sampler.times.size(); ++k) {
        double* q = sampler.values.data() + (k * per_key + (per_key == 3 ? 1 : 0)) * 4;
        const double length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        if (!(length > 1e-6) || !std::isfinite(length)) {
          fail(label + ": rotation key " + std::to_string(k) + " is not a unit quaternion");
        }
        for (int i = 0; i < 4; ++i) q[i] /= length;
      }
    }
    return sampler;
  }

  // --- the node hierarchy

  void walk_scene() {
    std::vector<int> roots;
    if (model_.defaultScene >= 0 || !model_.scenes.empty()) {
      const int chosen = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      if (static_cast<std::size_t>(chosen) >= model_.scenes.size()) {
        fail("scene " + std::to_string(chosen) + " is out of range");
      }
      scene_index_ = chosen;
      roots = model_.scenes[static_cast<std::size_t>(chosen)].nodes;
    } else {
      std::vector<bool> is_child(model_.nodes.size(), false);
      for (const auto& node : model_.nodes) {
        for (int child : node.children) {
          if (child >= 0 && static_cast<std::size_t>(child) < model_.nodes.size()) {
            is_child[static_cast<std::size_t>(child)] = true;
          }
        }
      }
      for (std::size_t i = 0; i < model_.nodes.size(); ++i) {
        if (!is_child[i]) roots.push_back(static_cast<int>(i));
      }
      if (!roots.empty()) warn("the file has no scene; drawing every root node");
    }

    parent_.assign(model_.nodes.size(), -1);
    std::vector<bool> seen(model_.nodes.size(), false);
    // Depth first, parents before children, without recursion.
    std::vector<std::pair<int, int>> stack;  // node, parent
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, -1);
    while (!stack.empty()) {
      const auto [node, parent] = stack.back();
      stack.pop_back();
      if (node < 0 || static_cast<std::size_t>(node) >= model_.nodes.size()) {
        fail("node " + std::to_string(node) + " is out of range" +
             (parent >= 0 ? " (a child of " + node_label(static_cast<std::size_t>(parent)) + ")" : ""));
      }
      const auto index = static_cast<std::size_t>(node);
      if (seen[index]) {
        fail(node_label(index) + " is reached twice: the node hierarchy has a cycle or a shared child");
      }
      seen[index] = true;
      parent_[index] = parent;
      order_.push_back(index);
      const auto& children = model_.nodes[index].children;
      for (auto it = children.rbegin(); it != children.rend(); ++it) stack.emplace_back(*it, node);
    }

    animated_.assign(model_.nodes.size(), false);
    for (std::size_t index : order_) {
      const bool targeted = channels_.contains(index);
      animated_[index] = targeted || (parent_[index] >= 0 && animated_[static_cast<std::size_t>(parent_[index])]);
    }
  }

  std::vector<double> checked(const std::vector<double>& values, std::size_t size, const std::string& what,
                              std::size_t node) const {
    if (values.size() != size) {
      fail(node_label(node) + ": " + what + " must have " + std::to_string(size) + " numbers, not " +
           std::to_string(values.size()));
    }
    for (double v : values) {
      if (!std::isfinite(v)) fail(node_label(node) + ": " + what + " is not finite");
    }
    return values;
  }

  // Every node's local transform; the animated ones with their tracks.
  void read_links() {
    links_.resize(model_.nodes.size());
    world0_.assign(model_.nodes.size(), glm::dmat4(1.0));
    for (std::size_t index : order_) {
      const auto& node = model_.nodes[index];
      Link& link = links_[index];
      const auto tracks = channels_.find(index);
      if (!node.matrix.empty()) {
        if (tracks != channels_.end()) {
          fail(node_label(index) +
               " has a matrix and is animated; glTF allows only translation, rotation and scale "
               "on animated nodes");
        }
        const auto m = checked(node.matrix, 16, "matrix", index);
        for (int c = 0; c < 4; ++c) {
          for (int r = 0; r < 4; ++r) link.fixed[c][r] = m[static_cast<std::size_t>(4 * c + r)];
        }
      } else {
        if (!node.translation.empty()) {
          const auto t = checked(node.translation, 3, "translation", index);
          link.translation = {t[0], t[1], t[2]};
        }
        if (!node.rotation.empty()) {
          const auto q = checked(node.rotation, 4, "rotation", index);
          const glm::dquat rotation(q[3], q[0], q[1], q[2]);
          const double length = glm::length(rotation);
          if (!(length > 1e-6)) fail(node_label(index) + ": rotation is not a unit quaternion");
          link.rotation = rotation / length;
        }
        if (!node.scale.empty()) {
          const auto s = checked(node.scale, 3, "scale", index);
          link.scale = {s[0], s[1], s[2]};
        }
        link.fixed = glm::translate(glm::dmat4(1.0), link.translation) * glm::mat4_cast(link.rotation) *
                     glm::scale(glm::dmat4(1.0), link.scale);
        if (tracks != channels_.end()) {
          link.animated = true;
          link.translation_track = tracks->second.translation;
          link.rotation_track = tracks->second.rotation;
          link.scale_track = tracks->second.scale;
        }
      }
      const glm::dmat4 parent =
          parent_[index] >= 0 ? world0_[static_cast<std::size_t>(parent_[index])] : glm::dmat4(1.0);
      world0_[index] = parent * link.local_at(0.0);
      if (!finite(world0_[index])) fail(node_label(index) + ": its world transform is not finite");
    }
  }

  // The track of an animated node: its nearest static ancestor's world matrix and
  // the links from the topmost animated ancestor down to it.
  Track track_of(std::size_t index) const {
    Track track;
    track.duration = duration_;
    std::vector<std::size_t> chain;
    int at = static_cast<int>(index);
    while (at >= 0 && animated_[static_cast<std::size_t>(at)]) {
      chain.push_back(static_cast<std::size_t>(at));
      at = parent_[static_cast<std::size_t>(at)];
    }
    if (at >= 0) track.base = world0_[static_cast<std::size_t>(at)];
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) track.links.push_back(links_[*it]);

    // Check the pose at every key time and half way between them: finite, and
    // reproducing the world matrix (no shear, which a pose cannot express).
    std::vector<double> times{0.0};
    for (const auto& link : track.links) link.key_times(times);
    std::sort(times.begin(), times.end());
    times.erase(std::unique(times.begin(), times.end()), times.end());
    const std::size_t keys = times.size();
    for (std::size_t k = 1; k < keys; ++k) times.push_back(0.5 * (times[k - 1] + times[k]));
    for (double t : times) {
      const double local = track.wrap(t);
      const glm::dmat4 world = track.world_at(local);
      if (!finite(world)) {
        fail(node_label(index) + ": its world transform at t = " + std::to_string(local) + " s is not finite");
      }
      const Pose pose = decompose(world);
      if (!finite(pose) || !reproduces(pose, world)) {
        fail(node_label(index) + " is animated, but its world transform at t = " + std::to_string(local) +
             " s has shear (a non-uniformly scaled parent with a rotated child) or is not affine, which an "
             "animated object's pose cannot express");
      }
    }
    track.fallback = decompose(track.world_at(0.0));
    return track;
  }

  // --- meshes and materials

  const std::vector<Part>& parts_of(std::size_t mesh_index, std::size_t node) {
    if (mesh_index >= model_.meshes.size()) {
      fail(node_label(node) + ": mesh " + std::to_string(mesh_index) + " is out of range");
    }
    if (parts_.size() < model_.meshes.size()) parts_.resize(model_.meshes.size());
    auto& cached = parts_[mesh_index];
    if (!cached) {
      std::vector<Part> parts;
      const auto& mesh = model_.meshes[mesh_index];
      for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
        if (auto part = convert_primitive(mesh_index, p)) parts.push_back(*part);
      }
      cached = std::move(parts);
    }
    return *cached;
  }

  // A primitive's vertices (positions, and normals and texture coordinates where
  // it has them) and the order they are drawn in.
  struct Attributes {
    std::vector<double> positions;
    std::vector<double> normals;
    std::vector<double> uvs;
    std::vector<std::uint32_t> order;
  };

  // An attribute's values, checked to be one per vertex.
  std::vector<double> per_vertex(std::vector<double> values, std::size_t width, std::size_t vertex_count,
                                 const std::string& label, const std::string& name) const {
    if (values.size() / width != vertex_count) {
      fail(label + ": " + name + " has " + std::to_string(values.size() / width) + " elements but POSITION has " +
           std::to_string(vertex_count));
    }
    return values;
  }

  // Texture coordinates: FLOAT, or normalized UNSIGNED_BYTE / UNSIGNED_SHORT.
  std::vector<double> read_uvs(int index, const std::string& label) const {
    const auto& acc = accessor(index, label + " TEXCOORD_0");
    if (acc.componentType == TINYGLTF_COMPONENT_TYPE_BYTE || acc.componentType == TINYGLTF_COMPONENT_TYPE_SHORT) {
      fail(accessor_label(index, label + " TEXCOORD_0") + ": component type " + component_type_name(acc.componentType) +
           " is not allowed for texture coordinates (FLOAT, or normalized UNSIGNED_BYTE or UNSIGNED_SHORT)");
    }
    return read_floats(index, label + " TEXCOORD_0", TINYGLTF_TYPE_VEC2, /*normalized_ok=*/true);
  }

  static std::optional<int> attribute(const tinygltf::Primitive& primitive, const std::string& name) {
    const auto found = primitive.attributes.find(name);
    if (found == primitive.attributes.end()) return std::nullopt;
    return found->second;
  }

  Attributes read_accessors(const tinygltf::Primitive& primitive, const std::string& label) const {
    Attributes out;
    const auto position = attribute(primitive, "POSITION");
    if (!position) fail(label + " has no POSITION attribute");
    out.positions = read_floats(*position, label + " POSITION", TINYGLTF_TYPE_VEC3);
    const std::size_t vertex_count = out.positions.size() / 3;
    if (vertex_count > std::numeric_limits<std::uint32_t>::max()) fail(label + " has too many vertices");
    if (const auto normal = attribute(primitive, "NORMAL")) {
      out.normals =
          per_vertex(read_floats(*normal, label + " NORMAL", TINYGLTF_TYPE_VEC3), 3, vertex_count, label, "NORMAL");
    }
    if (const auto uv = attribute(primitive, "TEXCOORD_0")) {
      out.uvs = per_vertex(read_uvs(*uv, label), 2, vertex_count, label, "TEXCOORD_0");
    }
    if (primitive.indices >= 0) {
      out.order = read_indices(primitive.indices, label + " indices");
      for (std::size_t i = 0; i < out.order.size(); ++i) {
        if (out.order[i] >= vertex_count) {
          fail(label + ": index " + std::to_string(out.order[i]) + " (at " + std::to_string(i) +
               ") is out of range: there are " + std::to_string(vertex_count) + " vertices");
        }
      }
    } else {
      out.order.resize(vertex_count);
      for (std::size_t i = 0; i < vertex_count; ++i) out.order[i] = static_cast<std::uint32_t>(i);
    }
    return out;
  }

  // A KHR_draco_mesh_compression primitive: the attributes the extension maps
  // come from the compressed data, any other from its accessor (the extension
  // allows both); the accessors' counts must agree with what was decoded.
  Attributes read_draco(const tinygltf::Primitive& primitive, const std::string& label, std::int64_t indices,
                        int mode) const {
    const std::string what = label + ": " + kDracoExtension;
    if (mode != TINYGLTF_MODE_TRIANGLES) fail(what + " needs mode TRIANGLES");
    if (indices < -1) fail(what + ": its indices are not an accessor's index");
    const auto found = primitive.extensions.find(kDracoExtension);
    if (found == primitive.extensions.end() || !found->second.IsObject() || !found->second.Get("bufferView").IsInt() ||
        !found->second.Get("attributes").IsObject()) {
      fail(what + " must be an object with a bufferView and attributes");
    }
    const tinygltf::Value& extension = found->second;
    const std::span<const unsigned char> compressed = view_bytes(extension.Get("bufferView").GetNumberAsInt(), what);
    const tinygltf::Value& ids = extension.Get("attributes");
    const auto id_of = [&](const std::string& name) -> std::optional<int> {
      if (!ids.Has(name)) return std::nullopt;
      if (!ids.Get(name).IsInt()) fail(what + ": the id of " + name + " is not an integer");
      return ids.Get(name).GetNumberAsInt();
    };
    const auto position = attribute(primitive, "POSITION");
    if (!position) fail(label + " has no POSITION attribute");
    const auto position_id = id_of("POSITION");
    if (!position_id) fail(what + " does not compress POSITION");
    const bool has_normal = attribute(primitive, "NORMAL").has_value();
    const bool has_uv = attribute(primitive, "TEXCOORD_0").has_value();
    const std::optional<int> normal_id = has_normal ? id_of("NORMAL") : std::nullopt;
    const std::optional<int> uv_id = has_uv ? id_of("TEXCOORD_0") : std::nullopt;
    auto decoded = decode_draco_primitive(
        std::string_view(reinterpret_cast<const char*>(compressed.data()), compressed.size()), *position_id,
        normal_id, uv_id);
    if (!decoded) fail(what + ": " + decoded.error());
    DracoPrimitive& mesh = decoded.value();
    if (mesh.points > std::numeric_limits<std::uint32_t>::max()) fail(label + " has too many vertices");
    const auto expect_count = [&](int index, std::size_t count, const std::string& name) {
      const auto& acc = accessor(index, label + " " + name);
      if (acc.count != count) {
        fail(what + ": " + accessor_label(index, label + " " + name) + " has count " + std::to_string(acc.count) +
             " but the compressed data holds " + std::to_string(count));
      }
    };
    expect_count(*position, mesh.points, "POSITION");
    if (indices >= 0) expect_count(static_cast<int>(indices), mesh.indices.size(), "indices");
    Attributes out;
    out.positions = std::move(mesh.positions);
    if (has_normal) {
      out.normals =
          normal_id ? std::move(mesh.normals)
                    : per_vertex(read_floats(*attribute(primitive, "NORMAL"), label + " NORMAL", TINYGLTF_TYPE_VEC3), 3,
                                 mesh.points, label, "NORMAL");
    }
    if (has_uv) {
      out.uvs =
          uv_id ? std::move(mesh.uvs)
                : per_vertex(read_uvs(*attribute(primitive, "TEXCOORD_0"), label), 2, mesh.points, label, "TEXCOORD_0");
    }
    out.order = std::move(mesh.indices);
    return out;
  }

  std::optional<Part> convert_primitive(std::size_t mesh_index, std::size_t p) {
    const auto& mesh = model_.meshes[mesh_index];
    const auto& primitive = mesh.primitives[p];
    const std::string label = labelled("mesh", mesh_index, mesh.name) + " primitive " + std::to_string(p);

    const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
    switch (mode) {
      case TINYGLTF_MODE_TRIANGLES:
      case TINYGLTF_MODE_TRIANGLE_STRIP:
      case TINYGLTF_MODE_TRIANGLE_FAN:
        break;
      case TINYGLTF_MODE_POINTS:
        fail(label + ": primitive mode POINTS is not supported (triangles only)");
      case TINYGLTF_MODE_LINE:
      case TINYGLTF_MODE_LINE_LOOP:
      case TINYGLTF_MODE_LINE_STRIP:
        fail(label + ": primitive mode LINES is not supported (triangles only)");
      default:
        fail(label + ": primitive mode " + std::to_string(mode) + " is not supported (triangles only)");
    }
    if (!primitive.targets.empty()) fail(label + ": morph targets are not supported");

    Attributes read = source_.draco_indices.contains({mesh_index, p})
                          ? read_draco(primitive, label, source_.draco_indices.at({mesh_index, p}), mode)
                          : read_accessors(primitive, label);
    const std::vector<double>& positions = read.positions;
    const std::vector<double>& normals = read.normals;
    const std::vector<double>& uvs = read.uvs;
    const std::size_t vertex_count = positions.size() / 3;
    const auto uv = [&](std::uint32_t i) {
      if (uvs.empty()) return glm::vec2(0.0f);
      return glm::vec2(static_cast<float>(uvs[2 * i]), static_cast<float>(uvs[2 * i + 1]));
    };
    std::vector<std::uint32_t> order = std::move(read.order);

    // As a triangle list: strips and fans as the glTF spec orders them.
    std::vector<std::uint32_t> triangles;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (order.size() % 3 != 0) {
        fail(label + ": " + std::to_string(order.size()) + " indices are not a whole number of triangles");
      }
      triangles = std::move(order);
    } else {
      for (std::size_t i = 0; i + 2 < order.size(); ++i) {
        if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
          const bool odd = i % 2 == 1;
          triangles.insert(triangles.end(), {order[i], order[odd ? i + 2 : i + 1], order[odd ? i + 1 : i + 2]});
        } else {
          triangles.insert(triangles.end(), {order[i + 1], order[i + 2], order[0]});
        }
      }
    }
    if (triangles.empty()) {
      warn(label + " has no triangles; skipped");
      return std::nullopt;
    }

    Mesh out;
    out.name = mesh.name.empty() ? "mesh " + std::to_string(mesh_index) : mesh.name;
    if (mesh.primitives.size() > 1) out.name += " #" + std::to_string(p);
    const auto position = [&](std::uint32_t i) {
      return glm::vec3(static_cast<float>(positions[3 * i]), static_cast<float>(positions[3 * i + 1]),
                       static_cast<float>(positions[3 * i + 2]));
    };
    if (!normals.empty()) {
      // Unit length, as the renderer expects; a zero normal (invalid glTF) points
      // along +z rather than becoming NaN.
      out.vertices.reserve(vertex_count);
      bool degenerate = false;
      for (std::size_t i = 0; i < vertex_count; ++i) {
        const glm::dvec3 given(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
        const double length = glm::length(given);
        glm::vec3 normal(0.0f, 0.0f, 1.0f);
        if (length > 1e-20 && std::isfinite(length)) {
          normal = glm::vec3(given / length);
        } else {
          degenerate = true;
        }
        out.vertices.push_back({position(static_cast<std::uint32_t>(i)), normal, uv(static_cast<std::uint32_t>(i))});
      }
      if (degenerate) warn(label + ": some normals have zero length; they point along +z");
      out.indices = std::move(triangles);
    } else {
      // Flat normals: each triangle its own three vertices.
      if (triangles.size() > std::numeric_limits<std::uint32_t>::max()) fail(label + " has too many triangles");
      out.vertices.reserve(triangles.size());
      out.indices.reserve(triangles.size());
      for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
        const glm::dvec3 a(position(triangles[t]));
        const glm::dvec3 b(position(triangles[t + 1]));
        const glm::dvec3 c(position(triangles[t + 2]));
        const glm::dvec3 cross = glm::cross(b - a, c - a);
        const double length = glm::length(cross);
        const glm::vec3 normal =
            length > 0.0 && std::isfinite(length) ? glm::vec3(cross / length) : glm::vec3(0.0f, 0.0f, 1.0f);
        for (int k = 0; k < 3; ++k) {
          out.indices.push_back(static_cast<std::uint32_t>(out.vertices.size()));
          const std::uint32_t corner = triangles[t + static_cast<std::size_t>(k)];
          out.vertices.push_back({position(corner), normal, uv(corner)});
        }
      }
    }
    for (const auto& vertex : out.vertices) {
      if (!finite(glm::dvec3(vertex.position)) || !finite(glm::dvec3(vertex.normal)) || !std::isfinite(vertex.uv.x) ||
          !std::isfinite(vertex.uv.y)) {
        fail(label + ": a vertex is not finite in single precision");
      }
    }

    Part part;
    part.material = material(primitive.material, label);
    if (uvs.empty() && materials_[part.material].base_colour_texture) {
      warn(label + " has no TEXCOORD_0; its base colour texture is sampled at (0, 0) only");
    }
    meshes_.push_back(std::move(out));
    part.mesh = static_cast<std::uint32_t>(meshes_.size() - 1);
    return part;
  }

  float to_float(double v, const std::string& what) const {
    const auto f = static_cast<float>(v);
    if (!std::isfinite(v) || !std::isfinite(f)) fail(what + " is not a finite number");
    return f;
  }

  std::uint32_t material(int index, const std::string& user) {
    if (index < 0) {
      if (!default_material_) {
        materials_.push_back(Material{});  // grey, dielectric, medium rough
        default_material_ = static_cast<std::uint32_t>(materials_.size() - 1);
      }
      return *default_material_;
    }
    if (static_cast<std::size_t>(index) >= model_.materials.size()) {
      fail(user + ": material " + std::to_string(index) + " is out of range");
    }
    const auto i = static_cast<std::size_t>(index);
    if (material_index_.size() < model_.materials.size()) material_index_.resize(model_.materials.size());
    if (!material_index_[i]) {
      materials_.push_back(convert_material(i));
      material_index_[i] = static_cast<std::uint32_t>(materials_.size() - 1);
    }
    return *material_index_[i];
  }

  Material convert_material(std::size_t index) {
    const auto& source = model_.materials[index];
    const std::string label = labelled("material", index, source.name);
    const auto& pbr = source.pbrMetallicRoughness;
    Material out;
    if (pbr.baseColorFactor.size() < 3) fail(label + ": baseColorFactor must have 4 numbers");
    for (int c = 0; c < 3; ++c) {
      out.base_colour[c] = std::clamp(
          to_float(pbr.baseColorFactor[static_cast<std::size_t>(c)], label + ": baseColorFactor"), 0.0f, 1.0f);
    }
    out.metallic = std::clamp(to_float(pbr.metallicFactor, label + ": metallicFactor"), 0.0f, 1.0f);
    out.roughness = std::clamp(to_float(pbr.roughnessFactor, label + ": roughnessFactor"), 0.0f, 1.0f);
    float strength = 1.0f;
    const auto extension = source.extensions.find("KHR_materials_emissive_strength");
    if (extension != source.extensions.end() && extension->second.IsObject() &&
        extension->second.Has("emissiveStrength")) {
      const auto& value = extension->second.Get("emissiveStrength");
      if (!value.IsNumber()) fail(label + ": emissiveStrength is not a number");
      strength = std::max(0.0f, to_float(value.GetNumberAsDouble(), label + ": emissiveStrength"));
    }
    if (!source.emissiveFactor.empty()) {
      if (source.emissiveFactor.size() != 3) fail(label + ": emissiveFactor must have 3 numbers");
      for (int c = 0; c < 3; ++c) {
        out.emissive[c] = std::max(
            0.0f, to_float(source.emissiveFactor[static_cast<std::size_t>(c)] * strength, label + ": emissiveFactor"));
      }
    }

    if (pbr.baseColorTexture.index >= 0) out.base_colour_texture = base_colour_texture(pbr.baseColorTexture, label);
    std::vector<std::string> textures;
    if (pbr.metallicRoughnessTexture.index >= 0) textures.emplace_back("metallicRoughnessTexture");
    if (source.normalTexture.index >= 0) textures.emplace_back("normalTexture");
    if (source.occlusionTexture.index >= 0) textures.emplace_back("occlusionTexture");
    if (source.emissiveTexture.index >= 0) textures.emplace_back("emissiveTexture");
    if (!textures.empty()) {
      std::string list;
      for (const auto& name : textures) list += (list.empty() ? "" : ", ") + name;
      warn(label + ": only base colour textures are supported; ignored " + list);
    }
    if (!source.alphaMode.empty() && source.alphaMode != "OPAQUE") {
      warn(label + ": alphaMode " + source.alphaMode + " is ignored; drawn opaque");
    }
    return out;
  }

  // The texture for a material's baseColorTexture, or nothing (with a warning)
  // where it cannot be had. Sampler settings are not read: the renderer always
  // filters linearly (with mipmaps) and repeats.
  std::optional<std::uint32_t> base_colour_texture(const tinygltf::TextureInfo& info, const std::string& label) {
    const std::string what = label + ": baseColorTexture";
    if (info.texCoord != 0) {
      warn(what + " uses TEXCOORD_" + std::to_string(info.texCoord) + " (only TEXCOORD_0 is supported); ignored");
      return std::nullopt;
    }
    if (static_cast<std::size_t>(info.index) >= model_.textures.size()) {
      fail(what + ": texture " + std::to_string(info.index) + " is out of range");
    }
    if (info.extensions.contains("KHR_texture_transform")) {
      warn(what + ": KHR_texture_transform is ignored");
    }
    const auto& texture = model_.textures[static_cast<std::size_t>(info.index)];
    if (texture.source < 0) {
      warn(what + ": texture " + std::to_string(info.index) + " has no image we can read; ignored");
      return std::nullopt;
    }
    const auto image_index = static_cast<std::size_t>(texture.source);
    if (image_index >= model_.images.size()) {
      fail(what + ": image " + std::to_string(image_index) + " is out of range");
    }
    const auto cached = texture_of_image_.find(image_index);
    if (cached != texture_of_image_.end()) return cached->second;
    auto& slot = texture_of_image_[image_index];

    const auto& image = model_.images[image_index];
    const std::string image_label = labelled("image", image_index, image.name.empty() ? image.uri : image.name);
    // Embedded (a data URI), in a buffer view, or a file beside the glTF.
    std::span<const unsigned char> encoded(image.image);
    if (image.bufferView >= 0) {
      encoded = view_bytes(image.bufferView, image_label);
    } else if (image_index < source_.image_file.size() && source_.image_file[image_index]) {
      const std::string& bytes = *source_.files[*source_.image_file[image_index]].second;
      encoded = {reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()};
    }
    if (!decode_) return std::nullopt;  // not drawn here: the image is not needed
    auto decoded = decode_(encoded, image.mimeType);
    if (!decoded) {
      warn(what + ": " + image_label + " cannot be decoded (" + decoded.error() + "); ignored");
      return std::nullopt;
    }
    Texture out = std::move(decoded.value());
    out.name = image.name.empty() ? "image " + std::to_string(image_index) : image.name;
    textures_.push_back(std::move(out));
    slot = static_cast<std::uint32_t>(textures_.size() - 1);
    return slot;
  }

  // --- putting the scene together

  std::string scene_name() const {
    if (scene_index_ >= 0) {
      const auto& name = model_.scenes[static_cast<std::size_t>(scene_index_)].name;
      if (!name.empty()) return name;
    }
    return std::filesystem::path(path_).stem().string();
  }

  void add_instances(SceneDefinition& scene) {
    for (std::size_t index : order_) {
      const auto& node = model_.nodes[index];
      if (node.mesh < 0) continue;
      const auto parts = parts_of(static_cast<std::size_t>(node.mesh), index);
      if (parts.empty()) continue;
      if (animated_[index]) {
        const auto id = static_cast<std::uint32_t>(scene.objects.size() + 1);
        Track track = track_of(index);
        const std::string name = node.name.empty() ? "node " + std::to_string(index) : node.name;
        scene.objects.push_back({id, name, [track = std::move(track)](double t) { return track.pose_at(t); }});
        for (const auto& part : parts) scene.instances.push_back({part.mesh, part.material, id, glm::dmat4(1.0)});
      } else {
        for (const auto& part : parts) {
          scene.instances.push_back({part.mesh, part.material, std::nullopt, world0_[index]});
        }
      }
    }
    scene.meshes = std::move(meshes_);
    scene.materials = std::move(materials_);
    scene.textures = std::move(textures_);
  }

  void add_lights(SceneDefinition& scene) {
    for (std::size_t index : order_) {
      const auto& node = model_.nodes[index];
      const auto extension = node.extensions.find("KHR_lights_punctual");
      if (extension == node.extensions.end()) continue;
      if (!extension->second.IsObject() || !extension->second.Has("light") || !extension->second.Get("light").IsInt()) {
        fail(node_label(index) + ": KHR_lights_punctual must name a light by its index");
      }
      const int light_index = extension->second.Get("light").GetNumberAsInt();
      if (light_index < 0 || static_cast<std::size_t>(light_index) >= model_.lights.size()) {
        fail(node_label(index) + ": light " + std::to_string(light_index) + " is out of range");
      }
      const auto& light = model_.lights[static_cast<std::size_t>(light_index)];
      const std::string label = labelled("light", static_cast<std::size_t>(light_index), light.name);
      if (light.type != "point") {
        warn(label + " (on " + node_label(index) + "): " + light.type + " lights are not supported; skipped");
        continue;
      }
      PointLight out;
      out.position = glm::dvec3(world0_[index][3]);
      if (!light.color.empty()) {
        if (light.color.size() != 3) fail(label + ": color must have 3 numbers");
        for (int c = 0; c < 3; ++c) {
          out.colour[c] = std::max(0.0f, to_float(light.color[static_cast<std::size_t>(c)], label + ": color"));
        }
      }
      out.intensity = std::max(0.0f, to_float(light.intensity * kCandelaToIntensity, label + ": intensity"));
      if (animated_[index]) warn(label + " is on an animated node; it stays where it is at t = 0");
      scene.lights.push_back(out);
    }
  }

  struct NodeTracks {
    std::optional<Sampler> translation;
    std::optional<Sampler> rotation;
    std::optional<Sampler> scale;
  };

  std::string path_;
  const GltfSource& source_;
  const tinygltf::Model& model_;
  const ImageDecoder& decode_;
  std::vector<std::string>& warnings_;

  std::map<std::size_t, NodeTracks> channels_;  // by node
  double duration_ = 0.0;
  int scene_index_ = -1;
  std::vector<int> parent_;
  std::vector<std::size_t> order_;  // the scene's nodes, parents first
  std::vector<bool> animated_;
  std::vector<Link> links_;
  std::vector<glm::dmat4> world0_;  // world transforms at t = 0

  std::vector<Mesh> meshes_;
  std::vector<Material> materials_;
  std::vector<Texture> textures_;
  std::map<std::size_t, std::optional<std::uint32_t>> texture_of_image_;  // decoded (or not) glTF images
  std::vector<std::optional<std::vector<Part>>> parts_;                   // by glTF mesh
  std::vector<std::optional<std::uint32_t>> material_index_;
  std::optional<std::uint32_t> default_material_;
};

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
