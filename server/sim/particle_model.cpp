#include "server/sim/particle_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "server/sim/drop_physics.hpp"

namespace downpour::sim {
namespace {

constexpr int kRepulsionIterations = 3;  // at most, per step; stops once nothing overlaps

}  // namespace

ParticleModel::ParticleModel(const WaterConfig& config)
    : config_(config), particle_mass_(drop_mass_mg(config.particle_radius_mm)) {}

double ParticleModel::mass() const {
  double m = 0.0;
  for (const Particle& p : particles_) m += p.mass;
  return m;
}

// Pairwise repulsion over a grid of cells one particle diameter wide. Once per step the particles
// are sorted by cell, row by row (a radix sort on the cell's key, so the order and the result are
// deterministic), and the iterations work on float copies of the positions in that order. A pair
// is then tested once, from its earlier particle: the rest of that particle's row up to the next
// cell, and the three cells below it in the next row. The start of those three in the sorted list
// only moves forward as the particle does, so one cursor finds it.
void ParticleModel::repel() {
  const WaterConfig& w = config_;
  const float touch = static_cast<float>(2.0 * w.particle_radius_mm);
  const float push = static_cast<float>(0.5 + w.penalty);  // half the overlap, plus the penalty
  const std::uint32_t count = static_cast<std::uint32_t>(particles_.size());
  if (count < 2) return;
  const float inv_touch = 1.0f / touch;
  sort_cell_.resize(count);
  glm::ivec2 lo(std::numeric_limits<int>::max()), hi(std::numeric_limits<int>::min());
  for (std::uint32_t i = 0; i < count; ++i) {
    const glm::dvec2 p = particles_[i].pos;
    const glm::ivec2 c(static_cast<int>(std::floor(static_cast<float>(p.x) * inv_touch)),
                       static_cast<int>(std::floor(static_cast<float>(p.y) * inv_touch)));
    sort_cell_[i] = c;
    lo = glm::min(lo, c);
    hi = glm::max(hi, c);
  }
  // Key = row * width + column, with a free column on each side so that a cell's neighbours
  // across never wrap into the next row.
  const std::uint64_t width = static_cast<std::uint64_t>(hi.x - lo.x) + 3;
  sort_key_.resize(count);
  sort_ids_.resize(count);
  std::uint64_t max_key = 0;
  for (std::uint32_t i = 0; i < count; ++i) {
    const glm::ivec2 c = sort_cell_[i] - lo;
    sort_key_[i] = static_cast<std::uint64_t>(c.y) * width + static_cast<std::uint64_t>(c.x) + 1;
    max_key = std::max(max_key, sort_key_[i]);
    sort_ids_[i] = i;
  }
  // LSD radix sort of the ids by key, 11 bits a pass (two passes for any windshield).
  constexpr int kDigitBits = 11;
  constexpr std::uint32_t kDigits = 1u << kDigitBits;
  sort_scratch_.resize(count);
  sort_counts_.resize(kDigits + 1);
  for (int shift = 0; shift < 64 && (max_key >> shift) != 0; shift += kDigitBits) {
    std::fill(sort_counts_.begin(), sort_counts_.end(), 0u);
    for (std::uint32_t i = 0; i < count; ++i)
      ++sort_counts_[((sort_key_[sort_ids_[i]] >> shift) & (kDigits - 1)) + 1];
    for (std::uint32_t d = 1; d <= kDigits; ++d) sort_counts_[d] += sort_counts_[d - 1];
    for (std::uint32_t i = 0; i < count; ++i) {
      const std::uint32_t id = sort_ids_[i];
      sort_scratch_[sort_counts_[(sort_key_[id] >> shift) & (kDigits - 1)]++] = id;
    }
    sort_ids_.swap(sort_scratch_);
  }
  sorted_key_.resize(count);
  sorted_pos_.resize(count);
  for (std::uint32_t a = 0; a < count; ++a) {
    sorted_key_[a] = sort_key_[sort_ids_[a]];
    sorted_pos_[a] = glm::vec2(particles_[sort_ids_[a]].pos);
  }

  const float touch2 = touch * touch;
  auto part = [&](std::uint32_t a, std::uint32_t k) {
    const glm::vec2 delta = sorted_pos_[k] - sorted_pos_[a];
    const float dist2 = glm::dot(delta, delta);
    if (dist2 >= touch2) return false;
    const float dist = std::sqrt(dist2);
    // Coincident particles part along a direction that depends only on their ids.
    const float angle =
        static_cast<float>(sort_ids_[a]) * 2.399f + static_cast<float>(sort_ids_[k]);
    const glm::vec2 dir = dist > 1e-6f ? delta / dist : glm::vec2(std::cos(angle), std::sin(angle));
    const glm::vec2 move = (push * (touch - dist)) * dir;
    sorted_pos_[a] -= move;
    sorted_pos_[k] += move;
    return true;
  };
  for (int iteration = 0; iteration < kRepulsionIterations; ++iteration) {
    bool overlapped = false;
    std::uint32_t below = 0;  // the first particle at or after the cell below-left of a's
    for (std::uint32_t a = 0; a < count; ++a) {
      const std::uint64_t key = sorted_key_[a];
      for (std::uint32_t k = a + 1; k < count && sorted_key_[k] <= key + 1; ++k)
        overlapped |= part(a, k);
      const std::uint64_t first = key + width - 1, last = key + width + 1;
      while (below < count && sorted_key_[below] < first) ++below;
      for (std::uint32_t k = below; k < count && sorted_key_[k] <= last; ++k)
        overlapped |= part(a, k);
    }
    if (!overlapped) break;
  }
  for (std::uint32_t a = 0; a < count; ++a) {
    glm::dvec2& p = particles_[sort_ids_[a]].pos;
    const glm::dvec2 moved(sorted_pos_[a]);
    if (moved != glm::dvec2(glm::vec2(p))) p = moved;  // untouched ones keep their precision
  }
}

bool ParticleModel::in_region(glm::dvec2 p, const std::array<BladePose, 2>& blades) const {
  const WaterConfig& w = config_;
  const double margin = w.region_particle_diameters * 2.0 * w.particle_radius_mm;
  for (const BladePose& b : blades) {
    const glm::dvec2 d = blade_direction(b.angle_rad);
    const glm::dvec2 rel = p - glm::dvec2(b.pivot_mm);
    const double along = glm::dot(d, rel), across = glm::dot(left_normal(d), rel);
    if (along >= 0.0 && along <= b.length_mm && std::abs(across) <= 0.5 * b.width_mm + margin)
      return true;
  }
  return false;
}

}  // namespace downpour::sim
