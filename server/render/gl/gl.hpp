// The one place that includes the GL headers: OpenGL 4.5 core, functions from libOpenGL (glvnd),
// which dispatches to Mesa or to NVIDIA's driver, whichever EGL display the context came from.
#pragma once

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>
