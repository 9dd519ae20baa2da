// A frame between key frames from the key frames' pixels (render/up_converter.h).
// motion: each pixel's surface was at motion_k.xy in key frame k; the key
// frame's four pixels around there are weighted by how much of a pixel-sized
// square at that point each covers (bilinear weights: overlap, falling with
// distance, as the up-conversion paper weighs them), those that saw another
// surface there left out. Two key frames mix by the frame's time between them.
// A pixel no key frame saw shows key 0's pixel at its place, alpha 0 (marked,
// to be shaded anew). average: the same pixel of both, half each.
// Built with "#version 450 core" first.
layout(binding = 0) uniform sampler2D key_colour_0;
layout(binding = 1) uniform sampler2D key_colour_1;
layout(binding = 2) uniform sampler2D key_depth_0;
layout(binding = 3) uniform sampler2D key_depth_1;
layout(binding = 4) uniform sampler2D motion_0;
layout(binding = 5) uniform sampler2D motion_1;
uniform int method;  // 0: motion, 1: average
uniform int keys;    // 1 or 2
uniform float toward_second;
uniform vec3 background;
layout(location = 0) out vec4 colour;

// The key frame's colour there times the weight that saw the same surface, and that weight.
vec4 taken(sampler2D key_colour, sampler2D key_depth, vec4 seen) {
  if (seen.w < 0.0) return vec4(0.0);
  vec2 p = seen.xy - 0.5;  // texel centres at integers
  vec2 corner = floor(p);
  vec2 f = p - corner;
  ivec2 base = ivec2(corner);
  ivec2 size = textureSize(key_colour, 0);
  vec4 sum = vec4(0.0);
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      ivec2 t = base + ivec2(i, j);
      float w = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y);
      if (w <= 0.0 || any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, size))) continue;
      if (abs(texelFetch(key_depth, t, 0).r - seen.z) > seen.w) continue;
      sum += vec4(w * texelFetch(key_colour, t, 0).rgb, w);
    }
  }
  return sum;
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec3 here_0 = texelFetch(key_colour_0, p, 0).rgb;
  if (method == 1) {
    colour = vec4(0.5 * (here_0 + texelFetch(key_colour_1, p, 0).rgb), 1.0);
    return;
  }
  vec4 seen_0 = texelFetch(motion_0, p, 0);
  if (seen_0.w < -1.5) {  // no surface: the background, as every key frame shows it
    colour = vec4(background, 1.0);
    return;
  }
  vec4 a = taken(key_colour_0, key_depth_0, seen_0);
  vec4 b = keys == 2 ? taken(key_colour_1, key_depth_1, texelFetch(motion_1, p, 0)) : vec4(0.0);
  const float kSeen = 1e-6;
  float t = keys == 2 ? toward_second : 0.0;
  if (a.w > kSeen && b.w > kSeen) {
    colour = vec4(((1.0 - t) * a.rgb + t * b.rgb) / ((1.0 - t) * a.w + t * b.w), 1.0);
  } else if (a.w > kSeen) {
    colour = vec4(a.rgb / a.w, 1.0);
  } else if (b.w > kSeen) {
    colour = vec4(b.rgb / b.w, 1.0);
  } else {
    colour = vec4(here_0, 0.0);
  }
}
