#pragma once
// A temporary folder for one test program's files, removed at the end; helpers to read / write raw bytes; and the
// parameter an InvalidParameter names.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "afmkit/core/error.hpp"

#include <unistd.h>

namespace scan_test {

struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& name)
      : path(std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void spit(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

/// The parameter named by the InvalidParameter that `make()` throws (checking that its message names it too), or
/// "(accepted)" when it throws nothing.
template <class F>
std::string rejected(F&& make) {
  try {
    make();
  } catch (const afmkit::InvalidParameter& e) {
    EXPECT_NE(std::string(e.what()).find(e.parameter()), std::string::npos) << e.what();
    return e.parameter();
  }
  return "(accepted)";
}

}  // namespace scan_test
