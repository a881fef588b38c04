#include "server/rpc/validation.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <set>
#include <sstream>

#include "server/encode/image_decoder.hpp"
#include "server/model/model_library.hpp"
#include "server/sim/file_name.hpp"
#include "server/sim/vehicle_class.hpp"

namespace downpour::rpc {
namespace {

std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

grpc::Status invalid(const std::string& field, const std::string& what) {
  return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, field + ": " + what);
}

grpc::Status in_range(double v, double lo, double hi, const std::string& field) {
  if (!std::isfinite(v)) return invalid(field, "must be a finite number, got " + number_text(v));
  if (v < lo || v > hi) {
    return invalid(field, "must be in [" + number_text(lo) + ", " + number_text(hi) + "], got " +
                              number_text(v));
  }
  return grpc::Status::OK;
}

bool to_view(int in, sim::View* out) {
  switch (in) {
    case v1::VIEW_COCKPIT:
      *out = sim::View::kCockpit;
      return true;
    case v1::VIEW_ROAD:
      *out = sim::View::kRoad;
      return true;
    case v1::VIEW_WINDSHIELD:
      *out = sim::View::kWindshield;
      return true;
    case v1::VIEW_RAIN:
      *out = sim::View::kRain;
      return true;
    default:
      return false;
  }
}

#define DP_RETURN_IF_ERROR(expr)         \
  do {                                   \
    const grpc::Status status_ = (expr); \
    if (!status_.ok()) return status_;   \
  } while (0)

grpc::Status to_vec3(const v1::Vec3& in, double limit, const std::string& field, glm::dvec3* out) {
  DP_RETURN_IF_ERROR(in_range(in.x(), -limit, limit, field + ".x"));
  DP_RETURN_IF_ERROR(in_range(in.y(), -limit, limit, field + ".y"));
  DP_RETURN_IF_ERROR(in_range(in.z(), -limit, limit, field + ".z"));
  *out = glm::dvec3(in.x(), in.y(), in.z());
  return grpc::Status::OK;
}

grpc::Status to_rotation(const v1::Rotation& in, const std::string& field, sim::Rotation* out) {
  DP_RETURN_IF_ERROR(in_range(in.yaw_deg(), -3600.0, 3600.0, field + ".yaw_deg"));
  DP_RETURN_IF_ERROR(in_range(in.pitch_deg(), -90.0, 90.0, field + ".pitch_deg"));
  DP_RETURN_IF_ERROR(in_range(in.roll_deg(), -180.0, 180.0, field + ".roll_deg"));
  *out = {in.yaw_deg(), in.pitch_deg(), in.roll_deg()};
  return grpc::Status::OK;
}

grpc::Status to_vehicle(const v1::VehicleState& in, const std::string& field,
                        sim::VehicleState* out) {
  DP_RETURN_IF_ERROR(to_vec3(in.position_m(), 1e6, field + ".position_m", &out->position_m));
  DP_RETURN_IF_ERROR(to_rotation(in.rotation(), field + ".rotation", &out->rotation));
  DP_RETURN_IF_ERROR(
      to_vec3(in.velocity_mps(), 150.0, field + ".velocity_mps", &out->velocity_mps));
  out->lights.reset();
  if (in.has_lights()) {
    const v1::VehicleLights& l = in.lights();
    sim::VehicleLights lights;
    switch (l.headlights()) {
      case v1::HEADLIGHTS_AUTO:
        lights.headlights = sim::Headlights::kAuto;
        break;
      case v1::HEADLIGHTS_OFF:
        lights.headlights = sim::Headlights::kOff;
        break;
      case v1::HEADLIGHTS_LOW:
        lights.headlights = sim::Headlights::kLow;
        break;
      case v1::HEADLIGHTS_HIGH:
        lights.headlights = sim::Headlights::kHigh;
        break;
      default:
        return invalid(field + ".lights.headlights",
                       "must be one of HEADLIGHTS_AUTO, HEADLIGHTS_OFF, HEADLIGHTS_LOW, "
                       "HEADLIGHTS_HIGH, got " +
                           std::to_string(l.headlights()));
    }
    lights.brake = l.brake();
    lights.left_indicator = l.left_indicator();
    lights.right_indicator = l.right_indicator();
    lights.reverse = l.reverse();
    out->lights = lights;
  }
  return grpc::Status::OK;
}

grpc::Status to_wipers(const v1::WiperState& in, const std::string& field, sim::WiperState* out) {
  switch (in.mode()) {
    case v1::WIPER_OFF:
      out->mode = sim::WiperMode::kOff;
      break;
    case v1::WIPER_INTERMITTENT:
      out->mode = sim::WiperMode::kIntermittent;
      break;
    case v1::WIPER_LOW:
      out->mode = sim::WiperMode::kLow;
      break;
    case v1::WIPER_HIGH:
      out->mode = sim::WiperMode::kHigh;
      break;
    case v1::WIPER_SINGLE:
      out->mode = sim::WiperMode::kSingle;
      break;
    case v1::WIPER_MANUAL:
      out->mode = sim::WiperMode::kManual;
      break;
    default:
      return invalid(field + ".mode",
                     "must be one of WIPER_OFF, WIPER_INTERMITTENT, WIPER_LOW, WIPER_HIGH, "
                     "WIPER_SINGLE, WIPER_MANUAL, got " +
                         std::to_string(in.mode()));
  }
  if (in.interval_s() != 0.0 || !std::isfinite(in.interval_s())) {
    DP_RETURN_IF_ERROR(in_range(in.interval_s(), 0.5, 60.0, field + ".interval_s"));
  }
  out->interval_s = in.interval_s() > 0.0 ? in.interval_s() : 4.0;
  if (in.blade_angle_deg_size() > 2) {
    return invalid(field + ".blade_angle_deg",
                   "at most 2 blades, got " + std::to_string(in.blade_angle_deg_size()));
  }
  if (out->mode == sim::WiperMode::kManual && in.blade_angle_deg_size() == 0) {
    return invalid(field + ".blade_angle_deg", "WIPER_MANUAL needs at least one blade angle");
  }
  out->blade_angle_deg.clear();
  for (int i = 0; i < in.blade_angle_deg_size(); ++i) {
    DP_RETURN_IF_ERROR(in_range(in.blade_angle_deg(i), 0.0, 180.0,
                                field + ".blade_angle_deg[" + std::to_string(i) + "]"));
    out->blade_angle_deg.push_back(in.blade_angle_deg(i));
  }
  return grpc::Status::OK;
}

// The contract's field for each of sim/weather.hpp's, found by its name once (a unit test checks
// that the two lists agree; a name missing from the contract stays null).
const std::array<const google::protobuf::FieldDescriptor*, sim::kWeatherFields.size()>&
weather_wire_fields() {
  static const auto fields = [] {
    std::array<const google::protobuf::FieldDescriptor*, sim::kWeatherFields.size()> found{};
    for (std::size_t i = 0; i < found.size(); ++i)
      found[i] =
          v1::Weather::descriptor()->FindFieldByName(std::string(sim::kWeatherFields[i].name));
    return found;
  }();
  return fields;
}

grpc::Status to_weather(const v1::Weather& in, const std::string& f, sim::Weather* out) {
  const google::protobuf::Reflection* reflection = in.GetReflection();
  sim::Weather w;
  for (std::size_t i = 0; i < sim::kWeatherFields.size(); ++i) {
    const sim::WeatherField& field = sim::kWeatherFields[i];
    const google::protobuf::FieldDescriptor* wire = weather_wire_fields()[i];
    if (wire == nullptr) {
      return grpc::Status(grpc::StatusCode::INTERNAL,
                          "weather field " + std::string(field.name) + " is not in the contract");
    }
    const double v = wire->cpp_type() == google::protobuf::FieldDescriptor::CPPTYPE_UINT32
                         ? reflection->GetUInt32(in, wire)
                         : reflection->GetDouble(in, wire);
    DP_RETURN_IF_ERROR(in_range(v, field.min, field.max, f + "." + std::string(field.name)));
    field.set(w, v);
  }
  *out = w;
  return grpc::Status::OK;
}

}  // namespace

grpc::Status to_update(const v1::Update& in, const std::string& field, const Limits& limits,
                       sim::Update* out) {
  DP_RETURN_IF_ERROR(in_range(in.sim_time_s(), -1e9, 1e9, field + ".sim_time_s"));
  sim::Update u;
  u.client_time_s = in.sim_time_s();
  if (in.has_vehicle()) {
    u.vehicle.emplace();
    DP_RETURN_IF_ERROR(to_vehicle(in.vehicle(), field + ".vehicle", &*u.vehicle));
  }
  if (in.has_wipers()) {
    u.wipers.emplace();
    DP_RETURN_IF_ERROR(to_wipers(in.wipers(), field + ".wipers", &*u.wipers));
  }
  if (in.has_weather()) {
    u.weather.emplace();
    DP_RETURN_IF_ERROR(to_weather(in.weather(), field + ".weather", &*u.weather));
  }
  if (in.traffic_size() > limits.max_traffic) {
    return invalid(field + ".traffic", "at most " + std::to_string(limits.max_traffic) +
                                           " vehicles, got " + std::to_string(in.traffic_size()));
  }
  if (in.replace_traffic() || in.traffic_size() > 0) {
    u.traffic.emplace();
    for (int i = 0; i < in.traffic_size(); ++i) {
      const std::string tf = field + ".traffic[" + std::to_string(i) + "]";
      const v1::TrafficVehicle& t = in.traffic(i);
      sim::TrafficVehicle v;
      v.id = t.id();
      DP_RETURN_IF_ERROR(to_vehicle(t.state(), tf + ".state", &v.state));
      switch (t.vehicle_class()) {
        case v1::VEHICLE_CLASS_UNSPECIFIED:
        case v1::VEHICLE_CLASS_CAR:
          v.vehicle_class = sim::VehicleClass::kCar;
          break;
        case v1::VEHICLE_CLASS_TRUCK:
          v.vehicle_class = sim::VehicleClass::kTruck;
          break;
        case v1::VEHICLE_CLASS_BUS:
          v.vehicle_class = sim::VehicleClass::kBus;
          break;
        case v1::VEHICLE_CLASS_MOTORBIKE:
          v.vehicle_class = sim::VehicleClass::kMotorbike;
          break;
        default:
          return invalid(tf + ".vehicle_class",
                         "unknown class " + std::to_string(t.vehicle_class()));
      }
      if (!t.model().empty() && !sim::plain_file_name(t.model()))
        return invalid(tf + ".model", model::ModelLibrary::name_rule(t.model()));
      v.size_m = sim::vehicle_layout(v.vehicle_class).size_m;
      if (t.has_size_m()) {
        glm::dvec3 size;
        DP_RETURN_IF_ERROR(to_vec3(t.size_m(), 30.0, tf + ".size_m", &size));
        if (size.x > 0.0 && size.y > 0.0 && size.z > 0.0) v.size_m = size;
      }
      u.traffic->push_back(v);
    }
  }
  *out = std::move(u);
  return grpc::Status::OK;
}

grpc::Status to_view_spec(const v1::ViewSpec& in, const std::string& field, const Limits& limits,
                          sim::ViewSpec* out) {
  if (!to_view(in.view(), &out->view)) {
    return invalid(field + ".view",
                   "must be one of VIEW_COCKPIT, VIEW_ROAD, VIEW_WINDSHIELD, VIEW_RAIN, got " +
                       std::to_string(in.view()));
  }
  DP_RETURN_IF_ERROR(in_range(in.width(), 16, limits.max_width, field + ".width"));
  DP_RETURN_IF_ERROR(in_range(in.height(), 16, limits.max_height, field + ".height"));
  out->width = static_cast<int>(in.width());
  out->height = static_cast<int>(in.height());
  if (in.jpeg_quality() != 0)
    DP_RETURN_IF_ERROR(in_range(in.jpeg_quality(), 1, 100, field + ".jpeg_quality"));
  out->jpeg_quality = in.jpeg_quality() == 0 ? 85 : static_cast<int>(in.jpeg_quality());
  if (in.fov_deg() != 0.0 || !std::isfinite(in.fov_deg())) {
    DP_RETURN_IF_ERROR(in_range(in.fov_deg(), 1.0, 170.0, field + ".fov_deg"));
  }
  out->fov_deg = in.fov_deg();
  if (in.has_camera_position_m() || in.has_camera_rotation()) {
    // (WINDSHIELD over a client's pictures looks through the glass from the pictures' camera.)
    const bool picture_windshield =
        out->view == sim::View::kWindshield && in.background() == v1::BACKGROUND_CLIENT;
    if (out->view != sim::View::kRoad && out->view != sim::View::kCockpit && !picture_windshield) {
      return invalid(field + ".camera_position_m",
                     "a camera pose is for VIEW_ROAD, VIEW_COCKPIT and a VIEW_WINDSHIELD whose "
                     "background is BACKGROUND_CLIENT");
    }
    sim::CameraPose pose;
    DP_RETURN_IF_ERROR(
        to_vec3(in.camera_position_m(), 100.0, field + ".camera_position_m", &pose.position_m));
    DP_RETURN_IF_ERROR(
        to_rotation(in.camera_rotation(), field + ".camera_rotation", &pose.rotation));
    out->camera = pose;
  }
  // The lens applies to every view; those without glass in sight ignore it.
  if (in.has_focus_distance_m()) {
    DP_RETURN_IF_ERROR(in_range(in.focus_distance_m(), 0.05, 10000.0, field + ".focus_distance_m"));
    out->focus_distance_m = in.focus_distance_m();
  }
  if (in.has_aperture_mm()) {
    DP_RETURN_IF_ERROR(in_range(in.aperture_mm(), 0.0, 50.0, field + ".aperture_mm"));
    out->aperture_mm = in.aperture_mm();
  }
  if (in.has_exposure_s()) {
    DP_RETURN_IF_ERROR(in_range(in.exposure_s(), 0.0, 0.25, field + ".exposure_s"));
    out->exposure_s = in.exposure_s();
  }
  switch (in.background()) {
    case v1::BACKGROUND_RENDERED:
      out->background = sim::Background::kRendered;
      break;
    case v1::BACKGROUND_CLIENT:
      if (out->view == sim::View::kRain)
        return invalid(field + ".background", "VIEW_RAIN is the rain over black: no background");
      out->background = sim::Background::kClient;
      break;
    default:
      return invalid(field + ".background",
                     "must be BACKGROUND_RENDERED or BACKGROUND_CLIENT, got " +
                         std::to_string(in.background()));
  }
  if (in.haze() && out->background != sim::Background::kClient) {
    return invalid(field + ".haze",
                   "is for a view over a client's pictures (BACKGROUND_CLIENT): the server's own "
                   "world always has its haze");
  }
  out->haze = in.haze();
  for (int i = 0; i < in.outputs_size(); ++i) {
    const std::string f = field + ".outputs[" + std::to_string(i) + "]";
    bool* wanted = nullptr;
    switch (in.outputs(i)) {
      case v1::OUTPUT_CLEAN:
        wanted = &out->outputs.clean;
        break;
      case v1::OUTPUT_WATER_MASK:
        wanted = &out->outputs.water_mask;
        break;
      case v1::OUTPUT_DEPTH:
        if (out->background == sim::Background::kClient)
          return invalid(f,
                         "OUTPUT_DEPTH is for views of the server's world: a client's "
                         "picture's depth is the client's own");
        wanted = &out->outputs.depth;
        break;
      default:
        return invalid(f, "must be OUTPUT_CLEAN, OUTPUT_WATER_MASK or OUTPUT_DEPTH, got " +
                              std::to_string(in.outputs(i)));
    }
    if (*wanted) return invalid(f, v1::Output_Name(in.outputs(i)) + " is asked for twice");
    *wanted = true;
  }
  if (out->outputs.any() && out->view == sim::View::kWindshield &&
      out->background == sim::Background::kRendered) {
    return invalid(field + ".outputs",
                   "VIEW_WINDSHIELD over the server's world is itself the water's ground truth: "
                   "no outputs");
  }
  return grpc::Status::OK;
}

namespace {

// A client image's depth in metres along the view's axis, 0 for the sky or unknown.
grpc::Status to_depth(const v1::ClientImage& in, const std::string& field, int width, int height,
                      std::vector<float>* out) {
  const std::string& bytes = in.depth();
  try {
    switch (in.depth_encoding()) {
      case v1::DEPTH_PNG16_CM: {
        const encode::Grey16Pixels d = encode::decode_png_grey16(bytes, width, height);
        out->resize(d.values.size());
        for (std::size_t i = 0; i < d.values.size(); ++i) (*out)[i] = 0.01f * d.values[i];
        return grpc::Status::OK;
      }
      case v1::DEPTH_CARLA_RGB: {
        if (!encode::is_png(bytes))
          return invalid(field + ".depth", "DEPTH_CARLA_RGB must be a PNG (JPEG rounds it)");
        const encode::BgrxPixels d = encode::decode_bgrx(bytes, width, height);
        out->resize(static_cast<std::size_t>(width) * height);
        for (std::size_t i = 0; i < out->size(); ++i) {
          const std::uint8_t* p = &d.bgrx[i * 4];
          const std::uint32_t v = p[2] + 256u * p[1] + 65536u * p[0];  // (B G R X)
          // Full scale is CARLA's sky.
          (*out)[i] = v >= 0xfffff0u ? 0.0f : static_cast<float>(1000.0 * v / 16777215.0);
        }
        return grpc::Status::OK;
      }
      default:
        return invalid(field + ".depth_encoding",
                       "a depth needs DEPTH_PNG16_CM or DEPTH_CARLA_RGB, got " +
                           std::to_string(in.depth_encoding()));
    }
  } catch (const encode::DecodeError& e) {
    return invalid(field + ".depth", e.what());
  }
}

}  // namespace

grpc::Status to_client_images(const v1::Update& in, const std::string& field,
                              const std::vector<sim::ViewSpec>& views, sim::Update* out) {
  static std::atomic<std::uint64_t> serial{0};
  sim::ClientImages images{};
  for (int i = 0; i < in.client_images_size(); ++i) {
    const v1::ClientImage& c = in.client_images(i);
    const std::string f = field + ".client_images[" + std::to_string(i) + "]";
    sim::View view{};
    const bool known = to_view(c.view(), &view);
    const auto spec = std::find_if(views.begin(), views.end(),
                                   [&](const sim::ViewSpec& v) { return known && v.view == view; });
    if (spec == views.end())
      return invalid(f + ".view", "the session has no view " + std::to_string(c.view()));
    if (spec->background != sim::Background::kClient) {
      return invalid(f + ".view", v1::View_Name(c.view()) +
                                      " draws the server's world (BACKGROUND_RENDERED): create the "
                                      "session with its background BACKGROUND_CLIENT to send it "
                                      "pictures");
    }
    const auto v = static_cast<std::size_t>(spec->view);
    if (images[v]) return invalid(f + ".view", "at most one picture a view in an update");
    auto image = std::make_shared<sim::ClientImage>();
    try {
      encode::BgrxPixels bgrx = encode::decode_bgrx(c.image(), spec->width, spec->height);
      image->bgrx = std::move(bgrx.bgrx);
    } catch (const encode::DecodeError& e) {
      return invalid(f + ".image", e.what());
    }
    image->width = spec->width;
    image->height = spec->height;
    if (!c.depth().empty()) {
      DP_RETURN_IF_ERROR(to_depth(c, f, spec->width, spec->height, &image->depth_m));
    } else if (c.depth_encoding() != v1::DEPTH_ENCODING_UNSPECIFIED) {
      return invalid(f + ".depth", "empty, but a depth_encoding is given");
    }
    image->serial = ++serial;
    images[v] = std::move(image);
  }
  for (std::size_t v = 0; v < images.size(); ++v) {
    if (images[v]) out->client_images[v] = std::move(images[v]);
  }
  return grpc::Status::OK;
}

grpc::Status check_glass(const sim::GlassConfig& g, const std::string& field) {
  DP_RETURN_IF_ERROR(in_range(g.bottom_width_mm, 800.0, 2400.0, field + ".bottom_width_mm"));
  DP_RETURN_IF_ERROR(in_range(g.top_width_mm, 500.0, g.bottom_width_mm, field + ".top_width_mm"));
  DP_RETURN_IF_ERROR(in_range(g.height_mm, 300.0, 1500.0, field + ".height_mm"));
  DP_RETURN_IF_ERROR(in_range(g.rake_deg, 0.0, 75.0, field + ".rake_deg"));
  DP_RETURN_IF_ERROR(in_range(g.bottom_left_m.x, 0.5, 4.0, field + ".bottom_left_m.x"));
  DP_RETURN_IF_ERROR(in_range(g.bottom_left_m.y, 0.0, 1.2, field + ".bottom_left_m.y"));
  DP_RETURN_IF_ERROR(in_range(g.bottom_left_m.z, 0.5, 1.8, field + ".bottom_left_m.z"));
  return grpc::Status::OK;
}

grpc::Status to_ego(const v1::EgoVehicle& in, const std::string& field, sim::EgoGeometry* out,
                    sim::GlassConfig* glass) {
  sim::EgoGeometry ego;
  for (const auto& [name, f] :
       {std::pair{&in.body_model(), ".body_model"}, std::pair{&in.cabin_model(), ".cabin_model"}}) {
    if (!name->empty() && !sim::plain_file_name(*name))
      return invalid(field + f, model::ModelLibrary::name_rule(*name));
  }
  if (in.has_windshield()) {
    const v1::Windshield& w = in.windshield();
    sim::GlassConfig g;
    g.bottom_width_mm = w.bottom_width_mm();
    g.top_width_mm = w.top_width_mm();
    g.height_mm = w.height_mm();
    g.rake_deg = w.rake_deg();
    g.bottom_left_m = {w.bottom_left_m().x(), w.bottom_left_m().y(), w.bottom_left_m().z()};
    DP_RETURN_IF_ERROR(check_glass(g, field + ".windshield"));
    *glass = g;
  }
  auto given = [](const v1::Vec3& v) { return v.x() != 0.0 || v.y() != 0.0 || v.z() != 0.0; };
  if (given(in.size_m())) {
    DP_RETURN_IF_ERROR(in_range(in.size_m().x(), 2.0, 20.0, field + ".size_m.x"));
    DP_RETURN_IF_ERROR(in_range(in.size_m().y(), 1.0, 3.5, field + ".size_m.y"));
    DP_RETURN_IF_ERROR(in_range(in.size_m().z(), 1.0, 5.0, field + ".size_m.z"));
    ego.size_m = {in.size_m().x(), in.size_m().y(), in.size_m().z()};
  }
  if (in.wheelbase_m() != 0.0 || !std::isfinite(in.wheelbase_m())) {
    DP_RETURN_IF_ERROR(in_range(in.wheelbase_m(), 1.0, 0.9 * ego.size_m.x, field + ".wheelbase_m"));
    ego.wheelbase_m = in.wheelbase_m();
  }
  if (in.track_m() != 0.0 || !std::isfinite(in.track_m())) {
    DP_RETURN_IF_ERROR(in_range(in.track_m(), 0.8, ego.size_m.y, field + ".track_m"));
    ego.track_m = in.track_m();
  }
  if (given(in.eye_m())) {
    // Within the cabin (the default car's, whatever the size): behind the windshield, under the
    // roof.
    DP_RETURN_IF_ERROR(in_range(in.eye_m().x(), 0.6, 1.6, field + ".eye_m.x"));
    DP_RETURN_IF_ERROR(in_range(in.eye_m().y(), -0.6, 0.6, field + ".eye_m.y"));
    DP_RETURN_IF_ERROR(in_range(in.eye_m().z(), 0.9, 1.35, field + ".eye_m.z"));
    ego.eye_m = {in.eye_m().x(), in.eye_m().y(), in.eye_m().z()};
  }
  *out = ego;
  return grpc::Status::OK;
}

grpc::Status to_session_config(const v1::CreateSessionRequest& in, const Limits& limits,
                               session::SessionConfig* config, sim::Update* initial) {
  if (in.views_size() == 0) return invalid("views", "at least one view is needed");
  if (in.views_size() > limits.max_views) {
    return invalid("views", "at most " + std::to_string(limits.max_views) + " views, got " +
                                std::to_string(in.views_size()));
  }
  session::SessionConfig c;
  std::set<sim::View> seen;
  for (int i = 0; i < in.views_size(); ++i) {
    const std::string field = "views[" + std::to_string(i) + "]";
    sim::ViewSpec spec;
    DP_RETURN_IF_ERROR(to_view_spec(in.views(i), field, limits, &spec));
    if (!seen.insert(spec.view).second)
      return invalid(field + ".view", "each view at most once per session");
    c.views.push_back(spec);
  }
  switch (in.mode()) {
    case v1::MODE_UNSPECIFIED:
    case v1::MODE_REALTIME:
      c.mode = sim::Mode::kRealtime;
      break;
    case v1::MODE_LOCKSTEP:
      c.mode = sim::Mode::kLockstep;
      break;
    default:
      return invalid("mode",
                     "must be MODE_REALTIME or MODE_LOCKSTEP, got " + std::to_string(in.mode()));
  }
  if (in.fps() != 0.0 || !std::isfinite(in.fps()))
    DP_RETURN_IF_ERROR(in_range(in.fps(), 0.1, limits.max_fps, "fps"));
  c.fps = in.fps() > 0.0 ? in.fps() : 30.0;
  c.seed = in.seed();
  DP_RETURN_IF_ERROR(to_ego(in.ego(), "ego", &c.ego, &c.glass));
  for (sim::ViewSpec& spec : c.views) spec.eye_m = c.ego.eye_m;
  DP_RETURN_IF_ERROR(to_update(in.initial(), "initial", limits, initial));
  DP_RETURN_IF_ERROR(to_client_images(in.initial(), "initial", c.views, initial));
  *config = std::move(c);
  return grpc::Status::OK;
}

grpc::Status check_dt(double dt_s, const std::string& field, bool allow_zero,
                      const Limits& limits) {
  DP_RETURN_IF_ERROR(in_range(dt_s, 0.0, limits.max_dt_s, field));
  if (!allow_zero && dt_s == 0.0)
    return invalid(field, "must be in (0, " + number_text(limits.max_dt_s) + "], got 0");
  return grpc::Status::OK;
}

grpc::Status check_request_size(const google::protobuf::Message& request, const Limits& limits) {
  const std::size_t bytes = request.ByteSizeLong();
  if (bytes <= limits.max_request_bytes) return grpc::Status::OK;
  return grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED,
                      "request: " + std::to_string(bytes) + " bytes, past the server's limit of " +
                          std::to_string(limits.max_request_bytes) +
                          " (its --max-message-mb raises it)");
}

grpc::Status check_session_id(const std::string& id, const std::string& field) {
  if (id.empty()) return invalid(field, "is required");
  if (id.size() > 64) return invalid(field, "is longer than 64 characters");
  return grpc::Status::OK;
}

}  // namespace downpour::rpc
