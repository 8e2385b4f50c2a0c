// tinygltf's implementation, compiled once (its header expands it only here).
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
