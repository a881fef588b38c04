// Domain -> wire conversions for what the server sends back.
#pragma once

#include <cstdint>

#include "downpour/v1/downpour.pb.h"
#include "server/session/frame.hpp"
#include "server/session/session.hpp"

namespace downpour::rpc {

v1::View to_proto(sim::View view);
v1::RoadState to_proto(sim::RoadState state);
void fill_frame(const session::EncodedFrame& frame, std::uint64_t reader_drops, v1::Frame* out);
void fill_session_info(const session::Session& session, v1::SessionInfo* out);

}  // namespace downpour::rpc
