#pragma once
// Internal to render (scene_renderer.h is the public door): the scene on the
// GPU and the programs that draw it. Its meshes, textures, materials and
// lights uploaded once; drawn for a moment and a viewpoint into whatever
// framebuffer is bound (render/linear_target.h), writing shaded colour, or also
// each fragment's velocity (the gather), or where each fragment was in kept key
// frames (up-conversion's motion field).

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "render/gl_objects.h"
#include "render/viewpoint.h"
#include "scene/definition.h"
#include "scene/state.h"
#include "util/result.h"

namespace optique::render {

// Which of the scene's instances a draw takes: all, those on no animated
// object, or those on one.
enum class Objects { all, still, moving };

// Where each drawn surface point also is at two other moments: in `state`,
// objects `fraction` of the way to their next pose, seen through
// `view_projection`. An object missing from that state has no place then.
struct MotionEnd {
  const scene::SceneState* state = nullptr;
  double fraction = 0.0;
  glm::dmat4 view_projection{1.0};
};

// Each fragment's screen velocity between the two ends (the gather's program
// and target, key_frames 0), or its place in the key_frames (1 or 2) key
// frames at the first ends (the up-conversion's motion field).
struct Motion {
  MotionEnd ends[2];
  int key_frames = 0;
};

class ScenePass {
 public:
  // Uploads the scene's static content and builds the colour program; fails
  // with the driver's message, or when a texture or material is malformed.
  [[nodiscard]] static Result<ScenePass> create(const scene::SceneDefinition& scene);
  // Uploads an asset an application loaded (by its asset_id): the live
  // instances of it are drawn from now on (its lights are not: the scene's
  // are). Fails as create() does; an id added before is replaced.
  [[nodiscard]] Result<void> add_asset(const scene::SceneDefinition& asset);
  [[nodiscard]] bool has_asset(const std::string& id) const;
  // The gather's program (velocity beside colour); once.
  [[nodiscard]] Result<void> prepare_velocity();
  // Up-conversion's motion-field programs (from one key frame, from two); once.
  [[nodiscard]] Result<void> prepare_motion_field();

  // Draws only these of the frame's point lights (indices: the scene's own,
  // then those applications added, scene/light_coverage.h), less those the
  // drawn state has switched off; an index the state has no light for is not
  // drawn. Or every light of the state (the default).
  void set_lights(std::span<const std::uint32_t> lights);
  void set_all_lights();

  // The scene at `view`'s moment from its place into the bound framebuffer of
  // `width` × `height` pixels; with `motion`, through the program that writes
  // it (prepared first).
  void draw(const scene::SceneState& state, const Viewpoint& view, const LightTerms& terms, int width, int height,
            Objects which = Objects::all, const Motion* motion = nullptr);

  [[nodiscard]] bool anything_still() const;  // an instance on no animated object
  [[nodiscard]] const glm::vec3& background() const { return background_; }

  // The uniforms of one program (scene_pass.cpp).
  struct Uniforms {
    GLint model_view_projection, model, normal_matrix, eye, base_colour, has_base_colour_texture, metallic, roughness,
        emissive, ambient, light_count;
    GLint model_view_projection_now, model_view_projection_next, half_size;  // velocity only
    GLint size, normal_matrix_now, normal_matrix_next, most_turn_cosine;     // motion field only
  };

 private:
  // One placement of the scene's instances: the installation's (the world
  // unmoved), or an instance of the whole scene an application placed.
  struct Placement {
    glm::dmat4 view_projection{1.0};
    glm::dmat4 world{1.0};                                                           // at the view's moment
    std::optional<glm::dmat4> world_at_end[2] = {glm::dmat4(1.0), glm::dmat4(1.0)};  // at the motion's ends
    glm::vec3 base_colour{1.0f};                                                     // factors on every material
    glm::vec3 emissive{1.0f};
    // An instance's own animation times (none: the objects' poses in the state).
    std::optional<scene::AnimationTimes> animation;
    std::optional<scene::AnimationTimes> animation_at_end[2];
    bool still_only = false;   // only the instances on no animated object
    bool moving_only = false;  // only those on one
  };

  struct MeshRange {
    GLsizei count = 0;
    std::size_t first_index = 0;
    GLint base_vertex = 0;
  };
  // One asset's static content on the GPU: the installation's scene, or one
  // an application loaded. All its meshes in one vertex and one index buffer.
  struct Asset {
    std::string id;  // the live instances of it are drawn
    glo::VertexArray vertex_array;
    glo::Buffer vertex_buffer;
    glo::Buffer index_buffer;
    std::vector<glo::Texture> textures;  // by index in its textures
    std::vector<MeshRange> meshes;
    std::vector<scene::Material> materials;
    std::vector<scene::Instance> instances;
    std::map<std::uint32_t, std::function<scene::Pose(double)>> animations;  // the objects' poses at any time
    bool own_scene = false;  // the installation's: its objects' poses are in the state
  };
  [[nodiscard]] static Result<Asset> upload(const scene::SceneDefinition& scene);

  ScenePass() = default;
  void upload_shining_lights(const scene::SceneState& state);
  // Where animated object `object` of `asset` puts what rides on it,
  // `fraction` of a frame on: from `state` (the installation's scene), or at
  // `times` of the asset's animations (an instance's own clock). None: the
  // object is not there.
  [[nodiscard]] static std::optional<glm::dmat4> object_matrix(const Asset& asset, const scene::SceneState& state,
                                                               std::uint32_t object,
                                                               const std::optional<scene::AnimationTimes>& times,
                                                               double fraction);
  void draw_placed(const Asset& asset, const Placement& placement, const scene::SceneState& state,
                   const Viewpoint& view, const LightTerms& terms, const Uniforms& u, const Motion* motion);
  // Every visible live instance of `asset` in `state`.
  void draw_instances(const Asset& asset, Placement placement, const scene::SceneState& state, const Viewpoint& view,
                      const LightTerms& terms, const Uniforms& u, const Motion* motion);
  glo::Program colour_program_;
  Uniforms colour_uniforms_{};
  glo::Program velocity_program_;  // prepare_velocity
  Uniforms velocity_uniforms_{};
  // prepare_motion_field: one per number of key frames, [0] from one, [1] from two.
  std::array<glo::Program, 2> key_frames_program_;
  std::array<Uniforms, 2> key_frames_uniforms_{};

  std::vector<Asset> assets_;  // [0]: the installation's scene
  glo::Buffer light_buffer_;
  glm::vec3 ambient_{0.0f};
  glm::vec3 background_{0.0f};
  std::vector<glm::vec4> all_lights_;                        // the scene's own: position, radiance, two per light
  std::optional<std::vector<std::uint32_t>> chosen_lights_;  // set_lights; none: every light
  std::vector<glm::vec4> uploaded_lights_;                   // what the light buffer holds: the lights that shine
  int light_count_ = 0;
};

}  // namespace optique::render
