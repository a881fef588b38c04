// The gRPC service (callback API): validates and converts requests, puts inputs into session
// inboxes and hands out frames. Its handlers never block on rendering.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <utility>

#include "downpour/v1/downpour.grpc.pb.h"
#include "server/model/model_library.hpp"
#include "server/rpc/auth.hpp"
#include "server/rpc/road_networks.hpp"
#include "server/rpc/validation.hpp"
#include "server/session/frame_scheduler.hpp"
#include "server/session/session_registry.hpp"

namespace downpour::rpc {

// Every method on the callback API; Drive raw (bytes), so that it can tell a message that does
// not parse from the end of the stream.
using ServiceBase = v1::Downpour::WithCallbackMethod_CreateSession<
    v1::Downpour::WithCallbackMethod_CloseSession<v1::Downpour::WithCallbackMethod_ListSessions<
        v1::Downpour::WithCallbackMethod_Update<v1::Downpour::WithCallbackMethod_Step<
            v1::Downpour::WithRawCallbackMethod_Drive<v1::Downpour::WithCallbackMethod_WatchFrames<
                v1::Downpour::WithCallbackMethod_GetStats<v1::Downpour::Service>>>>>>>>;

class DownpourService final : public ServiceBase {
 public:
  DownpourService(session::SessionRegistry& registry, session::FrameScheduler& scheduler,
                  Limits limits, Authenticator auth = {},
                  std::shared_ptr<RoadNetworks> road_networks = nullptr,
                  std::shared_ptr<model::ModelLibrary> models = nullptr);

  grpc::ServerUnaryReactor* CreateSession(grpc::CallbackServerContext* ctx,
                                          const v1::CreateSessionRequest* request,
                                          v1::SessionInfo* response) override;
  grpc::ServerUnaryReactor* CloseSession(grpc::CallbackServerContext* ctx,
                                         const v1::CloseSessionRequest* request,
                                         v1::CloseSessionResponse* response) override;
  grpc::ServerUnaryReactor* ListSessions(grpc::CallbackServerContext* ctx,
                                         const v1::ListSessionsRequest* request,
                                         v1::ListSessionsResponse* response) override;
  grpc::ServerUnaryReactor* Update(grpc::CallbackServerContext* ctx,
                                   const v1::UpdateRequest* request,
                                   v1::UpdateResponse* response) override;
  grpc::ServerUnaryReactor* Step(grpc::CallbackServerContext* ctx, const v1::StepRequest* request,
                                 v1::StepResponse* response) override;
  grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* Drive(
      grpc::CallbackServerContext* ctx) override;
  grpc::ServerWriteReactor<v1::Frame>* WatchFrames(grpc::CallbackServerContext* ctx,
                                                   const v1::WatchFramesRequest* request) override;
  grpc::ServerUnaryReactor* GetStats(grpc::CallbackServerContext* ctx,
                                     const v1::GetStatsRequest* request,
                                     v1::ServerStats* response) override;

  // Drain (SIGTERM): new sessions and new steps are refused with UNAVAILABLE from here on; the
  // steps already accepted are still answered.
  void begin_drain() { context_.draining = true; }
  // Steps accepted and not yet answered (Step calls and Drive steps).
  int steps_in_flight() const { return context_.steps_in_flight.load(); }
  // Drive and WatchFrames streams not yet done (their final status not yet sent).
  int open_streams() const { return context_.open_streams.load(); }
  // Frames that readers missed because they were slow (ServerStats.frames_dropped).
  std::uint64_t frames_dropped() const { return context_.reader_drops.load(); }
  // Before serving: the server's version (GetStats) and the address clients reach this server at
  // (--advertise; SessionInfo.endpoint), empty if none.
  void set_identity(std::string version, std::string endpoint) {
    context_.version = std::move(version);
    context_.endpoint = std::move(endpoint);
  }

  // Everything the stream reactors need from the service.
  struct Context {
    session::SessionRegistry& registry;
    Limits limits;
    Authenticator auth;
    std::shared_ptr<RoadNetworks> road_networks;
    std::shared_ptr<model::ModelLibrary> models;
    std::atomic<std::uint64_t> reader_drops{0};
    std::atomic<bool> draining{false};
    std::atomic<int> steps_in_flight{0};
    std::atomic<int> open_streams{0};
    std::string version{};   // set before serving, read-only after
    std::string endpoint{};  // likewise
  };

 private:
  session::FrameScheduler& scheduler_;
  Context context_;
  const std::chrono::steady_clock::time_point started_;
};

}  // namespace downpour::rpc
