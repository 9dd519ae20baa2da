#include "config/problem.h"

namespace optique::config {

std::string describe_problems(const std::vector<Problem>& problems, const std::string& origin) {
  std::string message;
  for (const Problem& p : problems)
    message += (message.empty() ? "" : "\n") + origin + ": " + p.path + ": " + p.message;
  return message;
}

}  // namespace optique::config
