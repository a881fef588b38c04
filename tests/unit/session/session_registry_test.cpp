#include "server/session/session_registry.hpp"

#include <atomic>
#include <chrono>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace downpour::session {
namespace {

class CountingSink : public FrameSink {
 public:
  void on_frame(const FramePtr&) override { ++frames; }
  void on_session_closed(const SessionEnd& end) override {
    ++closed;
    last_end = end;
  }
  int frames = 0;
  int closed = 0;
  SessionEnd last_end;
};

SessionConfig config(sim::Mode mode) {
  SessionConfig c;
  c.views = {sim::ViewSpec{}};
  c.mode = mode;
  return c;
}

class SessionRegistryTest : public ::testing::Test {
 protected:
  std::atomic<int> wakes_{0};
  SessionRegistry registry_{3, [this] { ++wakes_; }};
};

TEST_F(SessionRegistryTest, LimitIsEnforcedAndFreedByClose) {
  EXPECT_EQ(registry_.max_sessions(), 3);
  std::vector<std::shared_ptr<Session>> sessions;
  for (int i = 0; i < 3; ++i) {
    sessions.push_back(registry_.create(config(sim::Mode::kRealtime), {}));
    ASSERT_NE(sessions.back(), nullptr) << "session " << i;
  }
  EXPECT_EQ(registry_.create(config(sim::Mode::kRealtime), {}), nullptr);
  EXPECT_EQ(registry_.list().size(), 3u);
  ASSERT_TRUE(registry_.close(sessions[1]->id()));
  EXPECT_EQ(registry_.list().size(), 2u);
  const auto again = registry_.create(config(sim::Mode::kRealtime), {});
  ASSERT_NE(again, nullptr);
  EXPECT_EQ(registry_.create(config(sim::Mode::kRealtime), {}), nullptr);
  // Not reused: the closed session's id stays unknown.
  EXPECT_NE(again->id(), sessions[1]->id());
  EXPECT_EQ(registry_.find(sessions[1]->id()), nullptr);
}

TEST_F(SessionRegistryTest, IdsAreUniqueAndFound) {
  std::set<std::string> ids;
  std::set<std::uint64_t> numbers;
  for (int round = 0; round < 20; ++round) {
    const auto s = registry_.create(config(sim::Mode::kRealtime), {});
    ASSERT_NE(s, nullptr);
    EXPECT_FALSE(s->id().empty());
    EXPECT_TRUE(ids.insert(s->id()).second) << "duplicate id " << s->id();
    EXPECT_TRUE(numbers.insert(s->number()).second);
    EXPECT_EQ(registry_.find(s->id()), s);
    ASSERT_TRUE(registry_.close(s->id()));
  }
  EXPECT_EQ(registry_.find("no-such-session"), nullptr);
}

// Ids carry 128 random bits: 32 hex digits after the number, none shared between ids, and two
// registries (two server runs) give the same number different ids.
TEST_F(SessionRegistryTest, IdsCarry128RandomBits) {
  SessionRegistry other(8, [] {});
  const auto a = registry_.create(config(sim::Mode::kRealtime), {});
  const auto b = other.create(config(sim::Mode::kRealtime), {});
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(a->number(), b->number());
  EXPECT_NE(a->id(), b->id());
  std::set<std::string> randoms;
  for (const auto& s : {a, b}) {
    const std::string& id = s->id();
    const auto dash = id.find('-');
    ASSERT_NE(dash, std::string::npos) << id;
    EXPECT_EQ(id[0], 's') << id;
    EXPECT_EQ(id.substr(1, dash - 1), std::to_string(s->number()));
    const std::string random = id.substr(dash + 1);
    EXPECT_EQ(random.size(), 32u) << id;
    EXPECT_EQ(random.find_first_not_of("0123456789abcdef"), std::string::npos) << id;
    EXPECT_TRUE(randoms.insert(random).second);
  }
  // Bits that vary: over many ids every hex position takes many values.
  std::vector<std::set<char>> seen(32);
  for (int i = 0; i < 200; ++i) {
    const auto s = other.create(config(sim::Mode::kRealtime), {});
    ASSERT_NE(s, nullptr);
    const std::string random = s->id().substr(s->id().find('-') + 1);
    for (int k = 0; k < 32; ++k) seen[k].insert(random[k]);
    ASSERT_TRUE(other.close(s->id()));
  }
  for (int k = 0; k < 32; ++k) EXPECT_GE(seen[k].size(), 12u) << "hex digit " << k;
}

TEST_F(SessionRegistryTest, CreateKeepsTheConfigAndAppliesTheInitialUpdate) {
  SessionConfig c = config(sim::Mode::kLockstep);
  c.fps = 12.0;
  c.seed = 1234;
  sim::Update initial;
  initial.vehicle = sim::VehicleState{};
  initial.vehicle->position_m = {4.0, 5.0, 6.0};
  const auto s = registry_.create(c, initial);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->config().mode, sim::Mode::kLockstep);
  EXPECT_EQ(s->config().fps, 12.0);
  EXPECT_EQ(s->config().seed, 1234u);
  EXPECT_EQ(s->simulation().state().vehicle.position_m, glm::dvec3(4.0, 5.0, 6.0));
  EXPECT_FALSE(s->closed());
  EXPECT_GT(wakes_.load(), 0);
}

TEST_F(SessionRegistryTest, CloseOfAnUnknownIdIsFalse) {
  EXPECT_FALSE(registry_.close("s1-00000000"));
  const auto s = registry_.create(config(sim::Mode::kRealtime), {});
  ASSERT_TRUE(registry_.close(s->id()));
  EXPECT_FALSE(registry_.close(s->id()));
  EXPECT_TRUE(s->closed());
}

TEST_F(SessionRegistryTest, ClosingFailsQueuedStepsAndTellsTheSinks) {
  const auto s = registry_.create(config(sim::Mode::kLockstep), {});
  ASSERT_NE(s, nullptr);
  std::vector<StepOutcome> outcomes;
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(s->submit_step({}, 0.1, [&](StepOutcome o) { outcomes.push_back(std::move(o)); }),
              Session::Submit::kQueued);
  }
  const auto sink = std::make_shared<CountingSink>();
  s->add_sink(sink);
  const auto removed_sink = std::make_shared<CountingSink>();
  s->add_sink(removed_sink);
  s->remove_sink(removed_sink.get());

  ASSERT_TRUE(registry_.close(s->id()));
  ASSERT_EQ(outcomes.size(), 3u);
  for (const StepOutcome& o : outcomes) {
    EXPECT_FALSE(o.ok);
    EXPECT_NE(o.error.find(s->id()), std::string::npos) << o.error;
    EXPECT_EQ(o.failure, EndReason::kClosed);
    EXPECT_TRUE(o.frames.empty());
  }
  EXPECT_EQ(sink->closed, 1);
  EXPECT_EQ(sink->last_end.reason, EndReason::kClosed);
  EXPECT_EQ(removed_sink->closed, 0);
  EXPECT_FALSE(s->pop_job());

  // Closing again is a no-op (the first reason stays); later calls are refused; a late sink hears
  // at once, with the reason.
  s->close({EndReason::kShuttingDown, "server shutting down"});
  EXPECT_EQ(outcomes.size(), 3u);
  EXPECT_EQ(sink->closed, 1);
  EXPECT_EQ(s->submit_step({}, 0.1, [](StepOutcome) {}), Session::Submit::kClosed);
  EXPECT_EQ(s->post_update({}), Session::Submit::kClosed);
  const auto late = std::make_shared<CountingSink>();
  s->add_sink(late);
  EXPECT_EQ(late->closed, 1);
  EXPECT_EQ(late->last_end.reason, EndReason::kClosed);
}

TEST_F(SessionRegistryTest, AShutdownFailsTheWaitingStepsAsShutdownAndSaysSoToTheSinks) {
  const auto s = registry_.create(config(sim::Mode::kLockstep), {});
  std::vector<StepOutcome> outcomes;
  ASSERT_EQ(s->submit_step({}, 0.1, [&](StepOutcome o) { outcomes.push_back(std::move(o)); }),
            Session::Submit::kQueued);
  const auto sink = std::make_shared<CountingSink>();
  s->add_sink(sink);
  const SessionEnd end{EndReason::kShuttingDown, "server shutting down"};
  registry_.close_all(end);
  ASSERT_EQ(outcomes.size(), 1u);
  EXPECT_EQ(outcomes[0].failure, EndReason::kShuttingDown);
  EXPECT_EQ(outcomes[0].error, end.message);
  EXPECT_EQ(sink->last_end.reason, EndReason::kShuttingDown);
  EXPECT_EQ(sink->last_end.message, end.message);
}

TEST_F(SessionRegistryTest, CloseAllClosesEverySession) {
  const auto a = registry_.create(config(sim::Mode::kRealtime), {});
  const auto b = registry_.create(config(sim::Mode::kLockstep), {});
  const auto sink = std::make_shared<CountingSink>();
  b->add_sink(sink);
  registry_.close_all();
  EXPECT_TRUE(a->closed());
  EXPECT_TRUE(b->closed());
  EXPECT_EQ(sink->closed, 1);
  EXPECT_TRUE(registry_.list().empty());
  EXPECT_NE(registry_.create(config(sim::Mode::kRealtime), {}), nullptr);
}

TEST_F(SessionRegistryTest, IdleSessionsCloseAfterTheTimeoutAndADriveStreamHoldsTheirLease) {
  const auto quiet = registry_.create(config(sim::Mode::kRealtime), {});
  const auto driven = registry_.create(config(sim::Mode::kLockstep), {});
  const auto sink = std::make_shared<CountingSink>();
  quiet->add_sink(sink);
  driven->attach_stream();
  const Clock::time_point t0 = Clock::now();
  // No timeout set: nothing is ever idle-closed.
  EXPECT_TRUE(registry_.close_idle(t0 + std::chrono::hours(1)).empty());

  registry_.set_idle_timeout_s(10.0);
  EXPECT_TRUE(registry_.close_idle(t0 + std::chrono::seconds(5)).empty());
  EXPECT_NEAR(quiet->idle_s(t0 + std::chrono::seconds(5)), 5.0, 0.5);
  EXPECT_EQ(driven->idle_s(t0 + std::chrono::hours(1)), 0.0);  // attached: never idle

  const auto closed = registry_.close_idle(t0 + std::chrono::seconds(11));
  ASSERT_EQ(closed.size(), 1u);
  EXPECT_EQ(closed[0], quiet);
  EXPECT_TRUE(quiet->closed());
  EXPECT_EQ(sink->closed, 1);  // its watchers hear that it ended, and why
  EXPECT_EQ(sink->last_end.reason, EndReason::kIdle);
  EXPECT_EQ(registry_.find(quiet->id()), nullptr);
  EXPECT_FALSE(driven->closed());
  EXPECT_EQ(registry_.closed_idle(), 1u);

  // The stream ends: the lease runs from its end.
  driven->detach_stream();
  const Clock::time_point detached = Clock::now();
  EXPECT_TRUE(registry_.close_idle(detached + std::chrono::seconds(9)).empty());
  EXPECT_EQ(registry_.close_idle(detached + std::chrono::seconds(11)).size(), 1u);
  EXPECT_TRUE(driven->closed());
  EXPECT_EQ(registry_.closed_idle(), 2u);
  EXPECT_TRUE(registry_.list().empty());
}

TEST(SessionTest, TouchRestartsTheIdleClock) {
  Session s("s1-x", 1, config(sim::Mode::kRealtime), {}, [] {});
  const Clock::time_point later = Clock::now() + std::chrono::seconds(30);
  EXPECT_NEAR(s.idle_s(later), 30.0, 0.5);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  s.touch();
  EXPECT_LT(s.idle_s(later), 30.0 - 0.015);
  EXPECT_EQ(s.idle_s(Clock::now() - std::chrono::seconds(5)), 0.0);  // never negative
}

TEST(SessionTest, CancelledStepsAreDroppedAndFreeTheirPlace) {
  Session s("s1-x", 1, config(sim::Mode::kLockstep), {}, [] {});
  std::vector<std::shared_ptr<std::atomic<bool>>> flags;
  std::vector<StepOutcome> outcomes(Session::kMaxQueuedJobs);
  for (std::size_t i = 0; i < Session::kMaxQueuedJobs; ++i) {
    flags.push_back(std::make_shared<std::atomic<bool>>(false));
    sim::Update u;
    u.client_time_s = static_cast<double>(i);
    ASSERT_EQ(s.submit_step(
                  u, 0.1, [&outcomes, i](StepOutcome o) { outcomes[i] = std::move(o); }, flags[i]),
              Session::Submit::kQueued);
  }
  EXPECT_EQ(s.submit_step({}, 0.1, [](StepOutcome) {}), Session::Submit::kFull);
  flags[0]->store(true);
  flags[2]->store(true);
  // A cancelled step frees its place at the next submission.
  EXPECT_EQ(s.submit_step({}, 0.1, [](StepOutcome) {}), Session::Submit::kQueued);
  EXPECT_EQ(s.steps_cancelled(), 2u);
  for (int i : {0, 2}) {
    EXPECT_FALSE(outcomes[i].ok);
    EXPECT_EQ(outcomes[i].failure, EndReason::kCancelled);
  }
  // The render thread never sees a cancelled step.
  flags[3]->store(true);
  auto job = s.pop_job();
  ASSERT_TRUE(job);
  EXPECT_EQ(job->update.client_time_s, 1.0);
  job = s.pop_job();
  ASSERT_TRUE(job);
  EXPECT_EQ(job->update.client_time_s, 4.0);
  EXPECT_EQ(outcomes[3].failure, EndReason::kCancelled);
  EXPECT_EQ(s.steps_cancelled(), 3u);
}

TEST(SessionTest, LockstepQueueIsBounded) {
  Session s("s1-test", 1, config(sim::Mode::kLockstep), {}, [] {});
  int failed = 0;
  for (std::size_t i = 0; i < Session::kMaxQueuedJobs; ++i) {
    // Updates and steps share the queue, in order.
    const Session::Submit r = i % 2 == 0
                                  ? s.submit_step({}, 0.1, [&](StepOutcome o) { failed += !o.ok; })
                                  : s.post_update({});
    ASSERT_EQ(r, Session::Submit::kQueued) << "job " << i;
  }
  EXPECT_EQ(s.submit_step({}, 0.1, [](StepOutcome) {}), Session::Submit::kFull);
  // An update folds into the update waiting at the queue's end: it takes no room.
  EXPECT_EQ(s.post_update({}), Session::Submit::kQueued);
  // Popping one makes room for one.
  const auto first = s.pop_job();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->dt_s, 0.1);
  EXPECT_TRUE(first->done);
  EXPECT_EQ(s.submit_step({}, 0.1, [&](StepOutcome o) { failed += !o.ok; }),
            Session::Submit::kQueued);
  EXPECT_EQ(s.submit_step({}, 0.1, [](StepOutcome) {}), Session::Submit::kFull);
  const auto second = s.pop_job();
  ASSERT_TRUE(second);
  EXPECT_EQ(second->dt_s, 0.0);
  EXPECT_FALSE(second->done);  // an update-only job
  s.close();
  EXPECT_EQ(failed, static_cast<int>(Session::kMaxQueuedJobs / 2));
}

TEST(SessionTest, UpdatesAloneNeverFillTheLockstepQueueAndKeepTheirOrder) {
  Session s("s1-test", 1, config(sim::Mode::kLockstep), {}, [] {});
  ASSERT_EQ(s.submit_step({}, 0.1, nullptr), Session::Submit::kQueued);
  for (int i = 0; i < 1000; ++i) {
    sim::Update u;
    u.client_time_s = i;
    u.weather = sim::Weather{};
    u.weather->rain_rate_mm_h = i;
    ASSERT_EQ(s.post_update(u), Session::Submit::kQueued) << "update " << i;
  }
  EXPECT_FALSE(s.oldest_step_arrival() == std::nullopt);
  ASSERT_TRUE(s.pop_job());  // the step
  const auto folded = s.pop_job();
  ASSERT_TRUE(folded);
  EXPECT_EQ(folded->update.client_time_s, 999);  // the latest, as if applied one by one
  EXPECT_EQ(folded->update.weather->rain_rate_mm_h, 999);
  EXPECT_FALSE(s.pop_job());
  EXPECT_EQ(s.oldest_step_arrival(), std::nullopt);  // updates alone are not due
}

TEST(SessionTest, LockstepKeepsTheFeedOrder) {
  Session s("s1-test", 1, config(sim::Mode::kLockstep), {}, [] {});
  for (int i = 0; i < 5; ++i) {
    sim::Update u;
    u.client_time_s = i;
    ASSERT_EQ(s.submit_step(u, 0.1 * (i + 1), nullptr), Session::Submit::kQueued);
  }
  for (int i = 0; i < 5; ++i) {
    const auto job = s.pop_job();
    ASSERT_TRUE(job);
    EXPECT_EQ(job->update.client_time_s, i);
    EXPECT_DOUBLE_EQ(job->dt_s, 0.1 * (i + 1));
  }
  EXPECT_FALSE(s.pop_job());
  EXPECT_FALSE(s.take_update());  // lockstep updates do not go to the realtime inbox
}

TEST(SessionTest, RealtimeUpdatesFoldLaterFieldsWin) {
  int wakes = 0;
  Session s("s1-test", 1, config(sim::Mode::kRealtime), {}, [&] { ++wakes; });
  EXPECT_FALSE(s.take_update());

  sim::Update first;
  first.client_time_s = 1.0;
  first.vehicle = sim::VehicleState{};
  first.vehicle->position_m = {1.0, 0.0, 0.0};
  first.weather = sim::Weather{};
  first.weather->rain_rate_mm_h = 5.0;
  sim::Update second;
  second.client_time_s = 2.0;
  second.vehicle = sim::VehicleState{};
  second.vehicle->position_m = {2.0, 0.0, 0.0};
  second.wipers = sim::WiperState{sim::WiperMode::kHigh, 4.0, {}};
  for (int i = 0; i < 100; ++i) ASSERT_EQ(s.post_update(first), Session::Submit::kQueued);
  ASSERT_EQ(s.post_update(second), Session::Submit::kQueued);
  EXPECT_EQ(wakes, 101);
  EXPECT_FALSE(s.pop_job());  // nothing queued in realtime: updates fold, so no bound is needed

  const auto folded = s.take_update();
  ASSERT_TRUE(folded);
  const sim::Update& u = folded->first;
  EXPECT_EQ(u.client_time_s, 2.0);
  ASSERT_TRUE(u.vehicle);
  EXPECT_EQ(u.vehicle->position_m.x, 2.0);
  ASSERT_TRUE(u.weather);  // only in the first: kept
  EXPECT_EQ(u.weather->rain_rate_mm_h, 5.0);
  ASSERT_TRUE(u.wipers);  // only in the second: added
  EXPECT_EQ(u.wipers->mode, sim::WiperMode::kHigh);
  EXPECT_FALSE(u.traffic);
  EXPECT_LE(folded->second, Clock::now());
  // Taken means emptied.
  EXPECT_FALSE(s.take_update());
}

TEST(SessionTest, PublishReachesLiveSinksOnly) {
  Session s("s1-test", 1, config(sim::Mode::kRealtime), {}, [] {});
  const auto kept = std::make_shared<CountingSink>();
  auto dropped = std::make_shared<CountingSink>();
  s.add_sink(kept);
  s.add_sink(dropped);
  dropped.reset();  // a reader that went away: the session holds it weakly
  s.publish(std::make_shared<EncodedFrame>());
  EXPECT_EQ(kept->frames, 1);
}

TEST(SessionTest, FrameNumbersCountUpFromOne) {
  Session s("s1-test", 1, config(sim::Mode::kRealtime), {}, [] {});
  EXPECT_EQ(s.begin_frame(), 1u);
  EXPECT_EQ(s.begin_frame(), 2u);
  EXPECT_EQ(s.frames_rendered(), 2u);
}

}  // namespace
}  // namespace downpour::session
