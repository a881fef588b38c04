// The water on the road (seed 003's water model): rain fills the surface's texture, then stands and
// runs downhill by water level (ground + standing water) to the four neighbours, pools in ruts and
// bowls, and leaves the road at the paved edge; when the rain stops it evaporates. No GL.
//
// Cells are squares of the world's grid in level-of-detail rings around the car: level l has cells
// of cell_m * 2^l in a window of `cells` x `cells` of them, each window twice the last one's side
// and aligned to the next level's cells, so that every place belongs to the finest window that
// holds it (the rings: the finest window, then the part of each coarser one outside the finer).
// Water runs between the cells of a level and across a ring's border between a fine cell and its
// coarse neighbour. When the car moves, the windows move with it, coarse to fine: a place leaving a
// fine ring gives its water to the coarser cell that now holds it; a coarse cell entering a finer
// ring shares its water out to its finer cells, the texture first, then the standing water to the
// lowest of them, so puddles form again in the ruts and bowls as the car comes near. Water stays
// where it fell in the world: a coarsest cell leaving the last window keeps its water in a record,
// from which it is shared out again when the window comes back. Every cubic metre is accounted for
// (Ledger).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include <glm/vec2.hpp>

#include "server/sim/road_surface.hpp"
#include "server/sim/types.hpp"

namespace downpour::sim {

inline constexpr int kRoadWaterMaxLevels = 4;

// The rings' water as the renderer draws it: per level, per cell, rows along +y, the water on the
// surface as the cell's state sees it (RoadWater::sheet_m) and the part of all of it standing above
// the texture, both in mm (floats, 2 per cell). A cell inside a finer ring holds the mean of its
// finer cells, so that a lookup filtered across a ring's border blends what is there.
struct RoadWaterImage {
  int levels = 0;
  std::array<glm::ivec2, kRoadWaterMaxLevels> origins{};  // each window's lower-left cell in its
                                                          // level's grid (RoadWater::origin)
  double cell_m = 0.25;  // the finest level's; level l's is cell_m * 2^l
  int cells = 0;         // per side, every level
  double capacity_mm = 0.5;
  std::vector<float> water_standing_mm;  // [((level * cells + row) * cells + column) * 2 + k]
  float max_standing_mm = 0.0f;
  // Over the paved cells (by area): what the road beyond the last window is drawn with.
  float mean_water_mm = 0.0f;
  float mean_standing_mm = 0.0f;

  // Whether it holds its cells' water (a default one does not).
  bool complete() const {
    return cells > 0 && levels > 0 && levels <= kRoadWaterMaxLevels &&
           water_standing_mm.size() >= static_cast<std::size_t>(levels) * cells * cells * 2;
  }
  double level_cell_m(int level) const { return cell_m * static_cast<double>(1 << level); }
  // How far from the middle of the finest window (m, along x or y) `level`'s window reaches: its
  // half side, plus how far its middle lies from the finest's. No point that far out or further
  // lies in it. (The renderer finds a point's rings by it, without a loop over them:
  // road_surface.glsl's water_at.)
  double reach_m(int level) const;
  // Water and standing water (mm) at a world position: the finest level that holds it, else the
  // means. Requires complete().
  glm::vec2 at(glm::dvec2 xy) const;
};

struct RoadWaterConfig {
  // S0: a drop's wet spot is a centimetre or two; cells that small around a car would be millions,
  // so the finest cell is a quarter of a metre, finer than a rut (0.7 m wide) or a bowl.
  double cell_m = 0.25;
  // Every level's window side in cells (a multiple of 8, 64 or more): 16 m of 0.25 m cells, then
  // 32, 64 and 128 m of 0.5, 1 and 2 m cells. (From 64 a point that the finest window that may
  // hold it does not hold lies past the next one's fading band, which the renderer's lookup of the
  // rings takes for granted: RoadWaterImage::reach_m.)
  int cells = 64;
  int levels = 4;  // 1 to kRoadWaterMaxLevels
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
  // Out of the windows a film keeps running off the road: the time constant of what is left (a
  // film crosses a half-width of 8 m at about 0.1 m/s). A puddle's water stays.
  double film_runoff_s = 60.0;
  // The records kept out of the windows (one per coarsest cell of road that left them, about 100
  // bytes each): past this many, the farther half is let go (counted as drained: 2 m cells, 25 km
  // of a 16 m road).
  std::size_t max_records = 100000;
  // The water on every paved cell when the windows are first placed (m; booked as rain in): 0, a
  // dry road, by default; tools and tests start on a road that has been wet for a while.
  double initial_m = 0.0;
};

// The state of a cell holding water_m (all of it, m) under these thresholds.
RoadState road_state(double water_m, const RoadWaterConfig& config);

class RoadWater {
 public:
  RoadWater(const RoadSurface& surface, RoadWaterConfig config = {});

  // The rings' windows around `centre` (world, m): each level's lower-left cell in its grid, on a
  // multiple of 8 cells (on a cell of the next level's grid, so that a coarse cell is either
  // wholly in the finer window or wholly out of it).
  static std::array<glm::ivec2, kRoadWaterMaxLevels> ring_origins(glm::dvec2 centre, double cell_m,
                                                                  int cells, int levels);

  // Centres the windows on `centre` (world, m), then advances dt_s under rain_mm_h.
  void step(glm::dvec2 centre, double rain_mm_h, double dt_s);

  // At a world position, from the finest cell that holds it (0 out of the windows): all water on
  // the surface (m of depth), and the part standing above the texture (state_of gives the state).
  double water_m(glm::dvec2 xy) const;
  double standing_m(glm::dvec2 xy) const;
  // The cell that holds xy's water (an index of water()), -1 outside the windows.
  int cell_at(glm::dvec2 xy) const { return find(xy); }
  // Takes up to volume_m3 from the cell at xy (spray); returns what it took.
  double take(glm::dvec2 xy, double volume_m3);
  // Adds volume_m3 to the cell at xy (spray landing back); returns what it took (0 outside the
  // windows or off the paved road).
  double give(glm::dvec2 xy, double volume_m3);

  struct Ledger {
    // The rain on the windows' road and on the records', and the water of road the windows take in
    // without a record of it (never seen, or under a coarse cell whose centre lies off the road):
    // as much as the rings hold on average.
    double rain_in_m3 = 0.0;
    double drained_m3 = 0.0;     // off the paved edge (and records let go)
    double evaporated_m3 = 0.0;  // in the windows and in the records
    double thrown_m3 = 0.0;      // taken (spray)
    double returned_m3 = 0.0;    // given back (spray that landed)
  };
  const Ledger& ledger() const { return ledger_; }
  // Water held in the windows and in the records (m^3): rain in + returned = stored + drained +
  // evaporated + thrown.
  double stored_m3() const;

  const RoadWaterConfig& config() const { return config_; }
  int levels() const { return levels_; }
  int cells() const { return n_; }
  double cell_m(int level) const { return config_.cell_m * static_cast<double>(1 << level); }
  // A level's window's lower-left cell in that level's grid (cell (i, j) of level l spans
  // [i, i + 1) x [j, j + 1) times cell_m(l)).
  glm::ivec2 origin(int level) const { return origins_[level]; }
  // Per cell of every level, [(level * cells + j) * cells + i]: ground height (m), water (m; 0 in
  // a cell a finer ring holds), whether paved, whether the cell holds its place's water (it lies
  // in no finer window).
  const std::vector<double>& ground() const { return ground_; }
  const std::vector<double>& water() const { return water_; }
  const std::vector<std::uint8_t>& paved() const { return paved_; }
  const std::vector<std::uint8_t>& owned() const { return owned_; }
  std::size_t records() const { return records_.size(); }
  RoadState state_of(double water_m) const { return road_state(water_m, config_); }
  // A cell's water as its state sees it (m): a coarse cell's without what its hollows hold (its
  // ruts full, the rest of it under a film is not a puddle), and its state.
  double sheet_m(std::size_t c) const {
    return c < layer() ? water_[c] : water_[c] - held_m(water_[c], hollow_[c], true);
  }
  RoadState cell_state(std::size_t c) const { return state_of(sheet_m(c)); }
  // The rings as the renderer draws them.
  void image(RoadWaterImage& out) const;

 private:
  struct Record {
    double texture_m3 = 0.0;  // held in the texture
    double film_m3 = 0.0;     // standing as a film: it runs off while out of the windows
    double pooled_m3 = 0.0;   // standing in puddles: it stays
    double paved_m2 = 0.0;    // the paved area it came from (evaporation's)
    double dry_time_s = 0.0;  // dry_time_s_ when it was last settled
    double time_s = 0.0;      // time_s_ then
    double rain_m = 0.0;      // rain_m_ then
  };
  using Key = std::pair<int, int>;
  // Where the water of a place came from, for the cells that share it out when a window moves.
  struct Source {
    int level = -1;  // the old cell's level, or -1: a record (or the road the windows never saw)
    glm::ivec2 cell{0};
    bool operator<(const Source& o) const {
      return std::tie(level, cell.x, cell.y) < std::tie(o.level, o.cell.x, o.cell.y);
    }
  };

  std::size_t flat(int level, int i, int j) const {
    return (static_cast<std::size_t>(level) * n_ + j) * n_ + i;
  }
  bool inside(const std::array<glm::ivec2, kRoadWaterMaxLevels>& origins, int level,
              glm::ivec2 cell) const {
    const glm::ivec2 d = cell - origins[level];
    return d.x >= 0 && d.y >= 0 && d.x < n_ && d.y < n_;
  }
  // The cell levels_up levels coarser that holds a cell (in that level's grid).
  static glm::ivec2 coarser(glm::ivec2 cell, int levels_up) {
    return {cell.x >> levels_up, cell.y >> levels_up};  // (C++20: an arithmetic shift, floor)
  }
  void move_to(const std::array<glm::ivec2, kRoadWaterMaxLevels>& origins);
  // move_to's steps. The first placement: every window from the surface, the initial film.
  void place_first(const std::array<glm::ivec2, kRoadWaterMaxLevels>& origins);
  // Copies the levels whose windows (and the finer ones') stay; which levels moved.
  std::array<bool, kRoadWaterMaxLevels> keep_levels_that_stay();
  // The mean water (and film over the hollows) of the old windows' paved cells, by area (m): what
  // road the windows never saw holds, as the rain fell there as here.
  struct UnseenWater {
    double fresh_m = 0.0, film_m = 0.0;
  };
  UnseenWater unseen_water() const;
  // The moved levels' new cells: ground, paving and place from the old windows or the surface,
  // and which cells hold their place's water.
  void fill_new_cells(const std::array<bool, kRoadWaterMaxLevels>& moved);
  // The old windows' water that no new window holds, to the records.
  void record_water_left_behind(const std::array<bool, kRoadWaterMaxLevels>& moved);
  // Each new cell's water from where the old windows, the records or the rain held it.
  void hand_water_on(const std::array<bool, kRoadWaterMaxLevels>& moved, const UnseenWater& unseen);
  // A level's whole window from the surface.
  void sample_window(int level);
  // A cell's ground, whether paved and its place on the roads, from the surface (guess: a place
  // within a few metres).
  void sample(int level, glm::ivec2 cell, std::size_t c, const RoadPlace& guess);
  // How deep water stands at a point before it spills out of the relief's hollows (m).
  double held_at(const RoadPlace& place) const;
  // The old windows' water over a level's cell that a finer ring held (m^3).
  double old_volume(int level, glm::ivec2 cell) const;
  // Shares volume_m3 out to cells of the new windows: the texture first, evenly, then a film of up
  // to film_m evenly, then the hollows, deepest first, then the rest evenly.
  void share_out(std::span<const std::size_t> cells, double volume_m3, double film_m);
  // Of a cell's standing water, what stays where it is (m): in a coarse cell what its hollows
  // hold, in a finest cell all of a puddle's (the rest is film, which runs).
  double held_m(double water, double hollow, bool coarse) const {
    const double standing = std::max(water - config_.capacity_m, 0.0);
    return coarse                                  ? std::min(standing, hollow)
           : state_of(water) == RoadState::kPuddle ? standing
                                                   : 0.0;
  }
  // What a cell holds back from the flow over its texture (its hollows', if coarse).
  double storage(std::size_t c) const { return c < layer() ? 0.0 : hollow_[c]; }
  std::size_t layer() const { return static_cast<std::size_t>(n_) * n_; }
  void to_record(int level, glm::ivec2 cell, double water, double hollow, bool paved);
  // Brings a record to now: the rain since fills its texture, its film runs off (film_runoff_s),
  // then its water evaporates.
  void settle(Record& r);
  void trim_records(glm::dvec2 centre);
  int find(glm::dvec2 xy) const;  // the owned cell holding xy, -1 outside the windows
  double area(int level) const { return cell_m(level) * cell_m(level); }

  const RoadSurface& surface_;
  RoadWaterConfig config_;
  int n_ = 0;
  int levels_ = 1;
  bool placed_ = false;
  std::array<glm::ivec2, kRoadWaterMaxLevels> origins_{};
  double time_s_ = 0.0;
  double dry_time_s_ = 0.0;  // time stepped without rain: the records evaporate by it
  double rain_m_ = 0.0;      // the rain that has fallen (m): the records take theirs by it
  std::vector<double> ground_, water_;
  std::vector<std::uint8_t> paved_, owned_;
  std::vector<RoadPlace> places_;  // each cell's centre's place on the roads (the next's guess)
  // What the relief's hollows hold under a cell (m of depth, held_at): at a finest cell's centre;
  // in a coarse cell, the mean over it, which it holds back from the flow (its ground is the
  // section's: the water in its ruts and bowls does not run).
  std::vector<double> hollow_;
  std::vector<double> outflow_, flow_x_, flow_y_;  // one step's flows (m^3), made once
  struct Crossing {
    std::size_t fine = 0, coarse = 0;
    double volume = 0.0;  // from fine to coarse (signed)
  };
  std::vector<Crossing> crossings_;  // the edges across the rings' borders
  // move_to's, made once.
  std::vector<double> old_ground_, old_water_, old_hollow_;
  std::vector<RoadPlace> old_places_;
  std::vector<std::uint8_t> old_paved_, old_owned_;
  std::array<glm::ivec2, kRoadWaterMaxLevels> old_origins_{};
  // The new cells by the source of their water (sorted by source, then cell: each source's cells
  // in the order they were found), and one source's cells: kept, so that a move allocates nothing
  // once they have grown (a map of vectors made and freed its nodes on every move).
  std::vector<std::pair<Source, std::size_t>> shares_;
  std::vector<std::size_t> sharing_;
  std::map<Key, Record> records_;  // by coarsest cell
  Ledger ledger_;
};

}  // namespace downpour::sim
