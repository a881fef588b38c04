// Principal curvatures and directions at a mesh's vertices (seed 002, 3.1), for the relief
// shadows' correction along the light (relief.hpp). No GL.
#pragma once

#include <vector>

#include <glm/vec2.hpp>

#include "server/model/mesh_data.hpp"

namespace downpour::render {

// VertexCurvature: mesh_data.hpp.
// At every vertex: a quadric z = a x + b y + (A x^2 + 2 B x y + C y^2) / 2 fitted by least
// squares to its neighbours (those it shares a triangle with) in the frame of its normal; the
// eigenvalues of -[[A, B], [B, C]] are k1 and k2, and their eigenvectors, carried to (u, v) by
// the map fitted to the neighbours' texture coordinates, v1 and v2. A direction and its opposite
// are one: each is turned to point along +u (along +v when it is across u). Vertices with too few
// neighbours to fit get zero curvature.
std::vector<VertexCurvature> vertex_curvatures(const MeshData& mesh);

// Along a tangent direction l (the light projected on the tangent plane, in (u, v)): eq. 1,
// k1 cos^2 + k2 sin^2 with the cosines against v1 and v2 (squares: no square root).
float curvature_along(const VertexCurvature& c, glm::vec2 l);

}  // namespace downpour::render
