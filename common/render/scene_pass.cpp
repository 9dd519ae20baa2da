#include "render/scene_pass.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>

#include "render/shaders.h"
#include "scene/instance_tree.h"
#include "up/between.h"

namespace optique::render {
namespace {

// What a scene program writes besides the geometry: shaded colour; or that
// and each fragment's velocity (the gather); or only where each fragment was
// in one key frame or two (the up-conversion's motion field; from one, it
// writes one target: 6 ms instead of 11 on llvmpipe at 1280×720).
enum class SceneOutput { colour, velocity, key_frame, key_frames };

// Its sources come without a #version line, so that the choice goes first.
Result<glo::Program> scene_program(SceneOutput output, ScenePass::Uniforms& uniforms) {
  const std::string head = std::string("#version 450 core\n") +
                           (output != SceneOutput::colour ? "#define VELOCITY 1\n" : "") +
                           (output == SceneOutput::key_frame ? "#define ONE_END 1\n" : "");
  const bool field = output == SceneOutput::key_frame || output == SceneOutput::key_frames;
  const std::string_view fragment = field ? shaders::motion_field_frag : shaders::scene_frag;
  auto program = glo::link_program(head + std::string(shaders::scene_vert), head + std::string(fragment));
  if (!program) return Error{program.error()};
  const GLuint p = program.value().get();
  const auto at = [p](const char* name) { return glGetUniformLocation(p, name); };
  uniforms = {at("model_view_projection"),
              at("model"),
              at("normal_matrix"),
              at("eye"),
              at("base_colour_factor"),
              at("has_base_colour_texture"),
              at("metallic"),
              at("roughness"),
              at("emissive"),
              at("ambient"),
              at("light_count"),
              at("model_view_projection_0"),
              at("model_view_projection_1"),
              at("half_size"),
              at("size"),
              at("normal_matrix_0"),
              at("normal_matrix_1"),
              at("most_turn_cosine")};
  return program;
}

// Textures: sRGB colour (decoded to linear when sampled), linear alpha; mipmapped,
// trilinear, repeating. Rows go up as they are stored, top row first: that row
// is t = 0, which is where glTF's v = 0 (the image's top) is, so glTF uvs
// sample the texture unchanged.
Result<glo::Texture> upload_texture(const scene::Texture& texture) {
  if (texture.width <= 0 || texture.height <= 0 ||
      texture.rgba.size() != static_cast<std::size_t>(texture.width) * static_cast<std::size_t>(texture.height) * 4) {
    return Error{"texture '" + texture.name + "' has no or the wrong number of texels"};
  }
  glo::Texture made = glo::make_texture();
  const GLuint name = made.get();
  int levels = 1;
  for (int side = std::max(texture.width, texture.height); side > 1; side /= 2) ++levels;
  glTextureStorage2D(name, levels, GL_SRGB8_ALPHA8, texture.width, texture.height);
  glTextureSubImage2D(name, 0, 0, 0, texture.width, texture.height, GL_RGBA, GL_UNSIGNED_BYTE, texture.rgba.data());
  glGenerateTextureMipmap(name);
  glTextureParameteri(name, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(name, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(name, GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(name, GL_TEXTURE_WRAP_T, GL_REPEAT);
  return made;
}

}  // namespace

Result<ScenePass::Asset> ScenePass::upload(const scene::SceneDefinition& scene) {
  Asset asset;
  std::vector<scene::Vertex> vertices;
  std::vector<std::uint32_t> indices;
  for (const auto& mesh : scene.meshes) {
    asset.meshes.push_back(
        {static_cast<GLsizei>(mesh.indices.size()), indices.size(), static_cast<GLint>(vertices.size())});
    vertices.insert(vertices.end(), mesh.vertices.begin(), mesh.vertices.end());
    indices.insert(indices.end(), mesh.indices.begin(), mesh.indices.end());
  }
  asset.vertex_array = glo::make_vertex_array();
  asset.vertex_buffer = glo::make_buffer();
  asset.index_buffer = glo::make_buffer();
  const GLuint array = asset.vertex_array.get();
  glNamedBufferStorage(asset.vertex_buffer.get(),
                       static_cast<GLsizeiptr>(std::max<std::size_t>(1, vertices.size()) * sizeof(scene::Vertex)),
                       vertices.empty() ? nullptr : vertices.data(), 0);
  glNamedBufferStorage(asset.index_buffer.get(),
                       static_cast<GLsizeiptr>(std::max<std::size_t>(1, indices.size()) * sizeof(std::uint32_t)),
                       indices.empty() ? nullptr : indices.data(), 0);
  glVertexArrayVertexBuffer(array, 0, asset.vertex_buffer.get(), 0, sizeof(scene::Vertex));
  glVertexArrayElementBuffer(array, asset.index_buffer.get());
  const auto attribute = [array](GLuint index, GLint size, std::size_t offset) {
    glEnableVertexArrayAttrib(array, index);
    glVertexArrayAttribFormat(array, index, size, GL_FLOAT, GL_FALSE, static_cast<GLuint>(offset));
    glVertexArrayAttribBinding(array, index, 0);
  };
  attribute(0, 3, offsetof(scene::Vertex, position));
  attribute(1, 3, offsetof(scene::Vertex, normal));
  attribute(2, 2, offsetof(scene::Vertex, uv));

  for (const auto& texture : scene.textures) {
    auto uploaded = upload_texture(texture);
    if (!uploaded) return Error{uploaded.error()};
    asset.textures.push_back(std::move(uploaded).value());
  }
  for (const auto& material : scene.materials) {
    if (material.base_colour_texture && *material.base_colour_texture >= scene.textures.size()) {
      return Error{"a material's base colour texture " + std::to_string(*material.base_colour_texture) +
                   " is out of range (" + std::to_string(scene.textures.size()) + " textures)"};
    }
  }
  for (const auto& instance : scene.instances) {
    if (instance.mesh >= scene.meshes.size() || instance.material >= scene.materials.size()) {
      return Error{"an instance names mesh " + std::to_string(instance.mesh) + " and material " +
                   std::to_string(instance.material) + " (" + std::to_string(scene.meshes.size()) + " meshes, " +
                   std::to_string(scene.materials.size()) + " materials)"};
    }
  }
  asset.materials = scene.materials;
  asset.instances = scene.instances;
  for (const auto& object : scene.objects) asset.animations.emplace(object.id, object.pose_at);
  asset.id = scene.asset_id;
  return asset;
}

Result<ScenePass> ScenePass::create(const scene::SceneDefinition& scene) {
  ScenePass pass;
  auto program = scene_program(SceneOutput::colour, pass.colour_uniforms_);
  if (!program) return Error{program.error()};
  pass.colour_program_ = std::move(program).value();
  auto asset = upload(scene);
  if (!asset) return Error{asset.error()};
  asset.value().own_scene = true;
  // A texture's first mipmaps cost a driver its setup (llvmpipe: about 200 ms):
  // paid here, not by the first frames after an application loads a textured
  // asset.
  if (scene.textures.empty()) {
    scene::Texture warm;
    warm.name = "warm-up";
    warm.width = warm.height = 4;
    warm.rgba.assign(4 * 4 * 4, 255);
    if (auto uploaded = upload_texture(warm); !uploaded) return Error{uploaded.error()};
  }
  pass.assets_.push_back(std::move(asset).value());

  for (const auto& light : scene.lights) {
    pass.all_lights_.emplace_back(glm::vec3(light.position), 1.0f);
    pass.all_lights_.emplace_back(light.colour * light.intensity, 0.0f);
  }
  pass.light_buffer_ = glo::make_buffer();
  // Room for the lights applications may add too.
  glNamedBufferStorage(
      pass.light_buffer_.get(),
      static_cast<GLsizeiptr>((pass.all_lights_.size() + 2 * scene::kMaxAddedLights) * sizeof(glm::vec4)), nullptr,
      GL_DYNAMIC_STORAGE_BIT);
  pass.ambient_ = scene.ambient;
  pass.background_ = scene.background;
  pass.set_all_lights();
  return pass;
}

Result<void> ScenePass::add_asset(const scene::SceneDefinition& asset) {
  assert(!asset.asset_id.empty());
  auto uploaded = upload(asset);
  if (!uploaded) return Error{"asset '" + asset.asset_id + "': " + uploaded.error()};
  for (std::size_t i = 1; i < assets_.size(); ++i) {
    if (assets_[i].id == asset.asset_id) {
      assets_[i] = std::move(uploaded).value();
      return {};
    }
  }
  assets_.push_back(std::move(uploaded).value());
  return {};
}

bool ScenePass::has_asset(const std::string& id) const {
  return std::any_of(assets_.begin(), assets_.end(), [&](const Asset& a) { return a.id == id; });
}

Result<void> ScenePass::prepare_velocity() {
  if (velocity_program_) return {};
  auto program = scene_program(SceneOutput::velocity, velocity_uniforms_);
  if (!program) return Error{program.error()};
  velocity_program_ = std::move(program).value();
  return {};
}

Result<void> ScenePass::prepare_motion_field() {
  if (key_frames_program_[0]) return {};
  std::array<glo::Program, 2> programs;
  std::array<Uniforms, 2> uniforms{};
  for (int keys = 1; keys <= 2; ++keys) {
    auto program = scene_program(keys == 1 ? SceneOutput::key_frame : SceneOutput::key_frames, uniforms[keys - 1]);
    if (!program) return Error{"the up-conversion's motion field: " + program.error()};
    programs[keys - 1] = std::move(program).value();
  }
  key_frames_program_ = std::move(programs);
  key_frames_uniforms_ = uniforms;
  return {};
}

void ScenePass::set_lights(std::span<const std::uint32_t> lights) {
  chosen_lights_ = std::vector<std::uint32_t>(lights.begin(), lights.end());
}

void ScenePass::set_all_lights() { chosen_lights_.reset(); }

void ScenePass::upload_shining_lights(const scene::SceneState& state) {
  const std::size_t own = all_lights_.size() / 2;
  std::vector<glm::vec4> data;
  const auto shine = [&](std::uint32_t i) {
    if (state.lights_off.contains(i)) return;
    if (i < own) {
      data.push_back(all_lights_[2 * i]);
      data.push_back(all_lights_[2 * i + 1]);
      return;
    }
    // An added light; one a share names that the state has not is drawn by nobody.
    const auto added = state.point_lights.find(i);
    if (added == state.point_lights.end() || data.size() / 2 >= own + scene::kMaxAddedLights) return;
    const scene::PointLightState& light = added->second;
    data.emplace_back(glm::vec3(light.position), 1.0f);
    data.emplace_back(glm::vec3(light.colour * light.intensity), 0.0f);
  };
  if (chosen_lights_) {
    for (std::uint32_t i : *chosen_lights_) shine(i);
  } else {
    for (std::uint32_t i = 0; i < own; ++i) shine(i);
    for (const auto& [i, light] : state.point_lights) {
      if (i >= own) shine(i);
    }
  }
  if (data == uploaded_lights_) return;
  if (!data.empty()) {
    glNamedBufferSubData(light_buffer_.get(), 0, static_cast<GLsizeiptr>(data.size() * sizeof(glm::vec4)), data.data());
  }
  light_count_ = static_cast<int>(data.size() / 2);
  uploaded_lights_ = std::move(data);
}

bool ScenePass::anything_still() const {
  const auto& instances = assets_.front().instances;
  return std::any_of(instances.begin(), instances.end(), [](const scene::Instance& i) { return !i.object; });
}

void ScenePass::draw(const scene::SceneState& state, const Viewpoint& view, const LightTerms& terms, int width,
                     int height, Objects which, const Motion* motion) {
  upload_shining_lights(state);
  const int keys = motion ? motion->key_frames : 0;
  const bool key_frames = keys > 0;
  assert(keys >= 0 && keys <= 2);
  assert(!motion || (key_frames ? key_frames_program_[0] : velocity_program_));  // prepared first
  const int field = std::max(keys - 1, 0);
  glUseProgram(key_frames ? key_frames_program_[field].get()
               : motion   ? velocity_program_.get()
                          : colour_program_.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, light_buffer_.get());
  const Uniforms& u = key_frames ? key_frames_uniforms_[field] : motion ? velocity_uniforms_ : colour_uniforms_;
  if (motion) glUniform2f(u.half_size, 0.5f * static_cast<float>(width), 0.5f * static_cast<float>(height));
  if (key_frames) {
    glUniform2f(u.size, static_cast<float>(width), static_cast<float>(height));
    glUniform1f(u.most_turn_cosine, static_cast<float>(std::cos(up::kMostTurn)));
  }
  const glm::dvec3& eye = view.eye;
  glUniform3f(u.eye, static_cast<float>(eye.x), static_cast<float>(eye.y), static_cast<float>(eye.z));
  const glm::vec3 ambient = terms.ambient ? ambient_ : glm::vec3(0.0f);
  glUniform3fv(u.ambient, 1, glm::value_ptr(ambient));
  glUniform1i(u.light_count, light_count_);
  const glm::dmat4 view_projection = view.view_projection();

  // The installation's scene where it is, then every visible instance an
  // application placed (which moves between frames: never drawn as still).
  Placement placement;
  placement.view_projection = view_projection;
  placement.moving_only = which == Objects::moving;
  placement.still_only = which == Objects::still;
  const Asset& own = assets_.front();
  glBindVertexArray(own.vertex_array.get());
  draw_placed(own, placement, state, view, terms, u, motion);
  if (which == Objects::still || state.instances.empty()) return;
  placement.moving_only = false;
  for (const Asset& asset : assets_) {
    if (asset.id.empty()) continue;
    glBindVertexArray(asset.vertex_array.get());
    draw_instances(asset, placement, state, view, terms, u, motion);
  }
}

void ScenePass::draw_instances(const Asset& asset, Placement placement, const scene::SceneState& state,
                               const Viewpoint& view, const LightTerms& terms, const Uniforms& u,
                               const Motion* motion) {
  for (const auto& [id, instance] : state.instances) {
    if (instance.asset != asset.id) continue;
    const auto now = scene::instance_world(state, id, view.fraction);
    if (!now) continue;
    placement.world = *now;
    for (int e = 0; e < (motion ? 2 : 0); ++e) {
      const MotionEnd& end = motion->ends[e];
      placement.world_at_end[e] = end.state ? scene::instance_world(*end.state, id, end.fraction) : std::nullopt;
    }
    placement.base_colour = glm::vec3(instance.base_color);
    placement.emissive = glm::vec3(instance.emissive);
    placement.animation = instance.animation;
    for (int e = 0; e < (motion ? 2 : 0); ++e) {
      const scene::SceneState* then = motion->ends[e].state;
      const auto there = then ? then->instances.find(id) : state.instances.end();
      placement.animation_at_end[e] = then && there != then->instances.end() ? there->second.animation : std::nullopt;
    }
    draw_placed(asset, placement, state, view, terms, u, motion);
  }
}

std::optional<glm::dmat4> ScenePass::object_matrix(const Asset& asset, const scene::SceneState& state,
                                                   std::uint32_t object,
                                                   const std::optional<scene::AnimationTimes>& times, double fraction) {
  // An asset an application loaded plays on its instance's clock; without
  // one (never so from the master) it stands as at its start.
  if (times || !asset.own_scene) {
    const auto animated = asset.animations.find(object);
    if (animated == asset.animations.end()) return std::nullopt;
    const scene::AnimationTimes at = times.value_or(scene::AnimationTimes{});
    const scene::ObjectState poses{animated->second(at.now), animated->second(at.next)};
    return scene::model_matrix(scene::interpolate(poses, fraction));
  }
  const auto found = state.objects.find(object);
  if (found == state.objects.end()) return std::nullopt;
  return scene::model_matrix(scene::interpolate(found->second, fraction));
}

void ScenePass::draw_placed(const Asset& asset, const Placement& placement, const scene::SceneState& state,
                            const Viewpoint& view, const LightTerms& terms, const Uniforms& u, const Motion* motion) {
  const int keys = motion ? motion->key_frames : 0;
  for (const auto& instance : asset.instances) {
    if ((placement.still_only && instance.object) || (placement.moving_only && !instance.object)) continue;
    glm::dmat4 model = instance.transform;
    if (instance.object) {
      const auto on = object_matrix(asset, state, *instance.object, placement.animation, view.fraction);
      if (!on) continue;  // not in the state (yet): nothing to place
      model = *on * instance.transform;
    }
    model = placement.world * model;
    // Products in double, then to float: keeps precision for large worlds.
    const glm::mat4 mvp(placement.view_projection * model);
    const glm::mat4 model_f(model);
    const glm::mat3 normal_matrix(glm::transpose(glm::inverse(glm::dmat3(model))));
    glUniformMatrix4fv(u.model_view_projection, 1, GL_FALSE, glm::value_ptr(mvp));
    if (motion) {
      // Where this instance is at the motion's two ends; an object (or a
      // placed instance) not in the scene then projects to w = 0: no place.
      const GLint locations[2] = {u.model_view_projection_now, u.model_view_projection_next};
      const GLint normal_locations[2] = {u.normal_matrix_now, u.normal_matrix_next};
      for (int e = 0; e < (keys == 1 ? 1 : 2); ++e) {
        const MotionEnd& end = motion->ends[e];
        glm::dmat4 then = instance.transform;
        bool there = placement.world_at_end[e].has_value();
        if (instance.object && there) {
          const auto on =
              object_matrix(asset, *end.state, *instance.object, placement.animation_at_end[e], end.fraction);
          there = on.has_value();
          if (there) then = *on * instance.transform;
        }
        if (there) then = *placement.world_at_end[e] * then;
        const glm::mat4 clip(there ? end.view_projection * then : glm::dmat4(0.0));
        glUniformMatrix4fv(locations[e], 1, GL_FALSE, glm::value_ptr(clip));
        if (keys > 0) {
          const glm::mat3 normals(glm::transpose(glm::inverse(glm::dmat3(then))));
          glUniformMatrix3fv(normal_locations[e], 1, GL_FALSE, glm::value_ptr(normals));
        }
      }
    }
    glUniformMatrix4fv(u.model, 1, GL_FALSE, glm::value_ptr(model_f));
    glUniformMatrix3fv(u.normal_matrix, 1, GL_FALSE, glm::value_ptr(normal_matrix));
    const scene::Material& m = asset.materials[instance.material];
    const glm::vec3 base_colour = m.base_colour * placement.base_colour;
    glUniform3fv(u.base_colour, 1, glm::value_ptr(base_colour));
    glUniform1i(u.has_base_colour_texture, m.base_colour_texture ? 1 : 0);
    if (m.base_colour_texture) glBindTextureUnit(1, asset.textures[*m.base_colour_texture].get());  // unit 0: encode
    glUniform1f(u.metallic, m.metallic);
    glUniform1f(u.roughness, m.roughness);
    const glm::vec3 emissive = terms.emissive ? m.emissive * placement.emissive : glm::vec3(0.0f);
    glUniform3fv(u.emissive, 1, glm::value_ptr(emissive));
    const MeshRange& mesh = asset.meshes[instance.mesh];
    glDrawElementsBaseVertex(GL_TRIANGLES, mesh.count, GL_UNSIGNED_INT,
                             reinterpret_cast<const void*>(mesh.first_index * sizeof(std::uint32_t)), mesh.base_vertex);
  }
}

}  // namespace optique::render
