#include "server/session/session_registry.hpp"

#include <atomic>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace downpour::session {
namespace {

class CountingSink : public FrameSink {
 public:
  void on_frame(const FramePtr&) override { ++frames; }
  void on_session_closed() override { ++closed; }
  int frames = 0;
  int closed = 0;
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
    EXPECT_TRUE(o.frames.empty());
  }
  EXPECT_EQ(sink->closed, 1);
  EXPECT_EQ(removed_sink->closed, 0);
  EXPECT_FALSE(s->pop_job());

  // Closing again is a no-op; later calls are refused; a late sink hears at once.
  s->close();
  EXPECT_EQ(outcomes.size(), 3u);
  EXPECT_EQ(sink->closed, 1);
  EXPECT_EQ(s->submit_step({}, 0.1, [](StepOutcome) {}), Session::Submit::kClosed);
  EXPECT_EQ(s->post_update({}), Session::Submit::kClosed);
  const auto late = std::make_shared<CountingSink>();
  s->add_sink(late);
  EXPECT_EQ(late->closed, 1);
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
  EXPECT_EQ(s.post_update({}), Session::Submit::kFull);
  // Popping one makes room for one.
  const auto first = s.pop_job();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->dt_s, 0.1);
  EXPECT_TRUE(first->done);
  EXPECT_EQ(s.post_update({}), Session::Submit::kQueued);
  EXPECT_EQ(s.post_update({}), Session::Submit::kFull);
  const auto second = s.pop_job();
  ASSERT_TRUE(second);
  EXPECT_EQ(second->dt_s, 0.0);
  EXPECT_FALSE(second->done);  // an update-only job
  s.close();
  EXPECT_EQ(failed, static_cast<int>(Session::kMaxQueuedJobs / 2) - 1);
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
