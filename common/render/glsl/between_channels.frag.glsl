// A frame built from a key frame laid into another image, only the channels the
// colour mask leaves on: a colour field built by up-conversion
// (render/up_converter.h, SceneRenderer::draw_fields_up_converted).
// Built with "#version 450 core" first.
layout(binding = 0) uniform sampler2D between;
layout(location = 0) out vec4 colour;
void main() { colour = vec4(texelFetch(between, ivec2(gl_FragCoord.xy), 0).rgb, 1.0); }
