// The models a request names (TrafficVehicle.model, EgoVehicle.body_model and cabin_model), read
// from the server's model library on the request's thread and checked before they reach a
// session; and the glass a session's cabin and windshield give.
#pragma once

#include <string>

#include <grpcpp/support/status.h>

#include "downpour/v1/downpour.pb.h"
#include "server/model/model_library.hpp"
#include "server/session/session.hpp"
#include "server/sim/types.hpp"

namespace downpour::rpc {

// Each traffic vehicle's model into `out`'s traffic (converted by to_update from the same
// message): all of them, or the status that says which cannot be had and why (NOT_FOUND,
// FAILED_PRECONDITION without a models directory, INVALID_ARGUMENT).
grpc::Status to_traffic_models(model::ModelLibrary& library, const v1::Update& in,
                               const std::string& field, sim::Update* out);
// The ego car's body and cabin models into config->ego, and the session's glass: the request's
// windshield (config->glass as to_session_config read it), else the cabin model's, else the
// default car's; a cabin whose windshield disagrees with the request's is refused. A body seen from
// a glass or an eye not the default car's has its bonnet marked for them (mark_bonnet).
grpc::Status to_ego_models(model::ModelLibrary& library, const v1::EgoVehicle& in,
                           const std::string& field, session::SessionConfig* config);

}  // namespace downpour::rpc
