#include "server/rpc/drive_reactor.hpp"

#include "server/rpc/models.hpp"

#include <array>
#include <cmath>
#include <deque>
#include <mutex>
#include <optional>
#include <utility>

#include <spdlog/spdlog.h>

#include "server/rpc/convert.hpp"
#include "server/rpc/session_access.hpp"
#include "server/session/latest_frame_slot.hpp"

namespace downpour::rpc {
namespace {

using session::FramePtr;
using session::Session;

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
    if (auto s = check_request_size(req, ctx_.limits); !s.ok()) return s;
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
    if (auto s = to_traffic_models(*ctx_.models, req.update(), "update", &update); !s.ok())
      return s;
    if (auto s = to_client_images(req.update(), "update", session->config().views, &update);
        !s.ok())
      return s;
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

}  // namespace

grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* start_drive(
    DownpourService::Context& ctx, Principal who) {
  return DriveReactor::start(ctx, std::move(who));
}

}  // namespace downpour::rpc
