// Writes the standard scenes to JSON files (clients/scenarios/), from their one definition in
// server/sim/scenario.cpp. Usage: downpour-scenes OUTPUT_DIR
#include <fstream>
#include <iostream>

#include "server/sim/scenario.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: downpour-scenes OUTPUT_DIR\n";
    return 2;
  }
  for (const auto& scenario :
       {downpour::sim::highway_heavy_rain(), downpour::sim::city_drizzle()}) {
    const std::string path = std::string(argv[1]) + "/" + scenario.name + ".json";
    std::ofstream out(path);
    out << scenario.to_json();
    if (!out) {
      std::cerr << "cannot write " << path << "\n";
      return 1;
    }
    std::cout << path << "\n";
  }
  return 0;
}
