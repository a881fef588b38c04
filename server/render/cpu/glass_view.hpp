// Where a view's camera meets the windshield: the CPU side of the camera and the glass (no GL),
// the one place that projects between the image and glass space. The points the view's rays hit,
// the glass plane's depth over the image, the glass's axes on screen, and how sharply the camera
// sees the glass: the circle of confusion of its lens, and the reduced size at which the water
// layer is drawn for that blur.
#pragma once

#include <optional>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "server/render/cpu/camera.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::render {

class GlassView {
 public:
  GlassView() = default;  // a view that does not look through the glass
  // min_layer_scale: the least reduction of the water layer where the lens blurs at all (a
  // renderer without a GPU pays for every pixel of it; a pinhole's layer is always full size).
  // layer_widening: how much wider than tall the layer's pixels are where the blur itself spans
  // two pixels or more (layer_size).
  GlassView(const Camera& camera, const sim::GlassConfig& glass, int image_height,
            int min_layer_scale = 1, double layer_widening = 1.0);

  // The glass-space point (mm) where the ray through image point (x right, y up, both in [-1, 1]
  // across the image) meets the glass's plane in front of the camera; none if it does not.
  std::optional<glm::dvec2> hit(double x, double y) const;
  // The glass plane's reversed-Z depth over the image as dot(g, (u, v, 1)), u and v in [0, 1]
  // across it (near / t at view distance t, and 1 / t is affine over the image for a plane);
  // negative where the plane is behind the camera.
  glm::vec3 depth_over_image() const;
  // Screen directions (x right, y up; unit) of glass +u (xy) and +v (zw).
  glm::vec4 screen_axes() const;
  // From the camera to the glass's plane along the camera's axis, m; 0 when it does not face it.
  double distance_m() const { return distance_m_; }
  // The image's scale on the glass at the view's centre, pixels per millimetre.
  double pixels_per_mm() const { return pixels_per_mm_; }
  // The circle of confusion of a thin lens focused at focus_m with aperture A, for the water on
  // the glass: A * |1 - d / focus| on the glass (mm), and in image pixels.
  double blur_mm() const { return blur_mm_; }
  double blur_px() const { return blur_mm_ * pixels_per_mm_; }
  // The water layer is drawn at 1 / layer_scale of the image's size: its pixels as wide as the
  // blur (the bilinear upsampling then blurs as much), 1 (sharp) to 4; no less than the minimum
  // unless the lens is a pinhole.
  int layer_scale() const;
  // The water layer's size for an image of width x height: 1 / layer_scale of its height, and of
  // its width too, but for the widening where the blur itself spans two pixels or more. (The raked
  // glass is seen foreshortened up the screen, twice over at the default rake: a drop's image is
  // wider than tall, and what it shows turned over, ground above and sky below, lies up it. A
  // renderer without a GPU gives up a little of the blur's sharpness across to keep it up.)
  glm::ivec2 layer_size(int width, int height) const;

 private:
  sim::GlassConfig glass_;
  glm::dvec3 origin_{0.0};  // camera, vehicle frame, m
  glm::dmat3 axes_{1.0};    // columns: forward, left, up
  double tan_x_ = 0.0, tan_y_ = 0.0;
  double near_m_ = 0.01;
  double distance_m_ = 0.0;
  double pixels_per_mm_ = 0.0;
  double blur_mm_ = 0.0;
  int min_layer_scale_ = 1;
  double layer_widening_ = 1.0;
  bool pinhole_ = false;
};

}  // namespace downpour::render
