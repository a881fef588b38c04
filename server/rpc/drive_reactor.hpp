// Drive: a simulator's feed, one bidirectional stream (drive_reactor.cpp says how it works).
#pragma once

#include <grpcpp/support/byte_buffer.h>
#include <grpcpp/support/server_callback.h>

#include "server/rpc/downpour_service.hpp"

namespace downpour::rpc {

// A Drive stream for `who` (authenticated): the reactor owns itself until gRPC is done with it.
grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* start_drive(
    DownpourService::Context& ctx, Principal who);

}  // namespace downpour::rpc
