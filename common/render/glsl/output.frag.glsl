// The output stage: the two-pass warp (if any), this projector's share of the
// light (its blend weights; for a focus/defocus pair its share of the depth of
// field), then the projector's model: the signal that makes it add exactly this
// light to its black, quantized to its bit depth (optics/projector_model.h does
// the same on the CPU; the tests hold the two together). Writes the signal sent
// to the projector; the light it then emits is the projector model's business
// (SceneRenderer::read_linear), worked out only when someone asks.
//
// Built for each output stage with its choices as preprocessor constants that
// come first, #version included (WARP, WEIGHTS, CURVE, SHARE, INSET:
// output_stage_defines in scene_renderer.cpp): a software rasterizer runs both
// sides of a branch on a uniform, which made this pass cost 5× the old encode.
in vec2 uv;
layout(binding = 0) uniform sampler2D rendered;
layout(binding = 2) uniform sampler2D weights;
layout(binding = 3) uniform sampler2D depth;
layout(binding = 4) uniform sampler2D response_table;
uniform mat3 projector_to_user;
uniform vec2 output_size;
uniform vec2 rendered_size;
uniform float gamma;
uniform int table_size;
uniform float levels;
uniform float black_level;
uniform float brightness;
uniform vec4 coc;           // k, b', lowest and highest window depth (optics/defocus.h)
uniform vec4 depth_unwarp;  // single pass: a31, a32, a33 and the depth scale
uniform mat3 fragment_to_screen;
uniform vec3 inset_disc;    // centre x, y and radius, screen metres
uniform float screen_metres_per_pixel;
layout(location = 0) out vec4 encoded;

float table_at(int i) { return texelFetch(response_table, ivec2(i, 0), 0).r; }

vec3 inverse_response(vec3 l) {
  l = clamp(l, 0.0, 1.0);
#if CURVE == 0
  return clamp(mix(l * 12.92, 1.055 * pow(l, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), l)), 0.0, 1.0);
#elif CURVE == 1
  return pow(l, vec3(1.0 / gamma));
#else
  // The first entry ≥ l, by bisection (the table does not decrease).
  vec3 v;
  for (int c = 0; c < 3; ++c) {
    int lo = 0;
    int hi = table_size;
    while (lo < hi) {
      int mid = (lo + hi) / 2;
      if (table_at(mid) < l[c]) lo = mid + 1; else hi = mid;
    }
    if (lo == 0) {
      v[c] = 0.0;
    } else {
      float a = table_at(lo - 1);
      float b = table_at(lo);
      float f = b > a ? (l[c] - a) / (b - a) : 0.0;
      v[c] = (float(lo - 1) + f) / float(table_size - 1);
    }
  }
  return v;
#endif
}

#if SHARE != 0
// Relative circle of confusion from the depth buffer: c_r = k·|z′ − b′| with z′
// the window depth a plain perspective frustum gives (the single pass's depth is
// first undone: its third row scales z_ndc, its fourth divides by a31·x + a32·y + a33).
float circle_of_confusion(vec2 user_ndc, vec2 at) {
#if WARP
  float d = texelFetch(depth, ivec2(clamp(at * rendered_size, vec2(0.0), rendered_size - 1.0)), 0).r;
#else
  float d = texelFetch(depth, ivec2(gl_FragCoord.xy), 0).r;
  float z_ndc = (2.0 * d - 1.0) * dot(depth_unwarp.xyz, vec3(user_ndc, 1.0)) / depth_unwarp.w;
  d = 0.5 * z_ndc + 0.5;
#endif
  return min(1.0, coc.x * abs(clamp(d, coc.z, coc.w) - coc.y));
}

float focus_weight(vec2 user_ndc, vec2 at) {
#if INSET
  vec3 s = fragment_to_screen * vec3(gl_FragCoord.xy, 1.0);
  float distance_to_edge = inset_disc.z - length(s.xy / s.z - inset_disc.xy);
  return clamp(distance_to_edge / screen_metres_per_pixel + 0.5, 0.0, 1.0);
#else
  return 1.0 - circle_of_confusion(user_ndc, at);
#endif
}
#endif

void main() {
  vec3 c;
#if WARP || SHARE != 0
  vec3 user = projector_to_user * vec3(gl_FragCoord.xy / output_size * 2.0 - 1.0, 1.0);
  vec2 user_ndc = user.xy / user.z;
  vec2 at = (user_ndc + 1.0) * 0.5;
#endif
#if WARP
  bool inside = user.z > 0.0 && all(greaterThanEqual(at, vec2(0.0))) && all(lessThanEqual(at, vec2(1.0)));
  c = inside ? texture(rendered, at).rgb : vec3(0.0);
#else
  c = texelFetch(rendered, ivec2(gl_FragCoord.xy), 0).rgb;
#endif
#if WEIGHTS
  c *= texelFetch(weights, ivec2(gl_FragCoord.xy), 0).r;
#endif
#if SHARE == 1
  c *= focus_weight(user_ndc, at);
#elif SHARE == 2
  c *= 1.0 - focus_weight(user_ndc, at);
#endif
  float headroom = brightness * (1.0 - black_level);
  vec3 signal = round(inverse_response(c / headroom) * levels) / levels;
  encoded = vec4(signal, 1.0);
}
