#include "render/scene_renderer.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <string>

#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>

#include "render/field_gather.h"
#include "render/gl_objects.h"
#include "render/shaders.h"
#include "render/up_converter.h"

namespace optique::render {
namespace {

// The output pass's choices for a stage, as the preprocessor constants it is
// built with (the enums' values are the shader's numbers).
std::string output_stage_defines(const OutputStage& stage) {
  return "#version 450 core\n#define WARP " + std::to_string(stage.projector_to_user ? 1 : 0) + "\n#define CURVE " +
         std::to_string(static_cast<int>(stage.projector.curve())) + "\n#define SHARE " +
         std::to_string(static_cast<int>(stage.focus.role)) + "\n#define INSET " +
         std::to_string(stage.focus.inset ? 1 : 0) + "\n#define WEIGHTS " +
         std::to_string(stage.weights.empty() ? 0 : 1) + "\n";
}

struct SceneUniforms {
  GLint model_view_projection, model, normal_matrix, eye, base_colour, has_base_colour_texture, metallic, roughness,
      emissive, ambient, light_count;
  GLint model_view_projection_now, model_view_projection_next, half_size;  // velocity only
  GLint size, normal_matrix_now, normal_matrix_next, most_turn_cosine;     // motion field only
};

// What a scene program writes besides the geometry: shaded colour; or that
// and each fragment's velocity (the gather); or only where each fragment was
// in one key frame or two (the up-conversion's motion field; from one, it
// writes one target: 6 ms instead of 11 on llvmpipe at 1280×720).
enum class SceneOutput { colour, velocity, key_frame, key_frames };

// Its sources come without a #version line, so that the choice goes first.
Result<glo::Program> scene_program(SceneOutput output, SceneUniforms& uniforms) {
  const std::string head = std::string("#version 450 core\n") +
                           (output != SceneOutput::colour ? "#define VELOCITY 1\n" : "") +
                           (output == SceneOutput::key_frame ? "#define ONE_END 1\n" : "");
  const bool field = output == SceneOutput::key_frame || output == SceneOutput::key_frames;
  const std::string_view fragment = field ? shaders::motion_field_frag : shaders::scene_frag;
  auto program = glo::link_program(head + std::string(shaders::scene_vert), head + std::string(fragment));
  if (!program) return Error{program.error()};
  const GLuint p = program.value().get();
  const auto at = [p](const char* name) { return glGetUniformLocation(p, name); };
  uniforms = {at("model_view_projection"),
              at("model"),
              at("normal_matrix"),
              at("eye"),
              at("base_colour_factor"),
              at("has_base_colour_texture"),
              at("metallic"),
              at("roughness"),
              at("emissive"),
              at("ambient"),
              at("light_count"),
              at("model_view_projection_0"),
              at("model_view_projection_1"),
              at("half_size"),
              at("size"),
              at("normal_matrix_0"),
              at("normal_matrix_1"),
              at("most_turn_cosine")};
  return program;
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
  glo::Program scene_program;
  glo::Program encode_program;
  glo::VertexArray vertex_array;
  glo::Buffer vertex_buffer;
  glo::Buffer index_buffer;
  glo::Buffer light_buffer;
  glo::VertexArray empty_vertex_array;
  glo::Framebuffer linear_framebuffer;
  glo::Texture linear_colour;
  glo::Texture depth;
  // With multisampling, the scene is drawn here and resolved into the above.
  int samples = 1;
  glo::Framebuffer multisample_framebuffer;
  glo::Texture multisample_colour;
  glo::Texture multisample_depth;
  GLenum depth_format = GL_DEPTH_COMPONENT32F;
  // Colour fields seen from one eye: the still objects' depth, drawn once and
  // brought back before each field's moving objects (made when first needed).
  glo::Framebuffer still_depth_framebuffer;
  glo::Texture still_depth;
  glo::Framebuffer encoded_framebuffer;  // the signal: drawn by the output pass, blitted to a window
  glo::Texture encoded_colour;
  // A copy of the output, shown while the next image is drawn (hold_output).
  glo::Framebuffer held_framebuffer;
  glo::Texture held_colour;
  glo::Texture weights;
  glo::Texture response_table;
  optics::ProjectorModel projector;  // of the output stage
  int output_width = 0;
  int output_height = 0;
  std::vector<glo::Texture> scene_textures;  // by index in the scene's textures
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
  SceneUniforms uniforms{};
  // The gather's (prepare_gather): the scene program that also writes velocity,
  // and the passes (which hold the image the fields are gathered into).
  glo::Program velocity_program;
  SceneUniforms velocity_uniforms{};
  std::unique_ptr<FieldGather> gather;
  // Up-conversion's (prepare_up_conversion): the motion field's program and
  // the key frames, targets and passes.
  // One program per number of key frames: [0] from one, [1] from two.
  std::array<glo::Program, 2> key_frames_program;
  std::array<SceneUniforms, 2> key_frames_uniforms{};
  std::unique_ptr<UpConverter> up_converter;
  // Where the last frame's image and depth before the output stage are: the
  // linear framebuffer, or a frame between key frames.
  GLuint rendered_colour_framebuffer = 0;
  GLuint rendered_depth_framebuffer = 0;
};

SceneRenderer::SceneRenderer(std::unique_ptr<Gl> gl) : gl_(std::move(gl)) {}
SceneRenderer::~SceneRenderer() = default;

Result<std::unique_ptr<SceneRenderer>> SceneRenderer::create(const scene::SceneDefinition& scene, int width, int height,
                                                             DepthFormat depth, int samples) {
  if (width <= 0 || height <= 0) return Error{"the image size must be positive"};
  if (samples < 1) return Error{"the samples per pixel must be at least 1, not " + std::to_string(samples)};
  auto gl = std::make_unique<Gl>();
  gl->width = width;
  gl->height = height;
  auto program = scene_program(SceneOutput::colour, gl->uniforms);
  if (!program) return Error{program.error()};
  gl->scene_program = std::move(program).value();

  // All meshes in one vertex and one index buffer.
  std::vector<scene::Vertex> vertices;
  std::vector<std::uint32_t> indices;
  for (const auto& mesh : scene.meshes) {
    gl->meshes.push_back(
        {static_cast<GLsizei>(mesh.indices.size()), indices.size(), static_cast<GLint>(vertices.size())});
    vertices.insert(vertices.end(), mesh.vertices.begin(), mesh.vertices.end());
    indices.insert(indices.end(), mesh.indices.begin(), mesh.indices.end());
  }
  gl->vertex_array = glo::make_vertex_array();
  gl->empty_vertex_array = glo::make_vertex_array();
  gl->vertex_buffer = glo::make_buffer();
  gl->index_buffer = glo::make_buffer();
  glNamedBufferStorage(gl->vertex_buffer.get(),
                       static_cast<GLsizeiptr>(std::max<std::size_t>(1, vertices.size()) * sizeof(scene::Vertex)),
                       vertices.empty() ? nullptr : vertices.data(), 0);
  glNamedBufferStorage(gl->index_buffer.get(),
                       static_cast<GLsizeiptr>(std::max<std::size_t>(1, indices.size()) * sizeof(std::uint32_t)),
                       indices.empty() ? nullptr : indices.data(), 0);
  glVertexArrayVertexBuffer(gl->vertex_array.get(), 0, gl->vertex_buffer.get(), 0, sizeof(scene::Vertex));
  glVertexArrayElementBuffer(gl->vertex_array.get(), gl->index_buffer.get());
  glEnableVertexArrayAttrib(gl->vertex_array.get(), 0);
  glVertexArrayAttribFormat(gl->vertex_array.get(), 0, 3, GL_FLOAT, GL_FALSE, offsetof(scene::Vertex, position));
  glVertexArrayAttribBinding(gl->vertex_array.get(), 0, 0);
  glEnableVertexArrayAttrib(gl->vertex_array.get(), 1);
  glVertexArrayAttribFormat(gl->vertex_array.get(), 1, 3, GL_FLOAT, GL_FALSE, offsetof(scene::Vertex, normal));
  glVertexArrayAttribBinding(gl->vertex_array.get(), 1, 0);
  glEnableVertexArrayAttrib(gl->vertex_array.get(), 2);
  glVertexArrayAttribFormat(gl->vertex_array.get(), 2, 2, GL_FLOAT, GL_FALSE, offsetof(scene::Vertex, uv));
  glVertexArrayAttribBinding(gl->vertex_array.get(), 2, 0);

  // Textures: sRGB colour (decoded to linear when sampled), linear alpha; mipmapped,
  // trilinear, repeating. Rows go up as they are stored, top row first: that row
  // is t = 0, which is where glTF's v = 0 (the image's top) is, so glTF uvs
  // sample the texture unchanged.
  for (const auto& texture : scene.textures) {
    if (texture.width <= 0 || texture.height <= 0 ||
        texture.rgba.size() != static_cast<std::size_t>(texture.width) * static_cast<std::size_t>(texture.height) * 4) {
      return Error{"texture '" + texture.name + "' has no or the wrong number of texels"};
    }
    gl->scene_textures.push_back(glo::make_texture());
    const GLuint name = gl->scene_textures.back().get();
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
  gl->light_buffer = glo::make_buffer();
  glNamedBufferStorage(gl->light_buffer.get(),
                       static_cast<GLsizeiptr>(std::max<std::size_t>(1, gl->all_lights.size()) * sizeof(glm::vec4)),
                       nullptr, GL_DYNAMIC_STORAGE_BIT);

  gl->materials = scene.materials;
  gl->instances = scene.instances;
  gl->ambient = scene.ambient;
  gl->background = scene.background;

  // Linear light in 32-bit floats: stacked projectors add their shares, and half
  // floats (2⁻¹¹ relative) put highlights of 3 off by 2e-3 after the sum.
  // Depth in 32-bit float (or 24-bit fixed point).
  gl->linear_colour = glo::make_texture();
  glTextureStorage2D(gl->linear_colour.get(), 1, GL_RGBA32F, width, height);
  // Bilinear for the two-pass warp; the single pass reads texels exactly.
  glTextureParameteri(gl->linear_colour.get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(gl->linear_colour.get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(gl->linear_colour.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(gl->linear_colour.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  gl->depth_format = depth == DepthFormat::fixed24 ? GL_DEPTH_COMPONENT24 : GL_DEPTH_COMPONENT32F;
  gl->depth = glo::make_storage(gl->depth_format, width, height);
  gl->linear_framebuffer = glo::make_framebuffer();
  glNamedFramebufferTexture(gl->linear_framebuffer.get(), GL_COLOR_ATTACHMENT0, gl->linear_colour.get(), 0);
  glNamedFramebufferTexture(gl->linear_framebuffer.get(), GL_DEPTH_ATTACHMENT, gl->depth.get(), 0);
  gl->rendered_colour_framebuffer = gl->rendered_depth_framebuffer = gl->linear_framebuffer.get();
  if (samples > 1) {
    GLint most = 1;
    glGetIntegerv(GL_MAX_SAMPLES, &most);
    if (samples > most) {
      return Error{std::to_string(samples) + " samples per pixel asked for; this GL driver draws at most " +
                   std::to_string(most)};
    }
    gl->samples = samples;
    gl->multisample_colour = glo::make_storage(GL_RGBA32F, width, height, samples);
    gl->multisample_depth = glo::make_storage(gl->depth_format, width, height, samples);
    gl->multisample_framebuffer = glo::make_framebuffer();
    glNamedFramebufferTexture(gl->multisample_framebuffer.get(), GL_COLOR_ATTACHMENT0, gl->multisample_colour.get(), 0);
    glNamedFramebufferTexture(gl->multisample_framebuffer.get(), GL_DEPTH_ATTACHMENT, gl->multisample_depth.get(), 0);
    if (glCheckNamedFramebufferStatus(gl->multisample_framebuffer.get(), GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      return Error{"this GL driver cannot draw " + std::to_string(samples) + " samples per pixel into RGBA32F"};
    }
  }
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
  const std::string source = output_stage_defines(stage) + std::string(shaders::output_frag);
  auto encode_program = glo::link_program(shaders::fullscreen_vert, source);
  if (!encode_program) return Error{encode_program.error()};
  gl.weights.reset();
  gl.output_width = width;
  gl.output_height = height;
  // Its uniforms are set once here, not per frame.
  gl.encode_program = std::move(encode_program).value();
  const GLuint program = gl.encode_program.get();
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
    gl.response_table = glo::make_texture();
    glTextureStorage2D(gl.response_table.get(), 1, GL_R32F, static_cast<GLsizei>(table.size()), 1);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(gl.response_table.get(), 0, 0, 0, static_cast<GLsizei>(table.size()), 1, GL_RED, GL_FLOAT,
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

  gl.held_framebuffer = {};  // made again at this size when needed
  gl.held_colour = {};
  gl.encoded_colour = glo::make_texture();
  // The signal at the projector's depth: 8 bits, or 16 to hold up to 16.
  glTextureStorage2D(gl.encoded_colour.get(), 1, model.bits() <= 8 ? GL_RGBA8 : GL_RGBA16, width, height);
  gl.encoded_framebuffer = glo::make_framebuffer();
  glNamedFramebufferTexture(gl.encoded_framebuffer.get(), GL_COLOR_ATTACHMENT0, gl.encoded_colour.get(), 0);
  if (!stage.weights.empty()) {
    image::FloatImage rows_up = stage.weights;  // GL's first row is the bottom one
    image::flip_rows(rows_up);
    gl.weights = glo::make_texture();
    glTextureStorage2D(gl.weights.get(), 1, GL_R32F, width, height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(gl.weights.get(), 0, 0, 0, width, height, GL_RED, GL_FLOAT, rows_up.pixels.data());
  }
  for (GLuint fb : {gl.linear_framebuffer.get(), gl.encoded_framebuffer.get()}) {
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
    glNamedBufferSubData(gl.light_buffer.get(), 0, static_cast<GLsizeiptr>(data.size() * sizeof(glm::vec4)),
                         data.data());
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
  const GLuint program = gl.encode_program.get();
  glProgramUniform4f(program, gl.focus_uniforms.coc, static_cast<float>(frame.coc.k),
                     static_cast<float>(frame.coc.focal), static_cast<float>(frame.coc.lo),
                     static_cast<float>(frame.coc.hi));
  glProgramUniform3f(program, gl.focus_uniforms.inset_disc, static_cast<float>(frame.gaze.x),
                     static_cast<float>(frame.gaze.y), static_cast<float>(frame.inset_radius));
}

void SceneRenderer::draw(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                         const geometry::Frustum& frustum, const LightTerms& terms) {
  draw_linear(state, fraction, eye, frustum, terms);
  encode();
}

void SceneRenderer::draw_linear(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                                const geometry::Frustum& frustum, const LightTerms& terms) {
  begin_linear();
  draw_scene(state, fraction, eye, frustum, terms);
  resolve();
}

GatherReport SceneRenderer::draw_fields(const scene::SceneState& state, std::span<const FieldPass> passes,
                                        const LightTerms& terms, bool still_once_allowed, const GatherFrame* blur) {
  begin_linear();
  // Seen from one place in every field (the viewer does not move), what does not
  // move looks the same in each: it is drawn once, in every channel, and each
  // field draws only the moving objects over it, on the still objects' depth.
  const bool one_view = std::all_of(passes.begin(), passes.end(), [&](const FieldPass& p) {
    return p.eye == passes.front().eye && p.frustum.view == passes.front().frustum.view &&
           p.frustum.projection == passes.front().frustum.projection;
  });
  // With nothing still, keeping depth aside would only cost (measured: 0.86× the
  // frame time without it on the moving square).
  const bool anything_still =
      std::any_of(gl_->instances.begin(), gl_->instances.end(), [](const scene::Instance& i) { return !i.object; });
  const bool still_once = still_once_allowed && anything_still && !passes.empty() && one_view;
  if (still_once) {
    const FieldPass& first = passes.front();
    draw_scene(state, first.fraction, first.eye, first.frustum, terms, Objects::still);
    keep_still_depth();
  }
  for (const FieldPass& pass : passes) {
    // Each pass sees the scene at its moment: depth starts over (from the still
    // objects'), the other passes' colours stay. Alpha keeps the clear's 1.
    if (still_once) {
      bring_back_still_depth();
    } else {
      glClear(GL_DEPTH_BUFFER_BIT);
    }
    glColorMask(pass.red, pass.green, pass.blue, GL_FALSE);
    draw_scene(state, pass.fraction, pass.eye, pass.frustum, terms, still_once ? Objects::moving : Objects::all);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  }
  resolve();
  if (blur == nullptr) {
    encode();
    return {};
  }
  // The fields aside; the scene once more, with its velocity, for the blur of
  // what is too fast to follow, laid over them.
  Gl& gl = *gl_;
  assert(gl.gather);  // prepare_gather first
  gl.gather->keep(gl.linear_colour.get());
  draw_with_motion(state, *blur, terms);
  const GatherReport report = gl.gather->gather(gl.linear_colour.get(), {}, blur->settings);
  encode(gl.gather->output());
  return report;
}

Result<void> SceneRenderer::prepare_gather() {
  Gl& gl = *gl_;
  if (gl.gather) return {};
  auto program = scene_program(SceneOutput::velocity, gl.velocity_uniforms);
  if (!program) return Error{program.error()};
  auto gather = FieldGather::create(gl.width, gl.height, gl.samples);
  if (!gather) return Error{gather.error()};
  glNamedFramebufferTexture(draw_framebuffer(), GL_COLOR_ATTACHMENT1, gather.value()->motion_target(), 0);
  if (glCheckNamedFramebufferStatus(draw_framebuffer(), GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    return Error{"this GL driver cannot draw the scene's velocity beside its colour"};
  }
  gl.velocity_program = std::move(program).value();
  gl.gather = std::move(gather).value();
  return {};
}

GatherReport SceneRenderer::draw_gathered(const scene::SceneState& state, const GatherFrame& frame,
                                          const LightTerms& terms) {
  assert(gl_->gather);  // prepare_gather first
  draw_with_motion(state, frame, terms);
  return gather_again(frame.fields, frame.settings);
}

void SceneRenderer::draw_with_motion(const scene::SceneState& state, const GatherFrame& frame,
                                     const LightTerms& terms) {
  begin_linear(true);
  const Motion motion{{{&state, 0.0, frame.view_projection_now}, {&state, 1.0, frame.view_projection_next}}};
  draw_scene(state, frame.seen.fraction, frame.seen.eye, frame.seen.frustum, terms, Objects::all, &motion);
  resolve();
  gl_->gather->measure();
}

GatherReport SceneRenderer::gather_again(std::span<const GatherField> fields, const GatherSettings& settings) {
  Gl& gl = *gl_;
  assert(gl.gather);
  const GatherReport report = gl.gather->gather(gl.linear_colour.get(), fields, settings);
  encode(gl.gather->output());
  return report;
}

Result<void> SceneRenderer::prepare_up_conversion(int slots) {
  Gl& gl = *gl_;
  if (gl.up_converter) return {};
  std::array<glo::Program, 2> programs;
  std::array<SceneUniforms, 2> uniforms{};
  for (int keys = 1; keys <= 2; ++keys) {
    auto program = scene_program(keys == 1 ? SceneOutput::key_frame : SceneOutput::key_frames, uniforms[keys - 1]);
    if (!program) return Error{"the up-conversion's motion field: " + program.error()};
    programs[keys - 1] = std::move(program).value();
  }
  auto converter = UpConverter::create(gl.width, gl.height, gl.depth_format, slots, gl.samples);
  if (!converter) return Error{converter.error()};
  gl.key_frames_program = std::move(programs);
  gl.key_frames_uniforms = uniforms;
  gl.up_converter = std::move(converter).value();
  return {};
}

void SceneRenderer::keep_key(int slot, up::KeyView view) {
  Gl& gl = *gl_;
  assert(gl.up_converter);  // prepare_up_conversion first
  gl.up_converter->keep(slot, gl.linear_colour.get(), gl.depth.get(), gl.multisample_depth.get(), std::move(view));
}

up::BetweenReport SceneRenderer::build_between(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                                               const geometry::Frustum& frustum, const up::BetweenFrame& frame,
                                               const LightTerms& terms) {
  Gl& gl = *gl_;
  assert(gl.up_converter);  // prepare_up_conversion first
  UpConverter& converter = *gl.up_converter;
  const bool motion = frame.method == up::BetweenMethod::motion;
  if (motion) {
    converter.begin_motion_field(frame.two_keys);
    const up::KeyView& first = converter.key(frame.first);
    const up::KeyView& second = converter.key(frame.two_keys ? frame.second : frame.first);
    const Motion field{{{&first.state, first.fraction, first.view_projection},
                        {&second.state, second.fraction, second.view_projection}},
                       frame.two_keys ? 2 : 1};
    draw_scene(state, fraction, eye, frustum, terms, Objects::all, &field);
  }
  const up::BetweenReport report = converter.resolve(frame, gl.background);
  if (motion && frame.shade_unseen && report.unseen_pixels > 0) {
    converter.begin_shade_unseen();
    draw_scene(state, fraction, eye, frustum, terms);
    converter.end_shade_unseen();
  }
  converter.finish();
  return report;
}

up::BetweenReport SceneRenderer::draw_between(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                                              const geometry::Frustum& frustum, const up::BetweenFrame& frame,
                                              const LightTerms& terms) {
  Gl& gl = *gl_;
  const up::BetweenReport report = build_between(state, fraction, eye, frustum, frame, terms);
  const UpConverter& converter = *gl.up_converter;
  const bool motion = frame.method == up::BetweenMethod::motion;
  // The average has no depth of its own: the first key frame's (the linear
  // depth may hold bands of a key frame being drawn).
  if (!motion) converter.restore_depth(frame.first, gl.depth.get());
  gl.rendered_colour_framebuffer = converter.output_framebuffer();
  gl.rendered_depth_framebuffer = motion ? converter.output_framebuffer() : gl.linear_framebuffer.get();
  encode(converter.output(), motion ? converter.depth() : gl.depth.get());
  return report;
}

double SceneRenderer::check_between(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                                    const geometry::Frustum& frustum, const up::BetweenFrame& frame,
                                    const LightTerms& terms, std::optional<int> against_slot) {
  Gl& gl = *gl_;
  (void)build_between(state, fraction, eye, frustum, frame, terms);
  UpConverter& converter = *gl.up_converter;
  return converter.psnr_y_against(against_slot ? converter.key_colour(*against_slot) : gl.linear_colour.get());
}

void SceneRenderer::draw_key_band(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                                  const geometry::Frustum& frustum, const LightTerms& terms, int slot, int index,
                                  int count, int bands) {
  Gl& gl = *gl_;
  assert(gl.up_converter);  // prepare_up_conversion first
  assert(count >= 1 && index >= 0 && bands >= 1 && index + bands <= count);
  const int first_row = gl.height * index / count;
  const int rows = gl.height * (index + bands) / count - first_row;
  // The scissor bounds the clear, the fragments and the multisample resolve;
  // the geometry is processed whole each band.
  glEnable(GL_SCISSOR_TEST);
  glScissor(0, first_row, gl.width, rows);
  draw_linear(state, fraction, eye, frustum, terms);
  glDisable(GL_SCISSOR_TEST);
  gl.up_converter->keep_rows(slot, gl.linear_colour.get(), gl.depth.get(), gl.multisample_depth.get(),
                             {state, fraction, frustum.projection * frustum.view}, first_row, rows);
}

void SceneRenderer::draw_fields_up_converted(const scene::SceneState& state, const FieldPass* key,
                                             std::span<const FieldPass> passes, const LightTerms& terms) {
  assert(gl_->up_converter);  // prepare_up_conversion first
  if (key != nullptr) {
    draw_linear(state, key->fraction, key->eye, key->frustum, terms);
    keep_key(0, {state, key->fraction, key->frustum.projection * key->frustum.view});
  }
  up::BetweenFrame from;
  from.first = 0;
  (void)build_fields(state, passes, from, terms, key);
}

up::BetweenReport SceneRenderer::draw_fields_between(const scene::SceneState& state, std::span<const FieldPass> passes,
                                                     const up::BetweenFrame& from, const LightTerms& terms) {
  assert(gl_->up_converter);  // prepare_up_conversion first
  return build_fields(state, passes, from, terms, nullptr);
}

up::BetweenReport SceneRenderer::build_fields(const scene::SceneState& state, std::span<const FieldPass> passes,
                                              const up::BetweenFrame& from, const LightTerms& terms,
                                              const FieldPass* shown) {
  Gl& gl = *gl_;
  UpConverter& converter = *gl.up_converter;
  const auto at_shown = [&](const FieldPass& pass) {
    return shown != nullptr && pass.fraction == shown->fraction && pass.eye == shown->eye &&
           pass.frustum.view == shown->frustum.view && pass.frustum.projection == shown->frustum.projection;
  };
  up::BetweenReport most;
  for (const FieldPass& pass : passes) {
    if (at_shown(pass)) continue;  // shown as drawn
    up::BetweenFrame frame = from;
    if (frame.two_keys) frame.toward_second = std::clamp(from.toward_second + pass.fraction * from.per_frame, 0.0, 1.0);
    const up::BetweenReport report = build_between(state, pass.fraction, pass.eye, pass.frustum, frame, terms);
    if (report.unseen_share >= most.unseen_share) most = report;
    converter.write_channels(gl.linear_framebuffer.get(), pass.red, pass.green, pass.blue);
  }
  gl.rendered_colour_framebuffer = gl.rendered_depth_framebuffer = gl.linear_framebuffer.get();
  encode();
  return most;
}

void SceneRenderer::show_key(int slot) {
  Gl& gl = *gl_;
  assert(gl.up_converter);
  // Back where draw() leaves an image: read_rendered() and read_depth() find it.
  gl.up_converter->restore(slot, gl.linear_colour.get(), gl.depth.get());
  gl.rendered_colour_framebuffer = gl.rendered_depth_framebuffer = gl.linear_framebuffer.get();
  encode();
}

void SceneRenderer::hold_output() {
  Gl& gl = *gl_;
  if (gl.held_framebuffer.get() == 0) {
    gl.held_colour = glo::make_texture();
    GLint format = 0;
    glGetTextureLevelParameteriv(gl.encoded_colour.get(), 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
    glTextureStorage2D(gl.held_colour.get(), 1, static_cast<GLenum>(format), gl.output_width, gl.output_height);
    gl.held_framebuffer = glo::make_framebuffer();
    glNamedFramebufferTexture(gl.held_framebuffer.get(), GL_COLOR_ATTACHMENT0, gl.held_colour.get(), 0);
  }
  glCopyImageSubData(gl.encoded_colour.get(), GL_TEXTURE_2D, 0, 0, 0, 0, gl.held_colour.get(), GL_TEXTURE_2D, 0, 0, 0,
                     0, gl.output_width, gl.output_height, 1);
}

unsigned SceneRenderer::held_framebuffer() const { return gl_->held_framebuffer.get(); }

void SceneRenderer::keep_still_depth() {
  Gl& gl = *gl_;
  if (gl.still_depth_framebuffer.get() == 0) {
    gl.still_depth = glo::make_storage(gl.depth_format, gl.width, gl.height, gl.samples);
    gl.still_depth_framebuffer = glo::make_framebuffer();
    glNamedFramebufferTexture(gl.still_depth_framebuffer.get(), GL_DEPTH_ATTACHMENT, gl.still_depth.get(), 0);
  }
  glBlitNamedFramebuffer(draw_framebuffer(), gl.still_depth_framebuffer.get(), 0, 0, gl.width, gl.height, 0, 0,
                         gl.width, gl.height, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
}

void SceneRenderer::bring_back_still_depth() {
  const Gl& gl = *gl_;
  glBlitNamedFramebuffer(gl.still_depth_framebuffer.get(), draw_framebuffer(), 0, 0, gl.width, gl.height, 0, 0,
                         gl.width, gl.height, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
}

unsigned SceneRenderer::draw_framebuffer() const {
  return gl_->samples > 1 ? gl_->multisample_framebuffer.get() : gl_->linear_framebuffer.get();
}

void SceneRenderer::resolve() {
  const Gl& gl = *gl_;
  if (gl.samples == 1) return;
  // Each pixel's samples averaged (linear light); depth from one sample, for the
  // passes that read it.
  glBlitNamedFramebuffer(gl.multisample_framebuffer.get(), gl.linear_framebuffer.get(), 0, 0, gl.width, gl.height, 0, 0,
                         gl.width, gl.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBlitNamedFramebuffer(gl.multisample_framebuffer.get(), gl.linear_framebuffer.get(), 0, 0, gl.width, gl.height, 0, 0,
                         gl.width, gl.height, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
}

void SceneRenderer::begin_linear(bool with_motion) {
  Gl& gl = *gl_;
  gl.rendered_colour_framebuffer = gl.rendered_depth_framebuffer = gl.linear_framebuffer.get();
  const GLuint framebuffer = draw_framebuffer();
  if (gl.gather) {  // the velocity target is attached: drawn into only by a gather
    static constexpr GLenum kBoth[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(framebuffer, with_motion ? 2 : 1, kBoth);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glViewport(0, 0, gl.width, gl.height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);  // thin objects (quads) are seen from both sides
  glClearColor(gl.background.r, gl.background.g, gl.background.b, 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  if (with_motion) FieldGather::clear_motion(framebuffer);  // after: glClear cleared it to the background
}

void SceneRenderer::draw_scene(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                               const geometry::Frustum& frustum, const LightTerms& terms, Objects which,
                               const Motion* motion) {
  Gl& gl = *gl_;
  upload_shining_lights(state.lights_off);
  const int keys = motion ? motion->key_frames : 0;
  const bool key_frames = keys > 0;
  assert(keys >= 0 && keys <= 2);
  const int field = std::max(keys - 1, 0);
  glUseProgram(key_frames ? gl.key_frames_program[field].get()
               : motion   ? gl.velocity_program.get()
                          : gl.scene_program.get());
  glBindVertexArray(gl.vertex_array.get());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, gl.light_buffer.get());
  const SceneUniforms& u = key_frames ? gl.key_frames_uniforms[field] : motion ? gl.velocity_uniforms : gl.uniforms;
  if (motion) glUniform2f(u.half_size, 0.5f * static_cast<float>(gl.width), 0.5f * static_cast<float>(gl.height));
  if (key_frames) {
    glUniform2f(u.size, static_cast<float>(gl.width), static_cast<float>(gl.height));
    glUniform1f(u.most_turn_cosine, static_cast<float>(std::cos(up::kMostTurn)));
  }
  glUniform3f(u.eye, static_cast<float>(eye.x), static_cast<float>(eye.y), static_cast<float>(eye.z));
  const glm::vec3 ambient = terms.ambient ? gl.ambient : glm::vec3(0.0f);
  glUniform3fv(u.ambient, 1, glm::value_ptr(ambient));
  glUniform1i(u.light_count, gl.light_count);
  const glm::dmat4 view_projection = frustum.projection * frustum.view;

  for (const auto& instance : gl.instances) {
    if ((which == Objects::still && instance.object) || (which == Objects::moving && !instance.object)) continue;
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
    if (motion) {
      // Where this instance is at the motion's two ends; an object not in the
      // scene then projects to w = 0: no place.
      const GLint locations[2] = {u.model_view_projection_now, u.model_view_projection_next};
      const GLint normal_locations[2] = {u.normal_matrix_now, u.normal_matrix_next};
      for (int e = 0; e < (keys == 1 ? 1 : 2); ++e) {
        const MotionEnd& end = motion->ends[e];
        glm::dmat4 then = instance.transform;
        bool there = true;
        if (instance.object) {
          const auto found = end.state->objects.find(*instance.object);
          there = found != end.state->objects.end();
          if (there) then = scene::model_matrix(scene::interpolate(found->second, end.fraction)) * instance.transform;
        }
        const glm::mat4 clip(there ? end.view_projection * then : glm::dmat4(0.0));
        glUniformMatrix4fv(locations[e], 1, GL_FALSE, glm::value_ptr(clip));
        if (key_frames) {
          const glm::mat3 normals(glm::transpose(glm::inverse(glm::dmat3(then))));
          glUniformMatrix3fv(normal_locations[e], 1, GL_FALSE, glm::value_ptr(normals));
        }
      }
    }
    glUniformMatrix4fv(u.model, 1, GL_FALSE, glm::value_ptr(model_f));
    glUniformMatrix3fv(u.normal_matrix, 1, GL_FALSE, glm::value_ptr(normal_matrix));
    const scene::Material& m = gl.materials[instance.material];
    glUniform3fv(u.base_colour, 1, glm::value_ptr(m.base_colour));
    glUniform1i(u.has_base_colour_texture, m.base_colour_texture ? 1 : 0);
    if (m.base_colour_texture) glBindTextureUnit(1, gl.scene_textures[*m.base_colour_texture].get());  // unit 0: encode
    glUniform1f(u.metallic, m.metallic);
    glUniform1f(u.roughness, m.roughness);
    const glm::vec3 emissive = terms.emissive ? m.emissive : glm::vec3(0.0f);
    glUniform3fv(u.emissive, 1, glm::value_ptr(emissive));
    const MeshRange& mesh = gl.meshes[instance.mesh];
    glDrawElementsBaseVertex(GL_TRIANGLES, mesh.count, GL_UNSIGNED_INT,
                             reinterpret_cast<const void*>(mesh.first_index * sizeof(std::uint32_t)), mesh.base_vertex);
  }
}

void SceneRenderer::draw_black() {
  gl_->rendered_colour_framebuffer = gl_->rendered_depth_framebuffer = gl_->linear_framebuffer.get();
  glBindFramebuffer(GL_FRAMEBUFFER, gl_->linear_framebuffer.get());
  glViewport(0, 0, gl_->width, gl_->height);
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  encode();
}

void SceneRenderer::encode() { encode(gl_->linear_colour.get()); }
void SceneRenderer::encode(unsigned texture) { encode(texture, gl_->depth.get()); }

// The projector's response, last: linear light → what is sent to it.
void SceneRenderer::encode(unsigned texture, unsigned depth) {
  Gl& gl = *gl_;
  glBindFramebuffer(GL_FRAMEBUFFER, gl.encoded_framebuffer.get());
  glViewport(0, 0, gl.output_width, gl.output_height);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(gl.encode_program.get());
  glBindTextureUnit(0, texture);
  if (gl.weights) glBindTextureUnit(2, gl.weights.get());
  glBindTextureUnit(3, depth);
  glBindTextureUnit(4, gl.response_table.get());
  glBindVertexArray(gl.empty_vertex_array.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glFinish();
}

image::FloatImage SceneRenderer::read_linear() const {
  const image::WordImage signal = read_signal();
  image::FloatImage normalized(signal.width, signal.height, signal.channels);
  for (std::size_t i = 0; i < signal.pixels.size(); ++i) normalized.pixels[i] = signal.pixels[i] / 65535.0f;
  return optics::emitted_image(normalized, gl_->projector);
}

image::FloatImage SceneRenderer::read_rendered() const {
  image::FloatImage image = glo::read_float(gl_->rendered_colour_framebuffer, gl_->width, gl_->height, GL_RGBA, 4);
  for (std::size_t i = 3; i < image.pixels.size(); i += 4) image.pixels[i] = 1.0f;
  return image;
}

image::FloatImage SceneRenderer::read_depth() const {
  return glo::read_float(gl_->rendered_depth_framebuffer, gl_->width, gl_->height, GL_DEPTH_COMPONENT, 1);
}

image::ByteImage SceneRenderer::read_encoded() const {
  image::ByteImage image(gl_->output_width, gl_->output_height, 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, gl_->encoded_framebuffer.get());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, gl_->output_width, gl_->output_height, GL_RGBA, GL_UNSIGNED_BYTE, image.pixels.data());
  image::flip_rows(image);
  return image;
}

image::Image<std::uint16_t> SceneRenderer::read_signal() const {
  image::Image<std::uint16_t> image(gl_->output_width, gl_->output_height, 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, gl_->encoded_framebuffer.get());
  glPixelStorei(GL_PACK_ALIGNMENT, 2);
  glReadPixels(0, 0, gl_->output_width, gl_->output_height, GL_RGBA, GL_UNSIGNED_SHORT, image.pixels.data());
  image::flip_rows(image);
  return image;
}

unsigned SceneRenderer::output_framebuffer() const { return gl_->encoded_framebuffer.get(); }
unsigned SceneRenderer::rendered_framebuffer() const { return gl_->rendered_colour_framebuffer; }
int SceneRenderer::width() const { return gl_->output_width; }
int SceneRenderer::height() const { return gl_->output_height; }

}  // namespace optique::render
