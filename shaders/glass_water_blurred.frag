#version 450
// The water on the windshield where the lens blurs the glass (glass_water.glsl, GLASS_BLURRED).
#define GLASS_BLURRED
#include "glass_water.glsl"
