// The built-in test track written as an OpenDRIVE file, by the project's own code: what a
// simulator that wants to drive on it loads (CARLA, esmini, SUMO through netconvert).
#pragma once

#include <string>

#include "server/sim/track.hpp"

namespace downpour::sim {

// OpenDRIVE 1.6 text: one road (id "1") that loops onto itself, its reference line the track's
// centreline (lines and arcs as the track's own pieces), its hills as cubic pieces every 10 m
// (within a micrometre of the track's cosine), two driving lanes each way with a shoulder (right
// lanes in the direction of s, right-hand traffic), the crown as lane heights, and the track's
// markings as road marks.
std::string track_to_opendrive(const Track& track);

}  // namespace downpour::sim
