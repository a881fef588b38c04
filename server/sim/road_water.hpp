// The water on the road (seed 003's water model): rain fills the surface's texture, then stands and
// runs downhill by water level (ground + standing water) to the four neighbours, pools in ruts and
// bowls, and leaves the road at the paved edge; when the rain stops it evaporates. Cells are
// squares of the world's grid in a window that follows the car, so water stays where it fell: a
// cell that leaves the window gives its water to a coarse record, from which the cells take it back
// when they return. Every cubic metre is accounted for (Ledger). No GL.
//
// This is the finest level of the level-of-detail rings the issue asks for (square rings of
// S0 * 2^level around the car); the coarser rings are to come.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>

#include "server/sim/road_surface.hpp"
#include "server/sim/types.hpp"

namespace downpour::sim {

// The window's water as the renderer draws it: per cell, rows along +y, the water on the surface
// and the part of it standing above the texture, both in mm (floats, 2 per cell).
struct RoadWaterImage {
  glm::ivec2 origin{0};  // the window's lower-left cell in the world's grid (RoadWater::origin)
  double cell_m = 0.25;
  int cells = 0;  // per side
  double capacity_mm = 0.5;
  std::vector<float> water_standing_mm;
  float max_standing_mm = 0.0f;
  // Over the paved cells: what the road beyond the window is drawn with, until coarser rings hold
  // it.
  float mean_water_mm = 0.0f;
  float mean_standing_mm = 0.0f;

  // Whether it holds its cells' water (a default one does not).
  bool complete() const {
    return cells > 0 && water_standing_mm.size() >= static_cast<std::size_t>(cells) * cells * 2;
  }
};

struct RoadWaterConfig {
  // S0: a drop's wet spot is a centimetre or two; cells that small around a car would be millions,
  // so the finest cell is a quarter of a metre, finer than a rut (0.7 m wide) or a bowl.
  double cell_m = 0.25;
  int cells = 128;  // the window's side in cells (32 m)
  // What the asphalt's texture holds before water stands on it (macrotexture depth of a dense
  // asphalt is 0.4-1 mm; a film of about half of it fills the pores).
  double capacity_m = 0.0005;
  double wet_m = 0.00002;    // less than this is dry
  double drench_m = 0.0001;  // standing water from which a film shows (less is only wet)
  double puddle_m = 0.002;   // standing water from which a cell is a puddle
  double manning_n = 0.016;  // sheet flow over asphalt (Manning's roughness)
  // Evaporation from a wet road once the rain stops: a few tenths of a millimetre an hour under
  // cloud, more in sun and wind and with traffic; none while it rains (the air is saturated).
  double evaporation_m_per_s = 0.4e-3 / 3600.0;
  double record_m = 2.0;  // the coarse records' cells (a whole number of cells)
  // Out of the window a film keeps running off the road: the time constant of what is left (a film
  // crosses a half-width of 8 m at about 0.1 m/s).
  double film_runoff_s = 60.0;
};

// The state of a cell holding water_m (all of it, m) under these thresholds.
RoadState road_state(double water_m, const RoadWaterConfig& config);

class RoadWater {
 public:
  RoadWater(const RoadSurface& surface, RoadWaterConfig config = {});

  // Centres the window on `centre` (world, m), then advances dt_s under rain_mm_h.
  void step(glm::dvec2 centre, double rain_mm_h, double dt_s);

  // At a world position in the window (else 0): all water on the surface (m of depth),
  // and the part standing above the texture (state_of gives the state).
  double water_m(glm::dvec2 xy) const;
  double standing_m(glm::dvec2 xy) const;
  // Takes up to volume_m3 from the cell at xy (spray); returns what it took.
  double take(glm::dvec2 xy, double volume_m3);

  struct Ledger {
    double rain_in_m3 = 0.0;
    double drained_m3 = 0.0;     // off the paved edge
    double evaporated_m3 = 0.0;  // in the window and in the records
    double thrown_m3 = 0.0;      // taken (spray)
  };
  const Ledger& ledger() const { return ledger_; }
  // Water held in the window and in the records (m^3): rain in = stored + drained + evaporated +
  // thrown.
  double stored_m3() const;

  const RoadWaterConfig& config() const { return config_; }
  int cells() const { return n_; }
  // The window's lower-left cell, in cells of the world's grid (cell (i, j) spans
  // [i, i + 1) x [j, j + 1) times cell_m).
  glm::ivec2 origin() const { return origin_; }
  // Per cell of the window, rows along +y: ground height (m), water (m), whether paved.
  const std::vector<double>& ground() const { return ground_; }
  const std::vector<double>& water() const { return water_; }
  const std::vector<std::uint8_t>& paved() const { return paved_; }
  RoadState state_of(double water_m) const { return road_state(water_m, config_); }
  // The window as the renderer draws it.
  void image(RoadWaterImage& out) const;

 private:
  struct Record {
    double volume_m3 = 0.0;   // held in the texture (or a puddle's)
    double film_m3 = 0.0;     // standing as a film: it runs off while out of the window
    int cells_out = 0;        // of its cells, those outside the window with their water here
    double dry_time_s = 0.0;  // dry_time_s_ when it was last settled
    double time_s = 0.0;      // time_s_ then
  };
  using Key = std::pair<int, int>;

  void move_to(glm::ivec2 origin);
  // A cell entering the window: its water from its record, or, for a cell the window has not
  // seen, `fresh_m` (the rain that fell there before: as the window's cells have it).
  void fill_cell(int i, int j, glm::ivec2 world, double s_guess, double fresh_m);
  void leave_cell(int i, int j);  // a cell leaving it
  Key record_key(glm::ivec2 world) const;
  // Brings a record to now: its film runs off (film_runoff_s), then the rest evaporates.
  void settle(Record& r);
  int index(glm::dvec2 xy) const;  // -1 outside the window

  const RoadSurface& surface_;
  RoadWaterConfig config_;
  int n_ = 0;
  int record_cells_ = 8;  // per side
  bool placed_ = false;
  glm::ivec2 origin_{0};
  double time_s_ = 0.0;
  double dry_time_s_ = 0.0;  // time stepped without rain: the records evaporate by it
  std::vector<double> ground_, water_;
  std::vector<std::uint8_t> paved_;
  std::vector<double> outflow_, flow_x_, flow_y_;   // one step's flows (m^3), made once
  std::vector<double> spare_ground_, spare_water_;  // move_to's, made once
  std::vector<std::uint8_t> spare_paved_;
  std::map<Key, Record> records_;       // coarse, by record_m squares
  std::map<Key, Record> puddle_cells_;  // by cell: a puddle's water (cells_out unused)
  Ledger ledger_;
};

}  // namespace downpour::sim
