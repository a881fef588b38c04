// The shape of a drop on the glass and the fall of a raindrop: the physics that the water model,
// the glass water map and the tests share. Masses in milligrams (= cubic millimetres of water).
#pragma once

namespace downpour::sim {

// Drops on the glass are spherical caps meeting it at this angle (clean automotive glass: 30 to
// 50 degrees; the renderer draws its lenses with the same angle).
constexpr double kContactAngleDeg = 40.0;

// Radius (mm) of the contact circle of a drop of this mass, a spherical cap at kContactAngleDeg.
double drop_radius_mm(double mass_mg);
double drop_mass_mg(double radius_mm);
// Its cross-section facing air that flows along the glass, mm^2.
double drop_frontal_area_mm2(double radius_mm);

// Terminal fall speed (m/s) of a raindrop of diameter d (mm), Atlas et al. 1973.
double terminal_speed_mps(double diameter_mm);

}  // namespace downpour::sim
