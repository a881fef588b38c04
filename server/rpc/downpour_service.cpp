#include "server/rpc/downpour_service.hpp"

#include "server/rpc/models.hpp"

#include <array>
#include <cmath>
#include <utility>

#include <spdlog/spdlog.h>

#include "server/render/cpu/world_geometry.hpp"
#include "server/rpc/convert.hpp"
#include "server/rpc/drive_reactor.hpp"
#include "server/rpc/session_access.hpp"
#include "server/rpc/watch_reactor.hpp"

namespace downpour::rpc {
namespace {

using session::FramePtr;
using session::Session;

grpc::ServerUnaryReactor* finish(grpc::CallbackServerContext* ctx, const grpc::Status& status) {
  grpc::ServerUnaryReactor* reactor = ctx->DefaultReactor();
  reactor->Finish(status);
  return reactor;
}

// A unary Step: it notes a cancel (or a passed deadline) so that a step not yet started is
// dropped rather than rendered for nobody.
class StepReactor final : public grpc::ServerUnaryReactor {
 public:
  void OnCancel() override { cancelled_->store(true); }
  void OnDone() override { delete this; }
  session::CancelFlag cancelled() const { return cancelled_; }

 private:
  const std::shared_ptr<std::atomic<bool>> cancelled_ = std::make_shared<std::atomic<bool>>(false);
};

}  // namespace

DownpourService::DownpourService(session::SessionRegistry& registry,
                                 session::FrameScheduler& scheduler, Limits limits,
                                 Authenticator auth, std::shared_ptr<RoadNetworks> road_networks,
                                 std::shared_ptr<model::ModelLibrary> models)
    : scheduler_(scheduler),
      context_{registry, limits, std::move(auth),
               road_networks ? std::move(road_networks) : std::make_shared<RoadNetworks>(),
               models ? std::move(models) : std::make_shared<model::ModelLibrary>()},
      started_(std::chrono::steady_clock::now()) {}

grpc::ServerUnaryReactor* DownpourService::CreateSession(grpc::CallbackServerContext* ctx,
                                                         const v1::CreateSessionRequest* request,
                                                         v1::SessionInfo* response) {
  Principal who;
  if (auto s = context_.auth.authenticate(*ctx, &who); !s.ok()) return finish(ctx, s);
  if (!who.has(kDriver)) {
    return finish(ctx, grpc::Status(grpc::StatusCode::PERMISSION_DENIED,
                                    "'" + who.name + "' may not create sessions (driver role)"));
  }
  if (context_.draining) return finish(ctx, kDraining);
  if (auto s = check_request_size(*request, context_.limits); !s.ok()) return finish(ctx, s);
  session::SessionConfig config;
  sim::Update initial;
  if (auto s = to_session_config(*request, context_.limits, &config, &initial); !s.ok())
    return finish(ctx, s);
  config.owner = who.name;
  if (auto s = to_ego_models(*context_.models, request->ego(), "ego", &config); !s.ok())
    return finish(ctx, s);
  if (auto s = to_traffic_models(*context_.models, request->initial(), "initial", &initial);
      !s.ok())
    return finish(ctx, s);
  LoadedRoads roads;
  if (auto s = context_.road_networks->load(request->roads(), "roads", &roads); !s.ok())
    return finish(ctx, s);
  // The scene of a new network is built here, on this call's thread, not in the render loop that
  // every session shares (it only uploads it).
  render::prepare_world(roads.roads);
  config.roads = std::move(roads.roads);
  config.road_network = std::move(roads.name);
  std::string refusal;
  auto session = context_.registry.create(std::move(config), initial, &refusal);
  if (!session) return finish(ctx, grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, refusal));
  fill_session_info(*session, response);
  response->set_endpoint(context_.endpoint);
  spdlog::info("session {} started: {} mode, {} view(s), seed {}, roads {}, by {} from {}",
               session->id(),
               session->config().mode == sim::Mode::kLockstep ? "lockstep" : "realtime",
               session->config().views.size(), session->config().seed,
               session->config().road_network, who.name, ctx->peer());
  return finish(ctx, grpc::Status::OK);
}

grpc::ServerUnaryReactor* DownpourService::CloseSession(grpc::CallbackServerContext* ctx,
                                                        const v1::CloseSessionRequest* request,
                                                        v1::CloseSessionResponse*) {
  Principal who;
  if (auto s = context_.auth.authenticate(*ctx, &who); !s.ok()) return finish(ctx, s);
  if (auto s = check_session_id(request->session_id(), "session_id"); !s.ok())
    return finish(ctx, s);
  std::shared_ptr<Session> session;
  if (auto s = reach_session(context_.registry, request->session_id(), who, may_drive, &session);
      !s.ok())
    return finish(ctx, s);
  if (!context_.registry.close(request->session_id()))
    return finish(ctx, not_found(request->session_id()));
  spdlog::info("session {} ended: {} frames, sim time {:.2f} s", session->id(),
               session->frames_rendered(), session->sim_time_s());
  return finish(ctx, grpc::Status::OK);
}

grpc::ServerUnaryReactor* DownpourService::ListSessions(grpc::CallbackServerContext* ctx,
                                                        const v1::ListSessionsRequest*,
                                                        v1::ListSessionsResponse* response) {
  Principal who;
  if (auto s = context_.auth.authenticate(*ctx, &who); !s.ok()) return finish(ctx, s);
  for (const auto& s : context_.registry.list()) {
    // A client sees its own sessions; a viewer (or an admin) sees all, to pick one to watch.
    if (who.has(kViewer) || s->config().owner == who.name) {
      v1::SessionInfo* info = response->add_sessions();
      fill_session_info(*s, info);
      info->set_endpoint(context_.endpoint);
    }
  }
  return finish(ctx, grpc::Status::OK);
}

grpc::ServerUnaryReactor* DownpourService::Update(grpc::CallbackServerContext* ctx,
                                                  const v1::UpdateRequest* request,
                                                  v1::UpdateResponse* response) {
  Principal who;
  if (auto s = context_.auth.authenticate(*ctx, &who); !s.ok()) return finish(ctx, s);
  if (auto s = check_request_size(*request, context_.limits); !s.ok()) return finish(ctx, s);
  if (auto s = check_session_id(request->session_id(), "session_id"); !s.ok())
    return finish(ctx, s);
  sim::Update update;
  if (auto s = to_update(request->update(), "update", context_.limits, &update); !s.ok())
    return finish(ctx, s);
  if (auto s = to_traffic_models(*context_.models, request->update(), "update", &update); !s.ok())
    return finish(ctx, s);
  std::shared_ptr<Session> session;
  if (auto s = reach_session(context_.registry, request->session_id(), who, may_drive, &session);
      !s.ok())
    return finish(ctx, s);
  session->touch();
  if (auto s = to_client_images(request->update(), "update", session->config().views, &update);
      !s.ok())
    return finish(ctx, s);
  response->set_sim_time_s(session->sim_time_s());
  return finish(ctx, submit_status(session->post_update(update), session->id()));
}

grpc::ServerUnaryReactor* DownpourService::Step(grpc::CallbackServerContext* ctx,
                                                const v1::StepRequest* request,
                                                v1::StepResponse* response) {
  Principal who;
  if (auto s = context_.auth.authenticate(*ctx, &who); !s.ok()) return finish(ctx, s);
  if (auto s = check_request_size(*request, context_.limits); !s.ok()) return finish(ctx, s);
  if (auto s = check_session_id(request->session_id(), "session_id"); !s.ok())
    return finish(ctx, s);
  sim::Update update;
  if (auto s = to_update(request->update(), "update", context_.limits, &update); !s.ok())
    return finish(ctx, s);
  if (auto s = to_traffic_models(*context_.models, request->update(), "update", &update); !s.ok())
    return finish(ctx, s);
  if (auto s = check_dt(request->dt_s(), "dt_s", false, context_.limits); !s.ok())
    return finish(ctx, s);
  std::shared_ptr<Session> session;
  if (auto s = reach_session(context_.registry, request->session_id(), who, may_drive, &session);
      !s.ok())
    return finish(ctx, s);
  session->touch();
  if (auto s = to_client_images(request->update(), "update", session->config().views, &update);
      !s.ok())
    return finish(ctx, s);
  if (session->config().mode != sim::Mode::kLockstep) {
    return finish(ctx, grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                                    "session " + session->id() +
                                        " is realtime; Step needs a MODE_LOCKSTEP session"));
  }
  if (context_.draining) return finish(ctx, kDraining);
  auto* reactor = new StepReactor();  // deletes itself when done
  const auto result = session->submit_step(
      std::move(update), request->dt_s(),
      [reactor, response,
       counted = std::make_shared<StepInFlight>(context_.steps_in_flight)](session::StepOutcome o) {
        if (!o.ok) {
          reactor->Finish(step_failure_status(o));
          return;
        }
        for (const FramePtr& f : o.frames) fill_frame(*f, 0, response->add_frames());
        reactor->Finish(grpc::Status::OK);
      },
      reactor->cancelled());
  if (result != Session::Submit::kQueued) reactor->Finish(submit_status(result, session->id()));
  return reactor;
}

grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* DownpourService::Drive(
    grpc::CallbackServerContext* ctx) {
  Principal who;
  if (auto s = context_.auth.authenticate(*ctx, &who); !s.ok()) {
    struct Refused final : grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer> {
      explicit Refused(const grpc::Status& s) { Finish(s); }
      void OnDone() override { delete this; }
    };
    return new Refused(s);
  }
  return start_drive(context_, std::move(who));
}

grpc::ServerWriteReactor<v1::Frame>* DownpourService::WatchFrames(
    grpc::CallbackServerContext* ctx, const v1::WatchFramesRequest* request) {
  auto fail = [](const grpc::Status& status) {
    struct Failed final : grpc::ServerWriteReactor<v1::Frame> {
      explicit Failed(const grpc::Status& s) { Finish(s); }
      void OnDone() override { delete this; }
    };
    return new Failed(status);
  };
  Principal who;
  if (auto s = context_.auth.authenticate(*ctx, &who); !s.ok()) return fail(s);
  if (auto s = check_session_id(request->session_id(), "session_id"); !s.ok()) return fail(s);
  std::shared_ptr<Session> session;
  if (auto s = reach_session(context_.registry, request->session_id(), who, may_watch, &session);
      !s.ok())
    return fail(s);
  // Only the owner's own watching counts as hearing from its client; a viewer watching someone
  // else's session does not keep it alive once its driver has gone.
  if (who.name == session->config().owner) session->touch();
  std::array<bool, sim::kViewCount> wanted{};
  for (const sim::ViewSpec& v : session->config().views)
    wanted[static_cast<int>(v.view)] = request->views_size() == 0;
  for (int i = 0; i < request->views_size(); ++i) {
    const std::string field = "views[" + std::to_string(i) + "]";
    const int v = request->views(i);
    bool found = false;
    for (const sim::ViewSpec& spec : session->config().views) {
      if (to_proto(spec.view) == v) {
        wanted[static_cast<int>(spec.view)] = true;
        found = true;
      }
    }
    if (!found) {
      return fail(grpc::Status(
          grpc::StatusCode::INVALID_ARGUMENT,
          field + ": view " + std::to_string(v) + " is not one of the session's views"));
    }
  }
  if (!std::isfinite(request->max_fps()) || request->max_fps() < 0.0 ||
      request->max_fps() > 1000.0) {
    return fail(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "max_fps: must be in [0, 1000]"));
  }
  return start_watch(context_, session, wanted, request->max_fps());
}

grpc::ServerUnaryReactor* DownpourService::GetStats(grpc::CallbackServerContext* ctx,
                                                    const v1::GetStatsRequest*,
                                                    v1::ServerStats* response) {
  Principal who;
  if (auto s = context_.auth.authenticate(*ctx, &who); !s.ok()) return finish(ctx, s);
  const session::SchedulerStats s = scheduler_.stats();
  response->set_renderer(s.renderer);
  response->set_version(context_.version);
  response->set_endpoint(context_.endpoint);
  response->set_sessions(static_cast<std::uint32_t>(context_.registry.list().size()));
  response->set_frames_rendered(s.frames_rendered);
  response->set_frames_encoded(s.frames_encoded);
  response->set_frames_dropped(context_.reader_drops.load());
  response->set_render_ms_median(s.render_ms_median);
  response->set_encode_ms_median(s.encode_ms_median);
  response->set_encoder_threads(static_cast<std::uint32_t>(s.encoder_threads));
  response->set_frames_late(s.realtime_frames_late);
  response->set_sessions_closed_idle(context_.registry.closed_idle());
  const session::SessionCost used = context_.registry.cost_in_use();
  const session::AdmissionBudget budget = context_.registry.budget();
  constexpr double kMiB = 1024.0 * 1024.0;
  response->set_pixel_rate_mpx_s(used.pixel_rate / 1e6);
  response->set_pixel_rate_budget_mpx_s(budget.max_pixel_rate / 1e6);
  response->set_memory_estimate_mib(used.memory_bytes / kMiB);
  response->set_memory_budget_mib(budget.max_memory_bytes / kMiB);
  response->set_uptime_s(
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count());
  return finish(ctx, grpc::Status::OK);
}

}  // namespace downpour::rpc
