// Each output pixel: the mean of the factor × factor source texels under it (a
// box filter in linear light, as image::box_downsample on the CPU), alpha 1.
uniform sampler2D source;
uniform int factor;
out vec4 colour;
void main() {
  const ivec2 base = ivec2(gl_FragCoord.xy) * factor;
  vec3 sum = vec3(0.0);
  for (int y = 0; y < factor; ++y) {
    for (int x = 0; x < factor; ++x) sum += texelFetch(source, base + ivec2(x, y), 0).rgb;
  }
  colour = vec4(sum / float(factor * factor), 1.0);
}
