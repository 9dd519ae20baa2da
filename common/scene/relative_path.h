#pragma once
// Files a scene references, kept inside the scene's own folder. A glTF's URIs
// (buffers, images) and the file names of a scene sent by the master (a node's
// cache) go through here, so that neither a file nor a peer can make optique read
// or write outside that folder: '..', absolute paths and URI schemes are refused
// by name.

#include <string>
#include <string_view>

#include "util/result.h"

namespace optique::scene {

// A relative path inside a folder, '/'-separated, without '.', '..' or empty
// segments ("textures/wood.png"), or an error saying why it is not one:
// empty, absolute, with a '..' segment, a NUL or a backslash, or not UTF-8.
[[nodiscard]] Result<std::string> checked_relative_path(std::string_view path);

// A glTF URI that is not a data: URI, percent-decoded and checked as above; also
// refused: a scheme ("http:", "file:"), a query or a fragment, a bad escape.
[[nodiscard]] Result<std::string> relative_file_of_uri(std::string_view uri);

// Whether `uri` is a data: URI (embedded bytes), which names no file.
[[nodiscard]] bool is_data_uri(std::string_view uri);

}  // namespace optique::scene
