// Which session the render loop ticks next, and when: its scheduling, apart from GL, threads and
// the sessions themselves. Time is passed in by the caller, so that it is tested on a clock of
// the test's own, without sleeping.
//
// Realtime sessions are due at their frame rate; lockstep sessions once a step is waiting. Of the
// sessions due, the one that has used the least of the render thread goes first (its charged
// time, as a fair-share scheduler counts it), then the one that has waited longest; so the loop is
// shared by cost, and no session's id or rate decides who is served. A session that becomes due
// after waiting for nothing starts from the least charge of those due, less a little credit: a
// small lockstep step beside heavy realtime sessions waits for at most the tick under way, not for
// every heavy session that is behind. A realtime session that falls behind does not catch up in a
// burst: the frame slots it missed are counted as late, and it carries on from now.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>

#include "server/sim/types.hpp"

namespace downpour::session {

using Clock = std::chrono::steady_clock;

// How a session has kept its rate.
struct TickStats {
  std::uint64_t ticks = 0;
  // Realtime frame slots that passed without a frame: the loop was busy elsewhere or the encoders
  // were full. A session that keeps its rate has none.
  std::uint64_t frames_late = 0;
  double achieved_fps = 0.0;  // ticks a second, over the last second or the last few ticks
  double target_fps = 0.0;    // realtime: its rate; lockstep: 0
};

class TickPolicy {
 public:
  struct Tick {
    std::uint64_t session = 0;
    double dt_s = 0.0;  // realtime: the time since its last tick (capped); lockstep: 0
  };
  // For a lockstep session: when its oldest waiting request arrived, if it has one.
  using WaitingSince = std::function<std::optional<Clock::time_point>(std::uint64_t session)>;
  // Whether the encoders can take this session's frames now (and, if so, holds room for them).
  using CanRender = std::function<bool(std::uint64_t session)>;

  static constexpr double kMaxRealtimeStepS = 0.25;  // a stalled loop does not make a sim jump

  // The credit a session gets when it becomes due: it may go ahead of sessions that have used up
  // to this much more of the loop.
  static constexpr double kWakeCreditS = 0.05;

  void add(std::uint64_t session, sim::Mode mode, double fps, Clock::time_point now);
  // The render thread's time a tick of this session took (its share of the loop is by this).
  void charge(std::uint64_t session, double seconds);
  void remove(std::uint64_t session);
  bool contains(std::uint64_t session) const { return sessions_.count(session) != 0; }

  // The session to tick at `now`, if any is due and can render. A realtime session that is due
  // but cannot render loses that frame slot (counted late); a lockstep one keeps waiting.
  std::optional<Tick> next(Clock::time_point now, const WaitingSince& waiting_since,
                           const CanRender& can_render);
  // When the next realtime session falls due (at the latest now + idle).
  Clock::time_point next_wake(Clock::time_point now, Clock::duration idle) const;
  TickStats stats(std::uint64_t session, Clock::time_point now) const;

 private:
  struct Schedule {
    sim::Mode mode = sim::Mode::kRealtime;
    double fps = 0.0;
    Clock::duration period{};
    Clock::time_point next_due;   // realtime: the frame slot it is due for
    Clock::time_point last_tick;  // realtime: for the step's dt
    std::uint64_t ticks = 0;
    std::uint64_t frames_late = 0;
    std::deque<Clock::time_point> recent;  // tick times: the last second's, or the last few
    double charged_s = 0.0;                // render thread time used, from the credit on waking
  };
  // Moves a realtime schedule past a slot served (or dropped) at `now`; returns the slots missed.
  static std::uint64_t pass_slot(Schedule& s, Clock::time_point now);
  static void note_tick(Schedule& s, Clock::time_point now);

  std::map<std::uint64_t, Schedule> sessions_;
  double floor_s_ = 0.0;  // the least charge of the sessions due, never going back
};

}  // namespace downpour::session
