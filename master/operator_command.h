#pragma once
// What the operator may ask of a run (from the status server's controls,
// master/status/operator_api.h): pause, resume, stop. The core carries it out
// (MasterProtocol::operator_command) without knowing HTTP.

#include <string_view>

namespace optique::master {

enum class OperatorCommand { pause, resume, stop };
[[nodiscard]] std::string_view to_string(OperatorCommand command);

}  // namespace optique::master
