// TinyGLTF's implementation, compiled once (scene/tinygltf.h).
#define TINYGLTF_IMPLEMENTATION
#include "scene/tinygltf.h"
