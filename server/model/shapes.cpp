#include "server/model/shapes.hpp"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "server/model/materials.hpp"
#include "server/model/vehicle_model.hpp"

namespace downpour::model {

namespace {

constexpr float kPi = 3.14159265f;

// Samples across one axis of a rounded box's face, half-extent h, radius r: the core's two ends
// and `segments` steps of the rounding beyond each (its first half: the next face has the rest).
std::vector<float> face_samples(float h, float r, int segments) {
  std::vector<float> s;
  for (int k = segments; k >= 1; --k)
    s.push_back(-(h - r) - r * std::tan(static_cast<float>(k) * 0.25f * kPi / segments));
  s.push_back(-(h - r));
  if (h - r > 1e-5f) s.push_back(h - r);
  for (int k = 1; k <= segments; ++k)
    s.push_back((h - r) + r * std::tan(static_cast<float>(k) * 0.25f * kPi / segments));
  return s;
}

float signed_pow(float c, float e) { return std::copysign(std::pow(std::abs(c), e), c); }

}  // namespace

void add_rounded_box(render::MeshData& m, const glm::vec3& lo, const glm::vec3& hi, float radius,
                     Look look, glm::vec2 taper, int segments) {
  const glm::vec3 centre = 0.5f * (lo + hi), half = 0.5f * (hi - lo);
  const float r = std::clamp(radius, 0.0f, std::min({half.x, half.y, half.z}));
  const glm::vec3 core = half - glm::vec3(r);
  const glm::vec2 uv(look.material, look.colour);
  // Each face: its axis, and the two in-face axes (so that a x b is the outward normal).
  for (int axis = 0; axis < 3; ++axis) {
    for (float side : {-1.0f, 1.0f}) {
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      const std::vector<float> sa = face_samples(half[a], r, segments);
      const std::vector<float> sb = face_samples(half[b], r, segments);
      const auto first = static_cast<std::uint32_t>(m.vertices.size());
      for (float vb : sb) {
        for (float va : sa) {
          glm::vec3 p;
          p[axis] = side * half[axis];
          p[a] = va;
          p[b] = vb;
          const glm::vec3 q = glm::clamp(p, -core, core);
          const glm::vec3 d = p - q;
          // (A plain box, radius 0, has no rounding to take a normal from: its face's.)
          glm::vec3 face(0.0f);
          face[axis] = side;
          const glm::vec3 n = glm::length(d) > 0.0f ? glm::normalize(d) : face;
          glm::vec3 out = q + r * n;
          const float up = (out.z + half.z) / (2.0f * half.z);  // 0 at the bottom, 1 at the top
          out.x *= 1.0f + (taper.x - 1.0f) * up;
          out.y *= 1.0f + (taper.y - 1.0f) * up;
          m.add_vertex(centre + out, n, uv);
        }
      }
      const auto na = static_cast<std::uint32_t>(sa.size());
      for (std::uint32_t jb = 0; jb + 1 < sb.size(); ++jb) {
        for (std::uint32_t ja = 0; ja + 1 < na; ++ja) {
          const std::uint32_t i0 = first + jb * na + ja;
          if (side > 0.0f)
            m.add_quad(i0, i0 + 1, i0 + na + 1, i0 + na);
          else
            m.add_quad(i0, i0 + na, i0 + na + 1, i0 + 1);
        }
      }
    }
  }
}

void add_loft(render::MeshData& m, const std::vector<Section>& sections, int around,
              const LoftLook& look, bool upper_only) {
  const int n = static_cast<int>(sections.size());
  const int count = upper_only ? around / 2 + 1 : around;  // points a section
  std::vector<glm::vec3> p(static_cast<std::size_t>(n * count));
  auto at = [&](int i, int j) -> glm::vec3& { return p[static_cast<std::size_t>(i * count + j)]; };
  for (int i = 0; i < n; ++i) {
    const Section& s = sections[i];
    const float zc = upper_only ? s.z_bottom : 0.5f * (s.z_bottom + s.z_top);
    const float hh = s.z_top - zc;
    const float e = 0.12f + 0.88f * std::clamp(s.corner, 0.0f, 1.0f);
    for (int j = 0; j < count; ++j) {
      const float t =
          (upper_only ? 0.0f : -0.5f * kPi) + 2.0f * kPi * static_cast<float>(j) / around;
      const float cz = signed_pow(std::sin(t), e);
      const float scale = 1.0f + (s.top_scale - 1.0f) * std::max(cz, 0.0f);
      at(i, j) = {s.x, -s.half_width * scale * signed_pow(std::cos(t), e), zc + hh * cz};
    }
  }
  auto normal = [&](int i, int j) {
    const glm::vec3 along = at(std::min(i + 1, n - 1), j) - at(std::max(i - 1, 0), j);
    const int jn = upper_only ? std::min(j + 1, count - 1) : (j + 1) % count;
    const int jp = upper_only ? std::max(j - 1, 0) : (j + count - 1) % count;
    glm::vec3 nn = glm::cross(along, at(i, jn) - at(i, jp));
    const Section& s = sections[i];
    const glm::vec3 axis(s.x, 0.0f, upper_only ? s.z_bottom : 0.5f * (s.z_bottom + s.z_top));
    if (glm::dot(nn, at(i, j) - axis) < 0.0f) nn = -nn;
    const float len = glm::length(nn);
    return len > 0.0f ? nn / len : glm::vec3(0.0f, 0.0f, 1.0f);
  };
  auto quad = [&](const glm::vec3(&c)[4], const glm::vec3(&nn)[4], Look l) {
    const glm::vec2 uv(l.material, l.colour);
    const std::uint32_t a = m.add_vertex(c[0], nn[0], uv), b = m.add_vertex(c[1], nn[1], uv),
                        d = m.add_vertex(c[2], nn[2], uv), e = m.add_vertex(c[3], nn[3], uv);
    m.add_quad(a, b, d, e);
  };
  const int spans = upper_only ? count - 1 : count;
  for (int i = 0; i + 1 < n; ++i) {
    for (int j = 0; j < spans; ++j) {
      const int k = (j + 1) % count;
      const glm::vec3 c[4] = {at(i, j), at(i + 1, j), at(i + 1, k), at(i, k)};
      const glm::vec3 nn[4] = {normal(i, j), normal(i + 1, j), normal(i + 1, k), normal(i, k)};
      const glm::vec3 mid = 0.25f * (c[0] + c[1] + c[2] + c[3]);
      const glm::vec3 face = glm::normalize(nn[0] + nn[1] + nn[2] + nn[3]);
      quad(c, nn, look(i, j, mid, face));
    }
  }
  // The end caps: flat, fanned from each end section's middle.
  for (int end : {0, n - 1}) {
    const float sign = end == 0 ? -1.0f : 1.0f;
    const glm::vec3 nn(sign, 0.0f, 0.0f);
    glm::vec3 mid(0.0f);
    for (int j = 0; j < count; ++j) mid += at(end, j);
    mid /= static_cast<float>(count);
    const Look l = look(end == 0 ? -1 : n - 1, 0, mid, nn);
    const glm::vec2 uv(l.material, l.colour);
    const std::uint32_t centre = m.add_vertex(mid, nn, uv);
    for (int j = 0; j < spans; ++j) {
      const std::uint32_t a = m.add_vertex(at(end, j), nn, uv);
      const std::uint32_t b = m.add_vertex(at(end, (j + 1) % count), nn, uv);
      if (sign > 0.0f)
        m.add_triangle(centre, a, b);
      else
        m.add_triangle(centre, b, a);
    }
  }
}

void add_wheel(render::MeshData& m, const glm::vec3& c, float radius, float width, float outward,
               int spokes, float rim_colour, int around) {
  const int count = around;
  // (Cut coarsely, a wheel for the distance: its tread one band, no shoulders.)
  const float half = 0.5f * width, rim = 0.64f * radius,
              shoulder = around < 12 ? 0.0f : 0.04f * radius / 0.33f;
  const glm::vec2 tyre(material::kTyre, 0.0f);
  auto ring = [&](float angle, float r, float y) {
    return c + glm::vec3(r * std::sin(angle), y, r * std::cos(angle));
  };
  for (int k = 0; k < count; ++k) {
    const float a0 = 2.0f * kPi * k / count, a1 = 2.0f * kPi * (k + 1) / count;
    const glm::vec3 n0(std::sin(a0), 0.0f, std::cos(a0)), n1(std::sin(a1), 0.0f, std::cos(a1));
    // The tread, and the shoulders rounding into the walls.
    const float ys[4] = {-half, -half + shoulder, half - shoulder, half};
    const float rs[4] = {radius - shoulder, radius, radius, radius - shoulder};
    for (int s = shoulder > 0.0f ? 0 : 1; s < (shoulder > 0.0f ? 3 : 2); ++s) {
      const glm::vec3 tilt0(0.0f, s == 0 ? -0.7f : s == 2 ? 0.7f : 0.0f, 0.0f);
      const std::uint32_t a =
          m.add_vertex(ring(a0, rs[s], ys[s]), glm::normalize(n0 + tilt0), tyre);
      const std::uint32_t b =
          m.add_vertex(ring(a0, rs[s + 1], ys[s + 1]), glm::normalize(n0 + tilt0), tyre);
      const std::uint32_t d =
          m.add_vertex(ring(a1, rs[s + 1], ys[s + 1]), glm::normalize(n1 + tilt0), tyre);
      const std::uint32_t e =
          m.add_vertex(ring(a1, rs[s], ys[s]), glm::normalize(n1 + tilt0), tyre);
      m.add_quad(a, b, d, e);
    }
    // The walls, out to the rim, on both sides; the rim's face, spokes and gaps, on the outer
    // side, and a dark disc on the inner.
    for (float side : {-1.0f, 1.0f}) {
      const glm::vec3 n(0.0f, side, 0.0f);
      const float y = side * (half - shoulder * 0.5f);
      const bool outer = side == outward || outward == 0.0f;
      const std::uint32_t a = m.add_vertex(ring(a0, radius - shoulder, side * half), n, tyre);
      const std::uint32_t b = m.add_vertex(ring(a1, radius - shoulder, side * half), n, tyre);
      const std::uint32_t d = m.add_vertex(ring(a1, rim, y), n, tyre);
      const std::uint32_t e = m.add_vertex(ring(a0, rim, y), n, tyre);
      if (side > 0.0f)
        m.add_quad(a, e, d, b);
      else
        m.add_quad(a, b, d, e);
      // The rim: a spoke (its colour) or a gap (dark) in each of 2 * spokes wedges.
      const int wedge = (k * 2 * spokes) / count;
      const bool spoke = outer && wedge % 2 == 0;
      const glm::vec2 uv(material::kTrim, spoke || (outer && k % 2 == 0 && spokes == 0)
                                              ? rim_colour
                                              : pack_trim_colour(0.02, 0.02, 0.02));
      const float dish = outer ? -0.3f * half * side : 0.0f;  // the spokes dished in
      const std::uint32_t hub = m.add_vertex(c + glm::vec3(0.0f, y + dish, 0.0f), n, uv);
      const std::uint32_t r0 = m.add_vertex(ring(a0, rim, y), n, uv);
      const std::uint32_t r1 = m.add_vertex(ring(a1, rim, y), n, uv);
      if (side > 0.0f)
        m.add_triangle(hub, r0, r1);
      else
        m.add_triangle(hub, r1, r0);
    }
  }
}

}  // namespace downpour::model
