#pragma once
// The configs a test runs one by one (every .json in a folder, in name order),
// and each one's name as a gtest parameter.

#include <string>
#include <vector>

namespace optique::testing {

[[nodiscard]] std::vector<std::string> shipped_configs(const std::string& folder);
// "powerwall-2x2.json" → "powerwall_2x2".
[[nodiscard]] std::string config_test_name(const std::string& file);

}  // namespace optique::testing
