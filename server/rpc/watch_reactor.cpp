#include "server/rpc/watch_reactor.hpp"

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

grpc::ServerWriteReactor<v1::Frame>* start_watch(DownpourService::Context& ctx,
                                                 std::shared_ptr<Session> session,
                                                 std::array<bool, sim::kViewCount> views,
                                                 double max_fps) {
  return WatchReactor::start(ctx, std::move(session), views, max_fps);
}

}  // namespace downpour::rpc
