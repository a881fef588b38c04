#include "server/sim/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "server/sim/track.hpp"

namespace downpour::sim {
namespace {

using nlohmann::json;

VehicleState mix(const VehicleState& a, const VehicleState& b, double u) {
  VehicleState v;
  v.position_m = a.position_m + (b.position_m - a.position_m) * u;
  v.velocity_mps = a.velocity_mps + (b.velocity_mps - a.velocity_mps) * u;
  v.rotation.yaw_deg = lerp_angle_deg(a.rotation.yaw_deg, b.rotation.yaw_deg, u);
  v.rotation.pitch_deg = lerp_angle_deg(a.rotation.pitch_deg, b.rotation.pitch_deg, u);
  v.rotation.roll_deg = lerp_angle_deg(a.rotation.roll_deg, b.rotation.roll_deg, u);
  return v;
}

Weather mix(const Weather& a, const Weather& b, double u) {
  Weather w;
  for (const WeatherField& f : kWeatherFields) f.set(w, interpolate(f, f.get(a), f.get(b), u));
  return w;
}

// Interpolates one channel (a member of Keyframe) at t.
template <typename T, typename Mix>
std::optional<T> sample(const std::vector<Keyframe>& keys, std::optional<T> Keyframe::*channel,
                        double t, Mix mix_fn) {
  const Keyframe* before = nullptr;
  const Keyframe* after = nullptr;
  for (const Keyframe& k : keys) {
    if (!(k.*channel)) continue;
    if (k.t <= t) {
      before = &k;
    } else {
      after = &k;
      break;
    }
  }
  if (!before && !after) return std::nullopt;
  if (!before) return *(after->*channel);
  if (!after || after->t <= before->t) return *(before->*channel);
  const double u = (t - before->t) / (after->t - before->t);
  return mix_fn(*(before->*channel), *(after->*channel), u);
}

const char* wiper_mode_name(WiperMode m) {
  switch (m) {
    case WiperMode::kOff:
      return "OFF";
    case WiperMode::kIntermittent:
      return "INTERMITTENT";
    case WiperMode::kLow:
      return "LOW";
    case WiperMode::kHigh:
      return "HIGH";
    case WiperMode::kSingle:
      return "SINGLE";
    case WiperMode::kManual:
      return "MANUAL";
  }
  return "OFF";
}

[[noreturn]] void fail(const std::string& field, const std::string& what) {
  throw std::runtime_error("scenario " + field + ": " + what);
}

std::string join(const std::string& where, const char* key) {
  return where.empty() ? std::string(key) : where + "." + key;
}

double number(const json& j, const char* key, const std::string& where, double fallback) {
  if (!j.contains(key)) return fallback;
  const json& v = j.at(key);
  if (!v.is_number()) fail(join(where, key), "must be a number");
  const double d = v.get<double>();
  if (!std::isfinite(d)) fail(join(where, key), "must be finite");
  return d;
}

// A whole number in [lo, hi]; a fraction or anything outside is refused rather than cast.
std::int64_t integer(const json& j, const char* key, const std::string& where,
                     std::int64_t fallback, std::int64_t lo, std::int64_t hi) {
  const double d = number(j, key, where, static_cast<double>(fallback));
  if (d < static_cast<double>(lo) || d > static_cast<double>(hi) || d != std::floor(d)) {
    fail(join(where, key),
         "must be a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return static_cast<std::int64_t>(d);
}

std::string text(const json& j, const char* key, const std::string& where,
                 const std::string& fallback) {
  if (!j.contains(key)) return fallback;
  const json& v = j.at(key);
  if (!v.is_string()) fail(join(where, key), "must be a string");
  return v.get<std::string>();
}

bool flag(const json& j, const char* key, const std::string& where, bool fallback) {
  if (!j.contains(key)) return fallback;
  const json& v = j.at(key);
  if (!v.is_boolean()) fail(join(where, key), "must be true or false");
  return v.get<bool>();
}

// An object member that must be an object (or absent: nullptr).
const json* object(const json& j, const char* key, const std::string& where) {
  if (!j.contains(key)) return nullptr;
  const json& v = j.at(key);
  if (!v.is_object()) fail(join(where, key), "must be an object");
  return &v;
}

const json& array(const json& j, const char* key, const std::string& where) {
  static const json kEmpty = json::array();
  if (!j.contains(key)) return kEmpty;
  const json& v = j.at(key);
  if (!v.is_array()) fail(join(where, key), "must be an array");
  return v;
}

std::vector<double> numbers(const json& j, const char* key, const std::string& where) {
  std::vector<double> out;
  const json& v = array(j, key, where);
  for (const json& x : v) {
    if (!x.is_number() || !std::isfinite(x.get<double>()))
      fail(join(where, key), "must be an array of numbers");
    out.push_back(x.get<double>());
  }
  return out;
}

glm::dvec3 vec3(const json& j, const char* key, const std::string& where) {
  if (!j.contains(key)) return glm::dvec3(0.0);
  const json& v = j.at(key);
  if (!v.is_array() || v.size() != 3) fail(join(where, key), "must be an array of 3 numbers");
  glm::dvec3 out;
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number() || !std::isfinite(v[i].get<double>())) {
      fail(join(where, key), "must be an array of 3 finite numbers");
    }
    out[i] = v[i].get<double>();
  }
  return out;
}

View parse_view(const std::string& name, const std::string& where) {
  for (int i = 0; i < kViewCount; ++i) {
    if (view_name(static_cast<View>(i)) == name) return static_cast<View>(i);
  }
  fail(where, "unknown view '" + name + "'");
}

WiperMode parse_wiper_mode(const std::string& name, const std::string& where) {
  for (WiperMode m : {WiperMode::kOff, WiperMode::kIntermittent, WiperMode::kLow, WiperMode::kHigh,
                      WiperMode::kSingle, WiperMode::kManual}) {
    if (name == wiper_mode_name(m)) return m;
  }
  fail(where, "unknown wiper mode '" + name + "'");
}

}  // namespace

Update Scenario::at(double t_in) const {
  double t = t_in;
  if (loop && duration_s > 0.0) {
    t = std::fmod(t, duration_s);
    if (t < 0.0) t += duration_s;
  }
  Update u;
  u.client_time_s = t_in;
  u.vehicle =
      sample(keyframes, &Keyframe::vehicle, t,
             [](const VehicleState& a, const VehicleState& b, double w) { return mix(a, b, w); });
  u.weather = sample(keyframes, &Keyframe::weather, t,
                     [](const Weather& a, const Weather& b, double w) { return mix(a, b, w); });
  u.wipers = sample(keyframes, &Keyframe::wipers, t,
                    [](const WiperState& a, const WiperState&, double) { return a; });
  return u;
}

Scenario Scenario::from_json(const std::string& source) {
  json root;
  try {
    root = json::parse(source);
  } catch (const json::exception& e) {  // syntax errors, and numbers too large for a double
    fail("file", std::string("is not valid JSON: ") + e.what());
  }
  if (!root.is_object()) fail("file", "must be a JSON object");
  Scenario s;
  s.name = text(root, "name", "", "");
  s.description = text(root, "description", "", "");
  s.duration_s = number(root, "duration_s", "", 0.0);
  if (s.duration_s < 0.0) fail("duration_s", "must not be negative");
  s.loop = flag(root, "loop", "", false);
  s.seed = static_cast<std::uint64_t>(integer(root, "seed", "", 0, 0, std::int64_t{1} << 53));
  s.fps = number(root, "fps", "", 30.0);
  if (s.fps <= 0.0) fail("fps", "must be positive");
  const json& views = array(root, "views", "");
  for (std::size_t i = 0; i < views.size(); ++i) {
    const std::string where = "views[" + std::to_string(i) + "]";
    const json& jv = views[i];
    if (!jv.is_object()) fail(where, "must be an object");
    ViewSpec v;
    v.view = parse_view(text(jv, "view", where, ""), where + ".view");
    v.width = static_cast<int>(integer(jv, "width", where, 640, 1, 1 << 16));
    v.height = static_cast<int>(integer(jv, "height", where, 360, 1, 1 << 16));
    v.jpeg_quality = static_cast<int>(integer(jv, "jpeg_quality", where, 85, 1, 100));
    v.fov_deg = number(jv, "fov_deg", where, 0.0);
    s.views.push_back(v);
  }
  const json& keys = array(root, "keyframes", "");
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const std::string where = "keyframes[" + std::to_string(i) + "]";
    const json& jk = keys[i];
    if (!jk.is_object()) fail(where, "must be an object");
    Keyframe k;
    k.t = number(jk, "t", where, 0.0);
    if (!s.keyframes.empty() && k.t < s.keyframes.back().t)
      fail(where + ".t", "keyframes must be sorted by t");
    if (const json* jv = object(jk, "vehicle", where)) {
      const std::string wv = where + ".vehicle";
      VehicleState v;
      v.position_m = vec3(*jv, "position_m", wv);
      const glm::dvec3 r = vec3(*jv, "rotation_deg", wv);
      v.rotation = {r.x, r.y, r.z};
      v.velocity_mps = vec3(*jv, "velocity_mps", wv);
      k.vehicle = v;
    }
    if (const json* jw = object(jk, "wipers", where)) {
      const std::string ww = where + ".wipers";
      WiperState w;
      w.mode = parse_wiper_mode(text(*jw, "mode", ww, "OFF"), ww + ".mode");
      w.interval_s = number(*jw, "interval_s", ww, 4.0);
      w.blade_angle_deg = numbers(*jw, "blade_angle_deg", ww);
      k.wipers = w;
    }
    if (const json* jw = object(jk, "weather", where)) {
      const std::string ww = where + ".weather";
      Weather w;
      for (const WeatherField& f : kWeatherFields) {
        const std::string name(f.name);
        f.set(w, f.integer
                     ? static_cast<double>(integer(
                           *jw, name.c_str(), ww, static_cast<std::int64_t>(f.fallback),
                           static_cast<std::int64_t>(f.min), static_cast<std::int64_t>(f.max)))
                     : number(*jw, name.c_str(), ww, f.fallback));
      }
      k.weather = w;
    }
    s.keyframes.push_back(std::move(k));
  }
  return s;
}

std::string Scenario::samples_json(double step_s) const {
  json samples = json::array();
  auto arr = [](glm::dvec3 x) { return json::array({x.x, x.y, x.z}); };
  const int count = static_cast<int>(std::floor(duration_s / step_s + 1e-9));
  for (int i = 0; i <= count; ++i) {
    const double t = i * step_s;
    const Update u = at(t);
    json j;
    j["t"] = t;
    if (u.vehicle) {
      const Rotation& r = u.vehicle->rotation;
      j["vehicle"] = {{"position_m", arr(u.vehicle->position_m)},
                      {"rotation_deg", json::array({r.yaw_deg, r.pitch_deg, r.roll_deg})},
                      {"velocity_mps", arr(u.vehicle->velocity_mps)}};
    }
    if (u.wipers) {
      j["wipers"] = {{"mode", wiper_mode_name(u.wipers->mode)},
                     {"interval_s", u.wipers->interval_s},
                     {"blade_angle_deg", u.wipers->blade_angle_deg}};
    }
    if (u.weather) {
      json& jw = j["weather"];
      for (const WeatherField& f : kWeatherFields) jw[std::string(f.name)] = f.get(*u.weather);
    }
    samples.push_back(std::move(j));
  }
  return samples.dump() + "\n";
}

std::string Scenario::to_json() const {
  json root;
  root["name"] = name;
  root["description"] = description;
  root["duration_s"] = duration_s;
  root["loop"] = loop;
  root["seed"] = seed;
  root["fps"] = fps;
  root["views"] = json::array();
  for (const ViewSpec& v : views) {
    root["views"].push_back({{"view", view_name(v.view)},
                             {"width", v.width},
                             {"height", v.height},
                             {"jpeg_quality", v.jpeg_quality},
                             {"fov_deg", v.fov_deg}});
  }
  root["keyframes"] = json::array();
  auto round_to = [](double x, double unit) { return std::round(x / unit) * unit; };
  for (const Keyframe& k : keyframes) {
    json jk;
    jk["t"] = round_to(k.t, 1e-6);
    if (k.vehicle) {
      const VehicleState& v = *k.vehicle;
      auto arr = [&](glm::dvec3 x, double unit) {
        return json::array({round_to(x.x, unit), round_to(x.y, unit), round_to(x.z, unit)});
      };
      jk["vehicle"] = {{"position_m", arr(v.position_m, 1e-4)},
                       {"rotation_deg",
                        arr({v.rotation.yaw_deg, v.rotation.pitch_deg, v.rotation.roll_deg}, 1e-4)},
                       {"velocity_mps", arr(v.velocity_mps, 1e-4)}};
    }
    if (k.wipers) {
      jk["wipers"] = {{"mode", wiper_mode_name(k.wipers->mode)},
                      {"interval_s", k.wipers->interval_s},
                      {"blade_angle_deg", k.wipers->blade_angle_deg}};
    }
    if (k.weather) {
      const Weather& w = *k.weather;
      json& jw = jk["weather"];
      for (const WeatherField& f : kWeatherFields) {
        if (f.integer) {
          jw[std::string(f.name)] = static_cast<std::int64_t>(f.get(w));
        } else {
          jw[std::string(f.name)] = f.get(w);
        }
      }
    }
    root["keyframes"].push_back(jk);
  }
  return root.dump(1) + "\n";
}

namespace {

// Where a lane's centre is at centreline arc length s.
glm::dvec3 lane_point(const Track& track, double s, double lateral) {
  const TrackFrame f = track.at(s);
  glm::dvec3 p = f.position + glm::dvec3(f.left * lateral, 0.0);
  p.z = track.surface_height(s, lateral);
  return p;
}

// Keyframes that drive one lane of the test track at a constant speed, one lap, every step_s
// seconds. The lane is longer than the centreline on the curves (outer lane) or shorter (inner),
// so the distance travelled is measured along the lane itself: a table of centreline s against
// lane distance, inverted by interpolation.
std::vector<Keyframe> drive_lap(const Track& track, int lane, double speed_mps, double step_s) {
  const double lateral = track.lane_centre(lane);
  constexpr double kTableStep = 0.25;  // metres of centreline
  const int n = static_cast<int>(std::ceil(track.length() / kTableStep));
  std::vector<double> lane_distance(n + 1, 0.0);
  glm::dvec3 previous = lane_point(track, 0.0, lateral);
  for (int i = 1; i <= n; ++i) {
    const glm::dvec3 p = lane_point(track, track.length() * i / n, lateral);
    lane_distance[i] = lane_distance[i - 1] + glm::length(p - previous);
    previous = p;
  }
  auto centreline_s = [&](double d) {
    const auto it = std::lower_bound(lane_distance.begin(), lane_distance.end(), d);
    const auto i = std::clamp<std::ptrdiff_t>(it - lane_distance.begin(), 1, n);
    const double w = (d - lane_distance[i - 1]) / (lane_distance[i] - lane_distance[i - 1]);
    return track.length() * (static_cast<double>(i - 1) + std::clamp(w, 0.0, 1.0)) / n;
  };

  std::vector<Keyframe> keys;
  const double lap_s = lane_distance.back() / speed_mps;
  // Whole steps of about step_s, so that the last keyframe closes the loop onto the first.
  const int steps = static_cast<int>(std::ceil(lap_s / step_s));
  for (int i = 0; i <= steps; ++i) {
    const double t = lap_s * i / steps;
    const double s = i == steps ? track.length() : centreline_s(speed_mps * t);
    const TrackFrame f = track.at(s);
    VehicleState v;
    v.position_m = lane_point(track, s, lateral);
    v.rotation.yaw_deg = std::remainder(f.heading_rad * 180.0 / M_PI, 360.0);
    v.rotation.pitch_deg = -std::atan(f.grade) * 180.0 / M_PI;
    const glm::dvec2 dir(std::cos(f.heading_rad), std::sin(f.heading_rad));
    v.velocity_mps = glm::dvec3(dir * speed_mps, f.grade * speed_mps);
    keys.push_back({t, v, std::nullopt, std::nullopt});
  }
  return keys;
}

}  // namespace

Scenario highway_heavy_rain() {
  const Track track = Track::test_track();
  Scenario s;
  s.name = "highway_heavy_rain";
  s.description =
      "The test track's outer lane at 25 m/s in 25 mm/h rain, wipers on high, overcast.";
  s.loop = true;
  s.seed = 7;
  s.fps = 30.0;
  s.views = {view_spec(View::kCockpit, 640, 360), view_spec(View::kRoad, 640, 360)};
  s.keyframes = drive_lap(track, 1, 25.0, 0.5);
  s.duration_s = s.keyframes.back().t;
  Weather w;
  w.rain_rate_mm_h = 25.0;
  w.wind_speed_mps = 4.0;
  w.wind_direction_deg = 60.0;
  w.fog_density = 0.15;
  w.cloudiness = 0.95;
  w.sun_altitude_deg = 30.0;
  w.sun_azimuth_deg = 200.0;
  s.keyframes.front().weather = w;
  s.keyframes.front().wipers = WiperState{WiperMode::kHigh, 0.0, {}};
  return s;
}

Scenario city_drizzle() {
  const Track track = Track::test_track();
  Scenario s;
  s.name = "city_drizzle";
  s.description = "The test track's inner lane at 8 m/s in 2 mm/h drizzle, intermittent wipers.";
  s.loop = true;
  s.seed = 11;
  s.fps = 30.0;
  s.views = {view_spec(View::kCockpit, 640, 360), view_spec(View::kRoad, 640, 360)};
  s.keyframes = drive_lap(track, 0, 8.0, 1.0);
  s.duration_s = s.keyframes.back().t;
  Weather w;
  w.rain_rate_mm_h = 2.0;
  w.wind_speed_mps = 1.5;
  w.fog_density = 0.05;
  w.cloudiness = 0.7;
  w.sun_altitude_deg = 50.0;
  w.sun_azimuth_deg = 150.0;
  s.keyframes.front().weather = w;
  s.keyframes.front().wipers = WiperState{WiperMode::kIntermittent, 6.0, {}};
  return s;
}

Update behind_truck(const Scenario& scenario, double t, double gap_m) {
  Update u = scenario.at(t);
  if (!u.vehicle) return u;
  const double speed = std::max(glm::length(u.vehicle->velocity_mps), 1.0);
  TrafficVehicle truck;
  truck.id = 1;
  truck.state = scenario.at(t + gap_m / speed).vehicle.value_or(*u.vehicle);
  truck.size_m = kBehindTruckSize_m;
  truck.vehicle_class = VehicleClass::kTruck;
  u.traffic = std::vector<TrafficVehicle>{truck};
  return u;
}

}  // namespace downpour::sim
