// The squared difference of two images of one size, summed per channel over
// `block` × `block` pixels (one output texel each): what the adaptive ratio's
// check reads back to weigh a frame between against the key frame drawn for
// its moment. Built with "#version 450 core" first.
layout(binding = 0) uniform sampler2D a;
layout(binding = 1) uniform sampler2D b;
uniform int block;
layout(location = 0) out vec4 sum;
void main() {
  ivec2 size = textureSize(a, 0);
  ivec2 origin = ivec2(gl_FragCoord.xy) * block;
  vec3 s = vec3(0.0);
  for (int j = 0; j < block; ++j) {
    for (int i = 0; i < block; ++i) {
      ivec2 p = origin + ivec2(i, j);
      if (p.x >= size.x || p.y >= size.y) continue;
      vec3 d = texelFetch(a, p, 0).rgb - texelFetch(b, p, 0).rgb;
      s += d * d;
    }
  }
  sum = vec4(s, 1.0);
}
