#include "server/rpc/downpour_service.hpp"

#include <array>
#include <cmath>
#include <deque>
#include <mutex>
#include <optional>

#include <spdlog/spdlog.h>

#include "server/rpc/convert.hpp"
#include "server/session/latest_frame_slot.hpp"

namespace downpour::rpc {
namespace {

using session::FramePtr;
using session::Session;

grpc::ServerUnaryReactor* finish(grpc::CallbackServerContext* ctx, const grpc::Status& status) {
  grpc::ServerUnaryReactor* reactor = ctx->DefaultReactor();
  reactor->Finish(status);
  return reactor;
}

grpc::Status not_found(const std::string& id) {
  return grpc::Status(grpc::StatusCode::NOT_FOUND, "session_id: no session '" + id + "'");
}

grpc::Status submit_status(Session::Submit result, const std::string& id) {
  switch (result) {
    case Session::Submit::kQueued:
      return grpc::Status::OK;
    case Session::Submit::kFull:
      return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                          "session " + id + ": more than " +
                              std::to_string(Session::kMaxQueuedJobs) +
                              " requests waiting; wait for frames before sending more");
    case Session::Submit::kClosed:
      return not_found(id);
  }
  return grpc::Status(grpc::StatusCode::INTERNAL, "unexpected submit result");
}

// Drive: a simulator's feed. Lockstep: each request with dt_s > 0 is one step whose frames come
// back in order, at most kMaxAhead steps in flight (reading pauses beyond that). Realtime: updates
// apply on arrival, frames stream from a latest-frame slot.
class DriveReactor final : public grpc::ServerBidiReactor<v1::DriveRequest, v1::DriveResponse>,
                           public session::FrameSink,
                           public std::enable_shared_from_this<DriveReactor> {
 public:
  static constexpr std::size_t kMaxAhead = 4;

  static DriveReactor* start(DownpourService::Context& ctx) {
    auto r = std::shared_ptr<DriveReactor>(new DriveReactor(ctx));
    r->self_ = r;
    r->StartRead(&r->request_);
    return r.get();
  }

  void OnReadDone(bool ok) override {
    if (!ok) {
      std::unique_lock lock(mutex_);
      read_done_ = true;
      advance(lock);
      return;
    }
    const grpc::Status status = handle(request_);
    std::unique_lock lock(mutex_);
    if (!status.ok()) {
      finish_with(lock, status);
      return;
    }
    reading_ = false;
    advance(lock);
  }

  void OnWriteDone(bool ok) override {
    std::unique_lock lock(mutex_);
    writing_ = false;
    if (!ok) {
      finish_with(lock, grpc::Status(grpc::StatusCode::CANCELLED, "the client stopped reading"));
      return;
    }
    advance(lock);
  }

  void OnCancel() override {
    std::unique_lock lock(mutex_);
    finish_with(lock, grpc::Status(grpc::StatusCode::CANCELLED, "cancelled"));
  }

  void OnDone() override {
    std::shared_ptr<Session> session;
    {
      std::lock_guard lock(mutex_);
      done_ = true;
      session = session_;
    }
    if (session) session->remove_sink(this);
    self_.reset();  // the last step callback, if any, frees us
  }

  void on_frame(const FramePtr& frame) override {
    slot_.put(frame);
    std::unique_lock lock(mutex_);
    advance(lock);
  }

  void on_session_closed() override {
    std::unique_lock lock(mutex_);
    session_closed_ = true;
    advance(lock);
  }

 private:
  explicit DriveReactor(DownpourService::Context& ctx) : ctx_(ctx) {}

  grpc::Status handle(const v1::DriveRequest& req) {
    std::shared_ptr<Session> session;
    {
      std::lock_guard lock(mutex_);
      session = session_;
    }
    if (!session) {
      if (auto s = check_session_id(req.session_id(), "session_id"); !s.ok()) return s;
      session = ctx_.registry.find(req.session_id());
      if (!session) return not_found(req.session_id());
      {
        std::lock_guard lock(mutex_);
        session_ = session;
        lockstep_ = session->config().mode == sim::Mode::kLockstep;
      }
      if (!lockstep_) session->add_sink(shared_from_this());
      spdlog::debug("session {}: Drive stream attached", session->id());
    } else if (!req.session_id().empty() && req.session_id() != session->id()) {
      return grpc::Status(
          grpc::StatusCode::INVALID_ARGUMENT,
          "session_id: a Drive stream stays with its first session '" + session->id() + "'");
    }
    sim::Update update;
    if (auto s = to_update(req.update(), "update", ctx_.limits, &update); !s.ok()) return s;
    if (auto s = check_dt(req.dt_s(), "dt_s", true, ctx_.limits); !s.ok()) return s;
    if (!lockstep_ || req.dt_s() == 0.0)
      return submit_status(session->post_update(update), session->id());

    std::size_t index;
    {
      std::lock_guard lock(mutex_);
      index = next_index_++;
      pending_.emplace_back();
    }
    auto self = shared_from_this();
    const auto result =
        session->submit_step(std::move(update), req.dt_s(), [self, index](session::StepOutcome o) {
          std::unique_lock lock(self->mutex_);
          if (!o.ok) {
            self->finish_with(lock, grpc::Status(grpc::StatusCode::ABORTED, o.error));
            return;
          }
          v1::DriveResponse response;
          for (const FramePtr& f : o.frames) fill_frame(*f, 0, response.add_frames());
          self->pending_[index - self->first_index_] = std::move(response);
          self->advance(lock);
        });
    return submit_status(result, session->id());
  }

  // Decides the next operations under the lock, then starts them without it (a reaction may run
  // inline). Called with the lock held; releases it.
  void advance(std::unique_lock<std::mutex>& lock) {
    if (finished_ || done_) return;
    bool start_write = false, start_read = false;
    if (!writing_) {
      if (lockstep_) {
        if (!pending_.empty() && pending_.front()) {
          out_ = std::move(*pending_.front());
          pending_.pop_front();
          ++first_index_;
          start_write = true;
        }
      } else if (FramePtr frame = slot_.take()) {
        out_.Clear();
        fill_frame(*frame, slot_.drops(), out_.add_frames());
        start_write = true;
      }
      writing_ = start_write;
    }
    if (!reading_ && !read_done_ && !session_closed_ && pending_.size() < kMaxAhead) {
      reading_ = start_read = true;
    }
    if (!writing_ && (session_closed_ || (read_done_ && pending_.empty()))) {
      finish_with(lock, grpc::Status::OK);
      return;
    }
    lock.unlock();
    if (start_write) StartWrite(&out_);
    if (start_read) StartRead(&request_);
  }

  // Finish once no write is in flight (the write's completion comes back here).
  void finish_with(std::unique_lock<std::mutex>& lock, const grpc::Status& status) {
    if (finished_ || done_) return;
    if (!final_status_) final_status_ = status;
    if (writing_) return;
    finished_ = true;
    const grpc::Status s = *final_status_;
    lock.unlock();
    Finish(s);
  }

  DownpourService::Context& ctx_;
  std::shared_ptr<DriveReactor> self_;  // keeps us alive until OnDone
  v1::DriveRequest request_;
  v1::DriveResponse out_;
  session::LatestFrameSlot slot_;
  std::mutex mutex_;
  std::shared_ptr<Session> session_;  // guarded by mutex_
  bool lockstep_ = false;             // set with session_
  std::deque<std::optional<v1::DriveResponse>>
      pending_;                               // guarded by mutex_: lockstep responses in order
  std::size_t first_index_ = 0;               // guarded by mutex_: index of pending_.front()
  std::size_t next_index_ = 0;                // guarded by mutex_
  bool reading_ = true;                       // guarded by mutex_: a read is outstanding
  bool writing_ = false;                      // guarded by mutex_
  bool read_done_ = false;                    // guarded by mutex_
  bool session_closed_ = false;               // guarded by mutex_
  bool finished_ = false;                     // guarded by mutex_
  bool done_ = false;                         // guarded by mutex_
  std::optional<grpc::Status> final_status_;  // guarded by mutex_
};

// WatchFrames: the latest frames of the chosen views; one write in flight, a newer frame replaces
// an unsent one (a drop); max_fps thins the stream per view.
class WatchReactor final : public grpc::ServerWriteReactor<v1::Frame>,
                           public session::FrameSink,
                           public std::enable_shared_from_this<WatchReactor> {
 public:
  static WatchReactor* start(DownpourService::Context& ctx, std::shared_ptr<Session> session,
                             std::array<bool, sim::kViewCount> views, double max_fps) {
    auto r = std::shared_ptr<WatchReactor>(new WatchReactor(ctx, session, views, max_fps));
    r->self_ = r;
    session->add_sink(r);
    return r.get();
  }

  void on_frame(const FramePtr& frame) override {
    const int v = static_cast<int>(frame->view);
    if (!views_[v]) return;
    if (min_interval_s_ > 0.0) {
      std::lock_guard lock(mutex_);
      const double t = frame->sim_time_s;
      if (last_sent_time_[v] >= 0.0 && t - last_sent_time_[v] < min_interval_s_ * 0.999) return;
      last_sent_time_[v] = t;
    }
    if (slot_.put(frame).dropped) ++ctx_.reader_drops;
    advance();
  }

  void on_session_closed() override {
    {
      std::lock_guard lock(mutex_);
      session_closed_ = true;
    }
    advance();
  }

  void OnWriteDone(bool ok) override {
    {
      std::lock_guard lock(mutex_);
      writing_ = false;
      if (!ok) failed_ = true;
    }
    advance();
  }

  void OnCancel() override {
    {
      std::lock_guard lock(mutex_);
      failed_ = true;
    }
    advance();
  }

  void OnDone() override {
    session_->remove_sink(this);
    self_.reset();
  }

 private:
  WatchReactor(DownpourService::Context& ctx, std::shared_ptr<Session> session,
               std::array<bool, sim::kViewCount> views, double max_fps)
      : ctx_(ctx),
        session_(std::move(session)),
        views_(views),
        min_interval_s_(max_fps > 0.0 ? 1.0 / max_fps : 0.0) {
    last_sent_time_.fill(-1.0);
  }

  void advance() {
    std::unique_lock lock(mutex_);
    if (finished_ || writing_) return;
    if (failed_ || session_closed_) {
      finished_ = true;
      lock.unlock();
      Finish(failed_ ? grpc::Status(grpc::StatusCode::CANCELLED, "the reader went away")
                     : grpc::Status::OK);
      return;
    }
    FramePtr frame = slot_.take();
    if (!frame) return;
    writing_ = true;
    out_.Clear();
    fill_frame(*frame, slot_.drops(), &out_);
    lock.unlock();
    StartWrite(&out_);
  }

  DownpourService::Context& ctx_;
  const std::shared_ptr<Session> session_;
  const std::array<bool, sim::kViewCount> views_;
  const double min_interval_s_;
  std::shared_ptr<WatchReactor> self_;
  session::LatestFrameSlot slot_;
  v1::Frame out_;
  std::mutex mutex_;
  std::array<double, sim::kViewCount> last_sent_time_;  // guarded by mutex_
  bool writing_ = false;                                // guarded by mutex_
  bool failed_ = false;                                 // guarded by mutex_
  bool session_closed_ = false;                         // guarded by mutex_
  bool finished_ = false;                               // guarded by mutex_
};

}  // namespace

DownpourService::DownpourService(session::SessionRegistry& registry,
                                 session::FrameScheduler& scheduler, Limits limits)
    : scheduler_(scheduler),
      context_{registry, limits},
      started_(std::chrono::steady_clock::now()) {}

grpc::ServerUnaryReactor* DownpourService::CreateSession(grpc::CallbackServerContext* ctx,
                                                         const v1::CreateSessionRequest* request,
                                                         v1::SessionInfo* response) {
  session::SessionConfig config;
  sim::Update initial;
  if (auto s = to_session_config(*request, context_.limits, &config, &initial); !s.ok())
    return finish(ctx, s);
  auto session = context_.registry.create(std::move(config), initial);
  if (!session) {
    return finish(ctx, grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                                    "sessions: the server's limit of " +
                                        std::to_string(context_.registry.max_sessions()) +
                                        " sessions is reached; close one first"));
  }
  fill_session_info(*session, response);
  spdlog::info("session {} started: {} mode, {} view(s), seed {}, peer {}", session->id(),
               session->config().mode == sim::Mode::kLockstep ? "lockstep" : "realtime",
               session->config().views.size(), session->config().seed, ctx->peer());
  return finish(ctx, grpc::Status::OK);
}

grpc::ServerUnaryReactor* DownpourService::CloseSession(grpc::CallbackServerContext* ctx,
                                                        const v1::CloseSessionRequest* request,
                                                        v1::CloseSessionResponse*) {
  if (auto s = check_session_id(request->session_id(), "session_id"); !s.ok())
    return finish(ctx, s);
  const auto session = context_.registry.find(request->session_id());
  if (!session || !context_.registry.close(request->session_id()))
    return finish(ctx, not_found(request->session_id()));
  spdlog::info("session {} ended: {} frames, sim time {:.2f} s", session->id(),
               session->frames_rendered(), session->sim_time_s());
  return finish(ctx, grpc::Status::OK);
}

grpc::ServerUnaryReactor* DownpourService::ListSessions(grpc::CallbackServerContext* ctx,
                                                        const v1::ListSessionsRequest*,
                                                        v1::ListSessionsResponse* response) {
  for (const auto& s : context_.registry.list()) fill_session_info(*s, response->add_sessions());
  return finish(ctx, grpc::Status::OK);
}

grpc::ServerUnaryReactor* DownpourService::Update(grpc::CallbackServerContext* ctx,
                                                  const v1::UpdateRequest* request,
                                                  v1::UpdateResponse* response) {
  if (auto s = check_session_id(request->session_id(), "session_id"); !s.ok())
    return finish(ctx, s);
  sim::Update update;
  if (auto s = to_update(request->update(), "update", context_.limits, &update); !s.ok())
    return finish(ctx, s);
  const auto session = context_.registry.find(request->session_id());
  if (!session) return finish(ctx, not_found(request->session_id()));
  response->set_sim_time_s(session->sim_time_s());
  return finish(ctx, submit_status(session->post_update(update), session->id()));
}

grpc::ServerUnaryReactor* DownpourService::Step(grpc::CallbackServerContext* ctx,
                                                const v1::StepRequest* request,
                                                v1::StepResponse* response) {
  if (auto s = check_session_id(request->session_id(), "session_id"); !s.ok())
    return finish(ctx, s);
  sim::Update update;
  if (auto s = to_update(request->update(), "update", context_.limits, &update); !s.ok())
    return finish(ctx, s);
  if (auto s = check_dt(request->dt_s(), "dt_s", false, context_.limits); !s.ok())
    return finish(ctx, s);
  const auto session = context_.registry.find(request->session_id());
  if (!session) return finish(ctx, not_found(request->session_id()));
  if (session->config().mode != sim::Mode::kLockstep) {
    return finish(ctx, grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                                    "session " + session->id() +
                                        " is realtime; Step needs a MODE_LOCKSTEP session"));
  }
  grpc::ServerUnaryReactor* reactor = ctx->DefaultReactor();
  const auto result = session->submit_step(
      std::move(update), request->dt_s(), [reactor, response](session::StepOutcome o) {
        if (!o.ok) {
          reactor->Finish(grpc::Status(grpc::StatusCode::ABORTED, o.error));
          return;
        }
        for (const FramePtr& f : o.frames) fill_frame(*f, 0, response->add_frames());
        reactor->Finish(grpc::Status::OK);
      });
  if (result != Session::Submit::kQueued) reactor->Finish(submit_status(result, session->id()));
  return reactor;
}

grpc::ServerBidiReactor<v1::DriveRequest, v1::DriveResponse>* DownpourService::Drive(
    grpc::CallbackServerContext*) {
  return DriveReactor::start(context_);
}

grpc::ServerWriteReactor<v1::Frame>* DownpourService::WatchFrames(
    grpc::CallbackServerContext*, const v1::WatchFramesRequest* request) {
  auto fail = [](const grpc::Status& status) {
    struct Failed final : grpc::ServerWriteReactor<v1::Frame> {
      explicit Failed(const grpc::Status& s) { Finish(s); }
      void OnDone() override { delete this; }
    };
    return new Failed(status);
  };
  if (auto s = check_session_id(request->session_id(), "session_id"); !s.ok()) return fail(s);
  const auto session = context_.registry.find(request->session_id());
  if (!session) return fail(not_found(request->session_id()));
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
  return WatchReactor::start(context_, session, wanted, request->max_fps());
}

grpc::ServerUnaryReactor* DownpourService::GetStats(grpc::CallbackServerContext* ctx,
                                                    const v1::GetStatsRequest*,
                                                    v1::ServerStats* response) {
  const session::SchedulerStats s = scheduler_.stats();
  response->set_renderer(s.renderer);
  response->set_sessions(static_cast<std::uint32_t>(context_.registry.list().size()));
  response->set_frames_rendered(s.frames_rendered);
  response->set_frames_encoded(s.frames_encoded);
  response->set_frames_dropped(context_.reader_drops.load());
  response->set_render_ms_median(s.render_ms_median);
  response->set_encode_ms_median(s.encode_ms_median);
  response->set_encoder_threads(static_cast<std::uint32_t>(s.encoder_threads));
  response->set_uptime_s(
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count());
  return finish(ctx, grpc::Status::OK);
}

}  // namespace downpour::rpc
