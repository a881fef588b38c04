#include "server/rpc/downpour_service.hpp"

#include <array>
#include <cmath>
#include <deque>
#include <mutex>
#include <optional>
#include <utility>

#include <spdlog/spdlog.h>

#include "server/render/world_geometry.hpp"
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

// Access to a session (auth.hpp): its owner drives, watches and closes it; an admin any session;
// a viewer watches any. Anyone else gets PERMISSION_DENIED.
grpc::Status may_drive(const Principal& who, const Session& s) {
  if (who.has(kAdmin) || (who.has(kDriver) && who.name == s.config().owner))
    return grpc::Status::OK;
  if (who.name == s.config().owner) {
    return grpc::Status(grpc::StatusCode::PERMISSION_DENIED,
                        "'" + who.name + "' no longer has the driver role");
  }
  return grpc::Status(grpc::StatusCode::PERMISSION_DENIED,
                      "session " + s.id() + " belongs to another client; '" + who.name +
                          "' may only watch it with the viewer role");
}

grpc::Status may_watch(const Principal& who, const Session& s) {
  if (who.has(kViewer) || who.name == s.config().owner) return grpc::Status::OK;
  return grpc::Status(grpc::StatusCode::PERMISSION_DENIED,
                      "session " + s.id() +
                          " belongs to another client; watching it needs the "
                          "viewer role");
}

// The session that `id` (already checked) names, where `who` may reach it as `access` says
// (may_drive, may_watch): NOT_FOUND where there is none, or access's refusal.
grpc::Status reach_session(const session::SessionRegistry& registry, const std::string& id,
                           const Principal& who,
                           grpc::Status (*access)(const Principal&, const Session&),
                           std::shared_ptr<Session>* session) {
  *session = registry.find(id);
  if (!*session) return not_found(id);
  return access(who, **session);
}

const grpc::Status kDraining(grpc::StatusCode::UNAVAILABLE,
                             "server shutting down: it takes no new sessions or steps");

// The status a stream ends with when its session ends: a normal end is OK.
grpc::Status stream_end_status(const session::SessionEnd& end) {
  switch (end.reason) {
    case session::EndReason::kClosed:
    case session::EndReason::kIdle:
      return grpc::Status::OK;
    case session::EndReason::kFailed:
      return grpc::Status(grpc::StatusCode::INTERNAL, end.message);
    case session::EndReason::kShuttingDown:
      return grpc::Status(grpc::StatusCode::UNAVAILABLE, end.message);
    case session::EndReason::kCancelled:
      return grpc::Status(grpc::StatusCode::CANCELLED, end.message);
  }
  return grpc::Status(grpc::StatusCode::INTERNAL, "unknown session end");
}

// The status of a step that was accepted and then not rendered.
grpc::Status step_failure_status(const session::StepOutcome& o) {
  switch (o.failure) {
    case session::EndReason::kClosed:
    case session::EndReason::kIdle:
      return grpc::Status(grpc::StatusCode::ABORTED, o.error);
    case session::EndReason::kFailed:
      return grpc::Status(grpc::StatusCode::INTERNAL, o.error);
    case session::EndReason::kShuttingDown:
      return grpc::Status(grpc::StatusCode::UNAVAILABLE, o.error);
    case session::EndReason::kCancelled:
      return grpc::Status(grpc::StatusCode::CANCELLED, o.error);
  }
  return grpc::Status(grpc::StatusCode::INTERNAL, o.error);
}

// Counts a step from its acceptance to its answer (the drain waits for these).
class StepInFlight {
 public:
  explicit StepInFlight(std::atomic<int>& count) : count_(&count) { ++*count_; }
  StepInFlight(StepInFlight&& other) noexcept : count_(std::exchange(other.count_, nullptr)) {}
  StepInFlight(const StepInFlight&) = delete;
  StepInFlight& operator=(const StepInFlight&) = delete;
  StepInFlight& operator=(StepInFlight&&) = delete;
  ~StepInFlight() {
    if (count_) --*count_;
  }

 private:
  std::atomic<int>* count_;
};

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
      return grpc::Status(grpc::StatusCode::ABORTED, "session " + id + " was closed");
  }
  return grpc::Status(grpc::StatusCode::INTERNAL, "unexpected submit result");
}

// Drive: a simulator's feed. Lockstep: each request with dt_s > 0 is one step whose frames come
// back in order, at most kMaxAhead steps in flight (reading pauses beyond that). Realtime: updates
// apply on arrival, frames stream from a latest-frame slot.
// Drive is registered raw (bytes in, bytes out) so that a message that does not parse ends the
// stream with INVALID_ARGUMENT; gRPC's own decoding reports it as the end of the stream.
class DriveReactor final : public grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>,
                           public session::FrameSink,
                           public std::enable_shared_from_this<DriveReactor> {
 public:
  static constexpr std::size_t kMaxAhead = 4;

  static DriveReactor* start(DownpourService::Context& ctx, Principal who) {
    ++ctx.open_streams;  // until OnDone
    auto r = std::shared_ptr<DriveReactor>(new DriveReactor(ctx, std::move(who)));
    r->self_ = r;
    r->StartRead(&r->request_bytes_);
    return r.get();
  }

  void OnReadDone(bool ok) override {
    if (!ok) {
      std::unique_lock lock(mutex_);
      read_done_ = true;
      advance(lock);
      return;
    }
    const grpc::Status status =
        grpc::SerializationTraits<v1::DriveRequest>::Deserialize(&request_bytes_, &request_).ok()
            ? handle(request_)
            : grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                           "request: a message that is not a valid downpour.v1.DriveRequest");
    std::unique_lock lock(mutex_);
    if (!status.ok()) {
      finish_with(lock, status);
      return;
    }
    reading_ = false;
    if (draining_) {  // read no more; the steps accepted are answered, then UNAVAILABLE
      read_done_ = true;
      end_status_ = kDraining;
    }
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
    cancelled_->store(true);  // its steps not yet started are dropped
    std::unique_lock lock(mutex_);
    finish_with(lock, grpc::Status(grpc::StatusCode::CANCELLED, "cancelled"));
  }

  void OnDone() override {
    cancelled_->store(true);  // nobody is left to answer
    std::shared_ptr<Session> session;
    {
      std::lock_guard lock(mutex_);
      done_ = true;
      session = session_;
    }
    if (session) {
      session->remove_sink(this);
      session->detach_stream();
    }
    --ctx_.open_streams;
    self_.reset();  // the last step callback, if any, frees us
  }

  void on_frame(const FramePtr& frame) override {
    if (lockstep_) return;
    if (slot_.put(frame).dropped) ++ctx_.reader_drops;  // a slow realtime reader's, too
    std::unique_lock lock(mutex_);
    advance(lock);
  }

  void on_session_closed(const session::SessionEnd& end) override {
    std::unique_lock lock(mutex_);
    session_closed_ = true;
    end_status_ = stream_end_status(end);
    // The responses already made are sent first. A client still sending is told that no more
    // of its requests will be served; one that has half-closed gets a normal end.
    if (end_status_.ok() && !read_done_) {
      end_status_ = grpc::Status(grpc::StatusCode::ABORTED,
                                 end.message.empty()
                                     ? "session " + (session_ ? session_->id() : "") + " was closed"
                                     : end.message);
    }
    advance(lock);
  }

 private:
  DriveReactor(DownpourService::Context& ctx, Principal who) : ctx_(ctx), who_(std::move(who)) {}

  grpc::Status handle(const v1::DriveRequest& req) {
    std::shared_ptr<Session> session;
    {
      std::lock_guard lock(mutex_);
      session = session_;
    }
    if (!session) {
      if (auto s = check_session_id(req.session_id(), "session_id"); !s.ok()) return s;
      if (auto s = reach_session(ctx_.registry, req.session_id(), who_, may_drive, &session);
          !s.ok())
        return s;
      {
        std::lock_guard lock(mutex_);
        session_ = session;
        lockstep_ = session->config().mode == sim::Mode::kLockstep;
        views_ = session->config().views.size();
      }
      session->attach_stream();  // detached in OnDone
      // A sink in both modes: it hears when the session ends (a lockstep stream takes its frames
      // from its steps, not from the sink).
      session->add_sink(shared_from_this());
      spdlog::debug("session {}: Drive stream attached", session->id());
    } else if (!req.session_id().empty() && req.session_id() != session->id()) {
      return grpc::Status(
          grpc::StatusCode::INVALID_ARGUMENT,
          "session_id: a Drive stream stays with its first session '" + session->id() + "'");
    }
    session->touch();
    sim::Update update;
    if (auto s = to_update(req.update(), "update", ctx_.limits, &update); !s.ok()) return s;
    if (auto s = check_dt(req.dt_s(), "dt_s", true, ctx_.limits); !s.ok()) return s;
    if (!lockstep_ || req.dt_s() == 0.0)
      return submit_status(session->post_update(update), session->id());
    if (ctx_.draining) {
      std::lock_guard lock(mutex_);
      draining_ = true;
      return grpc::Status::OK;
    }

    std::size_t index;
    {
      std::lock_guard lock(mutex_);
      index = next_index_++;
      pending_.emplace_back();
    }
    auto self = shared_from_this();
    const auto result = session->submit_step(
        std::move(update), req.dt_s(),
        [self, index,
         counted = std::make_shared<StepInFlight>(ctx_.steps_in_flight)](session::StepOutcome o) {
          std::unique_lock lock(self->mutex_);
          if (!o.ok) {
            self->finish_with(lock, step_failure_status(o));
            return;
          }
          v1::DriveResponse response;
          for (const FramePtr& f : o.frames) fill_frame(*f, 0, response.add_frames());
          self->pending_[index - self->first_index_] = std::move(response);
          self->advance(lock);
        },
        cancelled_);
    return submit_status(result, session->id());
  }

  // Decides the next operations under the lock, then starts them without it (a reaction may run
  // inline). Called with the lock held; may release it.
  void advance(std::unique_lock<std::mutex>& lock) {
    if (finished_ || done_) return;
    if (final_status_) {  // a failure or a cancel waited for the write in flight: it is done now
      if (!writing_) finish_with(lock, *final_status_);
      return;
    }
    bool start_write = false, start_read = false;
    if (!writing_) {
      if (lockstep_) {
        if (!pending_.empty() && pending_.front()) {
          out_ = std::move(*pending_.front());
          pending_.pop_front();
          ++first_index_;
          start_write = true;
        }
      } else if (std::vector<FramePtr> tick = slot_.take_tick(views_); !tick.empty()) {
        // A tick's views together in one response, as lockstep sends them.
        out_.Clear();
        for (const FramePtr& frame : tick) fill_frame(*frame, slot_.drops(), out_.add_frames());
        start_write = true;
      }
      writing_ = start_write;
    }
    if (!reading_ && !read_done_ && !session_closed_ && pending_.size() < kMaxAhead) {
      reading_ = start_read = true;
    }
    if (!writing_ && (session_closed_ || (read_done_ && pending_.empty()))) {
      finish_with(lock, end_status_);
      return;
    }
    if (!start_write && !start_read) return;
    // Another thread may want to finish while this one starts the operations outside the lock;
    // it waits (starting_), since nothing may be started on a finished stream.
    ++starting_;
    lock.unlock();
    if (start_write) {
      // out_ is ours until the write completes (writing_ keeps other threads off it).
      bool own_buffer = false;
      out_bytes_.Clear();  // the last write's bytes
      grpc::SerializationTraits<v1::DriveResponse>::Serialize(out_, &out_bytes_, &own_buffer);
      StartWrite(&out_bytes_);
    }
    if (start_read) StartRead(&request_bytes_);
    lock.lock();
    --starting_;
    if (final_status_ && !finished_) finish_with(lock, *final_status_);
  }

  // Finish once no write is in flight (the write's completion comes back through advance()) and
  // no operation is being started.
  void finish_with(std::unique_lock<std::mutex>& lock, const grpc::Status& status) {
    if (finished_ || done_) return;
    if (!status.ok()) cancelled_->store(true);  // the steps not yet started will not be answered
    if (!final_status_) final_status_ = status;
    if (writing_ || starting_ > 0) return;
    finished_ = true;
    const grpc::Status s = *final_status_;
    lock.unlock();
    Finish(s);
  }

  DownpourService::Context& ctx_;
  const Principal who_;
  std::shared_ptr<DriveReactor> self_;  // keeps us alive until OnDone
  const std::shared_ptr<std::atomic<bool>> cancelled_ = std::make_shared<std::atomic<bool>>(false);
  grpc::ByteBuffer request_bytes_;
  v1::DriveRequest request_;
  v1::DriveResponse out_;
  grpc::ByteBuffer out_bytes_;  // out_, serialized when its write is decided
  session::LatestFrameSlot slot_;
  std::mutex mutex_;
  std::shared_ptr<Session> session_;  // guarded by mutex_
  bool lockstep_ = false;             // set with session_
  std::size_t views_ = 1;             // likewise: the session's views, a tick's frames
  std::deque<std::optional<v1::DriveResponse>>
      pending_;                               // guarded by mutex_: lockstep responses in order
  std::size_t first_index_ = 0;               // guarded by mutex_: index of pending_.front()
  std::size_t next_index_ = 0;                // guarded by mutex_
  bool reading_ = true;                       // guarded by mutex_: a read is outstanding
  bool writing_ = false;                      // guarded by mutex_
  int starting_ = 0;                          // guarded by mutex_: threads starting operations
  bool read_done_ = false;                    // guarded by mutex_
  bool session_closed_ = false;               // guarded by mutex_
  bool draining_ = false;                     // guarded by mutex_: a step came in during a drain
  bool finished_ = false;                     // guarded by mutex_
  bool done_ = false;                         // guarded by mutex_
  grpc::Status end_status_;                   // guarded by mutex_: for an orderly end (OK)
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
    ++ctx.open_streams;  // until OnDone
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

  void on_session_closed(const session::SessionEnd& end) override {
    {
      std::lock_guard lock(mutex_);
      session_closed_ = true;
      end_status_ = stream_end_status(end);
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
    --ctx_.open_streams;
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
                     : end_status_);
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
  grpc::Status end_status_;                             // guarded by mutex_: the session's end
  bool finished_ = false;                               // guarded by mutex_
};

}  // namespace

DownpourService::DownpourService(session::SessionRegistry& registry,
                                 session::FrameScheduler& scheduler, Limits limits,
                                 Authenticator auth, std::shared_ptr<RoadNetworks> road_networks)
    : scheduler_(scheduler),
      context_{registry, limits, std::move(auth),
               road_networks ? std::move(road_networks) : std::make_shared<RoadNetworks>()},
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
  session::SessionConfig config;
  sim::Update initial;
  if (auto s = to_session_config(*request, context_.limits, &config, &initial); !s.ok())
    return finish(ctx, s);
  config.owner = who.name;
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
  if (auto s = check_session_id(request->session_id(), "session_id"); !s.ok())
    return finish(ctx, s);
  sim::Update update;
  if (auto s = to_update(request->update(), "update", context_.limits, &update); !s.ok())
    return finish(ctx, s);
  std::shared_ptr<Session> session;
  if (auto s = reach_session(context_.registry, request->session_id(), who, may_drive, &session);
      !s.ok())
    return finish(ctx, s);
  session->touch();
  response->set_sim_time_s(session->sim_time_s());
  return finish(ctx, submit_status(session->post_update(update), session->id()));
}

grpc::ServerUnaryReactor* DownpourService::Step(grpc::CallbackServerContext* ctx,
                                                const v1::StepRequest* request,
                                                v1::StepResponse* response) {
  Principal who;
  if (auto s = context_.auth.authenticate(*ctx, &who); !s.ok()) return finish(ctx, s);
  if (auto s = check_session_id(request->session_id(), "session_id"); !s.ok())
    return finish(ctx, s);
  sim::Update update;
  if (auto s = to_update(request->update(), "update", context_.limits, &update); !s.ok())
    return finish(ctx, s);
  if (auto s = check_dt(request->dt_s(), "dt_s", false, context_.limits); !s.ok())
    return finish(ctx, s);
  std::shared_ptr<Session> session;
  if (auto s = reach_session(context_.registry, request->session_id(), who, may_drive, &session);
      !s.ok())
    return finish(ctx, s);
  session->touch();
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
  return DriveReactor::start(context_, std::move(who));
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
  return WatchReactor::start(context_, session, wanted, request->max_fps());
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
