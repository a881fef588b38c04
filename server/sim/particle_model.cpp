#include "server/sim/particle_model.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "server/sim/drop_physics.hpp"

namespace downpour::sim {
namespace {

constexpr int kRepulsionIterations = 3;  // at most, per step; stops once nothing overlaps

glm::dvec2 direction(float angle_rad) { return {std::cos(angle_rad), std::sin(angle_rad)}; }
glm::dvec2 left_normal(glm::dvec2 d) { return {-d.y, d.x}; }

}  // namespace

ParticleModel::ParticleModel(const WaterConfig& config)
    : config_(config), particle_mass_(drop_mass_mg(config.particle_radius_mm)) {}

double ParticleModel::mass() const {
  double m = 0.0;
  for (const Particle& p : particles_) m += p.mass;
  return m;
}

// Pairwise repulsion through a spatial hash: grid cells of one particle diameter, hashed into a
// table about twice the particle count, so the cost follows the particles, not the glass. The
// iterations work on float copies of the positions sorted by bucket (a counting sort, so the order
// and the result are deterministic): a bucket's particles are one contiguous run.
void ParticleModel::repel() {
  const WaterConfig& w = config_;
  const float touch = static_cast<float>(2.0 * w.particle_radius_mm);
  const float push = static_cast<float>(0.5 + w.penalty);  // half the overlap, plus the penalty
  const std::uint32_t count = static_cast<std::uint32_t>(particles_.size());
  if (count < 2) return;
  std::uint32_t buckets = 64;
  while (buckets < 2 * count) buckets *= 2;
  const std::uint32_t mask = buckets - 1;
  const float inv_touch = 1.0f / touch;
  auto bucket_of = [&](int cu, int cv) {
    return (static_cast<std::uint32_t>(cu) * 73856093u ^
            static_cast<std::uint32_t>(cv) * 19349663u) &
           mask;
  };
  hash_ids_.resize(count);
  hash_pos_.resize(count);
  hash_cell_.resize(count);
  // The particles sorted by bucket once per step: within a step they move by a fraction of their
  // size, and a pair that slips out of each other's 3 x 3 cells is found at the next step.
  hash_start_.assign(buckets + 1, 0u);
  for (std::uint32_t i = 0; i < count; ++i) {
    const glm::dvec2 p = particles_[i].pos;
    const glm::ivec2 c(static_cast<int>(std::floor(static_cast<float>(p.x) * inv_touch)),
                       static_cast<int>(std::floor(static_cast<float>(p.y) * inv_touch)));
    hash_cell_[i] = c;
    ++hash_start_[bucket_of(c.x, c.y) + 1];
  }
  for (std::uint32_t b = 1; b <= buckets; ++b) hash_start_[b] += hash_start_[b - 1];
  hash_fill_.assign(hash_start_.begin(), hash_start_.end() - 1);
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint32_t slot = hash_fill_[bucket_of(hash_cell_[i].x, hash_cell_[i].y)]++;
    hash_ids_[slot] = i;
    hash_pos_[slot] = glm::vec2(particles_[i].pos);
  }
  // The buckets of each particle's 3 x 3 cells, without repeats (hash collisions).
  hash_neighbours_.resize(static_cast<std::size_t>(count) * 9);
  hash_neighbour_count_.resize(count);
  for (std::uint32_t a = 0; a < count; ++a) {
    const glm::ivec2 c = hash_cell_[hash_ids_[a]];
    std::uint32_t* seen = &hash_neighbours_[static_cast<std::size_t>(a) * 9];
    int seen_count = 0;
    for (int dv = -1; dv <= 1; ++dv) {
      for (int du = -1; du <= 1; ++du) {
        const std::uint32_t b = bucket_of(c.x + du, c.y + dv);
        if (std::find(seen, seen + seen_count, b) == seen + seen_count) seen[seen_count++] = b;
      }
    }
    hash_neighbour_count_[a] = static_cast<std::uint8_t>(seen_count);
  }

  for (int iteration = 0; iteration < kRepulsionIterations; ++iteration) {
    bool overlapped = false;
    for (std::uint32_t a = 0; a < count; ++a) {
      const std::uint32_t* neighbours = &hash_neighbours_[static_cast<std::size_t>(a) * 9];
      for (int n = 0; n < hash_neighbour_count_[a]; ++n) {
        const std::uint32_t b = neighbours[n];
        for (std::uint32_t k = std::max(hash_start_[b], a + 1); k < hash_start_[b + 1]; ++k) {
          const glm::vec2 delta = hash_pos_[k] - hash_pos_[a];
          const float dist2 = glm::dot(delta, delta);
          if (dist2 >= touch * touch) continue;
          const float dist = std::sqrt(dist2);
          // Coincident particles part along a direction that depends only on their ids.
          const float angle =
              static_cast<float>(hash_ids_[a]) * 2.399f + static_cast<float>(hash_ids_[k]);
          const glm::vec2 dir =
              dist > 1e-6f ? delta / dist : glm::vec2(std::cos(angle), std::sin(angle));
          const glm::vec2 move = (push * (touch - dist)) * dir;
          hash_pos_[a] -= move;
          hash_pos_[k] += move;
          overlapped = true;
        }
      }
    }
    if (!overlapped) break;
  }
  for (std::uint32_t a = 0; a < count; ++a) {
    glm::dvec2& p = particles_[hash_ids_[a]].pos;
    const glm::dvec2 moved(hash_pos_[a]);
    if (moved != glm::dvec2(glm::vec2(p))) p = moved;  // untouched ones keep their precision
  }
}

bool ParticleModel::in_region(glm::dvec2 p, const std::array<BladePose, 2>& blades) const {
  const WaterConfig& w = config_;
  const double margin = w.region_particle_diameters * 2.0 * w.particle_radius_mm;
  for (const BladePose& b : blades) {
    const glm::dvec2 d = direction(b.angle_rad);
    const glm::dvec2 rel = p - glm::dvec2(b.pivot_mm);
    const double along = glm::dot(d, rel), across = glm::dot(left_normal(d), rel);
    if (along >= 0.0 && along <= b.length_mm && std::abs(across) <= 0.5 * b.width_mm + margin)
      return true;
  }
  return false;
}

}  // namespace downpour::sim
