#version 450 core
// The scene: world position, normal and texture coordinates for the fragment shader.
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
uniform mat4 model_view_projection;
uniform mat4 model;
uniform mat3 normal_matrix;
out vec3 world_position;
out vec3 world_normal;
out vec2 texture_uv;
void main() {
  world_position = (model * vec4(position, 1.0)).xyz;
  world_normal = normal_matrix * normal;
  texture_uv = uv;
  gl_Position = model_view_projection * vec4(position, 1.0);
}
