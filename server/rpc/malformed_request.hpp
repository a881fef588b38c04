// Requests that do not parse. gRPC's callback handlers answer a unary or server-streaming request
// whose bytes are not a valid message with UNIMPLEMENTED and no message; this interceptor turns
// that answer into INVALID_ARGUMENT naming the method. (Drive reads its messages itself.)
#pragma once

#include <memory>
#include <vector>

#include <grpcpp/support/server_interceptor.h>

namespace downpour::rpc {

std::vector<std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface>>
malformed_request_interceptors();

}  // namespace downpour::rpc
