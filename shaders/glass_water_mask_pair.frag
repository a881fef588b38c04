#version 450
// Where the water pass may find water, for the pair of samples (glass_water_mask.glsl).
#define GLASS_PAIR
#include "glass_water_mask.glsl"
