#version 450 core
// Scatter as gather: a pixel collects, from every pixel q within the largest
// circle, the share of q's light that q's own disc (radius c_r(q) · c_max) puts
// on it, with the discs of optics/defocus.h (D_R: dx² + dy² ≤ R(R + 1), a radius
// between R + ½ and R + 3/2 split between D_R and D_{R+1}). Unnormalized, that is
// the ideal image itself; normalized by the shares received (the usual real-time
// form, which never leaves holes), it differs where the circle changes abruptly
// and at the image's edge. c_r comes from the depth buffer as in the output pass.
layout(binding = 0) uniform sampler2D rendered;
layout(binding = 1) uniform sampler2D depth;
uniform vec4 coc;  // k, b', lowest and highest window depth (optics/defocus.h)
uniform float c_max;
uniform int reach;
uniform bool normalized;
uniform float inv_count[64];  // 1 / |D_R|
layout(location = 0) out vec4 colour;

float radius_at(ivec2 q) {
  float d = texelFetch(depth, q, 0).r;
  return min(1.0, coc.x * abs(clamp(d, coc.z, coc.w) - coc.y)) * c_max;
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 size = textureSize(rendered, 0);
  vec3 sum = vec3(0.0);
  float received = 0.0;
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      ivec2 q = p + ivec2(dx, dy);
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
      float r = radius_at(q);
      int d2 = dx * dx + dy * dy;
      float w = 0.0;
      if (r <= 0.5) {
        w = d2 == 0 ? 1.0 : 0.0;
      } else {
        float s = r - 0.5;
        int inner = int(floor(s));
        float t = s - float(inner);
        if (d2 <= inner * (inner + 1)) w += (1.0 - t) * inv_count[inner];
        if (t > 0.0 && d2 <= (inner + 1) * (inner + 2)) w += t * inv_count[inner + 1];
      }
      sum += w * texelFetch(rendered, q, 0).rgb;
      received += w;
    }
  }
  colour = vec4(normalized ? sum / received : sum, 1.0);
}
