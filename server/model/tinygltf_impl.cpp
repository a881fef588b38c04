// tinygltf's code, compiled here once (Debian ships it as a header; README.Debian allows either
// route). Built without its image decoders and its file system (tinygltf.hpp): gltf_model.cpp
// decodes the textures itself, and every file a model names goes through its checks. Compiled with
// our own flags, so that the fuzzer and the sanitizers see into it.
#define TINYGLTF_IMPLEMENTATION
#include "server/model/tinygltf.hpp"
