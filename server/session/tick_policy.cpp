#include "server/session/tick_policy.hpp"

#include <algorithm>
#include <tuple>
#include <vector>

namespace downpour::session {
namespace {

// The achieved rate is measured over the last second; a session slower than that (a frame or two
// a second) over its last few ticks, as far back as the long window.
constexpr Clock::duration kRateWindow = std::chrono::seconds(1);
constexpr Clock::duration kSlowRateWindow = std::chrono::seconds(10);
constexpr std::size_t kSlowRateTicks = 3;

}  // namespace

void TickPolicy::add(std::uint64_t session, sim::Mode mode, double fps, Clock::time_point now) {
  Schedule s;
  s.mode = mode;
  // A new session starts level with the others, not ahead of them: a stream of new sessions does
  // not push the running ones back.
  s.charged_s = floor_s_;
  if (mode == sim::Mode::kRealtime) {
    s.fps = fps;
    s.period =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / fps));
    s.next_due = now;
    s.last_tick = now - s.period;
  }
  sessions_.insert_or_assign(session, std::move(s));
}

void TickPolicy::remove(std::uint64_t session) { sessions_.erase(session); }

void TickPolicy::charge(std::uint64_t session, double seconds) {
  if (const auto it = sessions_.find(session); it != sessions_.end())
    it->second.charged_s += std::max(0.0, seconds);
}

std::uint64_t TickPolicy::pass_slot(Schedule& s, Clock::time_point now) {
  // Slots after the one served whose time has also passed are missed: no catching up in a burst.
  const auto behind = now - s.next_due;
  const std::uint64_t missed =
      behind >= s.period ? static_cast<std::uint64_t>(behind / s.period) : 0;
  s.next_due += s.period * static_cast<Clock::rep>(missed + 1);
  return missed;
}

void TickPolicy::note_tick(Schedule& s, Clock::time_point now) {
  ++s.ticks;
  s.recent.push_back(now);
  while (s.recent.size() > kSlowRateTicks && now - s.recent.front() > kRateWindow)
    s.recent.pop_front();
  while (!s.recent.empty() && now - s.recent.front() > kSlowRateWindow) s.recent.pop_front();
}

std::optional<TickPolicy::Tick> TickPolicy::next(Clock::time_point now,
                                                 const WaitingSince& waiting_since,
                                                 const CanRender& can_render) {
  // The sessions due, by the loop's time they have used, then by how long they have waited, then
  // by number (a fixed order). One that has been idle starts from the least charge among them, less
  // the credit: it cannot bank the time it did not use.
  struct Due {
    double charged_s;
    Clock::time_point since;
    std::uint64_t id;
    bool operator<(const Due& o) const {
      return std::tie(charged_s, since, id) < std::tie(o.charged_s, o.since, o.id);
    }
  };
  std::vector<Due> due;
  for (auto& [id, s] : sessions_) {
    if (s.mode == sim::Mode::kRealtime) {
      if (s.next_due <= now) due.push_back({0.0, s.next_due, id});
    } else if (const auto since = waiting_since(id); since && *since <= now) {
      due.push_back({0.0, *since, id});
    }
  }
  if (due.empty()) return std::nullopt;
  for (Due& d : due) {
    Schedule& s = sessions_.at(d.id);
    s.charged_s = std::max(s.charged_s, floor_s_ - kWakeCreditS);
    d.charged_s = s.charged_s;
  }
  std::sort(due.begin(), due.end());
  floor_s_ = std::max(floor_s_, due.front().charged_s);
  for (const auto& [charged, since, id] : due) {
    Schedule& s = sessions_.at(id);
    const bool renders = can_render(id);
    if (s.mode == sim::Mode::kLockstep) {
      if (!renders) continue;  // its step waits for the encoders
      note_tick(s, now);
      return Tick{id, 0.0};
    }
    const std::uint64_t missed = pass_slot(s, now);
    s.frames_late += missed;
    if (!renders) {
      ++s.frames_late;  // this slot is dropped too
      continue;
    }
    const double dt =
        std::min(std::chrono::duration<double>(now - s.last_tick).count(), kMaxRealtimeStepS);
    s.last_tick = now;
    note_tick(s, now);
    return Tick{id, dt};
  }
  return std::nullopt;
}

Clock::time_point TickPolicy::next_wake(Clock::time_point now, Clock::duration idle) const {
  Clock::time_point wake = now + idle;
  for (const auto& [id, s] : sessions_) {
    if (s.mode == sim::Mode::kRealtime) wake = std::min(wake, s.next_due);
  }
  return wake;
}

TickStats TickPolicy::stats(std::uint64_t session, Clock::time_point now) const {
  TickStats out;
  const auto it = sessions_.find(session);
  if (it == sessions_.end()) return out;
  const Schedule& s = it->second;
  out.ticks = s.ticks;
  out.frames_late = s.frames_late;
  out.target_fps = s.fps;
  // Ticks within the last second over the time they span, once they span half a second (two
  // ticks close together say little). A slower session: its last few ticks within the long window.
  // Either way, once the time since the last tick is longer than any interval between those ticks,
  // no more than one over it: a session that stops rendering shows its rate falling, not the rate
  // it last had. (Not before: beside a heavy session a light one ticks in bursts, and a wait as
  // long as its usual ones is no slowdown.)
  std::size_t recent = 0;
  for (auto t : s.recent) recent += now - t <= kRateWindow;
  const bool fast = recent >= 2 && s.recent.back() - s.recent[s.recent.size() - recent] >=
                                       std::chrono::milliseconds(500);
  if (!fast) {
    recent = 0;
    for (auto t : s.recent) recent += now - t <= kSlowRateWindow;
  }
  if (recent >= 2) {
    const std::size_t first = s.recent.size() - recent;
    const double span = std::chrono::duration<double>(s.recent.back() - s.recent[first]).count();
    Clock::duration longest{};
    for (std::size_t i = first + 1; i < s.recent.size(); ++i)
      longest = std::max(longest, s.recent[i] - s.recent[i - 1]);
    const Clock::duration since_last = now - s.recent.back();
    if (span > 0.0) {
      out.achieved_fps = (recent - 1) / span;
      if (since_last > longest) {
        out.achieved_fps =
            std::min(out.achieved_fps, 1.0 / std::chrono::duration<double>(since_last).count());
      }
    }
  }
  return out;
}

}  // namespace downpour::session
