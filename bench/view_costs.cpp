#include "bench/view_costs.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <map>

#include "server/render/renderer.hpp"

namespace downpour::bench {
namespace {

// CPU time of the process (every llvmpipe thread): steadier than wall time on a busy machine.
double cpu_time_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

}  // namespace

double ViewCost::windshield_passes_ms() const {
  double sum = 0.0;
  for (const auto& [name, ms] : passes) {
    if (name.rfind("glass_", 0) == 0 || name == "windshield") sum += ms;
  }
  return sum;
}

std::vector<ViewCost> measure_views(const std::vector<NamedView>& views, const sim::SceneState& wet,
                                    int frames) {
  constexpr int kWarmUp = 2;
  constexpr double kTickS = 1.0 / 30.0;
  const sim::SceneState dry = [&] {
    sim::SceneState s = wet;
    s.windshield = sim::WindshieldState{};
    return s;
  }();
  std::vector<ViewCost> costs;
  {
    auto renderer = render::Renderer::create({});
    std::vector<std::uint8_t> pixels;
    for (const NamedView& v : views) {
      // A session of its own, as the server's: what it keeps from tick to tick stays.
      const auto session = renderer->open_session();
      ViewCost cost;
      cost.name = v.name;
      cost.width = v.spec.width;
      cost.height = v.spec.height;
      for (const sim::SceneState* scene : {&wet, &dry}) {
        std::vector<double> ms, cpu_ms;
        sim::SceneState frame = *scene;
        for (int i = 0; i < frames + kWarmUp; ++i) {
          // Each frame a tick later, as a session's are (what refreshes by the tick does).
          frame.sim_time_s = scene->sim_time_s + i * kTickS;
          const double c0 = cpu_time_ms();
          const auto t0 = std::chrono::steady_clock::now();
          renderer->finish(renderer->render(*session, 0, v.spec, frame), pixels);
          const auto t1 = std::chrono::steady_clock::now();
          if (i < kWarmUp) continue;
          ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
          cpu_ms.push_back(cpu_time_ms() - c0);
        }
        (scene == &wet ? cost.wet_ms : cost.dry_ms) = median(ms);
        (scene == &wet ? cost.wet_cpu_ms : cost.dry_cpu_ms) = median(cpu_ms);
      }
      costs.push_back(std::move(cost));
    }
  }
  auto renderer = render::Renderer::create({});
  renderer->set_profiling(true);
  std::vector<std::uint8_t> pixels;
  for (std::size_t k = 0; k < views.size(); ++k) {
    const auto session = renderer->open_session();
    std::map<std::string, std::vector<double>> passes;
    std::vector<std::string> order;
    sim::SceneState frame = wet;
    for (int i = 0; i < frames + kWarmUp; ++i) {
      frame.sim_time_s = wet.sim_time_s + i * kTickS;
      renderer->finish(renderer->render(*session, 0, views[k].spec, frame), pixels);
      if (i < kWarmUp) continue;
      for (const auto& p : renderer->last_pass_timings()) {
        if (!passes.count(p.name)) order.push_back(p.name);
        passes[p.name].push_back(p.ms);
      }
    }
    for (const std::string& name : order) costs[k].passes.emplace_back(name, median(passes[name]));
  }
  return costs;
}

}  // namespace downpour::bench
