// Every call's final status, for the server's metrics: an interceptor that tells a callback the
// method and the status code each call ends with (after malformed_request's rewrite, when it is
// installed after that one).
#pragma once

#include <functional>
#include <memory>
#include <string_view>

#include <grpcpp/support/server_interceptor.h>
#include <grpcpp/support/status.h>

namespace downpour::rpc {

// method: the short name of one of the server's own methods ("CreateSession", "Check", ...), or
// "other" for any other path a client may send, so that a client cannot grow the set of names.
// Called on the thread that sends the status; it must be cheap and thread-safe.
using CallStatusCallback = std::function<void(std::string_view method, grpc::StatusCode code)>;

std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface> call_status_interceptor(
    CallStatusCallback callback);

// The label a full method path ("/downpour.v1.Downpour/Step") is counted under.
std::string_view method_label(std::string_view path);

}  // namespace downpour::rpc
