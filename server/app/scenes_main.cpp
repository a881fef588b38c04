// Writes the standard scenes to JSON files (clients/scenarios/), from their one definition in
// server/sim/scenario.cpp; the built-in track as an OpenDRIVE file; or the weather's fields
// (server/sim/weather.hpp) as the Python client's module and the docs' table. Usage:
//   downpour-scenes OUTPUT_DIR
//   downpour-scenes --xodr FILE
//   downpour-scenes --weather PYTHON_FILE MARKDOWN_FILE
//   downpour-scenes --sample SCENARIO_FILE STEP_S   (the C++ reader's updates, JSON on stdout)
#include <charconv>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "server/sim/scenario.hpp"
#include "server/sim/track_opendrive.hpp"
#include "server/sim/weather.hpp"

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

// The shortest text that reads back as the same double, always with a point or an exponent.
std::string real(double v) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, v).ptr;
  std::string text(buffer, end);
  if (text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}

std::string_view interpolation_name(downpour::sim::Interpolation i) {
  switch (i) {
    case downpour::sim::Interpolation::kAngle:
      return "angle";
    case downpour::sim::Interpolation::kRound:
      return "round";
    case downpour::sim::Interpolation::kLinear:
      break;
  }
  return "linear";
}

std::string weather_python() {
  std::ostringstream out;
  out << "\"\"\"The weather's fields, as server/sim/weather.hpp defines them.\n\n"
         "Written by `build/downpour-scenes --weather`; do not edit (a test compares it with the\n"
         "definition). interpolation: linear; angle (a + remainder(b - a, 360) * f); round "
         "(linear,\n"
         "to the nearest whole number).\n\"\"\"\n\n"
         "FIELDS = (\n";
  for (const auto& f : downpour::sim::kWeatherFields) {
    out << "    {\"name\": \"" << f.name << "\", \"unit\": \"" << f.unit
        << "\", \"min\": " << real(f.min) << ", \"max\": " << real(f.max)
        << ", \"default\": " << real(f.fallback) << ",\n     \"interpolation\": \""
        << interpolation_name(f.interpolation)
        << "\", \"integer\": " << (f.integer ? "True" : "False") << ",\n     \"meaning\": \""
        << f.meaning << "\"},\n";
  }
  out << ")\n";
  return out.str();
}

// Numbers as people write them: 500, 0.2, -360.
std::string plain(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string weather_markdown() {
  std::ostringstream out;
  out << "| `Weather` field | unit | range | default | between keyframes | meaning |\n"
         "|---|---|---|---|---|---|\n";
  for (const auto& f : downpour::sim::kWeatherFields) {
    out << "| `" << f.name << "` | " << (f.unit.empty() ? "–" : f.unit) << " | [" << plain(f.min)
        << ", " << plain(f.max) << "] | " << plain(f.fallback) << " | "
        << interpolation_name(f.interpolation) << " | " << f.meaning << " |\n";
  }
  return out.str();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--xodr") {
    return write(argv[2], downpour::sim::track_to_opendrive(downpour::sim::Track::built_in())) ? 0
                                                                                               : 1;
  }
  if (argc == 4 && std::string(argv[1]) == "--sample") {
    std::ifstream in(argv[2]);
    std::stringstream text;
    text << in.rdbuf();
    try {
      const double step = std::stod(argv[3]);
      if (!(step > 0.0)) throw std::runtime_error("STEP_S must be > 0");
      std::cout << downpour::sim::Scenario::from_json(text.str()).samples_json(step);
    } catch (const std::exception& e) {
      std::cerr << argv[2] << ": " << e.what() << "\n";
      return 1;
    }
    return 0;
  }
  if (argc == 4 && std::string(argv[1]) == "--weather") {
    return write(argv[2], weather_python()) && write(argv[3], weather_markdown()) ? 0 : 1;
  }
  if (argc != 2) {
    std::cerr << "usage: downpour-scenes OUTPUT_DIR | --xodr FILE | --weather PYTHON_FILE "
                 "MARKDOWN_FILE | --sample SCENARIO_FILE STEP_S\n";
    return 2;
  }
  for (const auto& scenario :
       {downpour::sim::highway_heavy_rain(), downpour::sim::city_drizzle()}) {
    if (!write(std::string(argv[1]) + "/" + scenario.name + ".json", scenario.to_json())) return 1;
  }
  return 0;
}
