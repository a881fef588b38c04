#include "server/rpc/call_status.hpp"

#include <array>
#include <utility>

namespace downpour::rpc {
namespace {

using grpc::experimental::InterceptionHookPoints;

class CallStatus final : public grpc::experimental::Interceptor {
 public:
  CallStatus(const CallStatusCallback* callback, std::string_view method)
      : callback_(callback), method_(method) {}

  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    if (methods->QueryInterceptionHookPoint(InterceptionHookPoints::PRE_SEND_STATUS))
      (*callback_)(method_, methods->GetSendStatus().error_code());
    methods->Proceed();
  }

 private:
  const CallStatusCallback* callback_;
  std::string_view method_;
};

class CallStatusFactory final : public grpc::experimental::ServerInterceptorFactoryInterface {
 public:
  explicit CallStatusFactory(CallStatusCallback callback) : callback_(std::move(callback)) {}

  grpc::experimental::Interceptor* CreateServerInterceptor(
      grpc::experimental::ServerRpcInfo* info) override {
    return new CallStatus(&callback_, method_label(info->method() ? info->method() : ""));
  }

 private:
  const CallStatusCallback callback_;
};

}  // namespace

std::string_view method_label(std::string_view path) {
  static constexpr std::array<std::string_view, 4> kServices = {
      "/downpour.v1.Downpour/", "/grpc.health.v1.Health/",
      "/grpc.reflection.v1alpha.ServerReflection/", "/grpc.reflection.v1.ServerReflection/"};
  for (std::string_view service : kServices) {
    if (path.substr(0, service.size()) != service) continue;
    static constexpr std::array<std::string_view, 11> kMethods = {
        "CreateSession", "CloseSession", "ListSessions",        "Update",
        "Step",          "Drive",        "WatchFrames",         "GetStats",
        "Check",         "Watch",        "ServerReflectionInfo"};
    const std::string_view name = path.substr(service.size());
    for (std::string_view known : kMethods) {
      if (name == known) return known;
    }
  }
  return "other";
}

std::unique_ptr<grpc::experimental::ServerInterceptorFactoryInterface> call_status_interceptor(
    CallStatusCallback callback) {
  return std::make_unique<CallStatusFactory>(std::move(callback));
}

}  // namespace downpour::rpc
