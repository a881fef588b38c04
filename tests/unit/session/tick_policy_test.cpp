// The render loop's scheduling on a clock of the test's own: realtime sessions tick at their rate,
// lockstep ones when a step waits, the one that has used the least of the loop first (then the one
// that has waited longest); an overloaded loop shares itself out whatever the sessions' ids, and a
// small step beside heavy sessions waits for one of their ticks at most; full encoders drop a
// session's frames (counted late) without holding up the others.
#include "server/session/tick_policy.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

namespace downpour::session {
namespace {

using namespace std::chrono_literals;

// A loop on a fake clock: every `step` it ticks whatever is due, each tick taking `cost`.
struct FakeLoop {
  TickPolicy policy;
  Clock::time_point now{};  // the fake clock
  std::map<std::uint64_t, int> ticks;
  std::map<std::uint64_t, std::optional<Clock::time_point>> waiting;  // lockstep steps
  std::map<std::uint64_t, bool> encoders_full;
  std::vector<std::uint64_t> order;  // of ticks

  std::optional<TickPolicy::Tick> next() {
    return policy.next(
        now, [&](std::uint64_t id) { return waiting.count(id) ? waiting[id] : std::nullopt; },
        [&](std::uint64_t id) { return !encoders_full[id]; });
  }
  void run(Clock::duration total, Clock::duration step, Clock::duration cost) {
    const Clock::time_point end = now + total;
    while (now < end) {
      if (const auto tick = next()) {
        ++ticks[tick->session];
        order.push_back(tick->session);
        waiting.erase(tick->session);
        now += cost;
      } else {
        now += step;
      }
    }
  }
};

TEST(TickPolicyTest, RealtimeSessionsTickAtTheirRate) {
  FakeLoop loop;
  loop.policy.add(1, sim::Mode::kRealtime, 30.0, loop.now);
  loop.policy.add(2, sim::Mode::kRealtime, 10.0, loop.now);
  loop.run(10s, 1ms, 2ms);
  EXPECT_NEAR(loop.ticks[1], 300, 2);
  EXPECT_NEAR(loop.ticks[2], 100, 1);
  EXPECT_EQ(loop.policy.stats(1, loop.now).frames_late, 0u);
  EXPECT_NEAR(loop.policy.stats(1, loop.now).achieved_fps, 30.0, 0.5);
  EXPECT_NEAR(loop.policy.stats(2, loop.now).achieved_fps, 10.0, 0.5);
  EXPECT_EQ(loop.policy.stats(1, loop.now).target_fps, 30.0);
}

TEST(TickPolicyTest, ASessionSlowerThanAFrameASecondStillShowsItsRate) {
  // Each tick takes 1.25 s (a heavy view on a slow build): 0.8 fps, not 0.
  FakeLoop loop;
  loop.policy.add(1, sim::Mode::kRealtime, 60.0, loop.now);
  loop.run(10s, 1ms, 1250ms);
  EXPECT_NEAR(loop.policy.stats(1, loop.now).achieved_fps, 0.8, 0.05);
  EXPECT_GT(loop.policy.stats(1, loop.now).frames_late, 400u);
}

TEST(TickPolicyTest, ASessionThatStopsRenderingShowsItsRateFalling) {
  FakeLoop loop;
  loop.policy.add(1, sim::Mode::kRealtime, 30.0, loop.now);
  loop.run(3s, 1ms, 2ms);
  EXPECT_NEAR(loop.policy.stats(1, loop.now).achieved_fps, 30.0, 0.5);
  loop.encoders_full[1] = true;  // its readers stop reading
  loop.run(2s, 1ms, 2ms);
  EXPECT_NEAR(loop.policy.stats(1, loop.now).achieved_fps, 0.5, 0.05);
  loop.run(20s, 1ms, 2ms);
  EXPECT_EQ(loop.policy.stats(1, loop.now).achieved_fps, 0.0);
}

// Beside a heavy session a light one ticks in bursts: a tick or two, then a wait while the heavy
// one renders. Its rate, read at any moment, is the rate it keeps: the drive page beside the demo
// read 7.8-8.1 fps while its frames came at 11.1-11.4 a second (the wait since the last tick,
// longer than most of its ticks' intervals, was taken for a slowdown).
TEST(TickPolicyTest, ASessionTickingInBurstsShowsTheRateItKeeps) {
  TickPolicy policy;
  Clock::time_point now{};
  policy.add(1, sim::Mode::kRealtime, 20.0, now);  // light: 40 ms a tick in the mean
  policy.add(2, sim::Mode::kRealtime, 30.0, now);  // heavy: 120 ms
  const auto always = [](std::uint64_t) { return true; };
  const auto none = [](std::uint64_t) { return std::optional<Clock::time_point>{}; };
  std::vector<double> read;
  int ticks = 0;
  std::uint32_t jitter = 1;
  Clock::time_point next_read = now + 2s;  // after the first seconds
  const Clock::time_point end = now + 12s;
  while (now < end) {
    const auto tick = policy.next(now, none, always);
    // Each tick's cost varies, as a frame's does: 0.5 to 1.5 times its mean.
    jitter = jitter * 1103515245u + 12345u;
    const double spread = 0.5 + ((jitter >> 8) % 1000) / 1000.0;
    const Clock::duration cost = !tick ? Clock::duration{1ms}
                                       : std::chrono::duration_cast<Clock::duration>(
                                             (tick->session == 1 ? 40ms : 120ms) * spread);
    if (tick) policy.charge(tick->session, std::chrono::duration<double>(cost).count());
    if (tick && tick->session == 1 && now >= Clock::time_point{} + 2s) ++ticks;
    // The page reads the rate every 7 ms, whatever the loop is doing.
    for (const Clock::time_point done = now + cost; now < done; now += 1ms) {
      if (now >= next_read) {
        read.push_back(policy.stats(1, now).achieved_fps);
        next_read += 7ms;
      }
    }
  }
  const double kept = ticks / 10.0;
  std::sort(read.begin(), read.end());
  EXPECT_GT(kept, 3.0);
  EXPECT_LT(kept, 15.0);  // in bursts, below its rate
  EXPECT_NEAR(read[read.size() / 2], kept, 0.1 * kept)
      << "the median reading; p10 " << read[read.size() / 10] << " kept " << kept;
  EXPECT_GT(read[read.size() / 10], 0.7 * kept) << "the tenth percentile";
}

TEST(TickPolicyTest, TheRealtimeStepIsTheTimeSinceTheLastTickCapped) {
  FakeLoop loop;
  loop.policy.add(1, sim::Mode::kRealtime, 20.0, loop.now);
  ASSERT_TRUE(loop.next());
  loop.now += 50ms;
  auto tick = loop.next();
  ASSERT_TRUE(tick);
  EXPECT_NEAR(tick->dt_s, 0.05, 1e-9);
  loop.now += 2s;  // a stalled loop
  tick = loop.next();
  ASSERT_TRUE(tick);
  EXPECT_EQ(tick->dt_s, TickPolicy::kMaxRealtimeStepS);
}

TEST(TickPolicyTest, LockstepSessionsTickOnlyWhenAStepWaitsOldestFirst) {
  FakeLoop loop;
  for (std::uint64_t id : {1, 2, 3}) loop.policy.add(id, sim::Mode::kLockstep, 0.0, loop.now);
  EXPECT_FALSE(loop.next());
  loop.waiting[3] = loop.now;
  loop.waiting[1] = loop.now + 1ms;
  loop.waiting[2] = loop.now + 2ms;
  loop.now += 5ms;
  std::vector<std::uint64_t> served;
  while (const auto tick = loop.next()) {
    served.push_back(tick->session);
    loop.waiting.erase(tick->session);
  }
  EXPECT_EQ(served, (std::vector<std::uint64_t>{3, 1, 2}));  // by arrival, not by id
  EXPECT_FALSE(loop.next());
}

TEST(TickPolicyTest, AStalledLoopCountsTheMissedFramesLateAndDoesNotCatchUpInABurst) {
  FakeLoop loop;
  loop.policy.add(1, sim::Mode::kRealtime, 30.0, loop.now);
  loop.run(1s, 1ms, 1ms);
  ASSERT_EQ(loop.policy.stats(1, loop.now).frames_late, 0u);
  loop.now += 200ms;  // the loop was busy
  int burst = 0;
  while (loop.next()) ++burst;
  EXPECT_EQ(burst, 1);
  const std::uint64_t late = loop.policy.stats(1, loop.now).frames_late;
  EXPECT_GE(late, 5u);  // 200 ms at 30 fps: 6 slots, one of them served now
  EXPECT_LE(late, 6u);
  const int before = loop.ticks[1];
  loop.run(1s, 1ms, 1ms);
  EXPECT_NEAR(loop.ticks[1] - before, 30, 1);  // back at its rate, nothing more late
  EXPECT_EQ(loop.policy.stats(1, loop.now).frames_late, late);
}

// Three sessions whose frames together cost more than the loop has: each still gets served, none
// starves, and their shares do not depend on which has the smaller id.
TEST(TickPolicyTest, AnOverloadedLoopIsSharedFairlyWhateverTheIds) {
  auto shares = [](std::array<std::uint64_t, 3> ids) {
    FakeLoop loop;
    loop.policy.add(ids[0], sim::Mode::kRealtime, 30.0, loop.now);
    loop.policy.add(ids[1], sim::Mode::kRealtime, 20.0, loop.now);
    loop.policy.add(ids[2], sim::Mode::kRealtime, 10.0, loop.now);
    loop.run(20s, 1ms, 40ms);  // 60 frames wanted a second, 25 possible
    std::array<double, 3> fps;
    for (int k = 0; k < 3; ++k) fps[k] = loop.ticks[ids[k]] / 20.0;
    EXPECT_GT(loop.policy.stats(ids[0], loop.now).frames_late, 0u);
    return fps;
  };
  const auto a = shares({1, 2, 3});
  const auto b = shares({3, 2, 1});
  for (int k = 0; k < 3; ++k) {
    EXPECT_GT(a[k], 4.0) << "session " << k << " starved";
    EXPECT_NEAR(a[k], b[k], 0.3) << "the ids decided the share of session " << k;
  }
  EXPECT_NEAR(a[0] + a[1] + a[2], 25.0, 0.5);  // the loop is never idle
  EXPECT_GE(a[0], a[1]);                       // the faster ones fall due more often
  EXPECT_GE(a[1], a[2]);
}

// A session whose encoders are full loses frame slots (late) while another renders at its rate:
// a slow encoder never holds up the loop. Once its encoders drain it is back at its rate.
TEST(TickPolicyTest, FullEncodersDropASessionsFramesWithoutHoldingUpTheOthers) {
  FakeLoop loop;
  loop.policy.add(1, sim::Mode::kRealtime, 30.0, loop.now);
  loop.policy.add(2, sim::Mode::kRealtime, 30.0, loop.now);
  loop.policy.add(3, sim::Mode::kLockstep, 0.0, loop.now);
  loop.encoders_full[1] = true;
  loop.encoders_full[3] = true;
  loop.waiting[3] = loop.now;
  loop.run(2s, 1ms, 2ms);
  EXPECT_EQ(loop.ticks[1], 0);
  EXPECT_NEAR(loop.ticks[2], 60, 1);
  EXPECT_EQ(loop.ticks[3], 0);  // its step waits, it is not dropped
  EXPECT_NEAR(static_cast<double>(loop.policy.stats(1, loop.now).frames_late), 60.0, 1.0);
  loop.encoders_full[1] = false;
  loop.encoders_full[3] = false;
  loop.run(2s, 1ms, 2ms);
  EXPECT_NEAR(loop.ticks[1], 60, 1);
  EXPECT_EQ(loop.ticks[3], 1);
}

// The case: heavy realtime sessions that cannot keep their rate (85 ms a tick, 60 fps
// asked) and a small lockstep session (9 ms a step) whose client sends a step 30 ms after each
// answer. Charged by cost, the small session's step waits for at most the tick under way: within
// twice its own cost plus one heavy tick (after the first round). The heavy sessions share the rest
// evenly.
TEST(TickPolicyTest, ASmallStepBesideHeavySessionsWaitsForAtMostOneHeavyTick) {
  TickPolicy policy;
  Clock::time_point now{};
  const std::array<std::uint64_t, 3> heavy = {1, 2, 3};
  const std::uint64_t small = 4;
  for (std::uint64_t id : heavy) policy.add(id, sim::Mode::kRealtime, 60.0, now);
  policy.add(small, sim::Mode::kLockstep, 0.0, now);
  std::optional<Clock::time_point> step_arrived = now + 5ms;
  std::map<std::uint64_t, int> ticks;
  Clock::duration worst{};
  int steps = 0;
  const Clock::time_point end = now + 20s;
  while (now < end) {
    const auto tick = policy.next(
        now,
        [&](std::uint64_t id) {
          return id == small && step_arrived && *step_arrived <= now ? step_arrived : std::nullopt;
        },
        [](std::uint64_t) { return true; });
    if (!tick) {
      now += 1ms;
      continue;
    }
    const bool is_small = tick->session == small;
    const Clock::duration cost = is_small ? Clock::duration(9ms) : Clock::duration(85ms);
    now += cost;
    policy.charge(tick->session, std::chrono::duration<double>(cost).count());
    ++ticks[tick->session];
    if (is_small) {
      // After the first second: at the start every session has used nothing, and the small one
      // waits its turn behind the heavy ones that were due before it (one round).
      if (*step_arrived > Clock::time_point{} + 1s) worst = std::max(worst, now - *step_arrived);
      ++steps;
      step_arrived = now + 30ms;
    }
  }
  EXPECT_LE(worst, 2 * 9ms + 85ms)
      << "the small step waited " << std::chrono::duration<double, std::milli>(worst).count()
      << " ms";
  EXPECT_GT(steps, 150);  // about one every 40 ms and a heavy tick
  for (std::uint64_t id : heavy) {
    EXPECT_NEAR(ticks[id], ticks[heavy[0]], 2) << "heavy session " << id;
    EXPECT_GT(ticks[id], 40) << "heavy session " << id << " starved";
  }
}

TEST(TickPolicyTest, RemovedSessionsAreNotTicked) {
  FakeLoop loop;
  loop.policy.add(1, sim::Mode::kRealtime, 30.0, loop.now);
  loop.policy.remove(1);
  loop.run(1s, 1ms, 1ms);
  EXPECT_EQ(loop.ticks[1], 0);
  EXPECT_EQ(loop.policy.stats(1, loop.now).ticks, 0u);
  EXPECT_EQ(loop.policy.next_wake(loop.now, 100ms), loop.now + 100ms);
}

}  // namespace
}  // namespace downpour::session
