#pragma once
// Where the tests find the built `afmkit` program and the source tree. Every test source sees AFMKIT_CLI and
// AFMKIT_SOURCE_DIR as calls of these functions (CMakeLists.txt: a forced include of this header), defined in a
// file CMake writes into each build folder: so the test sources compile to the same objects in every build folder
// and clone, and ccache shares them (docs/development.md#build-and-ci).
namespace afmkit_test_paths {
const char* cli();         ///< the built program, <build>/bin/afmkit
const char* source_dir();  ///< the source tree
}  // namespace afmkit_test_paths
