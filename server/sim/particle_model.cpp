#include "server/sim/particle_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "server/sim/drop_physics.hpp"

namespace downpour::sim {
namespace {

// At most, per step; stops once nothing overlaps. Once the blades no longer set what they push on
// one line (blade_sweep.cpp; measured with a first version that kept each particle's gap ahead of
// the blade) a third did not show in pictures of a wipe, and its cost did: behind a truck after
// 120 s, the step's tick p90 8.5-9.3 ms with two against 10.2-12.2 with three. (On a loaded glass
// two leave more overlap than three: a review's simulated 100 mm/h, the p90 of a step's summed
// overlaps 42,100 diameters against 39,000.)
constexpr int kRepulsionIterations = 2;

// The lanes set in a 4-bit mask (x86-64's baseline has no popcnt instruction: the builtin would
// be a call to libgcc).
constexpr int kLanesSet[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};

// How two particles that touch part.
struct Parting {
  float touch;               // their distance apart when they just touch, mm
  float push;                // each moves this times the overlap
  const std::uint32_t* ids;  // the particles' ids in sorted order
};

// Particle a, at p, and each of the particles [k, end) (later in the sorted order, at x, y) that
// touches it part, as if all those pairs parted at once, each by its overlap from where p is now.
// Each k moves at once; a's moves are summed into `moved`. Returns how many touched.
inline int part_from(float* x, float* y, std::uint32_t a, glm::vec2 p, std::uint32_t k,
                     std::uint32_t end, const Parting& parting, glm::vec2& moved) {
  // Coincident particles part along a direction that depends only on their ids.
  auto coincident = [&](std::uint32_t k) {
    const float angle =
        static_cast<float>(parting.ids[a]) * 2.399f + static_cast<float>(parting.ids[k]);
    return glm::vec2(std::cos(angle), std::sin(angle));
  };
  const float touch2 = parting.touch * parting.touch;
  int touched = 0;
#if defined(__SSE2__)
  // Four candidates at a time: most do not touch, and those that do no longer wait on each other.
  const __m128 px = _mm_set1_ps(p.x), py = _mm_set1_ps(p.y);
  const __m128 limit = _mm_set1_ps(touch2), touch = _mm_set1_ps(parting.touch);
  const __m128 push = _mm_set1_ps(parting.push), apart = _mm_set1_ps(1e-6f);
  const __m128i lane = _mm_set_epi32(3, 2, 1, 0);
  __m128 sum_x = _mm_setzero_ps(), sum_y = _mm_setzero_ps();
  for (; k < end; k += 4) {
    const __m128 xs = _mm_loadu_ps(x + k), ys = _mm_loadu_ps(y + k);
    const __m128 dx = _mm_sub_ps(xs, px), dy = _mm_sub_ps(ys, py);
    const __m128 dist2 = _mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy));
    const __m128 within =
        _mm_castsi128_ps(_mm_cmplt_epi32(lane, _mm_set1_epi32(static_cast<std::int32_t>(end - k))));
    const __m128 touching = _mm_and_ps(_mm_cmplt_ps(dist2, limit), within);
    const int touching_lanes = _mm_movemask_ps(touching);
    if (touching_lanes == 0) continue;
    touched += kLanesSet[touching_lanes];
    const __m128 dist = _mm_sqrt_ps(dist2);
    const __m128 length = _mm_mul_ps(push, _mm_sub_ps(touch, dist));
    const __m128 per_mm = _mm_div_ps(length, dist);  // the move along each mm of the centre line
    __m128 move_x = _mm_and_ps(_mm_mul_ps(dx, per_mm), touching);
    __m128 move_y = _mm_and_ps(_mm_mul_ps(dy, per_mm), touching);
    if ((_mm_movemask_ps(_mm_cmpgt_ps(dist, apart)) & touching_lanes) != touching_lanes) {
      alignas(16) float mx[4], my[4], l[4], d[4];
      _mm_store_ps(mx, move_x);
      _mm_store_ps(my, move_y);
      _mm_store_ps(l, length);
      _mm_store_ps(d, dist);
      for (int i = 0; i < 4; ++i) {
        if ((touching_lanes >> i & 1) && !(d[i] > 1e-6f)) {
          const glm::vec2 move = l[i] * coincident(k + static_cast<std::uint32_t>(i));
          mx[i] = move.x;
          my[i] = move.y;
        }
      }
      move_x = _mm_load_ps(mx);
      move_y = _mm_load_ps(my);
    }
    // (Lanes past `end` add nothing: they are other particles, or the arrays' padding.)
    _mm_storeu_ps(x + k, _mm_add_ps(xs, move_x));
    _mm_storeu_ps(y + k, _mm_add_ps(ys, move_y));
    sum_x = _mm_add_ps(sum_x, move_x);
    sum_y = _mm_add_ps(sum_y, move_y);
  }
  // Each sum's four lanes: (x0 + x2) + (x1 + x3), and the same for y.
  const __m128 pairs = _mm_add_ps(_mm_unpacklo_ps(sum_x, sum_y), _mm_unpackhi_ps(sum_x, sum_y));
  const __m128 sums = _mm_add_ps(pairs, _mm_movehl_ps(pairs, pairs));
  moved += glm::vec2(_mm_cvtss_f32(sums), _mm_cvtss_f32(_mm_shuffle_ps(sums, sums, 1)));
#else
  for (; k < end; ++k) {
    const glm::vec2 delta = glm::vec2(x[k], y[k]) - p;
    const float dist2 = glm::dot(delta, delta);
    if (!(dist2 < touch2)) continue;
    ++touched;
    const float dist = std::sqrt(dist2);
    const float length = parting.push * (parting.touch - dist);
    const glm::vec2 move = dist > 1e-6f ? delta * (length / dist) : length * coincident(k);
    x[k] += move.x;
    y[k] += move.y;
    moved += move;
  }
#endif
  return touched;
}

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
// cell, and the three cells below it in the next row, which are contiguous runs of the sorted
// order, found once per step.
// In its turn a particle parts from all of its later neighbours that touch it at once
// (part_from): each pair's move is measured from where the particle stands then; each neighbour
// takes its move, and the particle the mean of its own. Later particles see where the earlier ones
// left them. Parted one pair after another, each pair waited on the last one's square root and
// division; at once, four pairs share them: 1.5 to 1.9 times as fast in a wiper's pile of 3,200
// to 4,100 particles. (Summed rather than averaged, a particle pressed by several neighbours
// overshot: its largest move in a step doubled, and the blades left arcs of droplets behind.)
// After a step's iterations (three, then) the pile held less overlap than one pair at a time
// left: the overlaps' sum, in diameters, 686 against 748, of 1,379 before the step.
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
  // The positions in sorted order, as floats, with room for a last group of four.
  sorted_key_.resize(count);
  sorted_x_.assign(count + 4, 0.0f);
  sorted_y_.assign(count + 4, 0.0f);
  float* const x = sorted_x_.data();
  float* const y = sorted_y_.data();
  for (std::uint32_t a = 0; a < count; ++a) {
    sorted_key_[a] = sort_key_[sort_ids_[a]];
    x[a] = static_cast<float>(particles_[sort_ids_[a]].pos.x);
    y[a] = static_cast<float>(particles_[sort_ids_[a]].pos.y);
  }
  const std::uint64_t* const keys = sorted_key_.data();
  const Parting parting{touch, push, sort_ids_.data()};
  // Each particle's candidates, the same in every iteration: the rest of its row up to the end of
  // the next cell, and the three cells below (below-left to below-right). Cursors that only move
  // forward as a does find them.
  ranges_.resize(count);
  for (std::uint32_t a = 0, row_end = 0, below = 0, below_end = 0; a < count; ++a) {
    const std::uint64_t key = keys[a];
    const std::uint64_t first = key + width - 1, last = key + width + 1;
    while (row_end < count && keys[row_end] <= key + 1) ++row_end;
    while (below < count && keys[below] < first) ++below;
    below_end = std::max(below_end, below);
    while (below_end < count && keys[below_end] <= last) ++below_end;
    ranges_[a] = {row_end, below, below_end};
  }
  for (int iteration = 0; iteration < kRepulsionIterations; ++iteration) {
    bool overlapped = false;
    for (std::uint32_t a = 0; a < count; ++a) {
      const std::array<std::uint32_t, 3> r = ranges_[a];
      const glm::vec2 p(x[a], y[a]);
      glm::vec2 moved(0.0f);
      const int touching = part_from(x, y, a, p, a + 1, r[0], parting, moved) +
                           part_from(x, y, a, p, r[1], r[2], parting, moved);
      overlapped |= touching > 0;
      if (touching > 1) moved /= static_cast<float>(touching);
      x[a] = p.x - moved.x;
      y[a] = p.y - moved.y;
    }
    if (!overlapped) break;
  }
  for (std::uint32_t a = 0; a < count; ++a) {
    glm::dvec2& p = particles_[sort_ids_[a]].pos;
    const glm::dvec2 moved(x[a], y[a]);
    if (moved != glm::dvec2(glm::vec2(p))) p = moved;  // untouched ones keep their precision
  }
}

ParticleModel::Regions::Regions(const WaterConfig& w, const std::array<BladePose, 2>& blades) {
  const double margin = w.region_particle_diameters * 2.0 * w.particle_radius_mm;
  for (std::size_t k = 0; k < blades.size(); ++k) {
    const BladePose& b = blades[k];
    const glm::dvec2 d = blade_direction(b.angle_rad);
    regions_[k] = {glm::dvec2(b.pivot_mm), d, left_normal(d), b.length_mm,
                   0.5 * b.width_mm + margin};
  }
}

bool ParticleModel::Regions::contain(glm::dvec2 p) const {
  for (const Region& r : regions_) {
    const glm::dvec2 rel = p - r.pivot;
    const double along = glm::dot(r.along, rel), across = glm::dot(r.across, rel);
    if (along >= 0.0 && along <= r.length && std::abs(across) <= r.half_width) return true;
  }
  return false;
}

}  // namespace downpour::sim
