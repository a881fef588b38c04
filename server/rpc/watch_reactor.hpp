// WatchFrames: a session's frames to a watcher, one server stream (watch_reactor.cpp).
#pragma once

#include <array>
#include <memory>

#include <grpcpp/support/server_callback.h>

#include "server/rpc/downpour_service.hpp"

namespace downpour::rpc {

// A WatchFrames stream of `session`'s chosen views (checked), at most max_fps each (0: every
// frame): the reactor owns itself until gRPC is done with it.
grpc::ServerWriteReactor<v1::Frame>* start_watch(DownpourService::Context& ctx,
                                                 std::shared_ptr<session::Session> session,
                                                 std::array<bool, sim::kViewCount> views,
                                                 double max_fps);

}  // namespace downpour::rpc
