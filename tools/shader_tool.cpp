// Writes every shader as the driver compiles it (includes resolved, #line marked) and the
// generated interface.glsl into a folder, for glslangValidator under ctest. Usage:
//   downpour-shader-tool OUT_DIR
#include <cstdio>
#include <fstream>
#include <string>

#include "server/render/gl/shader_source.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream out(dir + "/" + name);
    out << text;
    if (!out) {
      std::fprintf(stderr, "cannot write %s/%s\n", dir.c_str(), name.c_str());
      return false;
    }
    return true;
  };
  if (!write("interface.glsl", downpour::render::interface_glsl())) return 1;
  int written = 0;
  for (const std::string& file : downpour::render::shader_files()) {
    const bool stage = file.ends_with(".vert") || file.ends_with(".frag");
    if (!stage) continue;  // included files are checked within the stages that include them
    if (!write(file, downpour::render::resolve_shader(file).text)) return 1;
    ++written;
  }
  std::printf("%d shader stages written to %s\n", written, dir.c_str());
  return 0;
}
