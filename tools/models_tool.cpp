// downpour-models: the built-in vehicle and cabin models as glTF, for vendors to start from, and a
// check of model files as the server would read them (docs/models.md). Usage:
//   downpour-models export DIR          car.glb, truck.glb, bus.glb, motorbike.glb, cabin.glb
//   downpour-models check [--cabin] FILE...
//                                       each file read as a vehicle (or a cabin), or why not
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "server/model/default_models.hpp"
#include "server/model/gltf_model.hpp"

namespace {

using namespace downpour;

int export_models(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const std::pair<const char*, model::VehicleModel> models[] = {
      {"car", model::default_vehicle(sim::VehicleClass::kCar)},
      {"truck", model::default_vehicle(sim::VehicleClass::kTruck)},
      {"bus", model::default_vehicle(sim::VehicleClass::kBus)},
      {"motorbike", model::default_vehicle(sim::VehicleClass::kMotorbike)},
      {"cabin", model::default_cabin(sim::GlassConfig{})}};
  for (const auto& [name, m] : models) {
    const std::filesystem::path path = dir / (std::string(name) + ".glb");
    std::ofstream(path, std::ios::binary) << model::write_glb(m);
    std::printf("%s: %zu triangles, %zu wheels\n", path.c_str(), m.triangles(), m.wheels.size());
  }
  return 0;
}

int check(const std::vector<std::string>& files, model::ModelKind kind) {
  int failed = 0;
  for (const std::string& f : files) {
    try {
      const model::VehicleModel m = model::read_gltf_file(f, kind);
      const glm::vec3 s = m.size();
      std::printf("%s: %zu triangles, %zu wheels, %.2f x %.2f x %.2f m", f.c_str(), m.triangles(),
                  m.wheels.size(), s.x, s.y, s.z);
      if (m.windshield)
        std::printf(", windshield %.0f/%.0f x %.0f mm at %.1f deg, bowed %.0f mm",
                    m.windshield->bottom_width_mm, m.windshield->top_width_mm,
                    m.windshield->height_mm, m.windshield->rake_deg, m.windshield->bow_mm);
      std::printf("\n");
    } catch (const model::ModelError& e) {
      std::printf("%s: refused: %s\n", f.c_str(), e.what());
      failed = 1;
    }
  }
  return failed;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::strcmp(argv[1], "export") == 0) return export_models(argv[2]);
  if (argc >= 3 && std::strcmp(argv[1], "check") == 0) {
    const bool cabin = std::strcmp(argv[2], "--cabin") == 0;
    return check(std::vector<std::string>(argv + (cabin ? 3 : 2), argv + argc),
                 cabin ? model::ModelKind::kCabin : model::ModelKind::kVehicle);
  }
  std::fprintf(stderr,
               "usage: downpour-models export DIR\n"
               "       downpour-models check [--cabin] FILE...\n");
  return 2;
}
