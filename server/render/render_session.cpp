#include "server/render/render_session.hpp"

#include <algorithm>
#include <utility>

#include "server/render/cpu/camera.hpp"
#include "server/render/cpu/shader_interface.hpp"

namespace downpour::render {

RenderSession::RenderSession(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RenderSession::~RenderSession() = default;

void RenderSession::Impl::upload_glass_surface(
    std::shared_ptr<const sim::GlassWaterSurface> surface) {
  // No water (the blades alone): an empty grid, which the optics find dry everywhere.
  static const auto dry = std::make_shared<const sim::GlassWaterSurface>();
  if (!surface) surface = dry;
  if (surface_shown != surface) {
    // Into the set the last frames' draws did not read (kUploadCopies).
    glass_current = (glass_current + 1) % glass_surface.size();
    GlassSurfaceBuffers& set = glass_surface[glass_current];
    const std::array<std::pair<const void*, std::size_t>, 3> parts{{
        {surface->bodies.data(), surface->bodies.size() * sizeof(sim::WaterBody)},
        {surface->cells.data(), surface->cells.size() * sizeof(std::uint32_t)},
        {surface->entries.data(), surface->entries.size() * sizeof(std::uint32_t)},
    }};
    constexpr GLenum kFormats[3] = {GL_RGBA32F, GL_R32UI, GL_R32UI};
    for (std::size_t k = 0; k < parts.size(); ++k) {
      // Grown as needed (never empty: a texture buffer needs storage), else refilled.
      const std::size_t bytes = std::max<std::size_t>(parts[k].second, 16);
      if (!set.buffer[k].id() || set.bytes[k] < bytes) {
        set.buffer[k] = make_buffer();
        set.bytes[k] = std::max(bytes, 2 * set.bytes[k]);
        glNamedBufferStorage(set.buffer[k].id(), static_cast<GLsizeiptr>(set.bytes[k]), nullptr,
                             GL_DYNAMIC_STORAGE_BIT);
        GLuint tex = 0;
        glCreateTextures(GL_TEXTURE_BUFFER, 1, &tex);
        set.texture[k] = Texture(tex);
        glTextureBuffer(tex, kFormats[k], set.buffer[k].id());
      }
      if (parts[k].second > 0)
        glNamedBufferSubData(set.buffer[k].id(), 0, static_cast<GLsizeiptr>(parts[k].second),
                             parts[k].first);
    }
    surface_shown = surface;
  }
  const GLuint units[3] = {texture_unit::kGlassBodies, texture_unit::kGlassCells,
                           texture_unit::kGlassEntries};
  for (std::size_t k = 0; k < 3; ++k)
    glBindTextureUnit(units[k], glass_surface[glass_current].texture[k].id());
}

GLuint RenderSession::Impl::upload_road_water(
    const std::shared_ptr<const sim::RoadWaterImage>& image) {
  const bool valid = image && image->complete();
  const int n = valid ? image->cells : 1, rings = valid ? image->levels : 1;
  if (!road_water[0].id() || road_cells != n || road_rings != rings) {
    for (Texture& t : road_water) {
      t = make_texture_2d_array(GL_RG16F, n, n, rings);
      glTextureParameteri(t.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTextureParameteri(t.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    road_cells = n;
    road_rings = rings;
    road_shown.reset();
    road_dry_shown = false;
  }
  if (valid ? road_shown == image : road_dry_shown) return road_water[road_current].id();
  // Into the texture the last frames' draws did not read (kUploadCopies).
  road_current = (road_current + 1) % road_water.size();
  const GLuint id = road_water[road_current].id();
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  if (valid) {
    glTextureSubImage3D(id, 0, 0, 0, 0, n, n, rings, GL_RG, GL_FLOAT,
                        image->water_standing_mm.data());
  } else {
    const float dry[2] = {0.0f, 0.0f};
    glTextureSubImage3D(id, 0, 0, 0, 0, 1, 1, 1, GL_RG, GL_FLOAT, dry);
  }
  road_shown = valid ? image : nullptr;
  road_dry_shown = !valid;
  return id;
}

const RenderSession::Impl::ClientPicture& RenderSession::Impl::upload_client_image(
    sim::View view, const std::shared_ptr<const sim::ClientImage>& image, float near_m) {
  ClientPicture& c = client[static_cast<std::size_t>(view)];
  auto make = [](GLenum format, int w, int h, GLenum filter) {
    Texture t = make_texture_2d(format, w, h);
    glTextureParameteri(t.id(), GL_TEXTURE_MIN_FILTER, filter);
    glTextureParameteri(t.id(), GL_TEXTURE_MAG_FILTER, filter);
    glTextureParameteri(t.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(t.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
  };
  const int w = image ? image->width : 1, h = image ? image->height : 1;
  const bool has_depth = image && !image->depth_m.empty();
  if (!c.colour.id() || c.width != w || c.height != h) {
    c.colour = make(GL_RGBA8, w, h, GL_LINEAR);
    c.width = w;
    c.height = h;
    c.shown.reset();
    c.blank_shown = false;
    c.depth = Texture();
  }
  if (!c.depth.id() || c.has_depth != has_depth) {
    // The depth is read at the nearest texel: a blend of a near and a far one is neither.
    c.depth = make(GL_DEPTH_COMPONENT32F, has_depth ? w : 1, has_depth ? h : 1, GL_NEAREST);
    c.has_depth = has_depth;
    c.shown.reset();
    c.blank_shown = false;
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);  // (rows of 4-byte texels and of floats)
  if (!image && !c.blank_shown) {
    const std::uint8_t black[4] = {0, 0, 0, 255};
    const float none = 0.0f;
    glTextureSubImage2D(c.colour.id(), 0, 0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, black);
    glTextureSubImage2D(c.depth.id(), 0, 0, 0, 1, 1, GL_DEPTH_COMPONENT, GL_FLOAT, &none);
    c.blank_shown = true;
  } else if (image && (c.shown != image || (has_depth && c.near_m != near_m))) {
    if (c.shown != image)
      glTextureSubImage2D(c.colour.id(), 0, 0, 0, w, h, GL_BGRA, GL_UNSIGNED_BYTE,
                          image->bgrx.data());
    if (has_depth) {
      c.depth_buffer.resize(image->depth_m.size());
      for (std::size_t i = 0; i < c.depth_buffer.size(); ++i)
        c.depth_buffer[i] = reversed_z(near_m, image->depth_m[i]);
      glTextureSubImage2D(c.depth.id(), 0, 0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT,
                          c.depth_buffer.data());
    } else {
      const float none = 0.0f;
      glTextureSubImage2D(c.depth.id(), 0, 0, 0, 1, 1, GL_DEPTH_COMPONENT, GL_FLOAT, &none);
    }
    c.shown = image;
    c.near_m = near_m;
    c.blank_shown = false;
  }
  glBindTextureUnit(texture_unit::kClientImage, c.colour.id());
  glBindTextureUnit(texture_unit::kClientDepth, c.depth.id());
  return c;
}

}  // namespace downpour::render
