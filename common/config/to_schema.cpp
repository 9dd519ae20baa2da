#include "config/to_schema.h"

#include "config/light_list.h"

namespace optique::config {
namespace {

void put(google::protobuf::RepeatedField<double>& out, const glm::dvec3& v) {
  out.Clear();
  out.Add(v.x);
  out.Add(v.y);
  out.Add(v.z);
}

void put(google::protobuf::RepeatedField<double>& out, const glm::dvec2& v) {
  out.Clear();
  out.Add(v.x);
  out.Add(v.y);
}

}  // namespace

schema::Screen to_schema(const Screen& screen) {
  schema::Screen out;
  out.set_id(screen.id);
  put(*out.mutable_origin(), screen.origin);
  put(*out.mutable_right(), screen.right);
  put(*out.mutable_up(), screen.up);
  out.set_width(screen.width);
  out.set_height(screen.height);
  out.set_pixels_per_metre(screen.pixels_per_metre);
  return out;
}

schema::Projector to_schema(const Projector& p, const std::vector<Screen>& screens) {
  schema::Projector out;
  out.set_id(p.id);
  out.set_host(p.host);
  out.set_width(static_cast<std::uint32_t>(p.width));
  out.set_height(static_cast<std::uint32_t>(p.height));
  out.set_screen(screens.at(p.screen).id);
  if (p.region) {
    auto& r = *out.mutable_region();
    r.set_x(p.region->min.x);
    r.set_y(p.region->min.y);
    r.set_width(p.region->width());
    r.set_height(p.region->height());
  } else {
    for (double v : geometry::homography_rows(p.homography)) out.add_homography(v);
  }
  out.mutable_output()->set_kind(std::string(to_string(p.output.kind)));
  out.mutable_output()->set_monitor(p.output.monitor);
  out.mutable_output()->set_fullscreen(p.output.fullscreen);
  out.set_eye(std::string(to_string(p.eye)));
  out.set_rendering(std::string(to_string(p.rendering)));
  out.set_blend_ramp(p.blend_ramp);
  auto& response = *out.mutable_response();
  switch (p.response.curve) {
    case ResponseCurve::gamma:
      response.set_gamma(p.response.gamma);
      break;
    case ResponseCurve::table:
      response.mutable_table()->Add(p.response.table.begin(), p.response.table.end());
      break;
    case ResponseCurve::srgb:
      break;
  }
  response.set_bits(static_cast<std::uint32_t>(p.response.bits));
  out.set_black_level(p.response.black_level);
  out.set_brightness(p.response.brightness);
  auto& content = *out.mutable_content();
  content.set_role(std::string(to_string(p.content.role)));
  if (p.content.role == ContentRole::lights) {
    content.set_lights(p.content.automatic ? "auto" : format_light_list(p.content.lights));
    content.set_ambient(p.content.ambient);
  }
  content.set_blur_radius(p.content.blur_radius);
  if (!p.color_fields.fields.empty()) {  // the fields themselves, a preset expanded
    auto& fields = *out.mutable_color_fields();
    for (const ColorField& f : p.color_fields.fields) {
      auto& field = *fields.add_fields();
      field.set_channel(std::string(to_string(f.channel)));
      field.set_image(static_cast<std::uint32_t>(f.image));
      field.set_offset(f.offset);
      field.set_duration(f.duration);
    }
    fields.set_method(std::string(to_string(p.color_fields.method)));
    fields.set_velocity_threshold(p.color_fields.velocity_threshold);
    fields.set_gather_samples(static_cast<std::uint32_t>(p.color_fields.gather_samples));
  }
  if (p.up_conversion.enabled()) {
    auto& up = *out.mutable_up_conversion();
    up.set_ratio(static_cast<std::uint32_t>(p.up_conversion.ratio));
    up.set_method(std::string(to_string(p.up_conversion.method)));
    up.set_mode(std::string(to_string(p.up_conversion.mode)));
    // Method average keeps its ratio fixed: a floor there is refused, not ignored.
    if (p.up_conversion.method == UpMethod::motion) up.set_min_psnr(p.up_conversion.min_psnr);
    up.set_spread(p.up_conversion.spread);
  }
  return out;
}

schema::Viewer to_schema(const Viewer& viewer) {
  schema::Viewer out;
  if (viewer.path.size() == 1) {
    put(*out.mutable_eye(), viewer.path.front().position);
  } else {
    for (const PathPoint& point : viewer.path) {
      auto& p = *out.add_path();
      p.set_time(point.time);
      put(*p.mutable_position(), point.position);
    }
  }
  out.set_eye_separation(viewer.eye_separation);
  out.set_near(viewer.near);
  out.set_far(viewer.far);
  put(*out.mutable_head_right(), viewer.head_right);
  if (viewer.tracking) *out.mutable_tracking() = to_schema(*viewer.tracking);
  if (viewer.navigation) {
    const Navigation& n = *viewer.navigation;
    auto& to = *out.mutable_navigation();
    to.set_mode(std::string(to_string(n.mode)));
    to.set_flystick(n.flystick);
    to.set_speed(n.speed);
    to.set_turn_speed(n.turn_speed);
    to.set_reset_button(n.reset_button);
    to.set_dead_zone(n.dead_zone);
    put(*to.mutable_up(), n.up);
    put(*to.mutable_pointer(), n.pointer);
  }
  return out;
}

schema::Tracking to_schema(const Tracking& tracking) {
  schema::Tracking out;
  out.set_source(std::string(to_string(tracking.source)));
  out.set_listen(tracking.listen);
  out.set_from(tracking.from);
  out.set_port(tracking.port);
  out.set_file(tracking.file);
  out.set_body(tracking.body);
  put(*out.mutable_tracker_origin(), tracking.tracker_origin);
  put(*out.mutable_tracker_axes()->mutable_x(), tracking.tracker_axes[0]);
  put(*out.mutable_tracker_axes()->mutable_y(), tracking.tracker_axes[1]);
  put(*out.mutable_tracker_axes()->mutable_z(), tracking.tracker_axes[2]);
  put(*out.mutable_eye_offset(), tracking.eye_offset);
  out.set_prediction(std::string(to_string(tracking.prediction)));
  out.set_smoothing(tracking.smoothing);
  out.set_latency_ms(static_cast<double>(tracking.latency.count()) / 1000.0);
  out.set_lost_after_ms(static_cast<std::uint32_t>(tracking.lost_after.count()));
  out.set_hold_ms(static_cast<std::uint32_t>(tracking.hold.count()));
  out.set_ease_ms(static_cast<std::uint32_t>(tracking.ease.count()));
  return out;
}

schema::Scene to_schema(const SceneSource& scene) {
  schema::Scene out;
  out.set_builtin(scene.builtin);
  out.set_gltf(scene.gltf);
  for (const LightSwitch& entry : scene.light_switches) {
    auto& s = *out.add_light_switches();
    s.set_time(entry.time);
    s.set_off(format_light_list(entry.off));
    s.set_on(format_light_list(entry.on));
  }
  if (scene.placement) {
    const scene::Placement& placed = *scene.placement;
    auto& p = *out.mutable_placement();
    for (double v : {placed.rotation.w, placed.rotation.x, placed.rotation.y, placed.rotation.z}) p.add_rotation(v);
    if (placed.fit) {
      for (int i = 0; i < 3; ++i) {
        p.mutable_fit()->add_centre(placed.fit->centre[i]);
        p.mutable_fit()->add_size(placed.fit->size[i]);
      }
    } else {
      for (int i = 0; i < 3; ++i) p.add_position(placed.position[i]);
      p.set_scale(placed.scale);
    }
  }
  return out;
}

schema::MasterSettings to_schema(const MasterSettings& m) {
  schema::MasterSettings out;
  out.set_listen(m.listen);
  out.set_port(m.port);
  out.set_frame_rate(m.frame_rate);
  out.set_frame_timeout_ms(static_cast<std::uint32_t>(m.frame_timeout.count()));
  out.set_startup_timeout_ms(static_cast<std::uint32_t>(m.startup_timeout.count()));
  out.set_handshake_timeout_ms(static_cast<std::uint32_t>(m.handshake_timeout.count()));
  out.set_heartbeat_ms(static_cast<std::uint32_t>(m.heartbeat.count()));
  out.set_liveness_timeout_ms(static_cast<std::uint32_t>(m.liveness_timeout.count()));
  out.set_present_lead_us(static_cast<std::uint32_t>(m.present_lead.count()));
  out.set_max_message_bytes(m.max_message_bytes);
  out.set_secret_file(m.secret_file);
  out.set_max_pending_connections(m.max_pending_connections);
  out.set_straggler_policy(std::string(to_string(m.straggler_policy)));
  if (m.min_presented) out.set_min_presented(*m.min_presented);
  if (m.status) {
    schema::StatusServer& status = *out.mutable_status();
    status.set_listen(m.status->listen);
    status.set_port(m.status->port);
    status.set_max_connections(m.status->max_connections);
  }
  if (m.api) {
    schema::ApiServer& api = *out.mutable_api();
    api.set_listen(m.api->listen);
    api.set_port(m.api->port);
    api.set_max_sessions(m.api->max_sessions);
    api.set_max_edits_per_frame(m.api->max_edits_per_frame);
    api.set_max_instances(m.api->max_instances);
    api.set_assets(m.api->assets);
  }
  return out;
}

schema::DepthOfField to_schema(const DepthOfField& d, const std::vector<Screen>& screens) {
  schema::DepthOfField out;
  if (d.focal_depth) out.set_focal_depth(*d.focal_depth);
  for (const FocusPoint& point : d.focal_path) {
    auto& p = *out.add_focal_path();
    p.set_time(point.time);
    p.set_depth(point.depth);
  }
  if (d.gaze) {
    auto& gaze = *out.mutable_gaze();
    gaze.set_screen(screens.at(d.gaze->screen).id);
    if (d.gaze->path.size() == 1) {
      put(*gaze.mutable_point(), d.gaze->path.front().point);
    } else {
      for (const GazePoint& point : d.gaze->path) {
        auto& p = *gaze.add_path();
        p.set_time(point.time);
        put(*p.mutable_point(), point.point);
      }
    }
  }
  out.set_near(d.near);
  out.set_far(d.far);
  out.set_inset_radius(d.inset_radius);
  return out;
}

schema::Installation to_schema(const Installation& installation) {
  schema::Installation out;
  out.set_name(installation.name);
  for (const Screen& s : installation.screens) *out.add_screens() = to_schema(s);
  for (const Projector& p : installation.projectors) *out.add_projectors() = to_schema(p, installation.screens);
  *out.mutable_viewer() = to_schema(installation.viewer);
  *out.mutable_master() = to_schema(installation.master);
  *out.mutable_scene() = to_schema(installation.scene);
  if (installation.depth_of_field) {
    *out.mutable_depth_of_field() = to_schema(*installation.depth_of_field, installation.screens);
  }
  return out;
}

}  // namespace optique::config
