// The generated GLSL side of the renderer's interface (shader_interface.hpp): every texture unit,
// material id, storage buffer and frame-block field the C++ lists name, with the value the C++
// uses.
#include <cctype>
#include <string>

#include <gtest/gtest.h>

#include "server/render/cpu/shader_interface.hpp"
#include "server/render/gl/shader_source.hpp"

namespace downpour::render {
namespace {

TEST(ShaderInterfaceTest, TheGeneratedGlslDeclaresWhatTheCppLists) {
  const std::string glsl = interface_glsl();
  int units = 0, buffers = 0, fields = 0, materials = 0;
#define EXPECT_UNIT(name, unit, type, glsl_name, what)                                          \
  EXPECT_NE(glsl.find("layout(binding = " + std::to_string(texture_unit::name) + ") uniform " + \
                      #type + " " + #glsl_name + ";"),                                          \
            std::string::npos)                                                                  \
      << #glsl_name;                                                                            \
  ++units;
  DOWNPOUR_TEXTURE_UNITS(EXPECT_UNIT)
#undef EXPECT_UNIT
#define EXPECT_BUFFER(name, binding, macro, what)                  \
  EXPECT_NE(glsl.find(std::string("#define ") + #macro + " " +     \
                      std::to_string(storage_buffer::name) + " "), \
            std::string::npos)                                     \
      << #macro;                                                   \
  ++buffers;
  DOWNPOUR_STORAGE_BUFFERS(EXPECT_BUFFER)
#undef EXPECT_BUFFER
#define EXPECT_MATERIAL(name, id, constant, what)                              \
  EXPECT_NE(glsl.find(std::string("const int ") + #constant + " = " +          \
                      std::to_string(static_cast<int>(material::name)) + ";"), \
            std::string::npos)                                                 \
      << #constant;                                                            \
  ++materials;
  DOWNPOUR_MATERIALS(EXPECT_MATERIAL)
#undef EXPECT_MATERIAL
#define EXPECT_FIELD(type, name, what)                                                           \
  EXPECT_NE(glsl.find("  " + glsl_type(#type) + " " + #name + ";"), std::string::npos) << #name; \
  ++fields;
  DOWNPOUR_FRAME_BLOCK(EXPECT_FIELD)
#undef EXPECT_FIELD
  EXPECT_GE(units, 20);
  EXPECT_EQ(buffers, 3);
  EXPECT_EQ(materials, 9);
  EXPECT_GE(fields, 18);
  EXPECT_NE(glsl.find("layout(std140, binding = " + std::to_string(kFrameBlockBinding) +
                      ") uniform FrameBlock {"),
            std::string::npos);
  EXPECT_NE(glsl.find("layout(std140, binding = " + std::to_string(kLampBlockBinding) +
                      ") uniform LampBlock {"),
            std::string::npos);
  EXPECT_NE(glsl.find("vec4 lamp[4 * MAX_LAMPS];"), std::string::npos);
  int sizes = 0;
#define EXPECT_SIZE(name, size, constant, what)                                                    \
  EXPECT_NE(glsl.find(std::string("const int ") + #constant + " = " + std::to_string(name) + ";"), \
            std::string::npos)                                                                     \
      << #constant;                                                                                \
  ++sizes;
  DOWNPOUR_ARRAY_SIZES(EXPECT_SIZE)
#undef EXPECT_SIZE
  EXPECT_EQ(sizes, 5);
}

// Whether `text` declares a uniform array sized by a number: "uniform TYPE NAME [ DIGITS ]", with
// any white space between (a scan: <regex> alone doubled this file's compile time).
bool sizes_a_uniform_array_with_a_literal(const std::string& text) {
  const auto at_space = [&](std::size_t i) {
    return i < text.size() && std::isspace(static_cast<unsigned char>(text[i]));
  };
  const auto at_word = [&](std::size_t i) {
    return i < text.size() && (std::isalnum(static_cast<unsigned char>(text[i])) || text[i] == '_');
  };
  for (std::size_t at = text.find("uniform"); at != std::string::npos;
       at = text.find("uniform", at + 1)) {
    std::size_t i = at + 7;
    bool ok = true;
    for (int part = 0; part < 2 && ok; ++part) {  // the type, then the name
      ok = at_space(i);
      while (at_space(i)) ++i;
      ok = ok && at_word(i);
      while (at_word(i)) ++i;
    }
    while (at_space(i)) ++i;
    if (!ok || i >= text.size() || text[i] != '[') continue;
    ++i;
    while (at_space(i)) ++i;
    const std::size_t digits = i;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
    while (at_space(i)) ++i;
    if (i > digits && i < text.size() && text[i] == ']') return true;
  }
  return false;
}

// The shaders size their uniform arrays by the generated constants, never by a number of their own.
TEST(ShaderInterfaceTest, NoShaderSizesAUniformArrayWithALiteral) {
  EXPECT_TRUE(sizes_a_uniform_array_with_a_literal("uniform vec4 u_boxes[64];"));
  EXPECT_TRUE(sizes_a_uniform_array_with_a_literal("uniform  vec4\n u_glows [ 3 ];"));
  EXPECT_FALSE(sizes_a_uniform_array_with_a_literal("uniform vec4 u_boxes[MAX_LAMPS];"));
  EXPECT_FALSE(sizes_a_uniform_array_with_a_literal("uniform vec4 u_box; float a[4];"));
  int files = 0;
  for (const std::string& file : shader_files()) {
    const ShaderSource source = resolve_shader(file);
    EXPECT_FALSE(sizes_a_uniform_array_with_a_literal(source.text)) << file;
    ++files;
  }
  EXPECT_GE(files, 30);
}

TEST(ShaderInterfaceTest, NoTwoTextureUnitsOrStorageBuffersShareABinding) {
  bool unit_taken[64] = {};
#define CHECK_UNIT(name, unit, type, glsl_name, what) \
  ASSERT_LT(unit, 64);                                \
  EXPECT_FALSE(unit_taken[unit]) << #glsl_name;       \
  unit_taken[unit] = true;
  DOWNPOUR_TEXTURE_UNITS(CHECK_UNIT)
#undef CHECK_UNIT
  bool buffer_taken[16] = {};
#define CHECK_BUFFER(name, binding, macro, what) \
  ASSERT_LT(binding, 16);                        \
  EXPECT_FALSE(buffer_taken[binding]) << #macro; \
  buffer_taken[binding] = true;
  DOWNPOUR_STORAGE_BUFFERS(CHECK_BUFFER)
#undef CHECK_BUFFER
}

}  // namespace
}  // namespace downpour::render
