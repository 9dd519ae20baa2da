#include "node/gl/gl_renderer.h"

#include "config/to_schema.h"
#include "image/texture_decode.h"
#include "scene_load/installation_scene.h"
#include "scene_load/load_scene.h"

namespace optique::node {

GlRenderer::GlRenderer(spdlog::logger& log, std::string capture_folder)
    : log_(log), capture_folder_(std::move(capture_folder)) {}

GlRenderer::~GlRenderer() {
  captures_.reset();  // finish writing before the GL objects go
  pipeline_.reset();
  context_.reset();
}

Result<void> GlRenderer::configure(const protocol::NodeJob& node) {
  const config::ProjectorJob& job = node.job;
  const config::Projector& projector = job.self();
  const std::string key = config::to_schema(job.installation).SerializeAsString() + node.scene_sha256;
  ahead_.clear();  // sent ahead by the master before: a (re)join starts over
  last_frame_.reset();
  const auto add_assets = [&]() -> Result<void> {
    for (const protocol::AssetOffer& asset : node.assets) {
      if (assets_.contains(asset.asset)) continue;
      auto read = read_asset(asset);
      if (!read) return Error{read.error()};
      if (auto added = add_asset(asset, *read.value()); !added) return added;
    }
    return {};
  };
  if (key == configured_for_ && pipeline_) {  // a rejoin: the same job, keep everything
    if (node.lights) pipeline_->set_share(*node.lights);
    return add_assets();
  }

  // A glTF scene is read from this node's copy of the master's files.
  auto loaded = config::load_scene(job.installation, image::decode_texture, node.scene_path);
  if (!loaded) return Error{"cannot load the scene: " + loaded.error()};
  const scene::LoadedScene& scene = loaded.value();
  if (scene.content_sha256 != node.scene_sha256) {
    return Error{"the scene " + scene.source + " is not the master's (sha256 " + scene.content_sha256.substr(0, 12) +
                 "… here, " + node.scene_sha256.substr(0, 12) + "… on the master)"};
  }
  if (scene.definition.lights.size() != node.light_count) {
    return Error{"the scene " + scene.source + " has " + std::to_string(scene.definition.lights.size()) +
                 " lights here and " + std::to_string(node.light_count) + " on the master"};
  }
  for (const auto& warning : scene.warnings) log_.warn("scene: {}", warning);

  pipeline_.reset();
  context_.reset();
  auto context =
      projector.output.kind == config::OutputKind::window
          ? render::make_window_context("optique " + projector.id, projector.width, projector.height,
                                        static_cast<int>(projector.output.monitor), projector.output.fullscreen)
          : render::make_headless_context();
  if (!context) return Error{context.error()};
  context_ = std::move(context).value();
  auto pipeline = render::ProjectorPipeline::make(job, scene.definition);
  if (!pipeline) return Error{pipeline.error()};
  pipeline_ = std::move(pipeline).value();
  assets_.clear();
  if (auto added = add_assets(); !added) return added;
  if (node.lights) pipeline_->set_share(*node.lights);
  deep_signal_ = pipeline_->projector_model().settings().bits > 8;
  gathers_ = projector.color_fields.gathers();
  // Every animated object where it starts: the warm-up runs the programs the
  // first frame runs.
  scene::SceneState start;
  for (const scene::AnimatedObject& object : scene.definition.objects) {
    const scene::Pose pose = object.pose_at(0.0);
    start.objects.emplace(object.id, scene::ObjectState{pose, pose});
  }
  start.eye_now = start.eye_next = job.installation.viewer.eye_at(0.0);
  const clock::Nanos warm_up_started = clock::monotonic_now();
  pipeline_->warm_up(start);
  const clock::Nanos drawn = clock::monotonic_now();
  // A captured frame is read back before it is ready, so it is that much later:
  // each of its images (a stereo projector used as mono draws two).
  (void)read_back();
  warm_up_ = {drawn - warm_up_started, (clock::monotonic_now() - drawn) * pipeline_->images()};
  if (!captures_) captures_.emplace(capture_folder_, log_);
  configured_for_ = key;
  const render::ProjectorView& view = pipeline_->view();
  log_.info("rendering {} with {} ({}), {}×{} px, {}", scene.source, context_->renderer_name(),
            context_->has_window() ? "window" : "headless", projector.width, projector.height,
            view.method() == render::RenderMethod::two_pass
                ? "two passes (" + std::to_string(view.render_width()) + "×" + std::to_string(view.render_height()) +
                      " px, then warped)"
                : "single pass");
  return {};
}

Result<std::shared_ptr<const scene::SceneDefinition>> GlRenderer::read_asset(const protocol::AssetOffer& asset) const {
  auto loaded = config::load_asset(asset.asset, asset.path, image::decode_texture, asset.sha256);
  if (!loaded) return Error{"cannot load the asset '" + asset.asset + "': " + loaded.error()};
  for (const auto& warning : loaded.value().warnings) log_.warn("asset '{}': {}", asset.asset, warning);
  return std::make_shared<const scene::SceneDefinition>(std::move(loaded.value().definition));
}

Result<void> GlRenderer::add_asset(const protocol::AssetOffer& asset, const scene::SceneDefinition& read) {
  const clock::Nanos started = clock::monotonic_now();
  if (auto added = pipeline_->renderer().add_asset(read); !added) return added;
  assets_.insert(asset.asset);
  log_.info("the asset '{}' is ready to draw ({} mesh(es), {} texture(s); uploaded in {:.1f} ms)", asset.asset,
            read.meshes.size(), read.textures.size(), static_cast<double>(clock::monotonic_now() - started) / 1e6);
  return {};
}

GlRenderer::ReadBack GlRenderer::read_back() const {
  const render::SceneRenderer& renderer = pipeline_->renderer();
  return {renderer.output().read_linear(), deep_signal_ ? image::ByteImage{} : renderer.output().read_encoded(),
          deep_signal_ ? renderer.output().read_signal() : image::WordImage{}};
}

std::string GlRenderer::description() const {
  if (!context_) return "OpenGL (not configured)";
  return context_->renderer_name() + (context_->has_window() ? ", window" : ", headless");
}

Rendered GlRenderer::render(const FrameInput& frame) {
  read_back_shown_.reset();  // a captured frame that was never presented (stale) has no read-back
  take_along(frame);
  // Each image captured as it is drawn (a stereo projector used as mono draws two).
  const auto capture = [&](int image) {
    if (!frame.capture) return;
    ReadBack read = read_back();
    captures_->submit(frame.frame_id, image, std::move(read.linear), std::move(read.encoded), std::move(read.signal));
  };
  const render::DisplayFrame display{frame.frame_id, [this](std::uint64_t f) -> const scene::SceneState* {
                                       const auto found = ahead_.find(f);
                                       return found == ahead_.end() ? nullptr : &found->second;
                                     }};
  if (auto drawn = pipeline_->draw_frame(*frame.state, capture, &display); !drawn) {
    // The eye left the space in front of this screen: the projector shows black
    // rather than a wrong picture (from the image where it left on).
    log_.debug("frame {}: {}", frame.frame_id, drawn.error());
  }
  if (const render::GatherReport& gather = pipeline_->gather_report(); gather.clamped && !warned_gather_radius_) {
    warned_gather_radius_ = true;  // once: it would repeat every frame of the motion
    if (gathers_) {
      log_.warn(
          "frame {}: the scene moves {:.1f} px per frame; the gather moves a surface at most {} px per colour "
          "field, so faster motion is cut short there (its fields lag; method per-field has no such limit)",
          frame.frame_id, gather.fastest, render::kGatherRadius);
    } else {
      log_.warn(
          "frame {}: the scene moves {:.1f} px per frame; the motion blur above velocity_threshold spreads a "
          "surface at most {} px either way, so it is shorter than the motion there (the fields are not limited)",
          frame.frame_id, gather.fastest, render::kGatherRadius);
    }
  }
  if (frame.capture && context_->has_window()) read_back_shown_ = frame.frame_id;
  const render::UpReport& up = pipeline_->up_report();
  if (up.kind == up::FrameKind::full) return {};
  if (up.kind == up::FrameKind::key && up.why != "ratio" && up.why != "first frame") {
    log_.debug("frame {}: a key frame now ({})", frame.frame_id, up.why);
  }
  if (up.ratio != logged_ratio_) {
    if (logged_ratio_ != 0) {
      log_.info("frame {}: a key frame every {} frames from now (the frames between checked at {:.1f} dB PSNR_Y)",
                frame.frame_id, up.ratio, up.checked_psnr.value_or(0.0));
    }
    logged_ratio_ = up.ratio;
  }
  return {up.kind, up.kind == up::FrameKind::between && up.drew_key_ahead};
}

// A new share comes once, with the frame it starts at: taken even when this
// frame shows nothing or is skipped, so it is not lost; so is a scene sent ahead.
void GlRenderer::take_along(const FrameInput& frame) {
  if (frame.lights != nullptr) pipeline_->set_share(*frame.lights);
  if (frame.focus) pipeline_->set_focus(*frame.focus);
  if (last_frame_ && frame.frame_id <= *last_frame_) ahead_.clear();
  last_frame_ = frame.frame_id;
  if (frame.ahead != nullptr) ahead_[frame.ahead_frame] = *frame.ahead;
  while (!ahead_.empty() && ahead_.begin()->first < frame.frame_id) ahead_.erase(ahead_.begin());
}

void GlRenderer::skip(const FrameInput& frame) {
  read_back_shown_.reset();
  take_along(frame);
}

void GlRenderer::present(int image) {
  const unsigned framebuffer = pipeline_->image_framebuffer(image);
  const render::SceneRenderer& renderer = pipeline_->renderer();
  if (!read_back_shown_ || image != 0) {  // a window's read-back: of the frame's first image
    context_->present(framebuffer, renderer.output().width(), renderer.output().height());
    return;
  }
  image::ByteImage shown;
  context_->present(framebuffer, renderer.output().width(), renderer.output().height(), &shown);
  captures_->submit_shown(*read_back_shown_, std::move(shown));
  read_back_shown_.reset();
}

void GlRenderer::show_black() {
  if (!pipeline_) return;    // not configured yet: nothing is on the projector
  read_back_shown_.reset();  // black is not the captured frame
  render::SceneRenderer& renderer = pipeline_->renderer();
  renderer.draw_black();
  context_->present(renderer.output().framebuffer(), renderer.output().width(), renderer.output().height());
}

}  // namespace optique::node
