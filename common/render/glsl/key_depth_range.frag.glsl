// A multisampled key frame's depth per pixel as the nearest and the farthest of
// its samples (render/up_converter.h): a pixel at an edge holds two surfaces,
// and its colour is their mix, so the frames between take it for neither.
// Built with "#version 450 core" first.
layout(binding = 0) uniform sampler2DMS depth_samples;
uniform int samples;
layout(location = 0) out vec2 range;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  float first = texelFetch(depth_samples, p, 0).r;
  range = vec2(first);
  for (int i = 1; i < samples; ++i) {
    float depth = texelFetch(depth_samples, p, i).r;
    range = vec2(min(range.x, depth), max(range.y, depth));
  }
}
