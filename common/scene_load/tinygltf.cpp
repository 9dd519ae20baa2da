// TinyGLTF's implementation, compiled once (scene_load/tinygltf.h).
#define TINYGLTF_IMPLEMENTATION
#include "scene_load/tinygltf.h"
