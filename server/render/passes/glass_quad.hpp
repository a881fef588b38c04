// The windshield trapezoid drawn at its place in the world (glass.vert), for the passes that draw
// on the glass; the grid of the water's surface for those that read it (glass_surface.glsl); and
// whether a frame has anything on its glass at all.
#pragma once

#include "server/render/frame_context.hpp"

namespace downpour::render {

// The glass's place in the world for a program that uses glass.vert or glass_blades.vert:
// u_glass_origin, u_glass_u, u_glass_v (world) and u_glass_mm (bottom width, top width, height).
class GlassPlacement {
 public:
  explicit GlassPlacement(const ShaderProgram& program);
  void set(const FrameContext& frame) const;

 private:
  Uniform origin_, u_, v_, size_mm_;
};

// The water surface's grid for a program that includes glass_surface.glsl: u_cell_mm and
// u_count_bits once, u_cells per frame (its bodies are bound by the Resource kGlassSurface).
class GlassSurfaceGrid {
 public:
  explicit GlassSurfaceGrid(const ShaderProgram& program);
  void set(const sim::WindshieldState& water) const;

 private:
  Uniform cells_;
};

class GlassQuad {
 public:
  explicit GlassQuad(const ShaderProgram& program);  // one that uses glass.vert
  // Places the quad for this frame's vehicle and glass, and draws it with the bound program.
  void draw(const FrameContext& frame) const;

 private:
  GlassPlacement placement_;
  VertexArray empty_vao_;
};

// Water or a blade on the glass: without either there is nothing to draw on it.
bool glass_has_water_or_blades(const sim::WindshieldState& water);

}  // namespace downpour::render
