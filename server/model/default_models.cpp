#include "server/model/default_models.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "server/model/materials.hpp"
#include "server/model/shapes.hpp"
#include "server/sim/car_body.hpp"
#include "server/sim/vehicle_class.hpp"

namespace downpour::model {

namespace {

const Look kPaint{material::kBody};
const Look kGlass{material::kGlass};
const Look kTrim{material::kTrim};
const Look kLampLook{material::kLamp};
const Look kHeadlampLook{material::kHeadlamp};
Look indicator(float side) {
  return {side > 0.0f ? material::kIndicatorLeft : material::kIndicatorRight};
}
const float kSilver = pack_trim_colour(0.55, 0.56, 0.58);
const float kChrome = pack_trim_colour(0.35, 0.35, 0.37);

// A model from its fixed parts and its wheels, each wheel's triangles a range after the fixed.
struct Builder {
  explicit Builder(Detail d) : detail(d) {}
  Detail detail;
  render::MeshData fixed;
  std::vector<std::pair<render::MeshData, Wheel>> wheels;

  // A rounded box among the fixed parts, its edges cut as finely as the detail asks.
  void box(const glm::vec3& lo, const glm::vec3& hi, float radius, Look look,
           glm::vec2 taper = glm::vec2(1.0f), int segments = 2) {
    // For the distance, a plain box: its edges' rounding is under a pixel there.
    if (detail == Detail::kFar)
      add_rounded_box(fixed, lo, hi, 0.0f, look, taper, 0);
    else
      add_rounded_box(fixed, lo, hi, radius, look, taper, segments);
  }

  void wheel(const glm::vec3& centre, float radius, float width, int spokes, float rim) {
    const float outward = std::abs(centre.y) < 0.05f ? 0.0f : centre.y > 0.0f ? 1.0f : -1.0f;
    // For the distance, wheels that do not turn, among the fixed parts: one draw a vehicle.
    if (detail == Detail::kFar) {
      add_wheel(fixed, centre, radius, width, outward, 0, rim, 8);
      return;
    }
    render::MeshData w;
    add_wheel(w, centre, radius, width, outward, spokes, rim, 18);
    Wheel entry;
    entry.centre = centre;
    entry.radius_m = radius;
    wheels.emplace_back(std::move(w), entry);
  }

  VehicleModel finish() && {
    VehicleModel out;
    out.mesh = std::move(fixed);
    out.fixed_index_count = static_cast<std::uint32_t>(out.mesh.indices.size());
    for (auto& [mesh, entry] : wheels) {
      const auto base = static_cast<std::uint32_t>(out.mesh.vertices.size());
      for (const render::MeshVertex& v : mesh.vertices)
        out.mesh.add_vertex(v.position, v.normal, v.uv);
      entry.first_index = static_cast<std::uint32_t>(out.mesh.indices.size());
      for (std::uint32_t i : mesh.indices) out.mesh.indices.push_back(base + i);
      entry.index_count = static_cast<std::uint32_t>(mesh.indices.size());
      out.wheels.push_back(entry);
    }
    return out;
  }
};

// A rounded end in plan or elevation: how far a corner of radius r pulls in at distance e from
// the end.
float rounding(float e, float r) {
  if (e >= r) return 0.0f;
  const float d = r - e;
  return r - std::sqrt(std::max(r * r - d * d, 0.0f));
}

float lerp(float a, float b, float t) { return a + (b - a) * std::clamp(t, 0.0f, 1.0f); }

// Piecewise-linear through (x, z) points in order of x.
float profile(const std::vector<glm::vec2>& pts, float x) {
  if (x <= pts.front().x) return pts.front().y;
  for (std::size_t i = 1; i < pts.size(); ++i)
    if (x <= pts[i].x)
      return lerp(pts[i - 1].y, pts[i].y, (x - pts[i - 1].x) / (pts[i].x - pts[i - 1].x));
  return pts.back().y;
}

// A lamp's lens on a rounded end of a body: a strip across y0..y1 (left side; mirrored for the
// right) and z0..z1 that follows the end's plan rounding (half-width w, corner radius r, end at
// x_end, facing `facing` +1 forward, -1 back), standing 6 mm proud of it.
void add_lens(render::MeshData& m, float x_end, float facing, float w, float r, float y0, float y1,
              float z0, float z1, Look look) {
  constexpr int kSteps = 4;
  const glm::vec2 uv(look.material, look.colour);
  for (float side : {1.0f, -1.0f}) {
    std::vector<std::uint32_t> lo, hi;
    for (int k = 0; k <= kSteps; ++k) {
      const float y = lerp(y0, y1, static_cast<float>(k) / kSteps);
      // The end's surface at y: flat to w - r, then round.
      const float out = std::max(y - (w - r), 0.0f);
      const float e = r - std::sqrt(std::max(r * r - out * out, 0.0f));
      const glm::vec2 n = glm::normalize(glm::vec2(r - e, out));
      const float x = x_end - facing * (e - 0.006f);
      const glm::vec3 normal(facing * n.x, side * n.y, 0.0f);
      lo.push_back(m.add_vertex({x, side * y, z0}, normal, uv));
      hi.push_back(m.add_vertex({x, side * y, z1}, normal, uv));
    }
    for (int k = 0; k < kSteps; ++k) {
      if (facing * side > 0.0f)
        m.add_quad(lo[k], lo[k + 1], hi[k + 1], hi[k]);
      else
        m.add_quad(lo[k], hi[k], hi[k + 1], lo[k + 1]);
    }
  }
}

VehicleModel car(Detail detail) {
  namespace body = sim::car_body;
  Builder b(detail);
  const bool far = detail == Detail::kFar;
  const float rear = -0.95f, front = 3.65f, half = 0.9f;
  const float plan_front = 0.36f, plan_rear = 0.3f;
  // The lower body: the hood falls from the windshield's foot to the nose, the boot's deck is
  // level; the sills rise round the wheels into arches.
  auto top = [&](float x) {
    const float hood = x > 2.06f ? lerp(0.92f, 0.80f, std::pow((x - 2.06f) / 1.59f, 1.4f)) : 0.92f;
    const float deck = x < -0.55f ? lerp(0.92f, 0.88f, (-0.55f - x) / 0.4f) : hood;
    return deck - rounding(front - x, 0.08f) - rounding(x - rear, 0.10f);
  };
  auto bottom = [&](float x) {
    float z = static_cast<float>(body::kHullBottomZ) + rounding(front - x, 0.16f) +
              rounding(x - rear, 0.05f);
    for (float axle : {0.0f, static_cast<float>(body::kWheelbase)}) {
      const float d = std::abs(x - axle), r = 0.42f;
      if (d < r) z = std::max(z, 0.33f + std::sqrt(r * r - d * d));
    }
    return std::min(z, top(x) - 0.05f);
  };
  std::vector<float> xs;
  if (far) {
    xs = {rear,  rear + 0.05f, rear + 0.2f, -0.42f, -0.2f, 0.0f,  0.2f,  0.42f,         1.0f, 1.6f,
          2.06f, 2.28f,        2.5f,        2.7f,   2.9f,  3.12f, 3.45f, front - 0.05f, front};
  } else {
    xs = {rear, rear + 0.01f, rear + 0.03f, rear + 0.07f, rear + 0.13f, rear + 0.21f};
    for (float x = -0.65f; x < 3.3f; x += 0.1f) xs.push_back(x);
    for (float e : {0.28f, 0.2f, 0.13f, 0.08f, 0.04f, 0.015f, 0.0f}) xs.push_back(front - e);
  }
  std::vector<Section> hull;
  for (float x : xs) {
    const float w = half - rounding(front - x, plan_front) - rounding(x - rear, plan_rear);
    hull.push_back({x, bottom(x), top(x), w, 0.96f, 0.42f});
  }
  const int last = static_cast<int>(hull.size()) - 1;
  add_loft(b.fixed, hull, far ? 8 : 12, [&](int i, int, const glm::vec3& c, const glm::vec3& n) {
    if (i == last) return Look{material::kTrim};  // the grille and bumper's face
    if (n.z < -0.4f && c.x > -0.6f && c.x < 3.3f) return Look{material::kTrim};  // the floor
    if (c.z < 0.4f && std::abs(n.y) > 0.6f && c.x > -0.5f && c.x < 3.2f)
      return Look{material::kTrim};  // the sills between the bumpers
    return kPaint;
  });
  // The glasshouse on it: the rear window rises to the roof, the windshield falls along the
  // simulated glass's rake to its foot.
  const std::vector<glm::vec2> roof = {{-0.56f, 0.92f}, {-0.2f, 1.36f}, {-0.05f, 1.45f},
                                       {0.5f, 1.47f},   {1.2f, 1.46f},  {1.40f, 1.38f},
                                       {2.07f, 0.93f}};
  std::vector<Section> house;
  for (float x = -0.56f; x <= 2.0701f; x += far ? 0.2611f : 0.1305f)
    house.push_back({x, 0.9f, profile(roof, x), 0.83f, 0.82f, 0.35f});
  add_loft(
      b.fixed, house, far ? 8 : 12,
      [&](int, int, const glm::vec3& c, const glm::vec3& n) {
        const float across = std::abs(n.y);
        const bool side = across > 0.8f, corner = !side && across > 0.3f;
        if (c.x > 1.36f || c.x < -0.14f) return corner ? kPaint : kGlass;  // pillars, glass
        if (!side) return kPaint;                                          // the roof
        if (c.x > 0.52f && c.x < 0.66f) return kTrim;                      // the B-pillar
        return kGlass;
      },
      true);
  // Mirrors on the doors.
  for (float s : {1.0f, -1.0f}) {
    const float y0 = s > 0 ? 0.86f : -1.02f;
    b.box({1.86f, y0, 0.98f}, {2.0f, y0 + 0.16f, 1.1f}, 0.03f, kPaint, {1, 1}, 1);
  }
  // The lamps: headlamps with the indicators outboard, tail lamps with the indicators under.
  add_lens(b.fixed, front, 1.0f, half - 0.005f, plan_front, 0.46f, 0.74f, 0.60f, 0.70f,
           kHeadlampLook);
  add_lens(b.fixed, front, 1.0f, half - 0.005f, plan_front, 0.75f, 0.84f, 0.60f, 0.67f,
           indicator(1));
  add_lens(b.fixed, rear, -1.0f, half * 0.995f, plan_rear, 0.55f, 0.84f, 0.73f, 0.85f, kLampLook);
  add_lens(b.fixed, rear, -1.0f, half * 0.995f, plan_rear, 0.6f, 0.84f, 0.65f, 0.72f, indicator(1));
  // The indicators' lenses were made for the left side and mirrored: the right's are the right's.
  for (render::MeshVertex& v : b.fixed.vertices)
    if (v.uv.x == material::kIndicatorLeft && v.position.y < 0.0f)
      v.uv.x = material::kIndicatorRight;
  for (float x : {0.0f, static_cast<float>(body::kWheelbase)})
    for (float y : {-1.0f, 1.0f})
      b.wheel({x, y * static_cast<float>(body::kTrackHalfWidth), 0.33f}, 0.33f, 0.21f, 5, kSilver);
  return std::move(b).finish();
}

// A wide vehicle's lamps at its front and back (sim::VehicleLayout's places): a headlamp with an
// indicator outboard, a tail lamp with an indicator under it, each side.
void add_box_lamps(Builder& b, const sim::VehicleLayout& l, float front) {
  const auto hy = static_cast<float>(l.headlamp_m.y), hz = static_cast<float>(l.headlamp_m.z);
  const auto ty = static_cast<float>(l.tail_lamp_m.y), tz = static_cast<float>(l.tail_lamp_m.z);
  const auto rear = static_cast<float>(l.rear_m);
  for (float s : {1.0f, -1.0f}) {
    auto span = [s](float a, float b) { return s > 0 ? glm::vec2(a, b) : glm::vec2(-b, -a); };
    auto lamp = [&](float x0, float x1, glm::vec2 y, float z0, float z1, Look look) {
      b.box({x0, y.x, z0}, {x1, y.y, z1}, 0.015f, look, {1, 1}, 1);
    };
    lamp(front - 0.04f, front + 0.025f, span(hy - 0.15f, hy + 0.15f), hz - 0.08f, hz + 0.08f,
         kHeadlampLook);
    lamp(front - 0.04f, front + 0.025f, span(hy + 0.17f, hy + 0.25f), hz - 0.06f, hz + 0.06f,
         indicator(s));
    lamp(rear - 0.025f, rear + 0.04f, span(ty - 0.12f, ty + 0.12f), tz - 0.1f, tz + 0.1f,
         kLampLook);
    lamp(rear - 0.025f, rear + 0.04f, span(ty - 0.12f, ty + 0.12f), tz - 0.22f, tz - 0.12f,
         indicator(s));
  }
}

VehicleModel truck(Detail detail) {
  const sim::VehicleLayout& l = sim::vehicle_layout(sim::VehicleClass::kTruck);
  Builder b(detail);
  const float front = static_cast<float>(l.rear_m + l.size_m.x);  // 9.0
  const float cab = front - 2.3f;
  // Chassis rails, bumper, the cab (body below, windows, roof with a deflector), the box body.
  b.box({-3.0f, -0.5f, 0.55f}, {front - 0.3f, 0.5f, 1.0f}, 0.03f, kTrim);
  b.box({front - 0.25f, -1.24f, 0.38f}, {front + 0.03f, 1.24f, 0.75f}, 0.06f, kTrim);
  // The cab sits over its front wheels: its body from the wheel's top up, a skirt ahead of and
  // behind the wheel down to the bumper's height.
  b.box({cab, -1.25f, 1.02f}, {front, 1.25f, 1.95f}, 0.16f, kPaint);
  b.box({front - 0.85f, -1.25f, 0.45f}, {front, 1.25f, 1.1f}, 0.1f, kPaint);
  b.box({cab, -1.25f, 0.6f}, {cab + 0.22f, 1.25f, 1.1f}, 0.05f, kPaint);
  b.box({cab + 0.02f, -1.21f, 1.85f}, {front - 0.06f, 1.21f, 2.8f}, 0.12f, kGlass, {0.98f, 0.98f});
  b.box({cab, -1.22f, 2.72f}, {front - 0.16f, 1.22f, 3.25f}, 0.2f, kPaint);
  // A grille on the cab's face.
  b.box({front - 0.02f, -0.75f, 1.0f}, {front + 0.012f, 0.75f, 1.6f}, 0.01f,
        {material::kTrim, kChrome}, {1, 1}, 1);
  b.box({-3.0f, -1.25f, 1.0f}, {cab - 0.15f, 1.25f, 3.8f}, 0.06f, kPaint);
  // Mudguards over the wheels.
  for (float x : {0.0f, 7.5f})
    b.box({x - (x > 0 ? 0.6f : 1.3f), -1.28f, 1.0f},
          {x + 0.6f + (x > 0 ? 0.0f : 0.1f), 1.28f, 1.12f}, 0.03f, kTrim, {1, 1}, 1);
  add_box_lamps(b, l, front);
  for (float x : {-0.65f, 0.65f, 7.5f})
    for (float y : {-1.0f, 1.0f}) b.wheel({x, y * 1.0f, 0.5f}, 0.5f, 0.4f, 8, kSilver);
  return std::move(b).finish();
}

VehicleModel bus(Detail detail) {
  const sim::VehicleLayout& l = sim::vehicle_layout(sim::VehicleClass::kBus);
  Builder b(detail);
  const float front = static_cast<float>(l.rear_m + l.size_m.x);  // 8.6
  const float half = static_cast<float>(0.5 * l.size_m.y), rear = static_cast<float>(l.rear_m);
  // The lower body, the band of windows (the windscreen deep at the front), the roof.
  // The lower body over the wheels' arches: full depth between them, above them only from their
  // tops.
  const float axles[2] = {0.0f, 6.0f}, arch = 0.62f;
  b.box({rear, -half, 1.05f}, {front, half, 1.2f}, 0.06f, kPaint);
  float from = rear;
  for (float x : axles) {
    b.box({from, -half, 0.3f}, {x - arch, half, 1.15f}, 0.12f, kPaint);
    from = x + arch;
  }
  b.box({from, -half, 0.3f}, {front, half, 1.15f}, 0.12f, kPaint);
  b.box({rear + 0.03f, -half + 0.03f, 1.1f}, {front - 0.02f, half - 0.03f, 2.75f}, 0.1f, kGlass);
  b.box({rear, -half, 2.65f}, {front, half, 3.2f}, 0.22f, kPaint);
  // The rear's panel and the pillars between the side windows.
  b.box({rear - 0.01f, -half + 0.02f, 1.15f}, {rear + 0.8f, half - 0.02f, 2.7f}, 0.06f, kPaint);
  for (float x = rear + 2.0f; x < front - 1.0f; x += 1.6f)
    b.box({x, -half - 0.005f, 1.15f}, {x + 0.12f, half + 0.005f, 2.7f}, 0.02f, kTrim, {1, 1}, 1);
  add_box_lamps(b, l, front);
  for (float x : axles)
    for (float y : {-1.0f, 1.0f}) b.wheel({x, y * 1.02f, 0.5f}, 0.5f, 0.32f, 8, kSilver);
  return std::move(b).finish();
}

VehicleModel motorbike(Detail detail) {
  const sim::VehicleLayout& l = sim::vehicle_layout(sim::VehicleClass::kMotorbike);
  Builder b(detail);
  // The tank and seat between the wheels, the engine under, the forks; the rider sitting up,
  // helmeted, his arms to the bars.
  b.box({0.55f, -0.16f, 0.72f}, {1.15f, 0.16f, 0.98f}, 0.09f, kPaint);
  b.box({0.05f, -0.14f, 0.72f}, {0.62f, 0.14f, 0.86f}, 0.05f, kTrim);
  b.box({0.45f, -0.15f, 0.35f}, {1.05f, 0.15f, 0.72f}, 0.06f, {material::kTrim, kChrome});
  b.box({1.2f, -0.07f, 0.32f}, {1.32f, 0.07f, 1.02f}, 0.03f, kTrim);
  b.box({-0.05f, -0.1f, 0.62f}, {0.2f, 0.1f, 0.8f}, 0.04f, kPaint);
  b.box({0.3f, -0.2f, 0.86f}, {0.68f, 0.2f, 1.3f}, 0.1f, kTrim, {0.9f, 0.85f});
  b.box({0.6f, -0.3f, 1.05f}, {1.2f, 0.3f, 1.14f}, 0.04f, kTrim);
  b.box({0.36f, -0.14f, 1.28f}, {0.66f, 0.14f, 1.56f}, 0.13f, kPaint);
  const auto hx = static_cast<float>(l.headlamp_m.x), hz = static_cast<float>(l.headlamp_m.z);
  const auto tx = static_cast<float>(l.tail_lamp_m.x), tz = static_cast<float>(l.tail_lamp_m.z);
  b.box({hx - 0.12f, -0.09f, hz - 0.08f}, {hx, 0.09f, hz + 0.08f}, 0.05f, kHeadlampLook);
  b.box({tx, -0.08f, tz - 0.05f}, {tx + 0.08f, 0.08f, tz + 0.05f}, 0.02f, kLampLook);
  b.box({tx, 0.1f, tz - 0.03f}, {tx + 0.05f, 0.18f, tz + 0.03f}, 0.01f, indicator(1));
  b.box({tx, -0.18f, tz - 0.03f}, {tx + 0.05f, -0.1f, tz + 0.03f}, 0.01f, indicator(-1));
  b.box({tx, -0.08f, tz - 0.1f}, {0.05f, 0.08f, tz - 0.02f}, 0.02f, kTrim);
  for (float x : {0.0f, 1.45f}) b.wheel({x, 0.0f, 0.32f}, 0.32f, 0.13f, 6, kSilver);
  return std::move(b).finish();
}

}  // namespace

VehicleModel default_cabin(const sim::GlassConfig& glass) {
  const double inset = glass.inset_mm(glass.height_mm);
  const glm::vec3 bottom_right(glass.to_vehicle({glass.bottom_width_mm, 0.0}));
  const glm::vec3 bottom_left(glass.to_vehicle({0.0, 0.0}));
  const glm::vec3 top_left(glass.to_vehicle({inset, glass.height_mm}));
  const glm::vec3 top_right(glass.to_vehicle({glass.bottom_width_mm - inset, glass.height_mm}));
  render::MeshData m;
  const float dash_back = 1.45f, dash_top = bottom_left.z - 0.03f;
  // The dashboard's top, from the glass's foot back towards the driver, a little lower at the
  // back; its face towards the driver, and a bevel from the face up to the top (the view's bottom
  // rows look down through where the two would otherwise leave a gap, at the road).
  m.add_face({dash_back + 0.04f, -0.85f, dash_top},
             {bottom_right.x, -0.85f, bottom_right.z - 0.005f},
             {bottom_left.x, 0.85f, bottom_left.z - 0.005f}, {dash_back + 0.04f, 0.85f, dash_top},
             material::kTrim);
  m.add_face({dash_back, 0.85f, 0.55f}, {dash_back, -0.85f, 0.55f},
             {dash_back, -0.85f, dash_top - 0.03f}, {dash_back, 0.85f, dash_top - 0.03f},
             material::kTrim);
  m.add_face({dash_back, 0.85f, dash_top - 0.03f}, {dash_back, -0.85f, dash_top - 0.03f},
             {dash_back + 0.04f, -0.85f, dash_top}, {dash_back + 0.04f, 0.85f, dash_top},
             material::kTrim);
  // The instrument hood in front of the driver, rounded.
  add_rounded_box(m, {dash_back - 0.03f, 0.17f, 0.88f}, {1.78f, 0.57f, 1.03f}, 0.05f, kTrim,
                  {0.9f, 0.92f}, 1);
  // A-pillars along the glass's side edges, 9 cm wide, 6 cm deep.
  for (int side : {-1, 1}) {
    const glm::vec3 lo = side > 0 ? bottom_left : bottom_right;
    const glm::vec3 hi = side > 0 ? top_left : top_right;
    const glm::vec3 out(0.0f, static_cast<float>(side) * 0.09f, 0.0f);
    const glm::vec3 in(-0.04f, 0.0f, -0.05f);
    // The inner face, seen from the cabin, and the side face towards the glass.
    if (side > 0) {
      m.add_face(lo + in, hi + in, hi + out + in, lo + out + in, material::kTrim);
      m.add_face(lo, hi, hi + in, lo + in, material::kTrim);
    } else {
      m.add_face(lo + in, lo + out + in, hi + out + in, hi + in, material::kTrim);
      m.add_face(lo, lo + in, hi + in, hi, material::kTrim);
    }
  }
  // The roof liner from just inside the glass's top edge back over the driver: it hides the
  // edge, so that the water drawn on the glass stops where the liner begins.
  m.add_face({top_right.x - 0.03f, -0.9f, top_right.z - 0.01f},
             {top_left.x - 0.03f, 0.9f, top_left.z - 0.01f}, {0.2f, 0.9f, top_left.z + 0.06f},
             {0.2f, -0.9f, top_right.z + 0.06f}, material::kTrim);
  // The rear-view mirror on a short stem up to the glass, inside it.
  add_rounded_box(m, {1.495f, -0.1f, 1.215f}, {1.525f, 0.1f, 1.275f}, 0.02f, kPaint, {1, 1}, 1);
  add_rounded_box(m, {1.47f, -0.012f, 1.27f}, {1.49f, 0.012f, 1.32f}, 0.006f, kTrim, {1, 1}, 1);
  VehicleModel out;
  out.mesh = std::move(m);
  out.fixed_index_count = static_cast<std::uint32_t>(out.mesh.indices.size());
  out.bonnet_index_count = out.fixed_index_count;
  out.windshield = outline_of(glass);
  return out;
}

VehicleModel default_vehicle(sim::VehicleClass c, Detail detail) {
  VehicleModel m;
  switch (c) {
    case sim::VehicleClass::kTruck:
      m = truck(detail);
      break;
    case sim::VehicleClass::kBus:
      m = bus(detail);
      break;
    case sim::VehicleClass::kMotorbike:
      m = motorbike(detail);
      break;
    case sim::VehicleClass::kCar:
      m = car(detail);
      mark_bonnet(m);
      break;
  }
  return m;
}

void mark_bonnet(VehicleModel& model, const sim::GlassConfig& glass, const glm::dvec3& eye_m) {
  std::vector<std::uint32_t>& idx = model.mesh.indices;
  const glm::vec3 eye(eye_m);
  const glm::vec3 foot(glass.bottom_left_m);
  const float ahead_of_x = foot.x - 0.05f;
  // The sight line's slope (dz / dx) from the eye over the foot, lowered by 6 degrees.
  const float sight = std::tan(std::atan2(foot.z - eye.z, foot.x - eye.x) - 0.105f);
  auto ahead = [&](std::size_t t) {
    glm::vec3 normal(0.0f), centre(0.0f);
    bool above = false, reaches = false, behind = false, low = true;
    for (int k = 0; k < 3; ++k) {
      const render::MeshVertex& v = model.mesh.vertices[idx[t + k]];
      // Ahead of the foot; or reaching past it at the bonnet's height (the scuttle, the wings by
      // the glass), where a glass set further back than the model's leaves them in view.
      if (v.position.x < ahead_of_x) {
        behind = true;
        low = low && v.position.z < foot.z + 0.05f;
      } else {
        reaches = true;
      }
      normal += v.normal;
      centre += v.position / 3.0f;
      above = above || v.position.z - eye.z > sight * (v.position.x - eye.x);
    }
    // Facing the eye, or turned away by less than 20 degrees past grazing: at a silhouette the
    // smooth vertex normals turn further than the flat triangle does.
    const float facing = glm::dot(normal, eye - centre) /
                         std::max(glm::length(normal) * glm::length(eye - centre), 1e-6f);
    return (!behind || (reaches && low)) && above && facing > -0.35f &&
           model.mesh.vertices[idx[t]].uv.x != material::kGlass;
  };
  std::vector<std::uint32_t> first, rest;
  for (std::size_t t = 0; t + 2 < model.fixed_index_count; t += 3)
    (ahead(t) ? first : rest)
        .insert((ahead(t) ? first : rest).end(), idx.begin() + t, idx.begin() + t + 3);
  model.bonnet_index_count = static_cast<std::uint32_t>(first.size());
  first.insert(first.end(), rest.begin(), rest.end());
  std::copy(first.begin(), first.end(), idx.begin());
}

bool same_cabin(const sim::GlassConfig& a, const sim::GlassConfig& b) {
  return a.bottom_left_m == b.bottom_left_m && a.bottom_width_mm == b.bottom_width_mm &&
         a.top_width_mm == b.top_width_mm && a.height_mm == b.height_mm && a.rake_deg == b.rake_deg;
}

sim::ModelPtr bonnet_for(const sim::ModelPtr& body, const sim::GlassConfig& glass,
                         const glm::dvec3& eye_m) {
  if (same_cabin(glass, sim::GlassConfig{}) && eye_m == sim::EgoGeometry{}.eye_m) return nullptr;
  auto own =
      std::make_shared<VehicleModel>(body ? *body : default_vehicle(sim::VehicleClass::kCar));
  mark_bonnet(*own, glass, eye_m);
  return own;
}

}  // namespace downpour::model
