// A wide-angle picture of the world outside the windshield (beyond seed 000): what the rays that
// leave the water on the glass see. A drop turns them by tens of degrees, to where the view does
// not look, so the view's own image cannot serve. A cube map centred just outside the glass, in
// the car's axes (x forward, y left, z up), at low resolution: the world passes draw each face
// (display-encoded), then the face is made linear radiance with the sun and the lamps added at
// their true energy, as small spots; its mip levels then hand each ray the light of the spread of
// directions it stands for, so the sun and the lamps glint softly in every drop without per-pixel
// speckle. A face is redrawn every few ticks (the front every other time, the sides, sky and
// ground in turn between; never the back, which no ray through the glass meets), and the
// session's views share it.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "server/render/cpu/camera.hpp"
#include "server/render/gl/gl_objects.hpp"

namespace downpour::render {

struct Atmosphere;

struct EnvironmentConfig {
  int face_size = 128;  // texels a side: some 0.9 degrees each at a face's centre
  // A face is redrawn every this many ticks (the world passes cost llvmpipe some 4 ms a face: their
  // draws, not their pixels): the front every other time, the others in turn between. At 30 ticks
  // a second the front is at most 0.4 s old, the ground, sides and sky 1.6 s: a lens's image of
  // them is a few pixels, blurred by the pupil.
  int ticks_per_face = 6;
  // The probe's centre: this far out from the glass's centre along its normal (m).
  float clearance_m = 0.05f;
};

// The programs that make a probe's faces: compiled once, for every session's probe.
class EnvironmentPrograms {
 public:
  EnvironmentPrograms();

 private:
  friend class EnvironmentProbe;
  ShaderProgram resolve_;
  Uniform u_face_, u_texel_rad_, u_sun_energy_;
  ShaderProgram lamps_;
  Uniform u_lamp_texel_rad_;
  ShaderProgram level_;
  Uniform u_layer_;
  VertexArray empty_vao_;
};

class EnvironmentProbe {
 public:
  static constexpr int kFaces = 6;

  explicit EnvironmentProbe(EnvironmentConfig config = {});

  const EnvironmentConfig& config() const { return config_; }
  GLuint texture() const { return cube_.id(); }

  // The direction in the probe's axes through point xy (each in [-1, 1], x right, y up) of face
  // `face` (GL's cube face order: +x -x +y -y +z -z), unnormalised.
  static glm::vec3 direction(int face, glm::vec2 xy);
  // The camera that draws face `face` from `centre` (world), the probe's axes (columns) in the
  // world being `axes`.
  static Camera face_camera(int face, const glm::vec3& centre, const glm::mat3& axes);
  // What turns a world direction into the probe's axes for a lookup, for a car placed by
  // vehicle_to_world (a fixed environment's axes are the world's).
  glm::mat3 from_world(const glm::mat4& vehicle_to_world) const;
  // Where the world passes draw a face: display-encoded colour and reversed-Z depth.
  GLuint face_fbo() const { return face_fbo_.id(); }
  GLuint face_colour() const { return face_colour_.id(); }
  GLuint face_depth() const { return face_depth_.id(); }

  // Turns the drawn face into the cube's face `face`, linear, with the sun (its radiance on the
  // ground, less the overcast that hides it) and the first `lamps` lamps of the lamp block (their
  // light at the probe, under the frame's exposure and haze), then makes that face's mip levels.
  // The frame block must hold the face's camera; `axes` as for face_camera.
  void resolve(const EnvironmentPrograms& programs, int face, const glm::mat3& axes,
               const Atmosphere& atmosphere, int lamps);

  // The refresh's bookkeeping: the faces that a tick at `time_s` draws (none again within the same
  // tick), in order, and whether each shows the world or the sky alone. The first time, all six:
  // with `complete` (a picture of its own) all with the world, else the front alone, the others
  // the sky until their turn comes (a session's first frame costs a face, not six).
  struct Due {
    int face;
    bool world;
  };
  // (Kept by the probe, so that a tick allocates nothing.)
  const std::vector<Due>& faces_due(double time_s, bool complete);
  // The ticks of a session (its first included) until each face has been drawn on its own once:
  // the last of them draws the last face's first turn (the renderer's warm-up draws that many).
  static int ticks_until_each_face_alone(const EnvironmentConfig& config);
  // A fixed environment instead of the world (tests): six faces of linear RGB, face_size^2 texels
  // each, rows from the bottom. The probe then never refreshes.
  void set_fixed(const std::array<std::vector<glm::vec3>, kFaces>& faces);

 private:
  void make_levels(const EnvironmentPrograms& programs, int face);

  EnvironmentConfig config_;
  int levels_ = 1;
  Texture cube_;
  // The cube as six layers, for reading one face's level while writing the next.
  Texture levels_view_;
  Texture face_colour_, face_depth_;
  Framebuffer face_fbo_, resolve_fbo_;
  std::vector<Due> due_;
  bool drawn_ = false;
  bool fixed_ = false;
  double last_time_s_ = 0.0;
  int tick_ = 0;
};

}  // namespace downpour::render
