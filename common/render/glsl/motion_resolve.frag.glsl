// Multisampled motion to one value per pixel: the front-most sample's. Velocities
// are not averaged: at an object's edge, half its speed belongs to no surface.
// Built with "#version 450 core" first.
layout(binding = 0) uniform sampler2DMS motion_samples;
uniform int samples;
layout(location = 0) out vec4 motion;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  motion = texelFetch(motion_samples, p, 0);
  for (int i = 1; i < samples; ++i) {
    vec4 m = texelFetch(motion_samples, p, i);
    if (m.z < motion.z) motion = m;
  }
}
