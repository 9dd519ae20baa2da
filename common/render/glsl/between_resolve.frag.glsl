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
// Multisampled (SAMPLES > 1), the motion field holds each sample's surface and
// key_depth is each key-frame pixel's nearest and farthest sample depth
// (glsl/key_depth_range.frag.glsl). A pixel whose samples hold one surface, or
// surfaces that all moved alike (an edge of what stands still), is built once,
// from the key frames' pixels whose nearest and farthest samples saw its nearest
// and farthest surface (a still edge's mixed pixel, as it was). At a moving edge
// each sample is built from its own surface, only from key-frame pixels all of
// whose samples saw it (a pixel at a key frame's edge mixes two surfaces'
// colours; with less than half a pixel's weight of pure ones near, the sample
// is shaded anew); the samples some key frame saw get their mean and the sample
// mask keeps the others for shading anew, so that the pixel's average is that
// of each sample's own.
// Built with "#version 450 core", AVERAGE 0 or 1, KEYS 1 or 2 and SAMPLES first
// (one program each: a branch on a uniform still costs llvmpipe both sides).
layout(binding = 0) uniform sampler2D key_colour_0;
layout(binding = 1) uniform sampler2D key_colour_1;
layout(binding = 2) uniform sampler2D key_depth_0;
layout(binding = 3) uniform sampler2D key_depth_1;
#if SAMPLES > 1
layout(binding = 4) uniform sampler2DMS motion_0;
layout(binding = 5) uniform sampler2DMS motion_1;
#else
layout(binding = 4) uniform sampler2D motion_0;
layout(binding = 5) uniform sampler2D motion_1;
#endif
uniform float toward_second;
uniform vec3 background;
layout(location = 0) out vec4 colour;
// The box around what is left to shade anew (x0, y0, x1, y1; cleared to an
// empty one): the shading anew is scissored to it, as llvmpipe does not skip
// the scene's fragments that a multisampled stencil test rejects.
layout(std430, binding = 1) buffer Unseen { ivec4 unseen_box; };

void left_unseen(ivec2 p) {
  atomicMin(unseen_box.x, p.x);
  atomicMin(unseen_box.y, p.y);
  atomicMax(unseen_box.z, p.x);
  atomicMax(unseen_box.w, p.y);
}

// The key frame's colour there times the weight that saw the same surface, and
// that weight. One sample per pixel, the key frame's alpha is its depth (the
// scene's program writes it): four fetches give colour and depth. Multisampled,
// `far` is the depth (and its tolerance) that the key frame's farthest sample
// must match, seen.zw its nearest's (key_depth: the range), one surface or a
// still edge's two (see main); where all four saw it (most pixels), one
// bilinear fetch.
vec4 taken(sampler2D key_colour, sampler2D key_depth, vec4 seen, vec2 far) {
  vec2 size = vec2(textureSize(key_colour, 0));
  if (seen.w < 0.0 || any(lessThan(seen.xy, vec2(0.0))) || any(greaterThan(seen.xy, size))) return vec4(0.0);
  vec2 p = seen.xy - 0.5;  // texel centres at integers
  vec2 corner = floor(p);
  vec2 f = p - corner;
  // The four texels from `corner` (the weights' own), in the order (0, 1),
  // (1, 1), (1, 0), (0, 0); beyond the image's edge its edge pixel stands in.
  ivec2 base = ivec2(corner);
  ivec2 last = ivec2(size) - 1;
  vec4 bilinear = vec4((1.0 - f.x) * f.y, f.x * f.y, f.x * (1.0 - f.y), (1.0 - f.x) * (1.0 - f.y));
#if SAMPLES > 1
  vec2 four = (corner + 1.0) / size;  // gathered at their shared corner
  bvec4 same = bvec4(step(abs(textureGather(key_depth, four, 0) - seen.z), vec4(seen.w)) *
                     step(abs(textureGather(key_depth, four, 1) - far.x), vec4(far.y)));
  if (all(same)) return vec4(textureLod(key_colour, seen.xy / size, 0.0).rgb, 1.0);
#endif
  // llvmpipe runs both sides of an if: one sample per pixel, this is the only
  // way (a bilinear fetch where all four saw the surface cost more than it saved).
  vec4 t01 = texelFetch(key_colour, clamp(base + ivec2(0, 1), ivec2(0), last), 0);
  vec4 t11 = texelFetch(key_colour, clamp(base + ivec2(1, 1), ivec2(0), last), 0);
  vec4 t10 = texelFetch(key_colour, clamp(base + ivec2(1, 0), ivec2(0), last), 0);
  vec4 t00 = texelFetch(key_colour, clamp(base, ivec2(0), last), 0);
#if SAMPLES == 1
  bvec4 same = lessThanEqual(abs(vec4(t01.a, t11.a, t10.a, t00.a) - seen.z), vec4(seen.w));
#endif
  vec4 w = bilinear * vec4(same);
  return vec4(w.x * t01.rgb + w.y * t11.rgb + w.z * t10.rgb + w.w * t00.rgb, w.x + w.y + w.z + w.w);
}

// The colour of a surface seen at seen_0 in the first key frame and at seen_1
// in the second, w 1; w 0 where no key frame saw it. far_k: taken().
vec4 built(vec4 seen_0, vec4 seen_1, vec2 far_0, vec2 far_1) {
  if (seen_0.w < -1.5) return vec4(background, 1.0);  // no surface: as every key frame shows it
  vec4 a = taken(key_colour_0, key_depth_0, seen_0, far_0);
#if KEYS == 2
  vec4 b = taken(key_colour_1, key_depth_1, seen_1, far_1);
  float t = toward_second;
#else
  vec4 b = vec4(0.0);
  float t = 0.0;
#endif
#if SAMPLES > 1
  // Half a pixel's weight at least: beside a key frame's edge, where its own
  // pixel held two surfaces, a pure pixel farther off would lend its colour to
  // the sample (shaded anew instead: the edges are few, and then exact).
  const float kSeen = 0.5;
#else
  const float kSeen = 1e-6;
#endif
  if (a.w > kSeen && b.w > kSeen) return vec4(((1.0 - t) * a.rgb + t * b.rgb) / ((1.0 - t) * a.w + t * b.w), 1.0);
  if (a.w > kSeen) return vec4(a.rgb / a.w, 1.0);
  if (b.w > kSeen) return vec4(b.rgb / b.w, 1.0);
  return vec4(0.0);
}

#if SAMPLES > 1
// A sample's place in a key frame; where no surface was drawn, the background
// there (still, at the clear's depth 1).
vec4 placed(vec4 m) { return m.w < -1.5 ? vec4(gl_FragCoord.xy, 1.0, 0.0) : m; }

// Sample `m` of one key frame's motion field against the pixel's first: still
// one surface, still moved alike, and the nearest and farthest so far.
void take(vec4 m, vec4 first, inout bool one_surface, inout bool alike, inout vec4 near, inout vec4 far) {
  const float kAlike = 1e-3;  // pixels
  one_surface = one_surface && m == first;
  m = placed(m);
  alike = alike && m.w >= 0.0 && all(lessThanEqual(abs(m.xy - near.xy), vec2(kAlike)));
  near = m.z < near.z ? m : near;
  far = m.z > far.z ? m : far;
}
#endif

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
#if AVERAGE && KEYS == 2
  colour = vec4(0.5 * (texelFetch(key_colour_0, p, 0).rgb + texelFetch(key_colour_1, p, 0).rgb), 1.0);
#elif AVERAGE  // across a cut: the key frame on this frame's side, as it is
  colour = vec4(texelFetch(key_colour_0, p, 0).rgb, 1.0);
#else
  vec4 first_0 = texelFetch(motion_0, p, 0);
#if KEYS == 2
  vec4 first_1 = texelFetch(motion_1, p, 0);
#else
  vec4 first_1 = vec4(0.0);
#endif
#if SAMPLES > 1
  // One surface over the whole pixel, or surfaces that all moved alike since
  // the key frames (the edges of what stands still, most edges): the pixel is
  // the key frames' pixel there as it is, their mix included, where their
  // nearest and farthest samples saw the nearest and the farthest of these
  // surfaces. Otherwise sample by sample.
  bool one_surface = true;
  vec4 near_0 = placed(first_0);
  vec4 far_0 = near_0;
  bool alike = near_0.w >= 0.0;
#if KEYS == 2
  vec4 near_1 = placed(first_1);
  vec4 far_1 = near_1;
  alike = alike && near_1.w >= 0.0;
#else
  vec4 far_1 = vec4(0.0);
#endif
  for (int s = 1; s < SAMPLES; ++s) {
    take(texelFetch(motion_0, p, s), first_0, one_surface, alike, near_0, far_0);
#if KEYS == 2
    take(texelFetch(motion_1, p, s), first_1, one_surface, alike, near_1, far_1);
#endif
  }
  if (alike && !one_surface) {  // near_k: a surface (not every sample is the background)
    first_0 = near_0;
#if KEYS == 2
    first_1 = near_1;
#endif
  } else {
    far_0 = first_0;
    far_1 = first_1;
  }
  // One call of built() in a loop that ends early: llvmpipe runs every branch
  // of an if for all its pixels, a loop only while one of them goes on.
  int count = one_surface || alike ? 1 : SAMPLES;
  vec3 sum = vec3(0.0);
  float seen = 0.0;
  int mask = 0;
  for (int s = 0; s < count; ++s) {
    vec4 m_0 = s == 0 ? first_0 : texelFetch(motion_0, p, s);
#if KEYS == 2
    vec4 m_1 = s == 0 ? first_1 : texelFetch(motion_1, p, s);
#else
    vec4 m_1 = vec4(0.0);  // unread
#endif
    vec4 here = built(m_0, m_1, s == 0 ? far_0.zw : m_0.zw, s == 0 ? far_1.zw : m_1.zw);
    if (here.w > 0.0) {
      sum += here.rgb;
      seen += 1.0;
      mask |= 1 << s;
    }
  }
  if (count == 1 && mask != 0) mask = (1 << SAMPLES) - 1;
  if (mask != (1 << SAMPLES) - 1) left_unseen(p);
  vec4 c = vec4(sum / max(seen, 1.0), seen);
  gl_SampleMask[0] = mask;
#else
  vec4 c = built(first_0, first_1, first_0.zw, first_1.zw);
  if (c.w <= 0.0) left_unseen(p);
#endif
  if (c.w <= 0.0) discard;
  colour = vec4(c.rgb, 1.0);
#endif
}
