#include "server/rpc/road_networks.hpp"

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <system_error>

#include <spdlog/spdlog.h>

#include "server/sim/file_name.hpp"
#include "server/sim/opendrive_roads.hpp"

namespace downpour::rpc {

namespace {

constexpr std::size_t kMaxMapName = 128;

grpc::Status invalid(const std::string& field, const std::string& what) {
  return {grpc::StatusCode::INVALID_ARGUMENT, field + ": " + what};
}

}  // namespace

RoadNetworks::RoadNetworks(std::string maps_dir, road::Limits limits)
    : maps_dir_(std::move(maps_dir)), limits_(limits) {}

bool RoadNetworks::valid_map_name(const std::string& name) {
  return sim::plain_file_name(name, kMaxMapName);
}

std::shared_ptr<const sim::RoadNetwork> RoadNetworks::parse(const std::string& key,
                                                            const std::string& text,
                                                            const std::string& field,
                                                            grpc::Status* status) {
  // A hit is the same text, compared whole (a hash alone could be made to collide, giving one
  // client another's roads).
  auto same = [&](const Cached& c) { return c.text == text; };
  {
    std::lock_guard lock(mutex_);
    std::erase_if(cache_, [](const auto& e) { return e.second.roads.expired(); });
    if (const auto it = cache_.find(key); it != cache_.end() && same(it->second)) {
      if (auto roads = it->second.roads.lock()) return roads;
    }
  }
  // Parsed outside the lock: a large file does not hold up another session's.
  std::shared_ptr<const sim::RoadNetwork> roads;
  try {
    roads = std::make_shared<const sim::OpenDriveRoads>(road::parse_opendrive(text, limits_));
  } catch (const road::ParseError& e) {
    *status =
        invalid(field, "<" + e.element() + "> line " + std::to_string(e.line()) + ": " + e.what());
    return nullptr;
  } catch (const std::exception& e) {
    *status = invalid(field, e.what());
    return nullptr;
  }
  std::lock_guard lock(mutex_);
  if (const auto it = cache_.find(key); it != cache_.end() && same(it->second)) {
    if (auto first = it->second.roads.lock()) return first;  // parsed meanwhile by another request
  }
  cache_[key] = {roads, text};
  return roads;
}

grpc::Status RoadNetworks::load(const v1::RoadNetwork& in, const std::string& field,
                                LoadedRoads* out) {
  *out = {};
  grpc::Status status;
  switch (in.source_case()) {
    case v1::RoadNetwork::SOURCE_NOT_SET:
      out->name = "built-in track";
      return grpc::Status::OK;
    case v1::RoadNetwork::kOpendriveXml: {
      const std::string& text = in.opendrive_xml();
      const std::string key = "inline:" + std::to_string(text.size()) + ":" +
                              std::to_string(std::hash<std::string>{}(text));
      out->roads = parse(key, text, field + ".opendrive_xml", &status);
      out->name = "inline";
      return out->roads ? grpc::Status::OK : status;
    }
    case v1::RoadNetwork::kMapName: {
      const std::string& name = in.map_name();
      const std::string name_field = field + ".map_name";
      if (!valid_map_name(name)) {
        return invalid(name_field,
                       "a map's name is a file name in the server's maps directory (letters, "
                       "digits, '_', '-', '.'; not starting with '.'), got \"" +
                           name.substr(0, kMaxMapName) + "\"");
      }
      if (maps_dir_.empty()) {
        return {grpc::StatusCode::FAILED_PRECONDITION,
                name_field + ": this server has no maps (start it with --maps-dir)"};
      }
      namespace fs = std::filesystem;
      std::error_code ec;
      fs::path path = fs::path(maps_dir_) / name;
      if (!fs::is_regular_file(path, ec)) path = fs::path(maps_dir_) / (name + ".xodr");
      if (!fs::is_regular_file(path, ec)) {
        return {grpc::StatusCode::NOT_FOUND, name_field + ": no map \"" + name + "\""};
      }
      const auto size = fs::file_size(path, ec);
      if (ec || size > limits_.max_bytes) {
        return invalid(name_field, "the map's file is larger than " +
                                       std::to_string(limits_.max_bytes) + " bytes");
      }
      const auto written = fs::last_write_time(path, ec).time_since_epoch().count();
      const std::string key = "map:" + path.filename().string() + ":" + std::to_string(size) + ":" +
                              std::to_string(written);
      std::ifstream file(path, std::ios::binary);
      std::stringstream text;
      text << file.rdbuf();
      if (!file) return {grpc::StatusCode::INTERNAL, name_field + ": the map could not be read"};
      out->roads = parse(key, text.str(), name_field, &status);
      out->name = "map:" + name;
      return out->roads ? grpc::Status::OK : status;
    }
  }
  return invalid(field, "no source");
}

}  // namespace downpour::rpc
