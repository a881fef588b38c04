#include "server/render/gl/gl_objects.hpp"

#include <stdexcept>

#include <glm/gtc/type_ptr.hpp>

#include "server/render/gl/shader_source.hpp"

namespace downpour::render {

namespace {

GLuint compile(GLenum stage, const std::string& file, const std::vector<std::string>& defines) {
  ShaderSource source = resolve_shader(file);
  if (!defines.empty()) {
    // After the #version line, which must come first; then the file's own numbering again.
    const std::size_t after_version = source.text.find('\n') + 1;
    std::string lines;
    for (const std::string& d : defines) lines += "#define " + d + "\n";
    source.text.insert(after_version, lines + "#line 2 0\n");
  }
  const GLuint shader = glCreateShader(stage);
  const char* text = source.text.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096];
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    glDeleteShader(shader);
    throw std::runtime_error("compiling " + file + ": " + name_files_in_log(log, source));
  }
  return shader;
}

}  // namespace

VertexArray make_vertex_array() {
  GLuint id = 0;
  glCreateVertexArrays(1, &id);
  return VertexArray(id);
}

Buffer make_buffer() {
  GLuint id = 0;
  glCreateBuffers(1, &id);
  return Buffer(id);
}

Texture make_texture_2d(GLenum internal_format, int width, int height, int levels) {
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_2D, 1, &id);
  glTextureStorage2D(id, levels, internal_format, width, height);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, levels > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  return Texture(id);
}

Texture make_texture_2d_array(GLenum internal_format, int width, int height, int layers,
                              int levels) {
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &id);
  glTextureStorage3D(id, levels, internal_format, width, height, layers);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, levels > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  return Texture(id);
}

ShaderProgram::ShaderProgram(const std::string& vertex_file, const std::string& fragment_file,
                             const std::vector<std::string>& defines)
    : files_(vertex_file + " + " + fragment_file) {
  for (const std::string& d : defines) files_ += " (" + d + ")";
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex_file, defines);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment_file, defines);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  program_ = GlName<gl_delete::program>(program);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096];
    glGetProgramInfoLog(program, sizeof(log), nullptr, log);
    throw std::runtime_error("linking " + files_ + ": " + log);
  }
}

Uniform ShaderProgram::uniform(const char* name) const {
  const GLint location = glGetUniformLocation(program_.id(), name);
  if (location < 0) throw std::logic_error(files_ + " has no active uniform " + name);
  return Uniform(program_.id(), location);
}

void Uniform::set(const glm::mat4& m) const {
  glProgramUniformMatrix4fv(program_, location_, 1, GL_FALSE, glm::value_ptr(m));
}

Mesh::Mesh(const MeshData& data)
    : bounds_min(data.bounds_min),
      bounds_max(data.bounds_max),
      index_count_(static_cast<GLsizei>(data.indices.size())) {
  const auto& vertices = data.vertices;
  const auto& indices = data.indices;
  GLuint ids[2];
  glCreateBuffers(2, ids);
  vbo_ = Buffer(ids[0]);
  ibo_ = Buffer(ids[1]);
  glNamedBufferStorage(vbo_.id(), vertices.size() * sizeof(MeshVertex), vertices.data(), 0);
  glNamedBufferStorage(ibo_.id(), indices.size() * sizeof(std::uint32_t), indices.data(), 0);
  GLuint vao = 0;
  glCreateVertexArrays(1, &vao);
  vao_ = VertexArray(vao);
  glVertexArrayVertexBuffer(vao, 0, vbo_.id(), 0, sizeof(MeshVertex));
  glVertexArrayElementBuffer(vao, ibo_.id());
  const GLuint offsets[] = {offsetof(MeshVertex, position), offsetof(MeshVertex, normal),
                            offsetof(MeshVertex, uv)};
  const GLint sizes[] = {3, 3, 2};
  for (GLuint a = 0; a < 3; ++a) {
    glEnableVertexArrayAttrib(vao, a);
    glVertexArrayAttribFormat(vao, a, sizes[a], GL_FLOAT, GL_FALSE, offsets[a]);
    glVertexArrayAttribBinding(vao, a, 0);
  }
  if (!data.curvature.empty()) {
    glCreateBuffers(1, ids);
    curvature_ = Buffer(ids[0]);
    glNamedBufferStorage(curvature_.id(), data.curvature.size() * sizeof(VertexCurvature),
                         data.curvature.data(), 0);
    glVertexArrayVertexBuffer(vao, 1, curvature_.id(), 0, sizeof(VertexCurvature));
    const GLuint c_offsets[] = {offsetof(VertexCurvature, k1), offsetof(VertexCurvature, v1)};
    const GLint c_sizes[] = {2, 4};
    for (GLuint a = 0; a < 2; ++a) {
      glEnableVertexArrayAttrib(vao, 3 + a);
      glVertexArrayAttribFormat(vao, 3 + a, c_sizes[a], GL_FLOAT, GL_FALSE, c_offsets[a]);
      glVertexArrayAttribBinding(vao, 3 + a, 1);
    }
  }
  if (!data.texcoords.empty()) {
    glCreateBuffers(1, ids);
    texcoords_ = Buffer(ids[0]);
    glNamedBufferStorage(texcoords_.id(), data.texcoords.size() * sizeof(VertexTexture),
                         data.texcoords.data(), 0);
    glVertexArrayVertexBuffer(vao, 3, texcoords_.id(), 0, sizeof(VertexTexture));
    glEnableVertexArrayAttrib(vao, 6);
    glVertexArrayAttribFormat(vao, 6, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, 6, 3);
  }
  if (!data.lanes.empty()) {
    glCreateBuffers(1, ids);
    lanes_ = Buffer(ids[0]);
    glNamedBufferStorage(lanes_.id(), data.lanes.size() * sizeof(VertexLane), data.lanes.data(), 0);
    glVertexArrayVertexBuffer(vao, 2, lanes_.id(), 0, sizeof(VertexLane));
    glEnableVertexArrayAttrib(vao, 5);
    glVertexArrayAttribFormat(vao, 5, 4, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(vao, 5, 2);
  }
}

void Mesh::draw(std::uint32_t first_index, std::uint32_t count) const {
  if (count == 0) return;
  glBindVertexArray(vao_.id());
  glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(count), GL_UNSIGNED_INT,
                 reinterpret_cast<const void*>(static_cast<std::uintptr_t>(first_index) * 4u));
}

void Mesh::multi_draw(const GLsizei* counts, const void* const* offsets, GLsizei draws) const {
  if (draws == 0 || index_count_ == 0) return;
  glBindVertexArray(vao_.id());
  glMultiDrawElements(GL_TRIANGLES, counts, GL_UNSIGNED_INT, offsets, draws);
}

FullscreenTriangle::FullscreenTriangle() {
  GLuint vao = 0;
  glCreateVertexArrays(1, &vao);
  vao_ = VertexArray(vao);
}

void FullscreenTriangle::draw() const {
  glBindVertexArray(vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

}  // namespace downpour::render
