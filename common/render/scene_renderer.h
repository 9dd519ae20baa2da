#pragma once
// Draws a scene into its own framebuffers: linear light (RGBA32F colour, 32-bit
// float depth), then an output pass to the signal the projector is sent (its
// response, bit depth, black level and brightness: optics/projector_model.h). Needs a current OpenGL 4.5 context
// (render/gl_context.h); the same code runs headless and in a window.

#include <memory>
#include <optional>
#include <set>
#include <span>

#include <glm/mat3x3.hpp>

#include "geometry/projection.h"
#include "image/image.h"
#include "optics/defocus.h"
#include "optics/projector_model.h"
#include "render/fields.h"
#include "scene/definition.h"
#include "scene/state.h"
#include "up/between.h"
#include "util/result.h"

namespace optique::render {

// Which light terms this renderer draws (a node of a stacked group may carry only
// some of them); the point lights are chosen with SceneRenderer::set_lights.
struct LightTerms {
  bool ambient = true;
  bool emissive = true;
};

// A focus/defocus pair's share of the image: the focus projector shows (1 − c_r)
// of the light, the defocus one c_r (or, in the inset variant, inside and outside
// a disc around the gaze point).
enum class FocusRole { none, focus, defocus };

struct FocusShare {
  FocusRole role = FocusRole::none;
  bool inset = false;  // share by a disc around the gaze point instead of c_r
  // Single pass: A and the depth scale, to undo what they did to window depth.
  glm::dmat3 user_to_projector{1.0};
  double depth_scale = 1.0;
  // Output pixels (GL fragment coordinates, rows up) → screen metres, for the inset.
  glm::dmat3 fragment_to_screen{1.0};
  double screen_metres_per_pixel = 1e-3;  // the inset's edge is this soft
};

// What changes per frame for a focus/defocus projector.
struct FocusFrame {
  optics::CocFromWindowDepth coc;  // from the frame's focal depth
  glm::dvec2 gaze{0.0};            // screen metres
  double inset_radius = 0.0;
};

// The depth buffer's format: 32-bit float by default; 24-bit fixed point to
// measure what a common hardware default does to depth order.
enum class DepthFormat { float32, fixed24 };

// What lies between the rendered image and the projector. A two-pass projector
// warps the viewer's image (drawn through R) to its own pixels; every projector
// multiplies by its blend weights, which are zero where it is masked. The
// default does neither: the projector shows the rendered image as it is.
struct OutputStage {
  int width = 0;  // projector pixels; 0: the rendered image's size
  int height = 0;
  // Two-pass only: projector NDC → user NDC (A⁻¹); the rendered image spans
  // user NDC [−1, 1]² and is sampled bilinearly.
  std::optional<glm::dmat3> projector_to_user;
  image::FloatImage weights;         // 1 channel, width × height, top row first; empty: 1 everywhere
  optics::ProjectorModel projector;  // response, bit depth, black level, brightness
  FocusShare focus;
};

class SceneRenderer {
 public:
  // Uploads the scene's static content; draws `width` × `height` pixels, each
  // the average of `samples` (multisampling; 1: one at the pixel's centre).
  // Fails with the GL driver's message when a shader does not build or a
  // framebuffer is incomplete, or when the driver cannot draw that many samples.
  [[nodiscard]] static Result<std::unique_ptr<SceneRenderer>> create(const scene::SceneDefinition& scene, int width,
                                                                     int height,
                                                                     DepthFormat depth = DepthFormat::float32,
                                                                     int samples = 1);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Draws the scene with animated objects at `fraction` between their two frame
  // poses, seen from `eye` through `frustum`; returns when the GPU is done.
  void draw(const scene::SceneState& state, double fraction, const glm::dvec3& eye, const geometry::Frustum& frustum,
            const LightTerms& terms = {});

  // A single-chip DLP projector's frame: the scene drawn once per pass into one
  // image, each pass writing only its channels, so each colour shows the scene at
  // the moment its field is on screen; then the output stage, once. When every
  // pass sees the scene from the same place, what does not move is drawn once for
  // all of them (unless `still_once` is false: to measure what that saves).
  // With `blur` (its fields empty, a velocity threshold set; prepare_gather
  // first), the scene is drawn once more at its moment with its velocity, and
  // pixels faster than the threshold get motion blur over its frame window
  // instead of their fields (as draw_gathered does). Returns when the GPU is
  // done, with what the blur found.
  GatherReport draw_fields(const scene::SceneState& state, std::span<const FieldPass> passes,
                           const LightTerms& terms = {}, bool still_once = true, const GatherFrame* blur = nullptr);

  // The same by the gather method; prepare_gather first. Returns when the GPU is
  // done, with what the gather found.
  [[nodiscard]] GatherReport draw_gathered(const scene::SceneState& state, const GatherFrame& frame,
                                           const LightTerms& terms = {});
  // Other fields from the render draw_gathered made last (the second image of a
  // stereo projector used as mono), into the output.
  [[nodiscard]] GatherReport gather_again(std::span<const GatherField> fields, const GatherSettings& settings);
  // Makes the velocity target, tiles and passes draw_gathered needs (only
  // projectors that gather have them); fails with the driver's message.
  [[nodiscard]] Result<void> prepare_gather();

  // Frame-rate up-conversion (render/up_converter.h): makes the key slots, the
  // motion field's targets and passes (only projectors that up-convert have
  // them), `slots` key frames (2, or up::kKeySlots where they are drawn in
  // bands); fails with the driver's message.
  [[nodiscard]] Result<void> prepare_up_conversion(int slots = 2);
  // The image the last draw() made kept as key frame `slot`, drawn as `view`
  // says; prepare_up_conversion first.
  void keep_key(int slot, up::KeyView view);
  // Bands `index` … `index + bands − 1` of `count` (rows, from the bottom) of a
  // key frame drawn as draw() would, at `state`'s poses `fraction` of a frame
  // on, seen from `eye` through `frustum`, into key slot `slot`: the rest of
  // the slot stays. Drawn through the linear image: before the frame's own
  // (draw_between, show_key); nothing is shown.
  void draw_key_band(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                     const geometry::Frustum& frustum, const LightTerms& terms, int slot, int index, int count,
                     int bands = 1);
  // A frame between key frames, at `state`'s poses `fraction` of a frame on,
  // seen from `eye` through `frustum`: the motion field drawn with the scene's
  // geometry, each pixel from the kept key frames where its surface was, what
  // none saw shaded anew (as `frame` says); or their average. Then the output
  // stage, as draw() ends. Returns when the GPU is done.
  up::BetweenReport draw_between(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                                 const geometry::Frustum& frustum, const up::BetweenFrame& frame,
                                 const LightTerms& terms = {});
  // The frame between that `frame` would build for the state the last draw()
  // showed, weighed against what draw() made (or against kept key
  // `against_slot`, drawn for `state`): PSNR_Y (dB, the up-conversion paper's;
  // +infinity when equal). The output stays the last frame's.
  [[nodiscard]] double check_between(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                                     const geometry::Frustum& frustum, const up::BetweenFrame& frame,
                                     const LightTerms& terms = {}, std::optional<int> against_slot = {});
  // Key `slot` as it was kept, through the output stage (a key frame drawn
  // ahead, shown at its own moment).
  void show_key(int slot);
  // Colour fields by up-conversion: with `key`, the scene drawn at its moment
  // and kept as key frame 0; then each of `passes` (a field at its own moment)
  // built from key frame 0 as a frame between (what it did not see shaded
  // anew) into its channels of the image, except those at the key's own moment,
  // which show it as drawn. Then the output stage. prepare_up_conversion first.
  void draw_fields_up_converted(const scene::SceneState& state, const FieldPass* key, std::span<const FieldPass> passes,
                                const LightTerms& terms = {});
  // Colour fields of a frame that frame-rate up-conversion builds: each of
  // `passes` built from the kept key frames as `from` says (two weighed by the
  // pass's own moment), into its channels of the image. Then the output stage.
  // The largest share of a field's pixels that no key frame saw.
  up::BetweenReport draw_fields_between(const scene::SceneState& state, std::span<const FieldPass> passes,
                                        const up::BetweenFrame& from, const LightTerms& terms = {});

  // Fails when the weights do not match the output size.
  [[nodiscard]] Result<void> set_output(const OutputStage& stage);

  // Draws only these of the scene's point lights (indices; all by default), less
  // those the drawn state has switched off. Asserts that each exists.
  void set_lights(std::span<const std::uint32_t> lights);
  void set_all_lights();
  // The focal depth and gaze of the frame to come (focus/defocus projectors).
  void set_focus(const FocusFrame& frame);

  // Black everywhere (the projector shows nothing), encoded like a drawn frame.
  void draw_black();

  // The output, after the output stage (projector pixels).
  [[nodiscard]] image::FloatImage read_linear()
      const;  // RGBA, the light the projector emits for the signal (its model, on the CPU)
  [[nodiscard]] image::ByteImage read_encoded() const;  // RGBA8, the signal (8 bits deep at most)
  [[nodiscard]] image::WordImage read_signal() const;   // RGBA16: the signal at any depth, ·65535
  [[nodiscard]] unsigned output_framebuffer() const;    // the encoded image, for a window blit
  // Copies the output aside, to be shown while the next image is drawn into it
  // (a projector that shows two images per frame); GL orders the copy before
  // whatever is drawn next.
  void hold_output();
  [[nodiscard]] unsigned held_framebuffer() const;  // the copy; 0 before the first hold_output
  [[nodiscard]] int width() const;                  // of the output
  [[nodiscard]] int height() const;
  // The rendered image before the output stage (opaque: the alpha that carries
  // depth inside is read as 1), and its depth (window z in [0, 1]).
  [[nodiscard]] image::FloatImage read_rendered() const;
  // The framebuffer read_rendered reads (its colour: a single-sampled texture).
  [[nodiscard]] unsigned rendered_framebuffer() const;
  [[nodiscard]] image::FloatImage read_depth() const;

 private:
  struct Gl;
  explicit SceneRenderer(std::unique_ptr<Gl> gl);
  // Which of the scene's instances a draw takes: all, those on no animated
  // object, or those on one.
  enum class Objects { all, still, moving };
  // Binds and clears the image and depth the scene is drawn into (and the
  // velocity target, for a gather).
  void begin_linear(bool with_motion = false);
  void resolve();  // multisampled: averages the samples into the linear image
  // Where each drawn surface point also is at two other moments: in `state`,
  // objects `fraction` of the way to their next pose, seen through
  // `view_projection`. An object missing from that state has no place then.
  struct MotionEnd {
    const scene::SceneState* state = nullptr;
    double fraction = 0.0;
    glm::dmat4 view_projection{1.0};
  };
  // With `motion`, also each fragment's screen velocity between the two ends
  // (the gather's program and target, key_frames 0), or its place in the
  // key_frames (1 or 2) key frames at the first ends (the up-conversion's motion
  // field).
  struct Motion {
    MotionEnd ends[2];
    int key_frames = 0;
  };
  void draw_scene(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                  const geometry::Frustum& frustum, const LightTerms& terms, Objects which = Objects::all,
                  const Motion* motion = nullptr);
  // The whole scene into the linear image (begin_linear, draw_scene, resolve):
  // draw() without the output stage.
  void draw_linear(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                   const geometry::Frustum& frustum, const LightTerms& terms);
  // The scene at `frame.seen`'s moment with its velocity, resolved, and the
  // gather's tiles measured: what a gather or a blur starts from.
  void draw_with_motion(const scene::SceneState& state, const GatherFrame& frame, const LightTerms& terms);
  // A frame between key frames into the up-converter's output (draw_between
  // without the output stage).
  up::BetweenReport build_between(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                                  const geometry::Frustum& frustum, const up::BetweenFrame& frame,
                                  const LightTerms& terms);
  // Each of `passes` but `shown` (at the image's own moment: left as drawn)
  // built as `from` says into its channels of the linear image; then encoded.
  up::BetweenReport build_fields(const scene::SceneState& state, std::span<const FieldPass> passes,
                                 const up::BetweenFrame& from, const LightTerms& terms, const FieldPass* shown);
  void keep_still_depth();        // copies the depth drawn so far aside
  void bring_back_still_depth();  // and back
  [[nodiscard]] unsigned draw_framebuffer() const;
  void encode();                                  // the linear image
  void encode(unsigned texture);                  // or another of its size
  void encode(unsigned texture, unsigned depth);  // with the depth a focus share reads
  void upload_shining_lights(const std::set<std::uint32_t>& off);
  std::unique_ptr<Gl> gl_;
};

}  // namespace optique::render
