#include "clients/cpp/transaction.h"

namespace optique::client {
namespace {

void place(session::Transform& out, const Placement& placement) {
  if (placement.position) out.mutable_position()->Add(placement.position->begin(), placement.position->end());
  if (placement.rotation) out.mutable_rotation()->Add(placement.rotation->begin(), placement.rotation->end());
  if (placement.scale) out.mutable_scale()->Add(placement.scale->begin(), placement.scale->end());
}

}  // namespace

Transaction& Transaction::create(const std::string& instance, const std::string& asset, const Placement& placement,
                                 const std::string& parent, bool hidden) {
  auto& c = *message_.add_edits()->mutable_create();
  c.set_instance(instance);
  c.set_asset(asset);
  c.set_parent(parent);
  c.set_hidden(hidden);
  place(*c.mutable_transform(), placement);
  return *this;
}

Transaction& Transaction::move(const std::string& instance, const Placement& placement) {
  auto& t = *message_.add_edits()->mutable_transform();
  t.set_instance(instance);
  place(*t.mutable_transform(), placement);
  return *this;
}

Transaction& Transaction::navigate(const Placement& placement) {
  place(*message_.add_edits()->mutable_navigation()->mutable_transform(), placement);
  return *this;
}

Transaction& Transaction::switch_light(std::uint32_t light, bool on) {
  auto& l = *message_.add_edits()->mutable_light();
  l.set_light(light);
  l.set_on(on);
  return *this;
}

Transaction& Transaction::point_light(std::uint32_t light, std::optional<std::array<double, 3>> position,
                                      std::optional<std::array<double, 3>> colour, std::optional<double> intensity) {
  auto& l = *message_.add_edits()->mutable_point_light();
  l.set_light(light);
  if (position) l.mutable_position()->Add(position->begin(), position->end());
  if (colour) l.mutable_colour()->Add(colour->begin(), colour->end());
  if (intensity) l.set_intensity(*intensity);
  return *this;
}

Transaction& Transaction::remove_point_light(std::uint32_t light) {
  message_.add_edits()->mutable_remove_point_light()->set_light(light);
  return *this;
}

Transaction& Transaction::animate(const std::string& instance, std::optional<bool> playing,
                                  std::optional<double> seek) {
  auto& a = *message_.add_edits()->mutable_animation();
  a.set_instance(instance);
  if (playing) a.set_playing(*playing);
  if (seek) a.set_seek(*seek);
  return *this;
}

Transaction& Transaction::reparent(const std::string& instance, const std::string& parent) {
  auto& p = *message_.add_edits()->mutable_parent();
  p.set_instance(instance);
  p.set_parent(parent);
  return *this;
}

Transaction& Transaction::show(const std::string& instance, bool visible) {
  auto& v = *message_.add_edits()->mutable_visible();
  v.set_instance(instance);
  v.set_visible(visible);
  return *this;
}

Transaction& Transaction::tint(const std::string& instance, const std::array<double, 4>& base_color) {
  auto& f = *message_.add_edits()->mutable_factors();
  f.set_instance(instance);
  f.mutable_base_color()->Add(base_color.begin(), base_color.end());
  return *this;
}

Transaction& Transaction::glow(const std::string& instance, const std::array<double, 3>& emissive) {
  auto& f = *message_.add_edits()->mutable_factors();
  f.set_instance(instance);
  f.mutable_emissive()->Add(emissive.begin(), emissive.end());
  return *this;
}

Transaction& Transaction::remove(const std::string& instance) {
  message_.add_edits()->mutable_remove()->set_instance(instance);
  return *this;
}

}  // namespace optique::client
