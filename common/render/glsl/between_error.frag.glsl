// The squared difference of two images of one size as displayed (sRGB-encoded,
// clamped to [0, 1], as the up-conversion paper compared frame buffers),
// summed per channel over `block` × `block` pixels (one output texel each):
// what the adaptive ratio's check reads back to weigh a frame between against
// the key frame drawn for its moment. Built with "#version 450 core" first.
layout(binding = 0) uniform sampler2D a;
layout(binding = 1) uniform sampler2D b;
uniform int block;
layout(location = 0) out vec4 sum;
vec3 displayed(vec3 linear) {
  vec3 c = clamp(linear, 0.0, 1.0);
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
void main() {
  ivec2 size = textureSize(a, 0);
  ivec2 origin = ivec2(gl_FragCoord.xy) * block;
  vec3 s = vec3(0.0);
  for (int j = 0; j < block; ++j) {
    for (int i = 0; i < block; ++i) {
      ivec2 p = origin + ivec2(i, j);
      if (p.x >= size.x || p.y >= size.y) continue;
      vec3 d = displayed(texelFetch(a, p, 0).rgb) - displayed(texelFetch(b, p, 0).rgb);
      s += d * d;
    }
  }
  sum = vec4(s, 1.0);
}
