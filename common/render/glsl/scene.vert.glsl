// The scene: world position, normal and texture coordinates for the fragment shader.
// Built with "#version 450 core" first, and VELOCITY for the gather (render/field_gather.h)
// and the motion field of up-conversion (render/up_converter.h), with ONE_END
// where that field is from one key frame alone.
// The same depth in every program built from this: a frame between key frames
// shades its unseen pixels on the depth its motion field left (up_converter.h).
invariant gl_Position;
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
uniform mat4 model_view_projection;
uniform mat4 model;
uniform mat3 normal_matrix;
out vec3 world_position;
out vec3 world_normal;
out vec2 texture_uv;
#ifdef VELOCITY
// The vertex seen at the frame's display time and a frame later (each moment
// with its own eye): the fragment's screen velocity comes from these.
uniform mat4 model_view_projection_0;
out vec4 clip_0;
// And its normal then (world space; the motion field's, up_converter.h).
uniform mat3 normal_matrix_0;
out vec3 normal_0;
#ifndef ONE_END
uniform mat4 model_view_projection_1;
out vec4 clip_1;
uniform mat3 normal_matrix_1;
out vec3 normal_1;
#endif
#endif
void main() {
  world_position = (model * vec4(position, 1.0)).xyz;
  world_normal = normal_matrix * normal;
  texture_uv = uv;
  gl_Position = model_view_projection * vec4(position, 1.0);
#ifdef VELOCITY
  clip_0 = model_view_projection_0 * vec4(position, 1.0);
  normal_0 = normal_matrix_0 * normal;
#ifndef ONE_END
  clip_1 = model_view_projection_1 * vec4(position, 1.0);
  normal_1 = normal_matrix_1 * normal;
#endif
#endif
}
