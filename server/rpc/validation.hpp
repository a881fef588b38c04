// Requests from the network are untrusted: every field is checked before it touches a session,
// and converted to domain types. A bad field gives INVALID_ARGUMENT with a message that names the
// field and its allowed range.
#pragma once

#include <cstddef>
#include <string>

#include <grpcpp/support/status.h>

#include "downpour/v1/downpour.pb.h"
#include "server/session/session.hpp"
#include "server/sim/types.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::rpc {

struct Limits {
  int max_width = 3840;
  int max_height = 2160;
  double max_fps = 120.0;
  int max_views = 4;
  int max_traffic = 64;
  double max_dt_s = 10.0;
  std::size_t max_request_bytes = std::size_t{1} << 20;  // --max-message-mb
};

// RESOURCE_EXHAUSTED naming the flag that raises the limit, for a request past it.
grpc::Status check_request_size(const google::protobuf::Message& request, const Limits& limits);

grpc::Status to_update(const v1::Update& in, const std::string& field, const Limits& limits,
                       sim::Update* out);
// The update's client images (Update.client_images), each decoded and checked against the session's
// view it names (which must have a client background): all of them into `out`, or none and the
// status that says which is wrong and why.
grpc::Status to_client_images(const v1::Update& in, const std::string& field,
                              const std::vector<sim::ViewSpec>& views, sim::Update* out);
grpc::Status to_view_spec(const v1::ViewSpec& in, const std::string& field, const Limits& limits,
                          sim::ViewSpec* out);
grpc::Status to_session_config(const v1::CreateSessionRequest& in, const Limits& limits,
                               session::SessionConfig* config, sim::Update* initial);
// A windshield's figures within the ranges the contract gives (Windshield).
grpc::Status check_glass(const sim::GlassConfig& g, const std::string& field);
// dt_s in (0, max] for Step; [0, max] for Drive (0 = update only).
grpc::Status check_dt(double dt_s, const std::string& field, bool allow_zero, const Limits& limits);
grpc::Status check_session_id(const std::string& id, const std::string& field);

}  // namespace downpour::rpc
