// Marks (in the stencil, counted by a query) the pixels of a frame between key
// frames that no key frame saw: the resolve left them at alpha 0.
// Built with "#version 450 core" first.
layout(binding = 0) uniform sampler2D between;
void main() {
  if (texelFetch(between, ivec2(gl_FragCoord.xy), 0).a > 0.5) discard;
}
