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
  const sim::SceneState dry = [&] {
    sim::SceneState s = wet;
    s.windshield = sim::WindshieldState{};
    return s;
  }();
  std::vector<ViewCost> costs;
  {
    auto renderer = render::Renderer::create({});
    for (const NamedView& v : views) {
      ViewCost cost;
      cost.name = v.name;
      cost.width = v.spec.width;
      cost.height = v.spec.height;
      for (const sim::SceneState* scene : {&wet, &dry}) {
        std::vector<double> ms, cpu_ms;
        for (int i = 0; i < frames + kWarmUp; ++i) {
          const double c0 = cpu_time_ms();
          const auto t0 = std::chrono::steady_clock::now();
          render::render_image(*renderer, v.spec, *scene);
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
  for (std::size_t k = 0; k < views.size(); ++k) {
    std::map<std::string, std::vector<double>> passes;
    std::vector<std::string> order;
    for (int i = 0; i < frames + kWarmUp; ++i) {
      render::render_image(*renderer, views[k].spec, wet);
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
