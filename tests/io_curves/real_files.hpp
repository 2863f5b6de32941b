#pragma once
// The real measured curves of four instruments (shared data beside the clone: see docs/curve-files.md#test-data);
// tests skip with a message when the folder is missing.
#include <filesystem>
#include <string>

namespace curves_test {

inline std::string real_file(const char* name) {
  return std::string(AFMKIT_SOURCE_DIR) + "/../shared/data/force-curves/" + name;
}

}  // namespace curves_test

#define CURVES_REAL_FILE(var, name)                                                                   \
  const std::string var = curves_test::real_file(name);                                               \
  if (!std::filesystem::exists(var)) GTEST_SKIP() << "shared test data missing: " << var << " (clone " \
                                                     "the shared data beside the repository)"
