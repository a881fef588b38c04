// The roads a CreateSession asks for (the contract's RoadNetwork): OpenDRIVE text inline, or a map
// from the server's --maps-dir by name (never a path). Parsed within the parser's limits; a bad
// file is INVALID_ARGUMENT naming the element and the line. Sessions that ask for the same map
// (or the same text) share one network, and so the renderer's one world for it, while any holds
// it.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include <grpcpp/support/status.h>

#include "downpour/v1/downpour.pb.h"
#include "server/road/opendrive.hpp"
#include "server/sim/road_network.hpp"

namespace downpour::rpc {

struct LoadedRoads {
  std::shared_ptr<const sim::RoadNetwork> roads;  // null: the built-in track
  std::string name;                               // SessionInfo.road_network
};

class RoadNetworks {
 public:
  // maps_dir empty: no maps, inline text only.
  explicit RoadNetworks(std::string maps_dir = {}, road::Limits limits = {});

  // field: the request's field, for the status's message.
  grpc::Status load(const v1::RoadNetwork& in, const std::string& field, LoadedRoads* out);
  // Whether a map name is one the server may open: a plain file name.
  static bool valid_map_name(const std::string& name);

 private:
  std::shared_ptr<const sim::RoadNetwork> parse(const std::string& key, const std::string& text,
                                                const std::string& field, grpc::Status* status);

  std::string maps_dir_;
  road::Limits limits_;
  std::mutex mutex_;
  struct Cached {
    std::weak_ptr<const sim::RoadNetwork> roads;
    std::string text;  // what was parsed, to tell it from another text of the same key
  };
  std::map<std::string, Cached> cache_;
};

}  // namespace downpour::rpc
