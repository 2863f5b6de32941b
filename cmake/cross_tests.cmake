# CTest tests of the freestanding filter core on ARM targets under QEMU (label `cross`), included from
# CMakeLists.txt inside if(AFMKIT_BUILD_TESTS):
#   cross_aarch64    scripts/cross.sh --target aarch64    (aarch64-linux-gnu-gcc, qemu-aarch64; float and double)
#   cross_cortex_m4  scripts/cross.sh --target cortex-m4  (arm-none-eabi-gcc, MPS2 AN386 under qemu-system-arm)
# Each exports C headers with the afmkit binary of this build (target afmkit_cli, part of `all`: build before ctest),
# cross-compiles tests/cross/cross_check.c with the core and checks the closed loop on the target against the host
# reference. A missing toolchain fails the test with the Debian package to install (scripts/bootstrap.sh).
# Scratch files: <build>/cross-test/<target>/ (removed on success, kept on failure).
#   ctest --test-dir build -L cross --output-on-failure
foreach(_cross_target aarch64 cortex-m4)
  string(REPLACE "-" "_" _cross_name "cross_${_cross_target}")
  add_test(NAME ${_cross_name}
    COMMAND ${CMAKE_SOURCE_DIR}/scripts/cross.sh --target ${_cross_target} --afmkit $<TARGET_FILE:afmkit_cli>
            --samples "1 10 50 1000" --work ${CMAKE_BINARY_DIR}/cross-test/${_cross_target})
  set_tests_properties(${_cross_name} PROPERTIES LABELS cross TIMEOUT 300)
endforeach()
