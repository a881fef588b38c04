#version 450
// The water on the windshield as the view sees it (seed 000, section 1.5 step 5, traced): each
// sample of a pixel follows the eye's ray through the water. The glass's parallel faces shift the
// ray without turning it; it enters the water (Snell, n = 1.333) and meets the water's surface
// (glass_surface.glsl) where Newton steps along the ray find it; there Fresnel splits it. The
// part that leaves turns by Snell's law and looks up the world outside (the environment probe, at
// the mip level of the spread of rays it stands for, or the view's own image where the water
// barely bends it); the part reflected inside, and all of it past the critical angle (the dark
// rim), goes back down through the glass into the cabin, or, too oblique to leave the glass, is
// trapped in it. Drawn into the glass layer, premultiplied: the mean of the samples that meet
// water, and the share that do.
#include "glass_water.glsl"
