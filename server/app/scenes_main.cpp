// Writes the standard scenes to JSON files (clients/scenarios/), from their one definition in
// server/sim/scenario.cpp; or the built-in track as an OpenDRIVE file. Usage:
//   downpour-scenes OUTPUT_DIR
//   downpour-scenes --xodr FILE
#include <fstream>
#include <iostream>
#include <string>

#include "server/sim/scenario.hpp"
#include "server/sim/track_opendrive.hpp"

namespace {

bool write(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) {
    std::cerr << "cannot write " << path << "\n";
    return false;
  }
  std::cout << path << "\n";
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--xodr") {
    return write(argv[2], downpour::sim::track_to_opendrive(downpour::sim::Track::built_in())) ? 0
                                                                                               : 1;
  }
  if (argc != 2) {
    std::cerr << "usage: downpour-scenes OUTPUT_DIR | downpour-scenes --xodr FILE\n";
    return 2;
  }
  for (const auto& scenario :
       {downpour::sim::highway_heavy_rain(), downpour::sim::city_drizzle()}) {
    if (!write(std::string(argv[1]) + "/" + scenario.name + ".json", scenario.to_json())) return 1;
  }
  return 0;
}
