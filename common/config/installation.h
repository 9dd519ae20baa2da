#pragma once
// The installation as the rest of optique sees it: parsed once from its file (or a
// node's welcome) by config/parse.h, checked, defaults applied, references
// resolved. Names are enums, vectors are vectors, every projector's homography is
// known. Strings stay at the edges: the file and the wire (schema::, the
// Protobuf messages of proto/optique/config.proto) and the logs (to_string).

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "config/color_fields.h"
#include "config/defaults.h"
#include "config/navigation.h"
#include "config/response.h"
#include "config/tracking.h"
#include "config/up_conversion.h"
#include "geometry/projection.h"
#include "geometry/projector_geometry.h"
#include "scene/placement.h"
#include "scene/state.h"

namespace optique::config {

using Eye = geometry::Eye;

enum class OutputKind { headless, window };
// "single-pass": the oblique projection (Raskar's method); "two-pass": render the
// viewer's image of the lit rectangle, then warp it.
enum class RenderMethod { single_pass, two_pass };
// What share of the light a projector shows (see Content).
enum class ContentRole { full, lights, focus, defocus };
// A node not ready in time: show the frame without it, or drop the frame everywhere.
enum class StragglerPolicy { present, drop };

// As the file writes them: "left", "two-pass", "defocus", "drop", "window".
[[nodiscard]] std::string_view to_string(Eye eye);
[[nodiscard]] std::string_view to_string(RenderMethod method);
[[nodiscard]] std::string_view to_string(ContentRole role);
[[nodiscard]] std::string_view to_string(StragglerPolicy policy);
[[nodiscard]] std::string_view to_string(OutputKind kind);

// A planar screen: a rectangle in world coordinates (metres). Its own frame has
// the origin at the lower-left corner, x along `right`, y along `up`, z towards
// the viewer (right × up).
struct Screen {
  std::string id;
  glm::dvec3 origin{0.0};
  glm::dvec3 right{1.0, 0.0, 0.0};  // unit
  glm::dvec3 up{0.0, 1.0, 0.0};     // unit, ⟂ right
  double width = 0.0;               // metres
  double height = 0.0;
  double pixels_per_metre = defaults::kPixelsPerMetre;  // reference renders and composites

  // The whole screen: the area that is shown (projectors are black outside it).
  [[nodiscard]] geometry::ScreenRect area() const { return {glm::dvec2(0.0), glm::dvec2(width, height)}; }
  // A rectangle of the screen (metres in its frame) in world space.
  [[nodiscard]] geometry::WorldRect world(const geometry::ScreenRect& part) const;
  [[nodiscard]] geometry::WorldRect world() const { return world(area()); }
  // A point of the screen (metres in its frame) in world space.
  [[nodiscard]] glm::dvec3 point(const glm::dvec2& p) const { return origin + p.x * right + p.y * up; }
};

struct Output {
  OutputKind kind = OutputKind::headless;
  std::uint32_t monitor = 0;  // window: which monitor (0 = primary)
  bool fullscreen = false;
};

// How the config gave a projector's geometry; `homography` holds the result.
enum class GeometrySource { whole_screen, region, homography, calibration, camera };

// Two projectors seen by one camera (see schema::CameraView).
struct CameraView {
  std::string camera;
  glm::dmat3 projector_to_camera{1.0};
};

struct Content {
  ContentRole role = ContentRole::full;
  // Role lights: the scene's lights it draws (ascending, unique; checked against
  // the scene when it is loaded), or, when `automatic`, the master's share.
  bool automatic = false;
  std::vector<std::uint32_t> lights;
  bool ambient = false;  // role lights: it carries ambient and emissive light
  // Role defocus: its optics' largest circle of confusion, screen pixels.
  double blur_radius = 0.0;

  friend bool operator==(const Content&, const Content&) = default;
};

struct Projector {
  std::string id;
  std::string host = "localhost";
  int width = 0;  // pixels
  int height = 0;
  std::size_t screen = 0;  // index into the installation's screens
  Eye eye = Eye::mono;
  Output output;
  GeometrySource geometry_source = GeometrySource::whole_screen;
  std::optional<geometry::ScreenRect> region;  // an aligned projector's rectangle
  // Screen metres (the screen's own frame) → projector pixels (top-left origin,
  // y down, pixel centres at half-integers). Always set; for an aligned projector
  // it is the region's.
  glm::dmat3 homography{1.0};
  std::optional<CameraView> camera;
  RenderMethod rendering = RenderMethod::single_pass;
  double blend_ramp = 0.0;  // metres of roll-off inside its edges; 0: across the whole overlap
  ProjectorResponse response;
  Content content;
  ColorFields color_fields;    // a single-chip DLP projector's colour fields; empty: all colours at once
  UpConversion up_conversion;  // key frames and the frames built between them; ratio 1: every frame rendered

  // Its geometry on the screen (checked when parsed: this cannot fail then).
  [[nodiscard]] geometry::ProjectorGeometry geometry() const;
};

struct PathPoint {
  double time = 0.0;  // seconds of simulation time, increasing
  glm::dvec3 position{0.0};
};

struct Viewer {
  // The centre of the eyes: one point (fixed), or a path, linear between its
  // points and looped over its duration.
  std::vector<PathPoint> path;
  double eye_separation = defaults::kEyeSeparation;
  double near = defaults::kNear;  // metres from the eye
  double far = defaults::kFar;
  // Unit vector from the left eye to the right, as the head is at rest (with
  // tracking: in the tracked body's own frame); the scene state's head
  // orientation turns it.
  glm::dvec3 head_right{1.0, 0.0, 0.0};
  // A tracked head: the master predicts it at each frame's display time, and
  // eye/path are where it rests while the tracker is lost.
  std::optional<Tracking> tracking;
  // Built-in navigation (none unless viewer.navigation says flystick).
  std::optional<Navigation> navigation;

  [[nodiscard]] glm::dvec3 eye_at(double seconds) const;
  [[nodiscard]] bool moves() const { return path.size() > 1; }
  // Where `eye` is `fraction` of a frame after `state`'s frame time: the eyes'
  // centre then, apart along head_right turned with the head.
  [[nodiscard]] glm::dvec3 eye_in(const scene::SceneState& state, double fraction, Eye eye) const;
};

// master.status: the operator's page, status and metrics over HTTP.
struct StatusServer {
  std::string listen = "127.0.0.1";
  std::uint16_t port = defaults::kStatusPort;  // 0: ephemeral
  std::uint32_t max_connections = defaults::kStatusMaxConnections;
};

// master.api: the scene session, where applications edit the live scene.
struct ApiServer {
  std::string listen = "127.0.0.1";
  std::uint16_t port = defaults::kApiPort;  // 0: ephemeral
  std::uint32_t max_sessions = defaults::kApiMaxSessions;
  std::uint32_t max_edits_per_frame = defaults::kApiMaxEditsPerFrame;
  std::uint32_t max_instances = defaults::kApiMaxInstances;
  // The folder LoadAsset's paths are in (absolute): the config's folder by default.
  std::string assets;
};

struct MasterSettings {
  std::string listen = "0.0.0.0";
  std::uint16_t port = 0;  // 0: ephemeral
  double frame_rate = defaults::kFrameRate;
  std::chrono::milliseconds frame_timeout{defaults::kFrameTimeoutMs};
  std::chrono::milliseconds startup_timeout{defaults::kStartupTimeoutMs};
  std::chrono::milliseconds handshake_timeout{defaults::kHandshakeTimeoutMs};
  std::chrono::milliseconds heartbeat{defaults::kHeartbeatMs};
  std::chrono::milliseconds liveness_timeout{defaults::kMinLivenessTimeoutMs};
  std::chrono::microseconds present_lead{defaults::kPresentLeadUs};
  std::uint32_t max_message_bytes = defaults::kMaxMessageBytes;
  std::string secret_file;  // as written, relative to the config file; empty: none
  std::uint32_t max_pending_connections = defaults::kMaxPendingConnections;
  StragglerPolicy straggler_policy = StragglerPolicy::present;
  std::optional<StatusServer> status;
  std::optional<ApiServer> api;  // none: no application can connect
  // The share of frames every projector must show for the run to succeed;
  // none: at least one frame shown by any projector.
  std::optional<double> min_presented;
};

// At `time`, these of the scene's point lights go dark and these come on again.
struct LightSwitch {
  double time = 0.0;
  std::vector<std::uint32_t> off;  // ascending, unique
  std::vector<std::uint32_t> on;
};

struct SceneSource {
  std::string builtin;                        // a procedural scene by name, or
  std::string gltf;                           // a glTF file, absolute
  std::vector<LightSwitch> light_switches;    // in time order
  std::optional<scene::Placement> placement;  // of the glTF model; none: as the file has it
};

struct FocusPoint {
  double time = 0.0;
  double depth = 0.0;  // metres from the eye along the screen's normal
};

struct GazePoint {
  double time = 0.0;
  glm::dvec2 point{0.0};  // metres in the screen's frame
};

// Where the viewer looks: a point of a screen, fixed (one point) or moving.
struct Gaze {
  std::size_t screen = 0;  // index into the installation's screens
  std::vector<GazePoint> path;

  [[nodiscard]] glm::dvec2 at(double seconds) const;
};

// Depth of field by optics (a focus/defocus pair). The focal depth of a frame
// comes from exactly one of `focal_depth`, `focal_path` and `gaze`.
struct DepthOfField {
  std::optional<double> focal_depth;
  std::vector<FocusPoint> focal_path;
  std::optional<Gaze> gaze;
  double near = defaults::kNear;  // where the relative circle of confusion reaches 1
  double far = defaults::kFar;
  double inset_radius = 0.0;  // > 0: the focused-inset variant, metres
};

struct Installation {
  std::string name;
  std::vector<Screen> screens;
  std::vector<Projector> projectors;
  Viewer viewer;
  MasterSettings master;
  SceneSource scene;
  std::optional<DepthOfField> depth_of_field;

  [[nodiscard]] const Screen& screen_of(const Projector& projector) const { return screens[projector.screen]; }
  // The projector with this id, if there is one.
  [[nodiscard]] std::optional<std::size_t> find_projector(std::string_view id) const;
};

}  // namespace optique::config
