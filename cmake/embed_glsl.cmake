# Writes OUTPUT, a header that holds each GLSL file of FILES (a ;-list) as a
# std::string_view named after the file: scene.vert.glsl → scene_vert. Run by
# optique_embed_glsl() at build time: editing a .glsl file rebuilds its users.
#   cmake -DOUTPUT=… -DNAMESPACE=… -DFILES=… -P embed_glsl.cmake
set(text "#pragma once\n// Generated from GLSL files by cmake/embed_glsl.cmake; edit those, not this.\n\n")
string(APPEND text "#include <string_view>\n\nnamespace ${NAMESPACE} {\n")
foreach(file IN LISTS FILES)
  get_filename_component(name "${file}" NAME)
  string(REGEX REPLACE "\\.glsl$" "" name "${name}")
  string(MAKE_C_IDENTIFIER "${name}" name)
  file(READ "${file}" source)
  string(FIND "${source}" ")glsl\"" clash)
  if(NOT clash EQUAL -1)
    message(FATAL_ERROR "${file} contains )glsl\", which ends the raw string it is embedded in")
  endif()
  string(APPEND text "\n// ${file}\ninline constexpr std::string_view ${name} = R\"glsl(${source})glsl\";\n")
endforeach()
string(APPEND text "\n}  // namespace ${NAMESPACE}\n")
# Only when it changed, so that its users do not rebuild for nothing.
set(old "")
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" old)
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUTPUT}" "${text}")
endif()
