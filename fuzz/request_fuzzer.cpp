// Fuzz target: bytes from the network -> a request message -> the checks and conversions the
// service runs before anything touches a session. The first byte picks the message; every
// accepted request must convert to values inside the limits (the invariants below), and nothing
// may crash, leak or hit undefined behaviour on the way.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "downpour/v1/downpour.pb.h"
#include "server/rpc/validation.hpp"

namespace {

using namespace downpour;

void require(bool ok) {
  if (!ok) std::abort();  // an invariant of an accepted request broke: a finding
}

bool finite_vec(const glm::dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

void check_update(const sim::Update& u, const rpc::Limits& limits) {
  if (u.vehicle) {
    require(finite_vec(u.vehicle->position_m));
    require(finite_vec(u.vehicle->velocity_mps));
  }
  if (u.weather) {
    require(std::isfinite(u.weather->rain_rate_mm_h) && u.weather->rain_rate_mm_h >= 0.0);
  }
  if (u.traffic) require(static_cast<int>(u.traffic->size()) <= limits.max_traffic);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const rpc::Limits limits;
  const std::uint8_t kind = data[0] % 5;
  const auto* body = reinterpret_cast<const char*>(data + 1);
  const int body_size = static_cast<int>(size - 1);
  switch (kind) {
    case 0: {
      v1::CreateSessionRequest req;
      if (!req.ParseFromArray(body, body_size)) return 0;
      session::SessionConfig config;
      sim::Update initial;
      if (!rpc::to_session_config(req, limits, &config, &initial).ok()) return 0;
      require(!config.views.empty() && static_cast<int>(config.views.size()) <= limits.max_views);
      for (const sim::ViewSpec& v : config.views) {
        require(v.width >= 16 && v.width <= limits.max_width);
        require(v.height >= 16 && v.height <= limits.max_height);
        require(v.jpeg_quality >= 1 && v.jpeg_quality <= 100);
      }
      if (config.mode == sim::Mode::kRealtime)
        require(config.fps > 0.0 && config.fps <= limits.max_fps);
      check_update(initial, limits);
      return 0;
    }
    case 1: {
      v1::UpdateRequest req;
      if (!req.ParseFromArray(body, body_size)) return 0;
      if (!rpc::check_session_id(req.session_id(), "session_id").ok()) return 0;
      sim::Update u;
      if (rpc::to_update(req.update(), "update", limits, &u).ok()) check_update(u, limits);
      return 0;
    }
    case 2: {
      v1::StepRequest req;
      if (!req.ParseFromArray(body, body_size)) return 0;
      sim::Update u;
      if (!rpc::to_update(req.update(), "update", limits, &u).ok()) return 0;
      check_update(u, limits);
      if (rpc::check_dt(req.dt_s(), "dt_s", false, limits).ok())
        require(req.dt_s() > 0.0 && req.dt_s() <= limits.max_dt_s);
      return 0;
    }
    case 3: {
      v1::DriveRequest req;
      if (!req.ParseFromArray(body, body_size)) return 0;
      if (!req.session_id().empty()) (void)rpc::check_session_id(req.session_id(), "session_id");
      sim::Update u;
      if (!rpc::to_update(req.update(), "update", limits, &u).ok()) return 0;
      check_update(u, limits);
      if (rpc::check_dt(req.dt_s(), "dt_s", true, limits).ok())
        require(req.dt_s() >= 0.0 && req.dt_s() <= limits.max_dt_s);
      return 0;
    }
    default: {
      v1::ViewSpec spec;
      if (!spec.ParseFromArray(body, body_size)) return 0;
      sim::ViewSpec v;
      if (!rpc::to_view_spec(spec, "views[0]", limits, &v).ok()) return 0;
      require(v.width >= 16 && v.width <= limits.max_width);
      require(v.height >= 16 && v.height <= limits.max_height);
      return 0;
    }
  }
}
