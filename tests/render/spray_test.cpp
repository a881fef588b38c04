// The spray (seed 001's screen-space liquid over seed 003's tire spray), measured on images: the
// smoothing of a body's depth against a surface of known normals (plane fitting against the
// bilateral filter near silhouettes); the CPU's and the GPU's maps of the parcels draw the same
// picture; behind a truck on a drenched road ROAD shows a mist that a dry road does not; goldens
// of spray behind a truck.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "server/render/cpu/spray_splat.hpp"
#include "tests/render/render_fixture.hpp"
#include "tests/support/spray_drive.hpp"

namespace downpour {
namespace {

using testing::RgbaImage;

class SprayRenderTest : public testing::RenderTest {
 protected:
  // The scene after a drive behind a truck at 25 m/s (the glass not simulated: the views see the
  // spray, not the water it leaves there).
  static sim::SceneState behind_truck(double road_mm, double seconds = 3.0) {
    testing::SprayDrive d;
    d.truck_gap_m = 22.0;
    d.road_water_m = road_mm * 1e-3;
    d.seconds = seconds;
    d.simulate_glass = false;
    return testing::drive(d).state();
  }
  static double luma(const RgbaImage& image, int x, int y) {
    const std::uint8_t* p = &image.pixels[(static_cast<std::size_t>(y) * image.width + x) * 4];
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
  }
  // The share of pixels in [x0, x1) x [y0, y1) whose luma differs by more than `by`.
  static double changed(const RgbaImage& a, const RgbaImage& b, int x0, int y0, int x1, int y1,
                        double by) {
    int n = 0, total = 0;
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        n += std::abs(luma(a, x, y) - luma(b, x, y)) > by;
        ++total;
      }
    }
    return static_cast<double>(n) / total;
  }
  static double stddev_luma(const RgbaImage& image, int x0, int y0, int x1, int y1) {
    double sum = 0.0, sum2 = 0.0;
    int n = 0;
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        const double l = luma(image, x, y);
        sum += l;
        sum2 += l * l;
        ++n;
      }
    }
    const double mean = sum / n;
    return std::sqrt(std::max(sum2 / n - mean * mean, 0.0));
  }
};

// Seed 001's claim: near silhouettes the bilateral filter bends the surface toward the viewer,
// plane fitting does not. A ball of 0.6 m made of 700 parcels of 8 cm, 4 m away; its true normal
// where each pixel's ray meets it. Mean angle errors of the normals from the depths (the neighbour
// on the side of the smaller step, as spray_shade.frag takes them), within 4 pixels of the
// silhouette and inside.
TEST_F(SprayRenderTest, PlaneFittingIsNoWorseThanBilateralNearSilhouettes) {
  constexpr int kW = 214, kH = 120;
  const glm::vec2 tan(0.5f, 0.5f * kH / kW);
  const glm::vec3 centre(0.1f, -0.05f, -4.0f);
  constexpr float kBall = 0.6f, kParcel = 0.08f;
  std::mt19937 random(7);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::vector<render::SprayBall> body, none;
  while (body.size() < 700) {
    glm::vec3 d(unit(random), unit(random), unit(random));
    if (glm::dot(d, d) > 1.0f || glm::dot(d, d) < 1e-4f) continue;
    d = glm::normalize(d);
    const float depth = 0.5f * (unit(random) + 1.0f) * 0.04f;  // just under the surface
    body.push_back({centre + d * (kBall - kParcel + 0.02f - depth), kParcel});
  }
  render::SprayDepthMaps maps;
  render::splat_depth({kW, kH, tan}, body, none, maps);
  std::vector<float> front(maps.depth.size());
  for (std::size_t i = 0; i < front.size(); ++i) front[i] = maps.depth[i].x;
  const float surface = kBall + 0.02f;  // the parcels' outer envelope

  auto ray = [&](int x, int y) {
    return glm::vec3(((x + 0.5f) / kW * 2.0f - 1.0f) * tan.x,
                     ((y + 0.5f) / kH * 2.0f - 1.0f) * tan.y, -1.0f);
  };
  auto valid = [](float z) { return z > 0.0f && z < 0.5f * render::kSprayFar; };
  auto at = [&](const std::vector<float>& z, int x, int y) {
    return x < 0 || y < 0 || x >= kW || y >= kH ? render::kSprayFar
                                                : z[static_cast<std::size_t>(y) * kW + x];
  };
  auto normal = [&](const std::vector<float>& z, int x, int y) {
    const float z0 = at(z, x, y);
    const glm::vec3 p0 = ray(x, y) * z0;
    auto side = [&](int dx, int dy) {
      const float a = at(z, x + dx, y + dy), b = at(z, x - dx, y - dy);
      const bool forward = valid(a) && (!valid(b) || std::abs(a - z0) < std::abs(b - z0));
      return forward ? ray(x + dx, y + dy) * a - p0
                     : p0 - ray(x - dx, y - dy) * (valid(b) ? b : z0);
    };
    glm::vec3 n = glm::normalize(glm::cross(side(1, 0), side(0, 1)));
    return n.z < 0.0f ? -n : n;
  };
  struct Errors {
    double edge = 0.0, inside = 0.0;
  };
  auto errors = [&](const std::vector<float>& z) {
    double edge = 0.0, inside = 0.0;
    int n_edge = 0, n_inside = 0;
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        if (!valid(at(front, x, y))) continue;
        // The truth: the ball's surface along the pixel's ray.
        const glm::vec3 d = ray(x, y);
        const float b = glm::dot(d, centre), dd = glm::dot(d, d);
        const float disc = b * b - dd * (glm::dot(centre, centre) - surface * surface);
        if (disc <= 0.0f) continue;
        const glm::vec3 hit = d * ((b - std::sqrt(disc)) / dd);
        const glm::vec3 truth = glm::normalize(hit - centre);
        const double angle =
            std::acos(std::clamp(static_cast<double>(glm::dot(normal(z, x, y), truth)), -1.0, 1.0));
        bool near_edge = false;
        for (int dy = -4; dy <= 4 && !near_edge; ++dy)
          for (int dx = -4; dx <= 4 && !near_edge; ++dx)
            near_edge = !valid(at(front, x + dx, y + dy));
        (near_edge ? edge : inside) += angle * 180.0 / M_PI;
        ++(near_edge ? n_edge : n_inside);
      }
    }
    EXPECT_GT(n_edge, 100);
    EXPECT_GT(n_inside, 100);
    return Errors{edge / std::max(n_edge, 1), inside / std::max(n_inside, 1)};
  };
  render::Renderer& r = renderer();
  std::vector<std::pair<const char*, Errors>> results;
  for (const render::SpraySmoothing s :
       {render::SpraySmoothing::kNone, render::SpraySmoothing::kPlaneFit,
        render::SpraySmoothing::kBilateral}) {
    r.set_spray_smoothing(s);
    results.emplace_back(render::spray_smoothing_name(s),
                         errors(r.smooth_spray_body(kW, kH, tan.x, tan.y, front)));
  }
  r.set_spray_smoothing(render::SpraySmoothing::kPlaneFit);
  for (const auto& [name, e] : results)
    std::printf("%-10s mean normal error: %.2f deg near the silhouette, %.2f inside\n", name,
                e.edge, e.inside);
  const Errors plane = results[1].second, bilateral = results[2].second, raw = results[0].second;
  EXPECT_LE(plane.edge, bilateral.edge);
  EXPECT_LT(plane.inside, raw.inside);  // it smooths the parcels' bumps
}

// The GPU's ray-cast squares and the CPU's splats make the same maps: the same picture, where the
// spray shows (the pixels it changes) and everywhere. The GPU draws first and again after the CPU,
// so that neither inherits the other's maps.
TEST_F(SprayRenderTest, TheCpuAndTheGpuDrawTheSameSpray) {
  const sim::SceneState scene = behind_truck(3.0, 2.0);
  ASSERT_TRUE(scene.spray && scene.spray->points.size() > 1000);
  const sim::ViewSpec spec = view_spec(sim::View::kRoad, 320, 180);
  render::Renderer& r = renderer();
  const bool was = r.spray_cpu_splat();
  r.set_spray_cpu_splat(false);
  render(spec, scene);
  r.set_spray_cpu_splat(true);
  const RgbaImage cpu = render(spec, scene);
  const auto drawn = r.last_spray_drawn();
  r.set_spray_cpu_splat(false);
  const RgbaImage gpu = render(spec, scene);
  r.set_spray_cpu_splat(was);
  sim::SceneState bare = scene;
  bare.spray.reset();
  const RgbaImage none = render(spec, bare);
  int shown = 0, differ = 0;
  for (int y = 0; y < 180; ++y) {
    for (int x = 0; x < 320; ++x) {
      if (std::abs(luma(cpu, x, y) - luma(none, x, y)) <= 2.0) continue;
      ++shown;
      differ += std::abs(luma(cpu, x, y) - luma(gpu, x, y)) > 12.0;
    }
  }
  const double db = testing::psnr(cpu, gpu);
  std::printf(
      "CPU against GPU maps: PSNR %.1f dB; of the %d pixels the spray changes, %.2f%% "
      "differ by more than 12 (%u body, %u spray parcels drawn)\n",
      db, shown, 100.0 * differ / std::max(shown, 1), drawn[0], drawn[1]);
  EXPECT_GT(drawn[1], 100u);
  EXPECT_GT(shown, 320 * 180 / 10);
  EXPECT_GT(db, 32.0);
  EXPECT_LT(differ, shown / 50);
}

// Behind the truck on a drenched road, ROAD shows a mist around it and behind it: the spray
// changes the pixels there and lowers their contrast. On a dry road there is no spray at all.
TEST_F(SprayRenderTest, RoadShowsMistBehindTheTruckOnADrenchedRoad) {
  const sim::ViewSpec spec = view_spec(sim::View::kRoad, 320, 180);
  // The middle of the view: the road ahead between the ego car and the truck, and the truck.
  const int x0 = 100, x1 = 220, y0 = 40, y1 = 110;
  for (const double road_mm : {0.8, 0.0}) {
    sim::SceneState scene = behind_truck(road_mm);
    const std::size_t parcels = scene.spray ? scene.spray->points.size() : 0;
    const RgbaImage with = render(spec, scene);
    scene.spray.reset();
    const RgbaImage without = render(spec, scene);
    const double share = changed(with, without, x0, y0, x1, y1, 4.0);
    const double contrast_with = stddev_luma(with, x0, y0, x1, y1);
    const double contrast_without = stddev_luma(without, x0, y0, x1, y1);
    std::printf(
        "road %.1f mm: %zu parcels; %.1f%% of the middle changed; luma %.1f against %.1f, "
        "contrast %.1f against %.1f\n",
        road_mm, parcels, 100.0 * share, testing::mean_luma(with, x0, y0, x1, y1),
        testing::mean_luma(without, x0, y0, x1, y1), contrast_with, contrast_without);
    if (road_mm > 0.0) {
      EXPECT_GT(share, 0.2);
      EXPECT_LT(contrast_with, contrast_without);
    } else {
      EXPECT_EQ(parcels, 0u);
      EXPECT_EQ(share, 0.0);
    }
  }
}

// No blocks in the spray: where it is thin (it changes a block of the picture by 1 to 40 levels of
// luma on average), the share of 8 x 8 blocks with an edge across which the spray's change steps by
// more than 10 levels while it changes smoothly beside the edge. Behind the truck at 25 m/s on a
// drenched road, COCKPIT and ROAD at 640 x 360 (the spray's layer is a third of that, its tiles 8
// layer pixels: 24 here, on block edges).
TEST_F(SprayRenderTest, ThinSprayHasNoBlocks) {
  const sim::SceneState scene = behind_truck(1.0);
  sim::SceneState bare = scene;
  bare.spray.reset();
  for (const sim::View view : {sim::View::kCockpit, sim::View::kRoad}) {
    const sim::ViewSpec spec = view_spec(view, 640, 360);
    const RgbaImage with = render(spec, scene), without = render(spec, bare);
    if (const char* dir = std::getenv("DOWNPOUR_TEST_IMAGES")) {
      const std::string name =
          std::string(dir) + "/spray_blocks_" + std::string(sim::view_name(view));
      testing::write_png(name + "_with.png", with);
      testing::write_png(name + "_without.png", without);
    }
    auto d = [&](int x, int y) { return luma(with, x, y) - luma(without, x, y); };
    // Across the edge between columns x - 1 and x over rows y0..y0+7: the mean step, and the mean
    // step one pixel to either side; not where the scene itself has an edge (the spray rightly
    // stops at a nearer object's outline: the roof liner's runs along a block's edge).
    auto edge = [&](bool vertical, int at, int from) {
      double step = 0.0, beside = 0.0, scene = 0.0;
      for (int k = from; k < from + 8; ++k) {
        auto v = [&](int i) { return vertical ? d(i, k) : d(k, i); };
        auto bare = [&](int i) { return vertical ? luma(without, i, k) : luma(without, k, i); };
        step += std::abs(v(at) - v(at - 1));
        beside += 0.5 * (std::abs(v(at + 1) - v(at)) + std::abs(v(at - 1) - v(at - 2)));
        scene += std::abs(bare(at) - bare(at - 1));
      }
      return step > 80.0 && step > 3.0 * beside && scene < 80.0;
    };
    int thin = 0, blocky = 0;
    for (int by = 1; by + 1 < 360 / 8; ++by) {
      for (int bx = 1; bx + 1 < 640 / 8; ++bx) {
        double mean = 0.0;
        for (int y = 8 * by; y < 8 * by + 8; ++y)
          for (int x = 8 * bx; x < 8 * bx + 8; ++x) mean += std::abs(d(x, y));
        mean /= 64.0;
        if (mean < 1.0 || mean > 40.0) continue;
        ++thin;
        const bool step = edge(true, 8 * bx, 8 * by) || edge(true, 8 * bx + 8, 8 * by) ||
                          edge(false, 8 * by, 8 * bx) || edge(false, 8 * by + 8, 8 * bx);
        if (step && std::getenv("DOWNPOUR_TEST_IMAGES"))
          std::printf("  a step at block (%d, %d)\n", 8 * bx, 8 * by);
        blocky += step;
      }
    }
    const double share = thin > 0 ? static_cast<double>(blocky) / thin : 0.0;
    std::printf("%s: %d blocks of thin spray, %d with a step at an edge (%.2f%%)\n",
                std::string(sim::view_name(view)).c_str(), thin, blocky, 100.0 * share);
    EXPECT_GT(thin, 50) << "the spray shows";
    EXPECT_LT(share, 0.01) << sim::view_name(view);
  }
}

// At night the spray behind the truck glows in the ego car's dipped beams: from the driver's seat,
// the spray in the beams (the lower middle of the view, over the road between the car and the
// truck) is brighter with them than without, by more than the road under it.
TEST_F(SprayRenderTest, TheBeamsLightTheSprayAtNight) {
  const sim::ViewSpec spec = view_spec(sim::View::kCockpit, 320, 180);
  const int x0 = 120, x1 = 200, y0 = 80, y1 = 100;
  sim::SceneState scene = behind_truck(1.0);
  scene.weather.sun_altitude_deg = -20.0;
  scene.weather.fog_density = 0.0;
  scene.rain.drops.clear();
  scene.rain.splashes.clear();
  const auto lit = [&](sim::Headlights beams, bool spray) {
    sim::SceneState s = scene;
    s.ego_lights.headlights = beams;
    if (!spray) s.spray.reset();
    return testing::mean_luma(render(spec, s), x0, y0, x1, y1);
  };
  const double spray_on = lit(sim::Headlights::kLow, true),
               spray_off = lit(sim::Headlights::kOff, true);
  const double road_on = lit(sim::Headlights::kLow, false),
               road_off = lit(sim::Headlights::kOff, false);
  std::printf("with the spray: luma %.3f in the beams, %.3f without; the road alone %.3f, %.3f\n",
              spray_on, spray_off, road_on, road_off);
  EXPECT_GT(spray_on - spray_off, 0.05);
  EXPECT_GT(spray_on - spray_off, road_on - road_off) << "the spray catches the beams";
}

// Spray behind a truck on a road with puddles, from the chase camera and from the driver's seat
// (dry glass, so that the spray is what is seen).
// The flooded road mirrors the spray: from the driver's seat behind the truck on 3 mm of water,
// the road ahead mirrors the truck, and the spray's clouds over it fade its mirror image as they
// fade the truck (lighter: the clouds scatter the sky's light). Without the clouds in the mirror,
// its image of the truck stands dark and clear under the haze.
TEST_F(SprayRenderTest, TheFloodedRoadMirrorsTheSpray) {
  const sim::SceneState scene = behind_truck(3.0);
  const sim::ViewSpec spec = view_spec(sim::View::kCockpit, 320, 180);
  render::Renderer& r = renderer();
  r.set_spray_in_mirror(false);
  const RgbaImage without = render(spec, scene);
  r.set_spray_in_mirror(true);
  const RgbaImage with = render(spec, scene);
  testing::write_png(::testing::TempDir() + "spray_mirror_without.png", without);
  testing::write_png(::testing::TempDir() + "spray_mirror_with.png", with);
  // The view's lower half: the road up to the bonnet.
  double brighter = 0.0;
  int changed = 0, n = 0;
  for (int y = spec.height / 2; y < spec.height; ++y) {
    for (int x = 0; x < spec.width; ++x, ++n) {
      const double d = luma(with, x, y) - luma(without, x, y);
      brighter += d;
      changed += std::abs(d) > 2.0;
    }
  }
  std::printf(
      "the view's lower half with the spray in the road's mirror: %d of %d pixels changed by "
      "more than 2 levels, mean %+.2f\n",
      changed, n, brighter / n);
  EXPECT_GT(changed, 200);
  EXPECT_GT(brighter / n, 0.15);
}

TEST_F(SprayRenderTest, GoldenSprayBehindATruck) {
  const sim::SceneState scene = behind_truck(3.0);
  expect_golden(render(view_spec(sim::View::kRoad, 320, 180), scene), "spray_ROAD.png");
  expect_golden(render(view_spec(sim::View::kCockpit, 320, 180), scene), "spray_COCKPIT.png");
}

}  // namespace
}  // namespace downpour
