#include "master/operator_command.h"

namespace optique::master {

std::string_view to_string(OperatorCommand command) {
  switch (command) {
    case OperatorCommand::pause:
      return "pause";
    case OperatorCommand::resume:
      return "resume";
    case OperatorCommand::stop:
      return "stop";
  }
  return "unknown";
}

}  // namespace optique::master
