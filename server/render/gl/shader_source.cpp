#include "server/render/gl/shader_source.hpp"

#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "server/render/cpu/shader_interface.hpp"

namespace downpour::render {

const std::map<std::string, std::string_view>& embedded_shaders();  // generated at build time

namespace {

constexpr const char* kInterfaceFile = "interface.glsl";

std::string_view file_text(const std::string& file, std::string& storage) {
  if (file == kInterfaceFile) {
    storage = interface_glsl();
    return storage;
  }
  const auto& shaders = embedded_shaders();
  const auto it = shaders.find(file);
  if (it == shaders.end()) throw std::runtime_error("no embedded shader named " + file);
  return it->second;
}

void resolve_into(const std::string& file, int depth, ShaderSource& out) {
  if (depth > 4) throw std::runtime_error("shader includes nest too deep at " + file);
  const int id = static_cast<int>(out.files.size());
  out.files.push_back(file);
  std::string storage;
  std::istringstream in{std::string(file_text(file, storage))};
  std::string line;
  int number = 0;
  const std::string directive = "#include \"";
  while (std::getline(in, line)) {
    ++number;
    if (line.rfind(directive, 0) != 0) {
      out.text += line;
      out.text += '\n';
      continue;
    }
    const auto end = line.find('"', directive.size());
    if (end == std::string::npos) throw std::runtime_error(file + ": malformed #include");
    out.text += "#line 1 " + std::to_string(out.files.size()) + "\n";
    resolve_into(line.substr(directive.size(), end - directive.size()), depth + 1, out);
    out.text += "#line " + std::to_string(number + 1) + " " + std::to_string(id) + "\n";
  }
}

}  // namespace

std::string glsl_type(std::string_view listed) {
  return listed == "scalar" ? "float" : std::string(listed);
}

ShaderSource resolve_shader(const std::string& file) {
  ShaderSource out;
  resolve_into(file, 0, out);
  return out;
}

std::string interface_glsl() {
  std::string s =
      "// Generated from server/render/cpu/shader_interface.hpp: the per-frame uniform block, the\n"
      "// texture units, the material ids, the storage buffers' bindings and the arrays' sizes.\n"
      "// Do not edit.\n";
#define DOWNPOUR_GLSL_SIZE(name, size, glsl, what) \
  s += std::string("const int ") + #glsl + " = " + std::to_string(size) + ";  // " + what + "\n";
  DOWNPOUR_ARRAY_SIZES(DOWNPOUR_GLSL_SIZE)
#undef DOWNPOUR_GLSL_SIZE
  s +=
      "layout(std140, binding = " + std::to_string(kFrameBlockBinding) + ") uniform FrameBlock {\n";
#define DOWNPOUR_GLSL_FIELD(type, name, what) \
  s += "  " + glsl_type(#type) + " " + #name + ";  // " + what + "\n";
  DOWNPOUR_FRAME_BLOCK(DOWNPOUR_GLSL_FIELD)
#undef DOWNPOUR_GLSL_FIELD
  s += "} frame;\n";
  s += "layout(std140, binding = " + std::to_string(kLampBlockBinding) +
       ") uniform LampBlock {\n  vec4 count;  // x the ego car's headlights, y all the lamps\n"
       "  vec4 lamp[4 * MAX_LAMPS];  // four per lamp (shader_interface.hpp)\n} lamps;\n";
#define DOWNPOUR_GLSL_UNIT(name, unit, type, glsl, what)                                      \
  s += std::string("layout(binding = ") + std::to_string(unit) + ") uniform " + #type + " " + \
       #glsl + ";  // " + what + "\n";
  DOWNPOUR_TEXTURE_UNITS(DOWNPOUR_GLSL_UNIT)
#undef DOWNPOUR_GLSL_UNIT
#define DOWNPOUR_GLSL_MATERIAL(name, id, glsl, what) \
  s += std::string("const int ") + #glsl + " = " + std::to_string(id) + ";  // " + what + "\n";
  DOWNPOUR_MATERIALS(DOWNPOUR_GLSL_MATERIAL)
#undef DOWNPOUR_GLSL_MATERIAL
#define DOWNPOUR_GLSL_BUFFER(name, binding, glsl, what) \
  s += std::string("#define ") + #glsl + " " + std::to_string(binding) + "  // " + what + "\n";
  DOWNPOUR_STORAGE_BUFFERS(DOWNPOUR_GLSL_BUFFER)
#undef DOWNPOUR_GLSL_BUFFER
  return s;
}

std::vector<std::string> shader_files() {
  std::vector<std::string> names;
  for (const auto& [name, text] : embedded_shaders()) names.push_back(name);
  return names;
}

std::string name_files_in_log(const std::string& log, const ShaderSource& source) {
  // Mesa writes "0:12(5): error", glslang "ERROR: 0:12:": a source number, a colon, a line.
  static const std::regex location(R"((^|[\s:])(\d+):(\d+))");
  std::string out;
  auto begin = std::sregex_iterator(log.begin(), log.end(), location);
  std::size_t last = 0;
  for (auto it = begin; it != std::sregex_iterator(); ++it) {
    const std::smatch& m = *it;
    const std::size_t id = std::stoul(m[2].str());
    if (id >= source.files.size()) continue;
    out += log.substr(last, m.position(2) - last);
    out += source.files[id] + ":" + m[3].str();
    last = m.position(0) + m.length(0);
  }
  return out + log.substr(last);
}

}  // namespace downpour::render
