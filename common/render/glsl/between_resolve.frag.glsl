// A frame between key frames from the key frames' pixels (render/up_converter.h).
// motion: each pixel's surface was at motion_k.xy in key frame k; the key
// frame's four pixels around there are weighted by how much of a pixel-sized
// square at that point each covers (bilinear weights: overlap, falling with
// distance, as the up-conversion paper weighs them), those that saw another
// surface there (or beyond the image's edge, where the key frame's edge pixel
// stands in) left out. Two key frames mix by the frame's time between them.
// A pixel no key frame saw is discarded: left unmarked in the stencil, to be
// shaded anew (up_converter.h); until then it holds the last frame's output.
// Every such pixel is drawn again, as the scene's program discards nothing.
// average: the same pixel of both, half each (of one across a cut).
// Built with "#version 450 core", AVERAGE 0 or 1 and KEYS 1 or 2 first (one
// program each: a branch on a uniform still costs llvmpipe both sides).
layout(binding = 0) uniform sampler2D key_colour_0;
layout(binding = 1) uniform sampler2D key_colour_1;
layout(binding = 2) uniform sampler2D key_depth_0;
layout(binding = 3) uniform sampler2D key_depth_1;
layout(binding = 4) uniform sampler2D motion_0;
layout(binding = 5) uniform sampler2D motion_1;
uniform float toward_second;
uniform vec3 background;
layout(location = 0) out vec4 colour;

// The key frame's colour there times the weight that saw the same surface, and
// that weight. Where all four saw it (most pixels), one bilinear fetch.
vec4 taken(sampler2D key_colour, sampler2D key_depth, vec4 seen) {
  vec2 size = vec2(textureSize(key_colour, 0));
  if (seen.w < 0.0 || any(lessThan(seen.xy, vec2(0.0))) || any(greaterThan(seen.xy, size))) return vec4(0.0);
  vec2 uv = seen.xy / size;
  // Gathered in the order (0, 1), (1, 1), (1, 0), (0, 0) from the lower-left texel.
  bvec4 same = lessThanEqual(abs(textureGather(key_depth, uv, 0) - seen.z), vec4(seen.w));
  if (all(same)) return vec4(textureLod(key_colour, uv, 0.0).rgb, 1.0);
  vec2 p = seen.xy - 0.5;  // texel centres at integers
  vec2 corner = floor(p);
  vec2 f = p - corner;
  vec4 w = vec4((1.0 - f.x) * f.y, f.x * f.y, f.x * (1.0 - f.y), (1.0 - f.x) * (1.0 - f.y)) * vec4(same);
  float weight = w.x + w.y + w.z + w.w;
  if (weight <= 0.0) return vec4(0.0);
  ivec2 base = ivec2(corner);
  ivec2 last = ivec2(size) - 1;
  vec3 sum = w.x * texelFetch(key_colour, clamp(base + ivec2(0, 1), ivec2(0), last), 0).rgb +
             w.y * texelFetch(key_colour, clamp(base + ivec2(1, 1), ivec2(0), last), 0).rgb +
             w.z * texelFetch(key_colour, clamp(base + ivec2(1, 0), ivec2(0), last), 0).rgb +
             w.w * texelFetch(key_colour, clamp(base, ivec2(0), last), 0).rgb;
  return vec4(sum, weight);
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
#if AVERAGE && KEYS == 2
  colour = vec4(0.5 * (texelFetch(key_colour_0, p, 0).rgb + texelFetch(key_colour_1, p, 0).rgb), 1.0);
#elif AVERAGE  // across a cut: the key frame on this frame's side, as it is
  colour = vec4(texelFetch(key_colour_0, p, 0).rgb, 1.0);
#else
  vec4 seen_0 = texelFetch(motion_0, p, 0);
  if (seen_0.w < -1.5) {  // no surface: the background, as every key frame shows it
    colour = vec4(background, 1.0);
    return;
  }
  vec4 a = taken(key_colour_0, key_depth_0, seen_0);
#if KEYS == 2
  vec4 b = taken(key_colour_1, key_depth_1, texelFetch(motion_1, p, 0));
  float t = toward_second;
#else
  vec4 b = vec4(0.0);
  float t = 0.0;
#endif
  const float kSeen = 1e-6;
  if (a.w > kSeen && b.w > kSeen) {
    colour = vec4(((1.0 - t) * a.rgb + t * b.rgb) / ((1.0 - t) * a.w + t * b.w), 1.0);
  } else if (a.w > kSeen) {
    colour = vec4(a.rgb / a.w, 1.0);
  } else if (b.w > kSeen) {
    colour = vec4(b.rgb / b.w, 1.0);
  } else {
    discard;
  }
#endif
}
