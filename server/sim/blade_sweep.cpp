#include "server/sim/blade_sweep.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <tuple>
#include <vector>

#include <glm/geometric.hpp>

#include "server/sim/water_inputs.hpp"

namespace downpour::sim {

namespace {

// A convex polygon cut by half-planes: the box of a blade's step cut by its sweep's lines.
struct Outline {
  // A box cut four times has eight corners at most; the room to spare is for rounding.
  std::array<glm::dvec2, 16> corners;
  std::size_t count = 0;
  // The part where dot(normal, p) >= offset. (Left whole where rounding would make more corners
  // than there is room for: a polygon that holds the part holds what the part holds.)
  void keep_where(glm::dvec2 normal, double offset) {
    std::array<glm::dvec2, 16> kept;
    std::size_t n = 0;
    for (std::size_t k = 0; k < count; ++k) {
      if (n + 2 > kept.size()) return;
      const glm::dvec2 p = corners[k], q = corners[(k + 1) % count];
      const double fp = glm::dot(normal, p) - offset, fq = glm::dot(normal, q) - offset;
      if (fp >= 0.0) kept[n++] = p;
      if ((fp >= 0.0) != (fq >= 0.0)) kept[n++] = p + (q - p) * (fp / (fp - fq));
    }
    corners = kept;
    count = n;
  }
};

}  // namespace

BladeSweep::BladeSweep(const WaterConfig& config, std::uint64_t seed)
    : config_(config), random_(seed, 3) {}

void BladeSweep::sweep(const WaterInputs& in, MeshModel& mesh, ParticleModel& model) {
  const WaterConfig& w = config_;
  std::vector<ParticleModel::Particle>& particles = model.particles();
  const double particle_mass = model.particle_mass();
  const std::vector<MeshModel::Drop>& drops = mesh.drops();
  const double rp = w.particle_radius_mm;
  for (int b = 0; b < 2; ++b) {
    const BladePose& before = in.blades_before[b];
    const BladePose& after = in.blades_after[b];
    const double turn = after.angle_rad - before.angle_rad;
    if (turn == 0.0) continue;
    const double side = turn > 0.0 ? 1.0 : -1.0;
    const glm::dvec2 pivot(after.pivot_mm);
    const glm::dvec2 d0 = blade_direction(before.angle_rad), d1 = blade_direction(after.angle_rad);
    const glm::dvec2 n0 = side * left_normal(d0), n1 = side * left_normal(d1);
    const double half = 0.5 * after.width_mm, length = after.length_mm;
    auto swept = [&](glm::dvec2 p, double r, double* along) {
      const glm::dvec2 rel = p - pivot;
      *along = glm::dot(d1, rel);
      if (*along < 0.0 || *along > length) return false;
      return glm::dot(n0, rel) >= -half && glm::dot(n1, rel) < half + r;
    };
    double along;
    // The particles it reached, by strips a particle wide along it, each strip's in the order they
    // stood across it.
    swept_.clear();
    for (std::uint32_t i = 0; i < particles.size(); ++i) {
      if (!swept(particles[i].pos, rp, &along)) continue;
      // (Across the blade after the step: the order its edge meets them in, for any turn.)
      const double across = glm::dot(n1, particles[i].pos - pivot);
      swept_.push_back(
          {static_cast<std::int64_t>(std::floor(along / (2.0 * rp))), across, along, i});
    }
    std::sort(swept_.begin(), swept_.end(), [](const Swept& a, const Swept& b) {
      return std::tie(a.strip, a.across, a.index) < std::tie(b.strip, b.across, b.index);
    });
    // Each strip's stacked against the edge, the nearest touching it and each further one a
    // particle's width ahead of the last, as the blade pushing the first pushes the rest. (All on
    // the edge, as the paper has it, a fast blade set everything it passed in a step on one line,
    // 2 cm at mid-blade at 60 steps a second: a knot the repulsion could not untie.) A strip with
    // more particles than fit in the particles' region gathers its water into as many as fit: the
    // bead ahead of a blade is one body of water, and in a downpour a strip held 30 particles,
    // pressed 0.37 mm apart, whose repulsion was most of the step's time.
    // (The region reaches region_particle_diameters ahead of the edge: that many particles.)
    const std::size_t fit = static_cast<std::size_t>(std::max(w.region_particle_diameters, 1));
    bool gathered = false;
    for (std::size_t first = 0, end = 0; first < swept_.size(); first = end) {
      end = first;
      double water = 0.0;
      while (end < swept_.size() && swept_[end].strip == swept_[first].strip) {
        water += particles[swept_[end].index].mass;
        ++end;
      }
      const std::size_t kept = std::min(end - first, fit);
      for (std::size_t k = first; k < end; ++k) {
        ParticleModel::Particle& p = particles[swept_[k].index];
        if (k - first >= kept) {
          p.mass = -1.0;  // its water is in the strip's kept ones (removed below)
          gathered = true;
          continue;
        }
        p.pos = pivot + swept_[k].along * d1 +
                (half + rp + static_cast<double>(k - first) * 2.0 * rp) * n1;
        if (end - first > fit) p.mass = water / static_cast<double>(kept);
      }
    }
    if (gathered) {
      std::erase_if(particles, [](const ParticleModel::Particle& p) { return p.mass < 0.0; });
    }
    // The swept sector's bounding box (the arc between the tips bulges out to the tip of the
    // middle direction, reached at length / cos(half the turn)), for a quick rejection.
    const glm::dvec2 mid = blade_direction(0.5f * (before.angle_rad + after.angle_rad));
    const glm::dvec2 bulge = pivot + mid * (length / std::cos(0.5 * turn));
    const glm::dvec2 tip0 = pivot + d0 * length, tip1 = pivot + d1 * length;
    const glm::dvec2 lo = glm::min(glm::min(pivot, bulge), glm::min(tip0, tip1)) - half;
    const glm::dvec2 hi = glm::max(glm::max(pivot, bulge), glm::max(tip0, tip1)) + half;
    // The drops that can pass both tests are those whose centres lie in that box grown by the
    // largest radius and inside swept()'s four lines at that radius: a convex polygon, the box
    // cut by each line in turn. (A hair wider all round: the cells it reaches are a superset,
    // and each drop is tested as before, so the same drops are swept in the same order.)
    const double r_max = mesh.radius_bound() + 1e-6;
    Outline outline{{lo - r_max, glm::dvec2(hi.x + r_max, lo.y - r_max), hi + r_max,
                     glm::dvec2(lo.x - r_max, hi.y + r_max)},
                    4};
    // (A box at no finite place, from a turn of half a circle in a step, is left whole: the grid
    // then gives every drop, as the box rejects none.)
    if (std::isfinite(lo.x + lo.y + hi.x + hi.y + r_max)) {
      constexpr double kSlack = 1e-6;
      outline.keep_where(d1, glm::dot(d1, pivot) - kSlack);
      outline.keep_where(-d1, -glm::dot(d1, pivot) - length - kSlack);
      outline.keep_where(n0, glm::dot(n0, pivot) - half - kSlack);
      outline.keep_where(-n1, -glm::dot(n1, pivot) - half - r_max - kSlack);
    }
    mesh.drops_within(std::span(outline.corners.data(), outline.count), near_);
    for (const int i : near_) {
      const MeshModel::Drop& d = drops[i];
      if (!d.alive || d.pos.x < lo.x - d.radius || d.pos.y < lo.y - d.radius ||
          d.pos.x > hi.x + d.radius || d.pos.y > hi.y + d.radius ||
          !swept(d.pos, d.radius, &along)) {
        continue;
      }
      // Particles are made equal: the drop's water joins what the blade already carries, and whole
      // particles' worth of it come off as particles here (a tiny trail drop alone makes none).
      const double mass = d.mass;
      mesh.remove(i);
      if (particles.size() >= w.max_particles) {
        wiped_off_ += mass;
        continue;
      }
      carried_[b] += mass;
      const int count = static_cast<int>(std::floor(carried_[b] / particle_mass + 1e-9));
      carried_[b] = std::max(0.0, carried_[b] - count * particle_mass);
      for (int k = 0; k < count; ++k) {
        // One at the drop, the rest jittered about it, all ahead of the blade; overlaps resolve
        // through repulsion.
        const double jitter_along = k == 0 ? 0.0 : random_.uniform(-rp, rp);
        const double jitter_ahead = k == 0 ? 0.0 : random_.uniform(0.0, 2.0 * rp);
        particles.push_back({pivot + (along + jitter_along) * d1 + (half + rp + jitter_ahead) * n1,
                             particle_mass, 0.0});
      }
    }
  }
}

}  // namespace downpour::sim
