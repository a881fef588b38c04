#include "server/model/model_library.hpp"

#include <cmath>
#include <cstdio>
#include <system_error>

#include <glm/geometric.hpp>

#include "server/model/default_models.hpp"
#include "server/sim/file_name.hpp"

namespace downpour::model {

namespace {

constexpr std::size_t kMaxName = 128;

std::string figures(double bottom, double top, double height, double rake) {
  char text[128];
  std::snprintf(text, sizeof(text), "%.0f (bottom) / %.0f (top) x %.0f mm, rake %.1f deg", bottom,
                top, height, rake);
  return text;
}

}  // namespace

ModelLibrary::ModelLibrary(std::filesystem::path dir, ModelLimits limits)
    : dir_(std::move(dir)), limits_(limits) {}

bool ModelLibrary::valid_name(const std::string& name) {
  return sim::plain_file_name(name, kMaxName);
}

std::string ModelLibrary::name_rule(const std::string& name) {
  return "a model's name is a file name in the server's models directory (letters, digits, '_', "
         "'-', '.'; not starting with '.'), got \"" +
         name.substr(0, kMaxName) + "\"";
}

std::shared_ptr<const VehicleModel> ModelLibrary::load(const std::string& name, ModelKind kind,
                                                       Refusal* refusal) {
  namespace fs = std::filesystem;
  if (!valid_name(name)) {
    *refusal = {Failure::kInvalid, name_rule(name)};
    return nullptr;
  }
  if (dir_.empty()) {
    *refusal = {Failure::kNoDirectory, "this server has no models (start it with --models-dir)"};
    return nullptr;
  }
  std::error_code ec;
  fs::path path;
  for (const char* ext : {"", ".glb", ".gltf"}) {
    path = dir_ / (name + ext);
    if (fs::is_regular_file(path, ec)) break;
    path.clear();
  }
  if (path.empty()) {
    *refusal = {Failure::kNotFound, "no model \"" + name + "\""};
    return nullptr;
  }
  const auto size = fs::file_size(path, ec);
  const auto written = fs::last_write_time(path, ec);
  const std::string key =
      std::string(kind == ModelKind::kCabin ? "cabin:" : "vehicle:") + path.filename().string();
  {
    std::lock_guard lock(mutex_);
    if (const auto it = cache_.find(key);
        it != cache_.end() && it->second.size == size && it->second.written == written)
      return it->second.model;
  }
  // Read outside the lock: a large model does not hold up another session's request.
  std::shared_ptr<const VehicleModel> model;
  try {
    VehicleModel read = read_gltf_file(path, kind, limits_);
    // From the driver's seat, a body shows what the driver sees past the default car's windshield
    // (rpc/models.cpp marks a copy for a session with another glass or eye).
    if (kind == ModelKind::kVehicle) mark_bonnet(read);
    model = std::make_shared<const VehicleModel>(std::move(read));
  } catch (const ModelError& e) {
    *refusal = {Failure::kInvalid, "the model \"" + name + "\": " + e.what()};
    return nullptr;
  }
  std::lock_guard lock(mutex_);
  cache_[key] = {size, written, model};
  return model;
}

std::optional<std::string> glass_disagreement(const WindshieldOutline& w,
                                              const sim::GlassConfig& g) {
  if (w.bow_mm > 25.0) {
    char text[160];
    std::snprintf(text, sizeof(text),
                  "its windshield bows %.0f mm out of flat; the simulated glass is flat (25 mm at "
                  "most)",
                  w.bow_mm);
    return std::string(text);
  }
  const bool agree = std::abs(w.bottom_width_mm - g.bottom_width_mm) <= 15.0 &&
                     std::abs(w.top_width_mm - g.top_width_mm) <= 15.0 &&
                     std::abs(w.height_mm - g.height_mm) <= 15.0 &&
                     std::abs(w.rake_deg - g.rake_deg) <= 1.5 &&
                     glm::length(w.bottom_left_m - g.bottom_left_m) <= 0.015;
  if (agree) return std::nullopt;
  char corner[160] = "";
  if (glm::length(w.bottom_left_m - g.bottom_left_m) > 0.015)
    std::snprintf(corner, sizeof(corner),
                  "; its foot's left end (%.3f, %.3f, %.3f) m against (%.3f, %.3f, %.3f)",
                  w.bottom_left_m.x, w.bottom_left_m.y, w.bottom_left_m.z, g.bottom_left_m.x,
                  g.bottom_left_m.y, g.bottom_left_m.z);
  return "its windshield, " + figures(w.bottom_width_mm, w.top_width_mm, w.height_mm, w.rake_deg) +
         ", does not match the glass, " +
         figures(g.bottom_width_mm, g.top_width_mm, g.height_mm, g.rake_deg) + corner;
}

}  // namespace downpour::model
