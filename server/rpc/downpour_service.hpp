// The gRPC service (callback API): validates and converts requests, puts inputs into session
// inboxes and hands out frames. Its handlers never block on rendering.
#pragma once

#include <atomic>

#include "downpour/v1/downpour.grpc.pb.h"
#include "server/rpc/validation.hpp"
#include "server/session/frame_scheduler.hpp"
#include "server/session/session_registry.hpp"

namespace downpour::rpc {

class DownpourService final : public v1::Downpour::CallbackService {
 public:
  DownpourService(session::SessionRegistry& registry, session::FrameScheduler& scheduler,
                  Limits limits);

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
  grpc::ServerBidiReactor<v1::DriveRequest, v1::DriveResponse>* Drive(
      grpc::CallbackServerContext* ctx) override;
  grpc::ServerWriteReactor<v1::Frame>* WatchFrames(grpc::CallbackServerContext* ctx,
                                                   const v1::WatchFramesRequest* request) override;
  grpc::ServerUnaryReactor* GetStats(grpc::CallbackServerContext* ctx,
                                     const v1::GetStatsRequest* request,
                                     v1::ServerStats* response) override;

  // Everything the stream reactors need from the service.
  struct Context {
    session::SessionRegistry& registry;
    Limits limits;
    std::atomic<std::uint64_t> reader_drops{0};
  };

 private:
  session::FrameScheduler& scheduler_;
  Context context_;
  const std::chrono::steady_clock::time_point started_;
};

}  // namespace downpour::rpc
