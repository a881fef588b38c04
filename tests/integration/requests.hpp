// Requests the integration tests send: a view, an update of a car driving in rain.
#pragma once

#include <string>

#include <grpcpp/grpcpp.h>

#include "downpour/v1/downpour.grpc.pb.h"

namespace downpour::testing {

inline v1::ViewSpec view(v1::View v, int w, int h) {
  v1::ViewSpec s;
  s.set_view(v);
  s.set_width(w);
  s.set_height(h);
  s.set_jpeg_quality(80);
  return s;
}

// An update that moves the vehicle along +x at 20 m/s in rain.
inline v1::Update drive_update(double t) {
  v1::Update u;
  u.set_sim_time_s(t);
  auto* v = u.mutable_vehicle();
  v->mutable_position_m()->set_x(20.0 * t);
  v->mutable_position_m()->set_y(-5.25);
  v->mutable_velocity_mps()->set_x(20.0);
  auto* w = u.mutable_weather();
  w->set_rain_rate_mm_h(10.0);
  w->set_cloudiness(0.8);
  w->set_sun_altitude_deg(35.0);
  u.mutable_wipers()->set_mode(v1::WIPER_LOW);
  return u;
}

// Closes a session; whether the server said OK.
inline bool close_session(v1::Downpour::Stub& stub, const std::string& id) {
  grpc::ClientContext ctx;
  v1::CloseSessionRequest req;
  req.set_session_id(id);
  v1::CloseSessionResponse resp;
  return stub.CloseSession(&ctx, req, &resp).ok();
}

}  // namespace downpour::testing
