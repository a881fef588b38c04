// tinygltf as this project builds it (tinygltf_impl.cpp): without its image decoders (images come
// to gltf_model.cpp as their bytes, external ones through its file checks) and its file
// system, so that the class's defaults agree between its code and its users.
#pragma once

#include <fstream>  // the header writes files with it even without its file system

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_FS
#include <tiny_gltf.h>
