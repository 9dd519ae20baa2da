// The motion field of a frame between key frames (render/up_converter.h): for
// each visible fragment, where its surface point was in each key frame (pixels,
// rows up, and window depth) and how far that depth may differ among the key
// frame's pixels around it and still be the same surface. Clip positions are
// linear in the surface point, so interpolated they are the fragment's own: the
// field is exact per pixel, not a vertex average. Built with "#version 450 core"
// and VELOCITY (for clip_0 and clip_1 from scene.vert.glsl) first; ONE_END for
// one key frame only (key_0 alone).
in vec4 clip_0;
in vec3 world_normal;  // now
in vec3 normal_0;      // in each key frame
#ifndef ONE_END
in vec4 clip_1;
in vec3 normal_1;
#endif
uniform vec2 size;  // the image's pixels
// A surface turned further than this since a key frame (cosine of the angle
// between its normals) is shaded there for another orientation to the lights
// and the eye: its pixels there are not taken, it is shaded anew.
uniform float most_turn_cosine;
// x, y: pixels; z: window depth; w: the depth tolerance, or −1 where the key
// frame has no place for the point (it was behind its eye, or its object was
// not in the scene then) or shows it turned too far. A pixel no surface covers keeps the clear's −2.
layout(location = 0) out vec4 key_0;
#ifndef ONE_END
layout(location = 1) out vec4 key_1;
#endif

vec4 seen_at(vec4 clip, vec3 normal_then) {
  // Derivatives first, outside any branch: each is taken over the pixel quad.
  float w = max(clip.w, 1e-6);
  vec3 ndc = clip.xyz / w;
  vec2 pixel = (ndc.xy * 0.5 + 0.5) * size;
  float depth = ndc.z * 0.5 + 0.5;
  vec2 pixel_x = dFdx(pixel);
  vec2 pixel_y = dFdy(pixel);
  vec2 depth_xy = vec2(dFdx(depth), dFdy(depth));
  if (clip.w <= 1e-6) return vec4(0.0, 0.0, 0.0, -1.0);
  if (dot(normalize(world_normal), normalize(normal_then)) < most_turn_cosine) return vec4(0.0, 0.0, 0.0, -1.0);
  // Depth per key-frame pixel: its change per pixel here through the inverse of
  // how far the key-frame position moves per pixel here.
  mat2 key_per_pixel = mat2(pixel_x, pixel_y);
  float det = determinant(key_per_pixel);
  vec2 slope = abs(det) > 1e-8 ? depth_xy * inverse(key_per_pixel) : vec2(abs(depth_xy.x) + abs(depth_xy.y));
  // The taps lie within a pixel each way; half again for the slope's own error,
  // and a floor above the depth buffer's rounding.
  return vec4(pixel, depth, 1.5 * (abs(slope.x) + abs(slope.y)) + 2e-6);
}

void main() {
  key_0 = seen_at(clip_0, normal_0);
#ifndef ONE_END
  key_1 = seen_at(clip_1, normal_1);
#endif
}
