#include "render/scene_renderer.h"

#include <algorithm>
#include <cassert>
#include <string>

#include <epoxy/gl.h>

#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>

namespace optique::render {
namespace {

constexpr const char* kSceneVertex = R"(#version 450 core
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
)";

// Blinn-Phong with a roughness-derived exponent and a normalized specular lobe,
// Fresnel F0 from metallic: a cheap stand-in for metallic/roughness. All linear:
// the base colour texture is sRGB8_ALPHA8, so sampling it decodes to linear.
constexpr const char* kSceneFragment = R"(#version 450 core
in vec3 world_position;
in vec3 world_normal;
in vec2 texture_uv;
uniform vec3 eye;
uniform vec3 base_colour_factor;
uniform bool has_base_colour_texture;
layout(binding = 1) uniform sampler2D base_colour_texture;
uniform float metallic;
uniform float roughness;
uniform vec3 emissive;
uniform vec3 ambient;
uniform int light_count;
layout(std430, binding = 0) readonly buffer Lights { vec4 lights[]; };  // position, radiance
out vec4 colour;
const float kPi = 3.14159265358979;
void main() {
  vec3 base_colour = base_colour_factor;
  if (has_base_colour_texture) base_colour *= texture(base_colour_texture, texture_uv).rgb;
  vec3 n = normalize(world_normal);
  if (!gl_FrontFacing) n = -n;
  vec3 v = normalize(eye - world_position);
  vec3 diffuse = base_colour * (1.0 - metallic) / kPi;
  vec3 f0 = mix(vec3(0.04), base_colour, metallic);
  float alpha = max(roughness * roughness, 0.02);
  float shininess = 2.0 / (alpha * alpha) - 2.0;
  float normalization = (shininess + 8.0) / (8.0 * kPi);
  vec3 result = ambient * base_colour + emissive;
  for (int i = 0; i < light_count; ++i) {
    vec3 to_light = lights[2 * i].xyz - world_position;
    float r2 = max(dot(to_light, to_light), 1e-8);
    vec3 l = to_light * inversesqrt(r2);
    float n_dot_l = dot(n, l);
    if (n_dot_l <= 0.0) continue;
    vec3 h = normalize(l + v);
    vec3 specular = f0 * normalization * pow(max(dot(n, h), 0.0), shininess);
    result += (diffuse + specular) * lights[2 * i + 1].rgb * (n_dot_l / r2);
  }
  colour = vec4(result, 1.0);
}
)";

constexpr const char* kFullscreenVertex = R"(#version 450 core
out vec2 uv;
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  uv = p;
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";

// The output stage: the two-pass warp (if any), this projector's share of the
// light (its blend weights; for a focus/defocus pair its share of the depth of
// field), then the projector's model: the signal that makes it add exactly this
// light to its black, quantized to its bit depth (optics/projector_model.h does
// the same on the CPU; the tests hold the two together). Writes the signal sent
// to the projector; the light it then emits is the projector model's business
// (read_linear), worked out only when someone asks.
//
// Built for each output stage with its choices as preprocessor constants (WARP,
// WEIGHTS, CURVE, SHARE, INSET: output_stage_defines): a software rasterizer runs both
// sides of a branch on a uniform, which made this pass cost 5× the old encode.
constexpr const char* kEncodeFragment = R"(
in vec2 uv;
layout(binding = 0) uniform sampler2D rendered;
layout(binding = 2) uniform sampler2D weights;
layout(binding = 3) uniform sampler2D depth;
layout(binding = 4) uniform sampler2D response_table;
uniform mat3 projector_to_user;
uniform vec2 output_size;
uniform vec2 rendered_size;
uniform float gamma;
uniform int table_size;
uniform float levels;
uniform float black_level;
uniform float brightness;
uniform vec4 coc;           // k, b', lowest and highest window depth (optics/defocus.h)
uniform vec4 depth_unwarp;  // single pass: a31, a32, a33 and the depth scale
uniform mat3 fragment_to_screen;
uniform vec3 inset_disc;    // centre x, y and radius, screen metres
uniform float screen_metres_per_pixel;
layout(location = 0) out vec4 encoded;

float table_at(int i) { return texelFetch(response_table, ivec2(i, 0), 0).r; }

vec3 inverse_response(vec3 l) {
  l = clamp(l, 0.0, 1.0);
#if CURVE == 0
  return clamp(mix(l * 12.92, 1.055 * pow(l, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), l)), 0.0, 1.0);
#elif CURVE == 1
  return pow(l, vec3(1.0 / gamma));
#else
  // The first entry ≥ l, by bisection (the table does not decrease).
  vec3 v;
  for (int c = 0; c < 3; ++c) {
    int lo = 0;
    int hi = table_size;
    while (lo < hi) {
      int mid = (lo + hi) / 2;
      if (table_at(mid) < l[c]) lo = mid + 1; else hi = mid;
    }
    if (lo == 0) {
      v[c] = 0.0;
    } else {
      float a = table_at(lo - 1);
      float b = table_at(lo);
      float f = b > a ? (l[c] - a) / (b - a) : 0.0;
      v[c] = (float(lo - 1) + f) / float(table_size - 1);
    }
  }
  return v;
#endif
}

#if SHARE != 0
// Relative circle of confusion from the depth buffer: c_r = k·|z′ − b′| with z′
// the window depth a plain perspective frustum gives (the single pass's depth is
// first undone: its third row scales z_ndc, its fourth divides by a31·x + a32·y + a33).
float circle_of_confusion(vec2 user_ndc, vec2 at) {
#if WARP
  float d = texelFetch(depth, ivec2(clamp(at * rendered_size, vec2(0.0), rendered_size - 1.0)), 0).r;
#else
  float d = texelFetch(depth, ivec2(gl_FragCoord.xy), 0).r;
  float z_ndc = (2.0 * d - 1.0) * dot(depth_unwarp.xyz, vec3(user_ndc, 1.0)) / depth_unwarp.w;
  d = 0.5 * z_ndc + 0.5;
#endif
  return min(1.0, coc.x * abs(clamp(d, coc.z, coc.w) - coc.y));
}

float focus_weight(vec2 user_ndc, vec2 at) {
#if INSET
  vec3 s = fragment_to_screen * vec3(gl_FragCoord.xy, 1.0);
  float distance_to_edge = inset_disc.z - length(s.xy / s.z - inset_disc.xy);
  return clamp(distance_to_edge / screen_metres_per_pixel + 0.5, 0.0, 1.0);
#else
  return 1.0 - circle_of_confusion(user_ndc, at);
#endif
}
#endif

void main() {
  vec3 c;
#if WARP || SHARE != 0
  vec3 user = projector_to_user * vec3(gl_FragCoord.xy / output_size * 2.0 - 1.0, 1.0);
  vec2 user_ndc = user.xy / user.z;
  vec2 at = (user_ndc + 1.0) * 0.5;
#endif
#if WARP
  bool inside = user.z > 0.0 && all(greaterThanEqual(at, vec2(0.0))) && all(lessThanEqual(at, vec2(1.0)));
  c = inside ? texture(rendered, at).rgb : vec3(0.0);
#else
  c = texelFetch(rendered, ivec2(gl_FragCoord.xy), 0).rgb;
#endif
#if WEIGHTS
  c *= texelFetch(weights, ivec2(gl_FragCoord.xy), 0).r;
#endif
#if SHARE == 1
  c *= focus_weight(user_ndc, at);
#elif SHARE == 2
  c *= 1.0 - focus_weight(user_ndc, at);
#endif
  float headroom = brightness * (1.0 - black_level);
  vec3 signal = round(inverse_response(c / headroom) * levels) / levels;
  encoded = vec4(signal, 1.0);
}
)";

// The output pass's choices for a stage, as the preprocessor constants it is
// built with (the enums' values are the shader's numbers).
std::string output_stage_defines(const OutputStage& stage) {
  return "#version 450 core\n#define WARP " + std::to_string(stage.projector_to_user ? 1 : 0) + "\n#define CURVE " +
         std::to_string(static_cast<int>(stage.projector.curve())) + "\n#define SHARE " +
         std::to_string(static_cast<int>(stage.focus.role)) + "\n#define INSET " +
         std::to_string(stage.focus.inset ? 1 : 0) + "\n#define WEIGHTS " +
         std::to_string(stage.weights.empty() ? 0 : 1) + "\n";
}

Result<GLuint> compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok == GL_TRUE) return shader;
  char log[2048] = {};
  glGetShaderInfoLog(shader, sizeof log, nullptr, log);
  glDeleteShader(shader);
  return Error{std::string("shader does not compile: ") + log};
}

Result<GLuint> link(const char* vertex_source, const char* fragment_source) {
  auto vertex = compile(GL_VERTEX_SHADER, vertex_source);
  if (!vertex) return Error{vertex.error()};
  auto fragment = compile(GL_FRAGMENT_SHADER, fragment_source);
  if (!fragment) {
    glDeleteShader(vertex.value());
    return Error{fragment.error()};
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, vertex.value());
  glAttachShader(program, fragment.value());
  glLinkProgram(program);
  glDeleteShader(vertex.value());
  glDeleteShader(fragment.value());
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok == GL_TRUE) return program;
  char log[2048] = {};
  glGetProgramInfoLog(program, sizeof log, nullptr, log);
  glDeleteProgram(program);
  return Error{std::string("shader program does not link: ") + log};
}

struct MeshRange {
  GLsizei count = 0;
  std::size_t first_index = 0;
  GLint base_vertex = 0;
};

}  // namespace

struct SceneRenderer::Gl {
  int width = 0;
  int height = 0;
  GLuint scene_program = 0;
  GLuint encode_program = 0;
  GLuint vertex_array = 0;
  GLuint vertex_buffer = 0;
  GLuint index_buffer = 0;
  GLuint light_buffer = 0;
  GLuint empty_vertex_array = 0;
  GLuint linear_framebuffer = 0;
  GLuint linear_colour = 0;
  GLuint depth = 0;
  GLuint encoded_framebuffer = 0;  // the signal: drawn by the output pass, blitted to a window
  GLuint encoded_colour = 0;
  GLuint weights = 0;
  GLuint response_table = 0;
  optics::ProjectorModel projector;  // of the output stage
  int output_width = 0;
  int output_height = 0;
  std::vector<GLuint> scene_textures;  // by index in the scene's textures
  std::vector<MeshRange> meshes;
  std::vector<scene::Material> materials;
  std::vector<scene::Instance> instances;
  glm::vec3 ambient{0.0f};
  glm::vec3 background{0.0f};
  std::vector<glm::vec4> all_lights;           // position, radiance: two per light
  std::vector<std::uint32_t> chosen_lights;    // set_lights
  std::vector<std::uint32_t> uploaded_lights;  // those of them that shine, in the light buffer
  int light_count = 0;
  struct {
    GLint coc, inset_disc;
  } focus_uniforms{};
  struct {
    GLint model_view_projection, model, normal_matrix, eye, base_colour, has_base_colour_texture, metallic, roughness,
        emissive, ambient, light_count;
  } uniforms{};

  ~Gl() {
    glDeleteProgram(scene_program);
    glDeleteProgram(encode_program);
    const GLuint arrays[] = {vertex_array, empty_vertex_array};
    glDeleteVertexArrays(2, arrays);
    const GLuint buffers[] = {vertex_buffer, index_buffer, light_buffer};
    glDeleteBuffers(3, buffers);
    const GLuint framebuffers[] = {linear_framebuffer, encoded_framebuffer};
    glDeleteFramebuffers(2, framebuffers);
    const GLuint textures[] = {linear_colour, depth, encoded_colour, weights, response_table};
    glDeleteTextures(5, textures);
    glDeleteTextures(static_cast<GLsizei>(scene_textures.size()), scene_textures.data());
  }
};

SceneRenderer::SceneRenderer(std::unique_ptr<Gl> gl) : gl_(std::move(gl)) {}
SceneRenderer::~SceneRenderer() = default;

Result<std::unique_ptr<SceneRenderer>> SceneRenderer::create(const scene::SceneDefinition& scene, int width, int height,
                                                             DepthFormat depth) {
  if (width <= 0 || height <= 0) return Error{"the image size must be positive"};
  auto gl = std::make_unique<Gl>();
  gl->width = width;
  gl->height = height;
  auto scene_program = link(kSceneVertex, kSceneFragment);
  if (!scene_program) return Error{scene_program.error()};
  gl->scene_program = scene_program.value();
  const GLuint p = gl->scene_program;
  gl->uniforms = {glGetUniformLocation(p, "model_view_projection"),
                  glGetUniformLocation(p, "model"),
                  glGetUniformLocation(p, "normal_matrix"),
                  glGetUniformLocation(p, "eye"),
                  glGetUniformLocation(p, "base_colour_factor"),
                  glGetUniformLocation(p, "has_base_colour_texture"),
                  glGetUniformLocation(p, "metallic"),
                  glGetUniformLocation(p, "roughness"),
                  glGetUniformLocation(p, "emissive"),
                  glGetUniformLocation(p, "ambient"),
                  glGetUniformLocation(p, "light_count")};

  // All meshes in one vertex and one index buffer.
  std::vector<scene::Vertex> vertices;
  std::vector<std::uint32_t> indices;
  for (const auto& mesh : scene.meshes) {
    gl->meshes.push_back(
        {static_cast<GLsizei>(mesh.indices.size()), indices.size(), static_cast<GLint>(vertices.size())});
    vertices.insert(vertices.end(), mesh.vertices.begin(), mesh.vertices.end());
    indices.insert(indices.end(), mesh.indices.begin(), mesh.indices.end());
  }
  glCreateVertexArrays(1, &gl->vertex_array);
  glCreateVertexArrays(1, &gl->empty_vertex_array);
  glCreateBuffers(1, &gl->vertex_buffer);
  glCreateBuffers(1, &gl->index_buffer);
  glNamedBufferStorage(gl->vertex_buffer,
                       static_cast<GLsizeiptr>(std::max<std::size_t>(1, vertices.size()) * sizeof(scene::Vertex)),
                       vertices.empty() ? nullptr : vertices.data(), 0);
  glNamedBufferStorage(gl->index_buffer,
                       static_cast<GLsizeiptr>(std::max<std::size_t>(1, indices.size()) * sizeof(std::uint32_t)),
                       indices.empty() ? nullptr : indices.data(), 0);
  glVertexArrayVertexBuffer(gl->vertex_array, 0, gl->vertex_buffer, 0, sizeof(scene::Vertex));
  glVertexArrayElementBuffer(gl->vertex_array, gl->index_buffer);
  glEnableVertexArrayAttrib(gl->vertex_array, 0);
  glVertexArrayAttribFormat(gl->vertex_array, 0, 3, GL_FLOAT, GL_FALSE, offsetof(scene::Vertex, position));
  glVertexArrayAttribBinding(gl->vertex_array, 0, 0);
  glEnableVertexArrayAttrib(gl->vertex_array, 1);
  glVertexArrayAttribFormat(gl->vertex_array, 1, 3, GL_FLOAT, GL_FALSE, offsetof(scene::Vertex, normal));
  glVertexArrayAttribBinding(gl->vertex_array, 1, 0);
  glEnableVertexArrayAttrib(gl->vertex_array, 2);
  glVertexArrayAttribFormat(gl->vertex_array, 2, 2, GL_FLOAT, GL_FALSE, offsetof(scene::Vertex, uv));
  glVertexArrayAttribBinding(gl->vertex_array, 2, 0);

  // Textures: sRGB colour (decoded to linear when sampled), linear alpha; mipmapped,
  // trilinear, repeating. Rows go up as they are stored, top row first: that row
  // is t = 0, which is where glTF's v = 0 (the image's top) is, so glTF uvs
  // sample the texture unchanged.
  for (const auto& texture : scene.textures) {
    if (texture.width <= 0 || texture.height <= 0 ||
        texture.rgba.size() != static_cast<std::size_t>(texture.width) * static_cast<std::size_t>(texture.height) * 4) {
      return Error{"texture '" + texture.name + "' has no or the wrong number of texels"};
    }
    GLuint name = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &name);
    gl->scene_textures.push_back(name);
    int levels = 1;
    for (int side = std::max(texture.width, texture.height); side > 1; side /= 2) ++levels;
    glTextureStorage2D(name, levels, GL_SRGB8_ALPHA8, texture.width, texture.height);
    glTextureSubImage2D(name, 0, 0, 0, texture.width, texture.height, GL_RGBA, GL_UNSIGNED_BYTE, texture.rgba.data());
    glGenerateTextureMipmap(name);
    glTextureParameteri(name, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTextureParameteri(name, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(name, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTextureParameteri(name, GL_TEXTURE_WRAP_T, GL_REPEAT);
  }
  for (const auto& material : scene.materials) {
    if (material.base_colour_texture && *material.base_colour_texture >= scene.textures.size()) {
      return Error{"a material's base colour texture " + std::to_string(*material.base_colour_texture) +
                   " is out of range (" + std::to_string(scene.textures.size()) + " textures)"};
    }
  }

  for (const auto& light : scene.lights) {
    gl->all_lights.emplace_back(glm::vec3(light.position), 1.0f);
    gl->all_lights.emplace_back(light.colour * light.intensity, 0.0f);
  }
  glCreateBuffers(1, &gl->light_buffer);
  glNamedBufferStorage(gl->light_buffer,
                       static_cast<GLsizeiptr>(std::max<std::size_t>(1, gl->all_lights.size()) * sizeof(glm::vec4)),
                       nullptr, GL_DYNAMIC_STORAGE_BIT);

  gl->materials = scene.materials;
  gl->instances = scene.instances;
  gl->ambient = scene.ambient;
  gl->background = scene.background;

  // Linear light in 32-bit floats: stacked projectors add their shares, and half
  // floats (2⁻¹¹ relative) put highlights of 3 off by 2e-3 after the sum.
  // Depth in 32-bit float (or 24-bit fixed point).
  glCreateTextures(GL_TEXTURE_2D, 1, &gl->linear_colour);
  glTextureStorage2D(gl->linear_colour, 1, GL_RGBA32F, width, height);
  // Bilinear for the two-pass warp; the single pass reads texels exactly.
  glTextureParameteri(gl->linear_colour, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(gl->linear_colour, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(gl->linear_colour, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(gl->linear_colour, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glCreateTextures(GL_TEXTURE_2D, 1, &gl->depth);
  glTextureStorage2D(gl->depth, 1, depth == DepthFormat::fixed24 ? GL_DEPTH_COMPONENT24 : GL_DEPTH_COMPONENT32F, width,
                     height);
  glCreateFramebuffers(1, &gl->linear_framebuffer);
  glNamedFramebufferTexture(gl->linear_framebuffer, GL_COLOR_ATTACHMENT0, gl->linear_colour, 0);
  glNamedFramebufferTexture(gl->linear_framebuffer, GL_DEPTH_ATTACHMENT, gl->depth, 0);
  auto renderer = std::unique_ptr<SceneRenderer>(new SceneRenderer(std::move(gl)));
  renderer->set_all_lights();
  if (auto output = renderer->set_output({}); !output) return Error{output.error()};
  return renderer;
}

Result<void> SceneRenderer::set_output(const OutputStage& stage) {
  Gl& gl = *gl_;
  const int width = stage.width > 0 ? stage.width : gl.width;
  const int height = stage.height > 0 ? stage.height : gl.height;
  if (!stage.weights.empty() &&
      (stage.weights.width != width || stage.weights.height != height || stage.weights.channels != 1)) {
    return Error{"blend weights are " + std::to_string(stage.weights.width) + "×" +
                 std::to_string(stage.weights.height) + "×" + std::to_string(stage.weights.channels) + ", the output " +
                 std::to_string(width) + "×" + std::to_string(height) + "×1"};
  }
  if (!stage.projector_to_user && (width != gl.width || height != gl.height)) {
    return Error{"a single-pass output must have the rendered image's size"};
  }
  // The output pass for this stage, built before anything of the old one goes.
  const std::string source = output_stage_defines(stage) + kEncodeFragment;
  auto encode_program = link(kFullscreenVertex, source.c_str());
  if (!encode_program) return Error{encode_program.error()};
  glDeleteFramebuffers(1, &gl.encoded_framebuffer);
  const GLuint textures[] = {gl.encoded_colour, gl.weights, gl.response_table};
  glDeleteTextures(3, textures);
  gl.weights = 0;
  gl.output_width = width;
  gl.output_height = height;
  // Its uniforms are set once here, not per frame.
  glDeleteProgram(gl.encode_program);
  gl.encode_program = encode_program.value();
  const GLuint program = gl.encode_program;
  gl.focus_uniforms = {glGetUniformLocation(program, "coc"), glGetUniformLocation(program, "inset_disc")};
  // A single pass needs A⁻¹ too: a focus/defocus share undoes A's effect on depth.
  const glm::mat3 to_user(stage.projector_to_user.value_or(glm::inverse(stage.focus.user_to_projector)));
  const auto uniform = [program](const char* name) { return glGetUniformLocation(program, name); };
  glProgramUniformMatrix3fv(program, uniform("projector_to_user"), 1, GL_FALSE, glm::value_ptr(to_user));
  glProgramUniform2f(program, uniform("output_size"), static_cast<float>(width), static_cast<float>(height));
  glProgramUniform2f(program, uniform("rendered_size"), static_cast<float>(gl.width), static_cast<float>(gl.height));

  gl.projector = stage.projector;
  const optics::ProjectorModel& model = stage.projector;
  glProgramUniform1f(program, uniform("gamma"), static_cast<float>(model.gamma()));
  glProgramUniform1i(program, uniform("table_size"), static_cast<int>(model.table().size()));
  glProgramUniform1f(program, uniform("levels"), static_cast<float>(model.levels()));
  glProgramUniform1f(program, uniform("black_level"), static_cast<float>(model.black_level()));
  glProgramUniform1f(program, uniform("brightness"), static_cast<float>(model.brightness()));
  {
    // A texture even when there is no table: every bound sampler needs one.
    std::vector<float> table(model.table().begin(), model.table().end());
    if (table.empty()) table = {0.0f, 1.0f};
    glCreateTextures(GL_TEXTURE_2D, 1, &gl.response_table);
    glTextureStorage2D(gl.response_table, 1, GL_R32F, static_cast<GLsizei>(table.size()), 1);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(gl.response_table, 0, 0, 0, static_cast<GLsizei>(table.size()), 1, GL_RED, GL_FLOAT,
                        table.data());
  }

  const FocusShare& focus = stage.focus;
  const glm::dmat3& a = focus.user_to_projector;
  glProgramUniform4f(program, uniform("depth_unwarp"), static_cast<float>(a[0][2]), static_cast<float>(a[1][2]),
                     static_cast<float>(a[2][2]), static_cast<float>(focus.depth_scale));
  const glm::mat3 fragment_to_screen(focus.fragment_to_screen);
  glProgramUniformMatrix3fv(program, uniform("fragment_to_screen"), 1, GL_FALSE, glm::value_ptr(fragment_to_screen));
  glProgramUniform1f(program, uniform("screen_metres_per_pixel"), static_cast<float>(focus.screen_metres_per_pixel));
  set_focus({});

  glCreateTextures(GL_TEXTURE_2D, 1, &gl.encoded_colour);
  // The signal at the projector's depth: 8 bits, or 16 to hold up to 16.
  glTextureStorage2D(gl.encoded_colour, 1, model.bits() <= 8 ? GL_RGBA8 : GL_RGBA16, width, height);
  glCreateFramebuffers(1, &gl.encoded_framebuffer);
  glNamedFramebufferTexture(gl.encoded_framebuffer, GL_COLOR_ATTACHMENT0, gl.encoded_colour, 0);
  if (!stage.weights.empty()) {
    image::FloatImage rows_up = stage.weights;  // GL's first row is the bottom one
    image::flip_rows(rows_up);
    glCreateTextures(GL_TEXTURE_2D, 1, &gl.weights);
    glTextureStorage2D(gl.weights, 1, GL_R32F, width, height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(gl.weights, 0, 0, 0, width, height, GL_RED, GL_FLOAT, rows_up.pixels.data());
  }
  for (GLuint fb : {gl.linear_framebuffer, gl.encoded_framebuffer}) {
    const GLenum status = glCheckNamedFramebufferStatus(fb, GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      return Error{"framebuffer incomplete (status " + std::to_string(status) + ")"};
    }
  }
  return {};
}

void SceneRenderer::set_lights(std::span<const std::uint32_t> lights) {
  assert(std::all_of(lights.begin(), lights.end(),
                     [&](std::uint32_t i) { return 2 * static_cast<std::size_t>(i) + 1 < gl_->all_lights.size(); }));
  gl_->chosen_lights.assign(lights.begin(), lights.end());
  upload_shining_lights({});
}

void SceneRenderer::upload_shining_lights(const std::set<std::uint32_t>& off) {
  Gl& gl = *gl_;
  std::vector<std::uint32_t> shining;
  for (std::uint32_t i : gl.chosen_lights) {
    if (!off.contains(i)) shining.push_back(i);
  }
  if (shining == gl.uploaded_lights && gl.light_count == static_cast<int>(shining.size())) return;
  std::vector<glm::vec4> data;
  for (std::uint32_t i : shining) {
    data.push_back(gl.all_lights[2 * i]);
    data.push_back(gl.all_lights[2 * i + 1]);
  }
  if (!data.empty()) {
    glNamedBufferSubData(gl.light_buffer, 0, static_cast<GLsizeiptr>(data.size() * sizeof(glm::vec4)), data.data());
  }
  gl.light_count = static_cast<int>(shining.size());
  gl.uploaded_lights = std::move(shining);
}

void SceneRenderer::set_all_lights() {
  std::vector<std::uint32_t> all(gl_->all_lights.size() / 2);
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::uint32_t>(i);
  set_lights(all);
}

void SceneRenderer::set_focus(const FocusFrame& frame) {
  const Gl& gl = *gl_;
  const GLuint program = gl.encode_program;
  glProgramUniform4f(program, gl.focus_uniforms.coc, static_cast<float>(frame.coc.k),
                     static_cast<float>(frame.coc.focal), static_cast<float>(frame.coc.lo),
                     static_cast<float>(frame.coc.hi));
  glProgramUniform3f(program, gl.focus_uniforms.inset_disc, static_cast<float>(frame.gaze.x),
                     static_cast<float>(frame.gaze.y), static_cast<float>(frame.inset_radius));
}

void SceneRenderer::draw(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                         const geometry::Frustum& frustum, const LightTerms& terms) {
  Gl& gl = *gl_;
  glBindFramebuffer(GL_FRAMEBUFFER, gl.linear_framebuffer);
  glViewport(0, 0, gl.width, gl.height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);  // thin objects (quads) are seen from both sides
  glClearColor(gl.background.r, gl.background.g, gl.background.b, 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  upload_shining_lights(state.lights_off);
  glUseProgram(gl.scene_program);
  glBindVertexArray(gl.vertex_array);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, gl.light_buffer);
  const auto& u = gl.uniforms;
  glUniform3f(u.eye, static_cast<float>(eye.x), static_cast<float>(eye.y), static_cast<float>(eye.z));
  const glm::vec3 ambient = terms.ambient ? gl.ambient : glm::vec3(0.0f);
  glUniform3fv(u.ambient, 1, glm::value_ptr(ambient));
  glUniform1i(u.light_count, gl.light_count);
  const glm::dmat4 view_projection = frustum.projection * frustum.view;

  for (const auto& instance : gl.instances) {
    glm::dmat4 model = instance.transform;
    if (instance.object) {
      const auto found = state.objects.find(*instance.object);
      if (found == state.objects.end()) continue;  // not in the state (yet): nothing to place
      model = scene::model_matrix(scene::interpolate(found->second, fraction)) * instance.transform;
    }
    // Products in double, then to float: keeps precision for large worlds.
    const glm::mat4 mvp(view_projection * model);
    const glm::mat4 model_f(model);
    const glm::mat3 normal_matrix(glm::transpose(glm::inverse(glm::dmat3(model))));
    glUniformMatrix4fv(u.model_view_projection, 1, GL_FALSE, glm::value_ptr(mvp));
    glUniformMatrix4fv(u.model, 1, GL_FALSE, glm::value_ptr(model_f));
    glUniformMatrix3fv(u.normal_matrix, 1, GL_FALSE, glm::value_ptr(normal_matrix));
    const scene::Material& m = gl.materials[instance.material];
    glUniform3fv(u.base_colour, 1, glm::value_ptr(m.base_colour));
    glUniform1i(u.has_base_colour_texture, m.base_colour_texture ? 1 : 0);
    if (m.base_colour_texture) glBindTextureUnit(1, gl.scene_textures[*m.base_colour_texture]);  // unit 0: encode
    glUniform1f(u.metallic, m.metallic);
    glUniform1f(u.roughness, m.roughness);
    const glm::vec3 emissive = terms.emissive ? m.emissive : glm::vec3(0.0f);
    glUniform3fv(u.emissive, 1, glm::value_ptr(emissive));
    const MeshRange& mesh = gl.meshes[instance.mesh];
    glDrawElementsBaseVertex(GL_TRIANGLES, mesh.count, GL_UNSIGNED_INT,
                             reinterpret_cast<const void*>(mesh.first_index * sizeof(std::uint32_t)), mesh.base_vertex);
  }

  encode();
}

void SceneRenderer::draw_black() {
  glBindFramebuffer(GL_FRAMEBUFFER, gl_->linear_framebuffer);
  glViewport(0, 0, gl_->width, gl_->height);
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  encode();
}

// The projector's response, last: linear light → what is sent to it.
void SceneRenderer::encode() {
  Gl& gl = *gl_;
  glBindFramebuffer(GL_FRAMEBUFFER, gl.encoded_framebuffer);
  glViewport(0, 0, gl.output_width, gl.output_height);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(gl.encode_program);
  glBindTextureUnit(0, gl.linear_colour);
  if (gl.weights != 0) glBindTextureUnit(2, gl.weights);
  glBindTextureUnit(3, gl.depth);
  glBindTextureUnit(4, gl.response_table);
  glBindVertexArray(gl.empty_vertex_array);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glFinish();
}

namespace {

image::FloatImage read_float(GLuint framebuffer, int width, int height, GLenum format, int channels) {
  image::FloatImage image(width, height, channels);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glReadBuffer(format == GL_DEPTH_COMPONENT ? GL_NONE : GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, format, GL_FLOAT, image.pixels.data());
  image::flip_rows(image);
  return image;
}

}  // namespace

image::FloatImage SceneRenderer::read_linear() const {
  const image::WordImage signal = read_signal();
  image::FloatImage normalized(signal.width, signal.height, signal.channels);
  for (std::size_t i = 0; i < signal.pixels.size(); ++i) normalized.pixels[i] = signal.pixels[i] / 65535.0f;
  return optics::emitted_image(normalized, gl_->projector);
}

image::FloatImage SceneRenderer::read_rendered() const {
  return read_float(gl_->linear_framebuffer, gl_->width, gl_->height, GL_RGBA, 4);
}

image::FloatImage SceneRenderer::read_depth() const {
  return read_float(gl_->linear_framebuffer, gl_->width, gl_->height, GL_DEPTH_COMPONENT, 1);
}

image::ByteImage SceneRenderer::read_encoded() const {
  image::ByteImage image(gl_->output_width, gl_->output_height, 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, gl_->encoded_framebuffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, gl_->output_width, gl_->output_height, GL_RGBA, GL_UNSIGNED_BYTE, image.pixels.data());
  image::flip_rows(image);
  return image;
}

image::Image<std::uint16_t> SceneRenderer::read_signal() const {
  image::Image<std::uint16_t> image(gl_->output_width, gl_->output_height, 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, gl_->encoded_framebuffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 2);
  glReadPixels(0, 0, gl_->output_width, gl_->output_height, GL_RGBA, GL_UNSIGNED_SHORT, image.pixels.data());
  image::flip_rows(image);
  return image;
}

unsigned SceneRenderer::output_framebuffer() const { return gl_->encoded_framebuffer; }
int SceneRenderer::width() const { return gl_->output_width; }
int SceneRenderer::height() const { return gl_->output_height; }

}  // namespace optique::render
