#include "shipped_configs.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace optique::testing {

std::vector<std::string> shipped_configs(const std::string& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() == ".json") names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::string config_test_name(const std::string& file) {
  std::string name = std::filesystem::path(file).stem().string();
  for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return name;
}

}  // namespace optique::testing
