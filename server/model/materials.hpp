// What a mesh's surfaces are made of, by id. No GL.
#pragma once

namespace downpour::model {

// Material ids, carried in a mesh vertex's uv.x (model/default_models.cpp, model/gltf_model.cpp,
// render/cpu/scene_geometry.cpp) and read by vehicle.frag and cockpit.frag (as GLSL constants the
// build writes from this list: render/cpu/shader_interface.hpp): X(C++ name, id, GLSL constant,
// what).
#define DOWNPOUR_MATERIALS(X)                                             \
  X(kBody, 0, MATERIAL_BODY, "paint, or the cabin's dashboard")           \
  X(kGlass, 1, MATERIAL_GLASS, "windows")                                 \
  X(kTyre, 2, MATERIAL_TYRE, "tyres")                                     \
  X(kLamp, 3, MATERIAL_LAMP, "tail and brake lamps")                      \
  X(kTrim, 4, MATERIAL_TRIM, "black trim, or the cabin's other plastics") \
  X(kHeadlamp, 5, MATERIAL_HEADLAMP, "headlamps")                         \
  X(kIndicatorLeft, 6, MATERIAL_INDICATOR_LEFT, "the left indicators")    \
  X(kIndicatorRight, 7, MATERIAL_INDICATOR_RIGHT, "the right indicators") \
  X(kStreetLamp, 8, MATERIAL_STREET_LAMP, "a street light's lens (street_light_pass.hpp)")

namespace material {
#define DOWNPOUR_MATERIAL_CONSTANT(name, id, glsl, what) inline constexpr float name = id;
DOWNPOUR_MATERIALS(DOWNPOUR_MATERIAL_CONSTANT)
#undef DOWNPOUR_MATERIAL_CONSTANT
}  // namespace material

}  // namespace downpour::model
