#pragma once
// Internal to scene: TinyGLTF as this library builds it, included only through
// here so that every file sees the same options. Its implementation is compiled
// once (tinygltf.cpp), so that an edit of the loader does not compile it again.
// It uses nlohmann/json; it decodes no images itself (no stb_image: base colour
// images go to the caller's ImageDecoder) and reads no external image files.
// (Debian ships a shared library too, but building it in keeps the link line as
// it is.)

#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>
