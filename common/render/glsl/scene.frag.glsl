// The scene in linear light. Blinn-Phong with a roughness-derived exponent and a
// normalized specular lobe, Fresnel F0 from metallic: a cheap stand-in for
// metallic/roughness. All linear: the base colour texture is sRGB8_ALPHA8, so
// sampling it decodes to linear. Built with "#version 450 core" first, and VELOCITY
// for the gather (render/field_gather.h): then also each fragment's screen velocity.
in vec3 world_position;
in vec3 world_normal;
in vec2 texture_uv;
uniform vec3 eye;
uniform vec3 base_colour_factor;
uniform bool has_base_colour_texture;
layout(binding = 1) uniform sampler2D base_colour_texture;
uniform float metallic;
uniform float roughness;
uniform vec3 emissive;
uniform vec3 ambient;
uniform int light_count;
layout(std430, binding = 0) readonly buffer Lights { vec4 lights[]; };  // position, radiance
layout(location = 0) out vec4 colour;
#ifdef VELOCITY
// Clip positions are linear in the surface point, so interpolated they are the
// fragment's own at both moments: its velocity is exact, not a vertex average.
in vec4 clip_0;
in vec4 clip_1;
uniform vec2 half_size;  // pixels per unit of NDC
const float kMostSpeed = 16384.0;  // pixels per frame
// Screen velocity (pixels per frame period, rows up) and linear depth.
layout(location = 1) out vec4 motion;
#endif
const float kPi = 3.14159265358979;
void main() {
  vec3 base_colour = base_colour_factor;
  if (has_base_colour_texture) base_colour *= texture(base_colour_texture, texture_uv).rgb;
  vec3 n = normalize(world_normal);
  if (!gl_FrontFacing) n = -n;
  vec3 v = normalize(eye - world_position);
  vec3 diffuse = base_colour * (1.0 - metallic) / kPi;
  vec3 f0 = mix(vec3(0.04), base_colour, metallic);
  float alpha = max(roughness * roughness, 0.02);
  float shininess = 2.0 / (alpha * alpha) - 2.0;
  float normalization = (shininess + 8.0) / (8.0 * kPi);
  vec3 result = ambient * base_colour + emissive;
  for (int i = 0; i < light_count; ++i) {
    vec3 to_light = lights[2 * i].xyz - world_position;
    float r2 = max(dot(to_light, to_light), 1e-8);
    vec3 l = to_light * inversesqrt(r2);
    float n_dot_l = dot(n, l);
    if (n_dot_l <= 0.0) continue;
    vec3 h = normalize(l + v);
    vec3 specular = f0 * normalization * pow(max(dot(n, h), 0.0), shininess);
    result += (diffuse + specular) * lights[2 * i + 1].rgb * (n_dot_l / r2);
  }
  // Alpha: the window depth (the clear's 1 where nothing was drawn), so that
  // the up-converter reads a key frame's colour and depth in one fetch
  // (glsl/between_resolve.frag.glsl). Nothing else reads the linear alpha.
  colour = vec4(result, gl_FragCoord.z);
#ifdef VELOCITY
  vec2 velocity = vec2(0.0);
  if (clip_0.w > 1e-6 && clip_1.w > 1e-6) velocity = (clip_1.xy / clip_1.w - clip_0.xy / clip_0.w) * half_size;
  // A point that passes close to the eye plane moves without bound on screen: kept
  // finite in the half-float target (the gather clamps far below this anyway).
  float speed = length(velocity);
  if (speed > kMostSpeed) velocity *= kMostSpeed / speed;
  motion = vec4(velocity, 1.0 / gl_FragCoord.w, 1.0);
#endif
}
