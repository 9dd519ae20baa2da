#pragma once
// A config file's JSON held against the schema before Protobuf's parser reads it.
// That parser stops at the first problem and speaks its own language
// ("widht: Cannot find field.", "invalid value -640 for type TYPE_UINT32"); this
// lists every unknown field (with the nearest known name) and every value of the
// wrong kind or out of its type's range, each with its field path.

#include <google/protobuf/descriptor.h>

#include <nlohmann/json_fwd.hpp>
#include <vector>

#include "config/problem.h"

namespace optique::config {

[[nodiscard]] std::vector<Problem> schema_problems(const nlohmann::ordered_json& document,
                                                   const google::protobuf::Descriptor& type);

}  // namespace optique::config
