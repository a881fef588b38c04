#version 450
// Where the water pass may find water, for the optics' grids of samples (glass_water_mask.glsl).
#include "glass_water_mask.glsl"
