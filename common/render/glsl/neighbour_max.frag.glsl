// The fastest tile velocity among a tile and its eight neighbours: whatever can
// move onto a pixel within one tile's reach is in it. Built with "#version 450
// core" first.
layout(binding = 0) uniform sampler2D tile_max;
layout(location = 0) out vec2 fastest;
void main() {
  ivec2 size = textureSize(tile_max, 0);
  ivec2 t = ivec2(gl_FragCoord.xy);
  fastest = vec2(0.0);
  float most = 0.0;
  for (int y = max(t.y - 1, 0); y <= min(t.y + 1, size.y - 1); ++y) {
    for (int x = max(t.x - 1, 0); x <= min(t.x + 1, size.x - 1); ++x) {
      vec2 v = texelFetch(tile_max, ivec2(x, y), 0).xy;
      float l = dot(v, v);
      if (l > most) {
        most = l;
        fastest = v;
      }
    }
  }
}
