// tinygltf's code, compiled here once (Debian ships it as a header; README.Debian allows either
// route). Built without its image decoders and its file system (tinygltf.hpp): the renderer reads
// no textures, and every file a model names goes through gltf_model.cpp's checks. Compiled with
// our own flags, so that the fuzzer and the sanitizers see into it.
#define TINYGLTF_IMPLEMENTATION
#include "server/model/tinygltf.hpp"
