#include "server/session/admission.hpp"

#include <gtest/gtest.h>

#include "server/session/session_registry.hpp"

namespace downpour::session {
namespace {

SessionConfig views(sim::Mode mode, double fps, std::initializer_list<std::pair<int, int>> sizes) {
  SessionConfig c;
  c.mode = mode;
  c.fps = fps;
  for (const auto& [w, h] : sizes) c.views.push_back(sim::view_spec(sim::View::kCockpit, w, h));
  return c;
}

TEST(AdmissionTest, CostIsPixelsTimesRateOverTheViewsAndLockstepCountsItsExpectedRate) {
  const SessionCost rt = estimate_cost(views(sim::Mode::kRealtime, 30.0, {{640, 360}, {320, 180}}));
  EXPECT_DOUBLE_EQ(rt.pixel_rate, (640.0 * 360 + 320.0 * 180) * 30.0);
  EXPECT_DOUBLE_EQ(rt.memory_bytes,
                   kBytesPerSession + (640.0 * 360 + 320.0 * 180) * kBytesPerViewPixel);
  const SessionCost ls = estimate_cost(views(sim::Mode::kLockstep, 120.0, {{1280, 720}}));
  EXPECT_DOUBLE_EQ(ls.pixel_rate, 1280.0 * 720 * 120.0);  // the rate its client said it steps at
  const SessionCost none = estimate_cost(views(sim::Mode::kLockstep, 0.0, {{1280, 720}}));
  EXPECT_DOUBLE_EQ(none.pixel_rate, 1280.0 * 720 * kLockstepNominalFps);
  // Ground truth holds more per pixel.
  SessionConfig truth = views(sim::Mode::kLockstep, 0.0, {{1280, 720}});
  truth.views[0].outputs.depth = true;
  EXPECT_DOUBLE_EQ(estimate_cost(truth).memory_bytes,
                   none.memory_bytes + 1280.0 * 720 * kBytesPerGroundTruthPixel);
}

TEST(AdmissionTest, RefusalNamesTheBudgetAndWhatIsFree) {
  const AdmissionBudget budget{10e6, 100.0 * 1024 * 1024};
  EXPECT_EQ(admission_refusal(budget, {}, {9e6, 50e6}), "");
  // Alone on an empty server, a session passes the pixel rate (it slows only itself), not memory.
  EXPECT_EQ(admission_refusal(budget, {}, {62e6, 50e6}), "");
  EXPECT_NE(admission_refusal(budget, {}, {62e6, 500e6}).find("memory"), std::string::npos);
  const std::string rate = admission_refusal(budget, {4e6, 0.0}, {7e6, 0.0});
  EXPECT_NE(rate.find("pixel rate"), std::string::npos) << rate;
  EXPECT_NE(rate.find("7.0 Mpx/s"), std::string::npos) << rate;
  EXPECT_NE(rate.find("6.0 of the server's 10.0"), std::string::npos) << rate;
  const std::string memory =
      admission_refusal(budget, {0.0, 60.0 * 1024 * 1024}, {1e6, 50.0 * 1024 * 1024});
  EXPECT_NE(memory.find("memory"), std::string::npos) << memory;
  EXPECT_NE(memory.find("50 MiB and 40 of the server's 100 MiB"), std::string::npos) << memory;
  EXPECT_EQ(admission_refusal({}, {1e12, 1e12}, {1e12, 1e12}), "");  // no budgets
}

TEST(AdmissionTest, TheRegistryRefusesWhatWouldPassABudgetAndAdmitsItOnceRoomIsFreed) {
  SessionRegistry registry(8, [] {});
  registry.set_budget({15e6, 0.0});
  const auto demo = views(sim::Mode::kRealtime, 30.0, {{640, 360}});  // 6.9 Mpx/s
  const auto a = registry.create(demo, {});
  const auto b = registry.create(demo, {});
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  std::string why;
  EXPECT_EQ(registry.create(demo, {}, &why), nullptr);
  EXPECT_NE(why.find("pixel rate"), std::string::npos) << why;
  EXPECT_NEAR(registry.cost_in_use().pixel_rate, 2 * 640.0 * 360 * 30, 1.0);
  // 8 sessions of 4 views at 3840x2160 and 120 fps would pass any budget this machine can keep.
  const auto heavy =
      views(sim::Mode::kRealtime, 120.0, {{3840, 2160}, {3840, 2160}, {3840, 2160}, {3840, 2160}});
  EXPECT_EQ(registry.create(heavy, {}, &why), nullptr);
  ASSERT_TRUE(registry.close(a->id()));
  EXPECT_NE(registry.create(demo, {}), nullptr);
  // The session limit says so too.
  SessionRegistry one(1, [] {});
  ASSERT_NE(one.create(demo, {}), nullptr);
  EXPECT_EQ(one.create(demo, {}, &why), nullptr);
  EXPECT_NE(why.find("--max-sessions"), std::string::npos) << why;
}

}  // namespace
}  // namespace downpour::session
