// Small owning wrappers for GL objects, and shader programs built from the embedded sources.
// Render thread only.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "server/model/mesh_data.hpp"
#include "server/render/gl/gl.hpp"

namespace downpour::render {

// A GL name with a deleter; move-only.
template <void (*Delete)(GLuint)>
class GlName {
 public:
  GlName() = default;
  explicit GlName(GLuint id) : id_(id) {}
  ~GlName() {
    if (id_) Delete(id_);
  }
  GlName(GlName&& o) noexcept : id_(o.id_) { o.id_ = 0; }
  GlName& operator=(GlName&& o) noexcept {
    if (this != &o) {
      if (id_) Delete(id_);
      id_ = o.id_;
      o.id_ = 0;
    }
    return *this;
  }
  GLuint id() const { return id_; }

 private:
  GLuint id_ = 0;
};

namespace gl_delete {
inline void texture(GLuint id) { glDeleteTextures(1, &id); }
inline void buffer(GLuint id) { glDeleteBuffers(1, &id); }
inline void framebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
inline void vertex_array(GLuint id) { glDeleteVertexArrays(1, &id); }
inline void program(GLuint id) { glDeleteProgram(id); }
}  // namespace gl_delete

using Texture = GlName<gl_delete::texture>;
using Buffer = GlName<gl_delete::buffer>;
using Framebuffer = GlName<gl_delete::framebuffer>;
using VertexArray = GlName<gl_delete::vertex_array>;

// How many copies of a texture or buffer refilled every frame are used in turn. llvmpipe counts a
// resource the last frames drew with as still in use, and an upload into it first finishes every
// pass drawn so far (the road water's, in place, cost the road pass 2.2 ms of waiting).
inline constexpr int kUploadCopies = 3;

// A new vertex array (the passes that draw from storage buffers bind an empty one) and buffer.
VertexArray make_vertex_array();
Buffer make_buffer();

Texture make_texture_2d(GLenum internal_format, int width, int height, int levels = 1);
// Layers of one size, filtered linearly within a layer.
Texture make_texture_2d_array(GLenum internal_format, int width, int height, int layers,
                              int levels = 1);

// A uniform's location in a program, looked up once (when the pass is made) and set by handle.
class Uniform {
 public:
  Uniform() = default;
  Uniform(GLuint program, GLint location) : program_(program), location_(location) {}
  void set(float v) const { glProgramUniform1f(program_, location_, v); }
  void set(int v) const { glProgramUniform1i(program_, location_, v); }
  void set(unsigned v) const { glProgramUniform1ui(program_, location_, v); }
  void set(glm::vec2 v) const { glProgramUniform2f(program_, location_, v.x, v.y); }
  void set(glm::ivec2 v) const { glProgramUniform2i(program_, location_, v.x, v.y); }
  void set(glm::vec3 v) const { glProgramUniform3f(program_, location_, v.x, v.y, v.z); }
  void set(glm::vec4 v) const { glProgramUniform4f(program_, location_, v.x, v.y, v.z, v.w); }
  void set(const glm::mat4& m) const;
  // An array of vec4 from its first element on.
  void set(const glm::vec4* v, int count) const {
    glProgramUniform4fv(program_, location_, count, &v->x);
  }
  void set(const glm::ivec2* v, int count) const {
    glProgramUniform2iv(program_, location_, count, &v->x);
  }

 private:
  GLuint program_ = 0;
  GLint location_ = -1;  // -1 (not in the program) makes set() a no-op, as GL defines
};

// A linked program from embedded shader files (by file name, e.g. "sky.frag"), their
// `#include "x.glsl"` lines resolved (shader_source.hpp), with `defines` (macro names, e.g.
// kLampBuilds' NO_LAMPS) defined in both stages. Throws with the driver's log, its locations named
// by file.
class ShaderProgram {
 public:
  ShaderProgram(const std::string& vertex_file, const std::string& fragment_file,
                const std::vector<std::string>& defines = {});
  void use() const { glUseProgram(program_.id()); }
  // Throws std::logic_error if the program has no such active uniform: a misspelt name fails at
  // start-up, not silently.
  Uniform uniform(const char* name) const;

 private:
  std::string files_;
  GlName<gl_delete::program> program_;
};

// A static indexed triangle mesh, uploaded from MeshData (attributes 0 position, 1 normal, 2 uv),
// with its bounds for culling.
class Mesh {
 public:
  Mesh() = default;
  explicit Mesh(const MeshData& data);
  // Indices [first_index, first_index + count).
  void draw(std::uint32_t first_index, std::uint32_t count) const;
  // Several index ranges in one call (glMultiDrawElements): counts[k] indices from byte offset
  // offsets[k] each.
  void multi_draw(const GLsizei* counts, const void* const* offsets, GLsizei draws) const;
  bool empty() const { return index_count_ == 0; }
  std::size_t triangles() const { return static_cast<std::size_t>(index_count_) / 3; }
  glm::vec3 bounds_min{0.0f};
  glm::vec3 bounds_max{0.0f};

 private:
  VertexArray vao_;
  Buffer vbo_;
  Buffer ibo_;
  Buffer curvature_;
  Buffer lanes_;
  Buffer texcoords_;
  GLsizei index_count_ = 0;
};

// Draws one triangle that covers the viewport; the vertex shader makes it from gl_VertexID.
class FullscreenTriangle {
 public:
  FullscreenTriangle();
  void draw() const;

 private:
  VertexArray vao_;
};

}  // namespace downpour::render
