// The fastest velocity in each tile of `tile` × `tile` pixels (McGuire, Hennessy,
// Bukowski & Osman, "A Reconstruction Filter for Plausible Motion Blur"): one
// output pixel per tile. Built with "#version 450 core" first.
layout(binding = 0) uniform sampler2D motion;
uniform int tile;
layout(location = 0) out vec2 fastest;
void main() {
  ivec2 size = textureSize(motion, 0);
  ivec2 first = ivec2(gl_FragCoord.xy) * tile;
  ivec2 last = min(first + ivec2(tile), size);
  fastest = vec2(0.0);
  float most = 0.0;
  for (int y = first.y; y < last.y; ++y) {
    for (int x = first.x; x < last.x; ++x) {
      vec2 v = texelFetch(motion, ivec2(x, y), 0).xy;
      float l = dot(v, v);
      if (l > most) {
        most = l;
        fastest = v;
      }
    }
  }
}
