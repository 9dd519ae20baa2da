#include "protocol/frame_message.h"

#include <fmt/format.h>

#include "config/up_conversion.h"
#include "protocol/welcome.h"

namespace optique::protocol {

Result<FrameMessage> decode_frame_begin(const wire::FrameBegin& begin, std::uint32_t light_count) {
  const auto failed = [&](const std::string& what) {
    return Error{fmt::format("frame {}: {}", begin.frame_id(), what)};
  };
  FrameMessage frame;
  frame.frame_id = begin.frame_id();
  frame.simulation_time = begin.simulation_time_ns();
  frame.present_time = begin.present_time_ns();
  frame.capture = begin.capture();
  frame.skip = begin.skip();
  if (begin.has_focus()) {
    auto focus = decode_focus(begin.focus());
    if (!focus) return failed(focus.error());
    frame.focus = focus.value();
  }
  if (begin.has_lights()) {
    auto share = decode_light_share(begin.lights(), light_count);
    if (!share) return failed("lights: " + share.error());
    frame.lights = std::move(share).value();
  }
  if (begin.has_ahead()) {
    const std::uint64_t on = begin.ahead_frame() - begin.frame_id();
    if (begin.ahead_frame() <= begin.frame_id() || on > static_cast<std::uint64_t>(config::kMostFramesAhead)) {
      return failed(fmt::format("the scene sent ahead is for frame {}, not 1…{} frames on", begin.ahead_frame(),
                                config::kMostFramesAhead));
    }
    auto ahead = scene::from_snapshot(begin.ahead());
    if (!ahead) return failed("the scene sent ahead: " + ahead.error());
    frame.ahead = std::move(ahead).value();
    frame.ahead_frame = begin.ahead_frame();
  }
  return frame;
}

}  // namespace optique::protocol
