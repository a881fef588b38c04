// Shader sources as the driver compiles them: an embedded file with its `#include "x.glsl"` lines
// resolved, each included file marked with #line so that an error names its file and line, and the
// generated interface (shader_interface.hpp) as the file interface.glsl. No GL.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace downpour::render {

struct ShaderSource {
  std::string text;
  std::vector<std::string> files;  // by GLSL source-string number (#line's second argument)
};

// Throws std::runtime_error for an unknown file or includes nested too deep.
ShaderSource resolve_shader(const std::string& file);

// The GLSL side of shader_interface.hpp: the FrameBlock and every texture unit's sampler.
std::string interface_glsl();

// The names of every embedded shader file.
std::vector<std::string> shader_files();
// A frame-block field's GLSL type from its type in shader_interface.hpp's list (scalar: float).
std::string glsl_type(std::string_view listed);

// A driver's log with its "N:line" source numbers replaced by file names.
std::string name_files_in_log(const std::string& log, const ShaderSource& source);

}  // namespace downpour::render
