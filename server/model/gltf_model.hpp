// Vehicle and cabin models from glTF 2.0 (binary .glb, or .gltf JSON whose buffers are embedded or
// lie beside it), read with tinygltf and checked before anything of them is used; and the
// built-in models written back out as .glb, for vendors to start from. No GL.
//
// What a model may hold (docs/models.md says it for vendors):
// - triangles (mode 4) with positions, normals where it has them (flat ones are made where it has
//   not), indices or none, through any node hierarchy of the default scene;
// - materials known by their names (case-insensitive, the first that matches):
//   "windshield"/"windscreen" the cabin's glass (not drawn: the simulated glass is), "glass"/
//   "window" windows, "tyre"/"tire"/"rubber" tyres, "headlamp"/"headlight", "indicator_left" and
//   "indicator_right" (or "blinker_"/"turn_"), "tail"/"brake" the red lamps, "paint"/"body" the
//   paint (the vehicle's own colour, or the cabin's dashboard); any other is trim of its base
//   colour (glTF's default, white, is the built-in dark trim);
// - wheels: nodes whose names begin with "wheel"; each turns about its lateral axis through the
//   centre of its bounds, its radius half its height.
// Textures, skins, morph targets and animations are not read. The model is placed as the vehicle
// frame wants it whatever its origin: the ground under its lowest point, the rear axle (the
// middle of the wheels behind its middle, or a fifth of its length from the rear without wheels)
// at x = 0, and centred across. A cabin is drawn in the vehicle frame as it was made.
#pragma once

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "server/model/vehicle_model.hpp"

namespace downpour::model {

// How much a model may hold: a hostile or broken file is refused before it costs memory or time
// out of proportion.
struct ModelLimits {
  std::size_t max_bytes = 64u << 20;  // the file, and the files beside it that it names
  std::size_t max_triangles = 500'000;
  std::size_t max_node_visits = 65'536;  // nodes through the hierarchy, instances counted
  int max_depth = 64;                    // of the JSON and of the node hierarchy
  // Images (PNG or JPEG) it carries: each at most this wide and tall, all of them at most this
  // many pixels; base-colour textures at most this many.
  int max_image_side = 4096;
  std::size_t max_image_pixels = 32u << 20;
  int max_textures = 16;
};

enum class ModelKind { kVehicle, kCabin };

// A model refused, and why.
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads a model from a file's bytes: binary glTF when they begin with "glTF", JSON otherwise.
// `beside`: where files the JSON names by bare name (buffers) are read from; empty, none are.
// Throws ModelError.
VehicleModel read_gltf(std::string_view bytes, ModelKind kind, const ModelLimits& limits = {},
                       const std::filesystem::path& beside = {});
// Reads a model file (its size checked before it is read). Throws ModelError.
VehicleModel read_gltf_file(const std::filesystem::path& path, ModelKind kind,
                            const ModelLimits& limits = {});

// The model as binary glTF: one node of fixed parts and one per wheel, materials named as the
// reader knows them, in glTF's axes (y up, z forward). The reader gives back the same triangles.
std::string write_glb(const VehicleModel& model);

}  // namespace downpour::model
