// The models a server's sessions may name: glTF files in its --models-dir, read when first named
// (on the calling thread: a request's, never the render thread) and kept while the file stays
// the same. And where a cabin model's windshield and the simulated glass must agree. No GL.
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "server/model/gltf_model.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::model {

class ModelLibrary {
 public:
  enum class Failure { kInvalid, kNotFound, kNoDirectory };
  // A model not given: why, and what to tell the client.
  struct Refusal {
    Failure failure = Failure::kInvalid;
    std::string message;
  };

  // dir empty: no models (every name is refused with kNoDirectory).
  explicit ModelLibrary(std::filesystem::path dir = {}, ModelLimits limits = {});

  // The model a name gives ("sedan": sedan.glb, sedan.gltf or the file "sedan"), read or found;
  // or why not.
  std::shared_ptr<const VehicleModel> load(const std::string& name, ModelKind kind,
                                           Refusal* refusal);

  // Whether a name is one the library may open: a plain file name (letters, digits, '_', '-',
  // '.'; not starting with '.', no "..", at most 128 characters).
  static bool valid_name(const std::string& name);
  // What valid_name asks, said to a client that named `name`.
  static std::string name_rule(const std::string& name);

  const ModelLimits& limits() const { return limits_; }

 private:
  std::filesystem::path dir_;
  ModelLimits limits_;
  std::mutex mutex_;
  struct Cached {
    std::uintmax_t size = 0;
    std::filesystem::file_time_type written;
    std::shared_ptr<const VehicleModel> model;
  };
  std::map<std::string, Cached> cache_;  // by kind and file name
};

// Why a windshield outline and a glass disagree (more than 15 mm, 1.5 degrees of rake, or bowed
// more than 25 mm out of flat), or nothing when they agree.
std::optional<std::string> glass_disagreement(const WindshieldOutline& w,
                                              const sim::GlassConfig& g);

}  // namespace downpour::model
