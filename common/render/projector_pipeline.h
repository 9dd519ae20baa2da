#pragma once
// What a projector's job needs to draw, built in one place: its view of the
// screen (single pass through R, or two passes), a scene renderer of the right
// size, and the output stage — blend weights shared with its blend group, its
// response, bit depth, black level and brightness, its share of the depth of
// field. The node's GL renderer builds one per welcome; tests and benches build
// theirs from config::job_for, the same way.

#include <functional>
#include <memory>
#include <optional>

#include <glm/vec3.hpp>

#include "config/job.h"
#include "protocol/focus.h"
#include "protocol/light_share.h"
#include "render/projector_view.h"
#include "render/scene_renderer.h"
#include "scene/definition.h"
#include "scene/state.h"
#include "up/schedule.h"
#include "util/result.h"

namespace optique::render {

struct PipelineOptions {
  DepthFormat depth = DepthFormat::float32;
  // Two-pass projectors render R at this density; 0: the projector's densest.
  double two_pass_pixels_per_metre = 0.0;
  // No blend weights (1 everywhere inside the screen's area): for experiments
  // that look at one projector alone.
  bool blend = true;
  // Samples per pixel (multisampling); 0: the projector's own, which is
  // kFieldSamples with colour fields and 1 without.
  int samples = 0;
  // Per-field colour fields: what does not move drawn once for all fields (when
  // the viewer is still). Off only to measure what it saves.
  bool still_once = true;
};

// A field's edge must land within a fraction of a pixel of where its moment puts
// it, and the other fields' edges are drawn at other moments: one sample per
// pixel would put each channel's edge on a different pixel boundary.
inline constexpr int kFieldSamples = 4;

// Where a frame stands in the display sequence, for a projector that up-
// converts (which frames are key frames): its number, and the states the
// master sent ahead of their frames (interpolation).
struct DisplayFrame {
  std::uint64_t number = 0;
  up::UpSchedule::Ahead ahead;
};

// What the last frame was, for a projector that up-converts.
struct UpReport {
  up::FrameKind kind = up::FrameKind::full;
  up::BetweenReport between;  // a frame between: what no key frame saw
  // A key frame checked against the frame between it replaces (dB PSNR_Y).
  std::optional<double> checked_psnr;
  bool drew_key_ahead = false;  // a later key frame was drawn with it (interpolation)
  int ratio = 1;                // display frames per key frame from now on
  std::string_view why;         // why a key frame was drawn now
};

class ProjectorPipeline {
 public:
  // Needs a current GL context. Fails with the reason (the projector lights none
  // of its screen, a shader or framebuffer the driver refuses).
  [[nodiscard]] static Result<std::unique_ptr<ProjectorPipeline>> make(const config::ProjectorJob& job,
                                                                       const scene::SceneDefinition& scene,
                                                                       const PipelineOptions& options = {});

  // Draws these of the scene's lights from now on, and the ambient and emissive
  // terms if the share carries them. By default: all of it.
  void set_share(const protocol::LightShare& share);
  // The frame's focal depth and gaze (focus/defocus projectors; ignored by others).
  void set_focus(const protocol::Focus& focus);

  // Where this projector's eye is `fraction` of a frame after the frame time of
  // `state` (its eyes' centre and its head's turn then).
  [[nodiscard]] glm::dvec3 eye(const scene::SceneState& state, double fraction) const;
  // Draws the scene in `state` as it is `fraction` of a frame after the display
  // time (objects and the viewer's eyes that far towards their next pose) from
  // this projector's eye. When the eye is not in front of the screen, nothing of
  // the scene can be seen through it: the projector shows black and the reason
  // comes back.
  [[nodiscard]] Result<void> draw(const scene::SceneState& state, double fraction = 0.0);
  // The frame as this projector shows it: with colour fields (a single-chip DLP
  // projector), each field's channel drawn at the moment it is on screen (one
  // render per field, or gathered from one render); else the whole image at the
  // display time. A projector that shows two images per frame (a stereo one used
  // as mono) draws both, one after the other, into the output: `drawn(image)`
  // is called when each is there to read (a capture, the screen simulator), and
  // image_framebuffer() then shows either. An image that cannot be seen (the eye
  // is not in front of the screen) is black, and so is the rest of the frame.
  using ImageDrawn = std::function<void(int image)>;
  // A projector that up-converts (config::UpConversion) draws a key frame or
  // builds the frame between as its schedule says, for display frame `display`
  // (without one: the frame after the last).
  [[nodiscard]] Result<void> draw_frame(const scene::SceneState& state, const ImageDrawn& drawn = {},
                                        const DisplayFrame* display = nullptr);
  [[nodiscard]] const UpReport& up_report() const { return up_report_; }
  // Images per frame: 1, or 2 (config::ColorFields::images).
  [[nodiscard]] int images() const { return color_fields_.images; }
  // Where image `image` of the last frame drawn is, to show it.
  [[nodiscard]] unsigned image_framebuffer(int image) const;
  // What the last frame's gather, or per-field's blur above the velocity
  // threshold, found (zero without either): how fast the scene moved, and
  // whether the gather radius cut a motion short (over all its images).
  [[nodiscard]] const GatherReport& gather_report() const { return gather_report_; }
  // One draw of `state` (every animated object somewhere, so that their
  // programs run too) from a metre in front of the screen, with every pass this
  // projector uses: drivers compile shaders lazily, and the first frame should
  // not pay for it.
  void warm_up(const scene::SceneState& state = {});

  [[nodiscard]] SceneRenderer& renderer() { return *renderer_; }
  [[nodiscard]] const SceneRenderer& renderer() const { return *renderer_; }
  [[nodiscard]] const ProjectorView& view() const { return view_; }
  [[nodiscard]] const optics::ProjectorModel& projector_model() const { return model_; }

 private:
  ProjectorPipeline(ProjectorView view, std::unique_ptr<SceneRenderer> renderer, const config::ProjectorJob& job,
                    optics::ProjectorModel model);
  // Where the scene is seen from `fraction` of a frame after the display time:
  // this projector's eye then, and its frustum through the screen.
  [[nodiscard]] Result<Viewpoint> moment(const scene::SceneState& state, double fraction) const;
  [[nodiscard]] Result<void> draw_image(const scene::SceneState& state, int image);
  // When the gather's one render shows the scene, frame periods from the display time.
  [[nodiscard]] double gather_moment() const;
  // The scene seen `rendered` frame periods after the display time, each
  // surface's velocity over the frame, `image`'s fields as shifts from then.
  [[nodiscard]] Result<GatherFrame> gather_frame(const scene::SceneState& state, int image, double rendered) const;
  void add(const GatherReport& report);  // to the frame's gather_report()
  [[nodiscard]] Result<void> draw_gathered(const scene::SceneState& state, int image);
  [[nodiscard]] Result<void> draw_up_converted(const scene::SceneState& state, const DisplayFrame& display);
  // Frame up-conversion with colour fields: every field of image `image` built
  // from the kept key frames at its own moment (from the key frame this frame
  // draws or shows, or from the frame's two around it: fields_from_).
  [[nodiscard]] Result<void> draw_fields_between(const scene::SceneState& state, int image);
  [[nodiscard]] Result<void> draw_fields_up_converted(const scene::SceneState& state, int image);
  // Image `image`'s fields, each at its moment with its channels; a moment that
  // cannot be seen draws black and fails.
  [[nodiscard]] Result<std::vector<FieldPass>> field_passes(const scene::SceneState& state, int image);

  ProjectorView view_;
  std::unique_ptr<SceneRenderer> renderer_;
  optics::ProjectorModel model_;
  config::Eye eye_;
  config::Viewer viewer_;
  FocusRole focus_role_;
  std::optional<config::DepthOfField> depth_of_field_;
  config::ColorFields color_fields_;
  LightTerms terms_;
  GatherReport gather_report_;
  bool still_once_ = true;
  std::optional<up::UpSchedule> schedule_;  // projectors that up-convert
  std::uint64_t next_frame_ = 0;            // without a DisplayFrame
  UpReport up_report_;
  // This frame's, for every image's fields (draw_fields_between); whether the
  // frame is one between key frames.
  up::BetweenFrame fields_from_;
  bool fields_between_ = false;
};

}  // namespace optique::render
