#include "server/render/cpu/mesh_curvature.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace downpour::render {
namespace {

// Solves the n x n system m x = b in place (Gaussian elimination with partial pivoting); false
// when it is singular.
template <std::size_t N>
bool solve(std::array<std::array<double, N>, N>& m, std::array<double, N>& b) {
  for (std::size_t c = 0; c < N; ++c) {
    std::size_t pivot = c;
    for (std::size_t r = c + 1; r < N; ++r) {
      if (std::abs(m[r][c]) > std::abs(m[pivot][c])) pivot = r;
    }
    if (std::abs(m[pivot][c]) < 1e-12) return false;
    std::swap(m[c], m[pivot]);
    std::swap(b[c], b[pivot]);
    for (std::size_t r = 0; r < N; ++r) {
      if (r == c) continue;
      const double f = m[r][c] / m[c][c];
      for (std::size_t k = c; k < N; ++k) m[r][k] -= f * m[c][k];
      b[r] -= f * b[c];
    }
  }
  for (std::size_t c = 0; c < N; ++c) b[c] /= m[c][c];
  return true;
}

// The quadric's second-order terms (A, B, C) from the neighbours' offsets (x, y, z) in the normal's
// frame: with the slope terms when five or more neighbours allow them.
template <std::size_t N>
bool fit_quadric(const std::vector<glm::dvec3>& d, double& a, double& b, double& c) {
  std::array<std::array<double, N>, N> m{};
  std::array<double, N> rhs{};
  for (const glm::dvec3& p : d) {
    std::array<double, 5> row = {0.5 * p.x * p.x, p.x * p.y, 0.5 * p.y * p.y, p.x, p.y};
    for (std::size_t i = 0; i < N; ++i) {
      for (std::size_t j = 0; j < N; ++j) m[i][j] += row[i] * row[j];
      rhs[i] += row[i] * p.z;
    }
  }
  if (!solve(m, rhs)) return false;
  a = rhs[0];
  b = rhs[1];
  c = rhs[2];
  return true;
}

glm::vec2 canonical(glm::dvec2 d) {
  const double len = glm::length(d);
  if (len < 1e-12) return {1.0f, 0.0f};
  d /= len;
  if (std::abs(d.x) >= std::abs(d.y) ? d.x < 0.0 : d.y < 0.0) d = -d;
  return glm::vec2(d);
}

}  // namespace

std::vector<VertexCurvature> vertex_curvatures(const MeshData& mesh) {
  const std::size_t n = mesh.vertices.size();
  std::vector<std::vector<std::uint32_t>> ring(n);
  auto link = [&](std::uint32_t a, std::uint32_t b) {
    if (std::find(ring[a].begin(), ring[a].end(), b) == ring[a].end()) ring[a].push_back(b);
  };
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const std::uint32_t i[3] = {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
    for (int e = 0; e < 3; ++e) {
      link(i[e], i[(e + 1) % 3]);
      link(i[(e + 1) % 3], i[e]);
    }
  }
  std::vector<VertexCurvature> out(n);
  std::vector<glm::dvec3> d;
  for (std::size_t v = 0; v < n; ++v) {
    if (ring[v].size() < 3) continue;
    const MeshVertex& c = mesh.vertices[v];
    const glm::dvec3 nn = glm::normalize(glm::dvec3(c.normal));
    const glm::dvec3 axis = std::abs(nn.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 e1 = glm::normalize(axis - nn * glm::dot(nn, axis));
    const glm::dvec3 e2 = glm::cross(nn, e1);
    d.clear();
    // The texture map's Jacobian (uv per tangent-plane metre), fitted alongside.
    std::array<std::array<double, 2>, 2> m{};
    std::array<double, 2> ju{}, jv{};
    for (std::uint32_t o : ring[v]) {
      const MeshVertex& q = mesh.vertices[o];
      const glm::dvec3 r = glm::dvec3(q.position) - glm::dvec3(c.position);
      const glm::dvec3 p(glm::dot(r, e1), glm::dot(r, e2), glm::dot(r, nn));
      d.push_back(p);
      const glm::dvec2 duv = glm::dvec2(q.uv) - glm::dvec2(c.uv);
      m[0][0] += p.x * p.x;
      m[0][1] += p.x * p.y;
      m[1][1] += p.y * p.y;
      ju[0] += p.x * duv.x;
      ju[1] += p.y * duv.x;
      jv[0] += p.x * duv.y;
      jv[1] += p.y * duv.y;
    }
    m[1][0] = m[0][1];
    auto m2 = m;
    if (!solve(m, ju) || !solve(m2, jv)) continue;
    double a = 0.0, b = 0.0, cc = 0.0;
    const bool fitted = d.size() >= 5 ? fit_quadric<5>(d, a, b, cc) : fit_quadric<3>(d, a, b, cc);
    if (!fitted) continue;
    // The shape operator with convex positive: a surface falling away from its normal has A < 0.
    const double p = -a, q = -b, r = -cc;
    const double mean = 0.5 * (p + r);
    const double dev = std::sqrt(0.25 * (p - r) * (p - r) + q * q);
    const double k1 = mean + dev, k2 = mean - dev;
    glm::dvec2 w1 = std::abs(q) > 1e-12 ? glm::dvec2(k1 - r, q)
                                        : (p >= r ? glm::dvec2(1, 0) : glm::dvec2(0, 1));
    w1 = glm::normalize(w1);
    const glm::dvec2 w2(-w1.y, w1.x);
    auto to_uv = [&](glm::dvec2 w) {
      return glm::dvec2(ju[0] * w.x + ju[1] * w.y, jv[0] * w.x + jv[1] * w.y);
    };
    out[v] = {static_cast<float>(k1), static_cast<float>(k2), canonical(to_uv(w1)),
              canonical(to_uv(w2))};
  }
  return out;
}

float curvature_along(const VertexCurvature& c, glm::vec2 l) {
  const float ll = glm::dot(l, l);
  if (ll <= 0.0f) return 0.0f;
  const float a = glm::dot(l, c.v1), b = glm::dot(l, c.v2);
  const float cos2 = a * a / (ll * glm::dot(c.v1, c.v1));
  const float sin2 = b * b / (ll * glm::dot(c.v2, c.v2));
  return c.k1 * cos2 + c.k2 * sin2;
}

}  // namespace downpour::render
