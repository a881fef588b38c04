#version 450
// The water on the windshield where the lens blurs the glass, two samples a layer pixel
// (glass_water.glsl, GLASS_BLURRED and GLASS_PAIR).
#define GLASS_BLURRED
#define GLASS_PAIR
#include "glass_water.glsl"
