# CTest script test `install_and_build_examples` (registered in CMakeLists.txt, label `install`):
#   1. `cmake --install` the build tree (already built) into a fresh prefix under <build>/install-test/<random>/;
#   2. checks the installed layout and compiles one file that includes every installed header against the
#      prefix only (a public header that includes a private src/ header or a missing file fails here);
#   3. configures, builds and runs every examples/<name>/ (a standalone project that does find_package(afmkit)
#      and builds the program <name>; C++ or C, as its project() says) against the prefix, and checks it exits
#      with 0 and prints a final "ok";
#   4. compiles and runs examples/delay_margin/delay_margin.cpp with `pkg-config --cflags --libs afmkit` only, and
#      examples/filter_c/filter_c.c (C99) with `pkg-config --cflags --libs afmkit_c` only (skipped with a message
#      when pkg-config is not installed);
#   5. imports the installed Python package (when built: -DPYTHON=<interpreter>) and runs the installed
#      `afmkit report` on one figure.
# The prefix is removed on success and kept (its path printed) on failure.
#
#   cmake -DSOURCE=<source dir> -DBINARY=<build dir> [-DCONFIG=Release] [-DCXX=<C++ compiler>] [-DCC=<C compiler>]
#         [-DGENERATOR=<gen>] [-DEXTRA_FLAGS=<compile and link flags, e.g. sanitizers>] [-DPYTHON=<python3>]
#         -P tests/install/install_and_build_examples.cmake
cmake_minimum_required(VERSION 3.20)

foreach(_v SOURCE BINARY)
  if(NOT DEFINED ${_v} OR "${${_v}}" STREQUAL "")
    message(FATAL_ERROR "install_and_build_examples: -D${_v}=<dir> is required")
  endif()
endforeach()
if(NOT CONFIG)
  set(CONFIG Release)
endif()
separate_arguments(_extra UNIX_COMMAND "${EXTRA_FLAGS}")

string(TIMESTAMP _stamp "%Y%m%d%H%M%S")
string(RANDOM LENGTH 6 ALPHABET abcdefghijklmnopqrstuvwxyz0123456789 _rand)
set(WORK "${BINARY}/install-test/${_stamp}-${_rand}")  # unique: concurrent runs do not collide
set(PREFIX "${WORK}/prefix")
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")

# Runs a command; stops the test with its output when it fails. The standard output goes to ${out_var}.
function(run what out_var)
  string(TIMESTAMP _t0 "%s")
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _err)
  string(TIMESTAMP _t1 "%s")
  math(EXPR _dt "${_t1} - ${_t0}")
  if(NOT _rc EQUAL 0)
    string(REPLACE ";" " " _cmd "${ARGN}")
    message(FATAL_ERROR "install_and_build_examples: ${what} failed (exit ${_rc}) after ${_dt} s\n"
                        "command: ${_cmd}\n--- stdout ---\n${_out}\n--- stderr ---\n${_err}\n${STALE_NOTE}"
                        "(files kept in ${WORK})")
  endif()
  message(STATUS "${what}: ok (${_dt} s)")
  set(${out_var} "${_out}" PARENT_SCOPE)
endfunction()

# Configures and builds the CMake project in `src` against the prefix, in ${WORK}/<name>. The compilers and flags
# are given for the languages its project() enables (CXX when it names none).
function(build_against_prefix name src)
  set(_args -S "${src}" -B "${WORK}/${name}" "-DCMAKE_PREFIX_PATH=${PREFIX}" "-DCMAKE_BUILD_TYPE=${CONFIG}"
            "-DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF")
  file(READ "${src}/CMakeLists.txt" _cml)
  set(_languages CXX)
  if(_cml MATCHES "project\\([^)]*LANGUAGES([^)]*)\\)")
    string(REGEX MATCHALL "[A-Z]+" _languages "${CMAKE_MATCH_1}")
  endif()
  if(GENERATOR)
    list(APPEND _args -G "${GENERATOR}")
  endif()
  if(CXX AND "CXX" IN_LIST _languages)
    list(APPEND _args "-DCMAKE_CXX_COMPILER=${CXX}")
  endif()
  if(CC AND "C" IN_LIST _languages)
    list(APPEND _args "-DCMAKE_C_COMPILER=${CC}")
  endif()
  if(EXTRA_FLAGS)
    foreach(_lang ${_languages})
      list(APPEND _args "-DCMAKE_${_lang}_FLAGS=${EXTRA_FLAGS}")
    endforeach()
    list(APPEND _args "-DCMAKE_EXE_LINKER_FLAGS=${EXTRA_FLAGS}")
  endif()
  run("configure ${name}" _out ${CMAKE_COMMAND} ${_args})
  # find_package must have found the fresh prefix, not another installed afmkit.
  file(STRINGS "${WORK}/${name}/CMakeCache.txt" _dir REGEX "^afmkit_DIR:")
  string(REGEX REPLACE "^afmkit_DIR:[A-Z]+=" "" _dir "${_dir}")
  file(REAL_PATH "${_dir}" _dir)
  file(REAL_PATH "${PREFIX}" _prefix)
  string(FIND "${_dir}" "${_prefix}/" _at)
  if(NOT _at EQUAL 0)
    message(FATAL_ERROR "install_and_build_examples: ${name} found afmkit in ${_dir}, not in ${_prefix}")
  endif()
  run("build ${name}" _out ${CMAKE_COMMAND} --build "${WORK}/${name}" --config "${CONFIG}")
endfunction()

# Runs a built example; it must exit with 0 and end its output with a line "ok".
function(run_example name exe)
  run("run ${name}" _out "${exe}")
  if(NOT _out MATCHES "(^|\n)ok\n?$")
    message(FATAL_ERROR "install_and_build_examples: ${name} did not end with \"ok\":\n${_out}")
  endif()
  message(STATUS "${name} output:\n${_out}")
endfunction()

# ---- 1. install ---------------------------------------------------------------------------------------------------
if(NOT EXISTS "${BINARY}/cmake_install.cmake")
  message(FATAL_ERROR "install_and_build_examples: ${BINARY} is not a configured afmkit build tree")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --install "${BINARY}" --prefix "${PREFIX}" --config "${CONFIG}"
                RESULT_VARIABLE _rc OUTPUT_VARIABLE _out ERROR_VARIABLE _err)
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "install_and_build_examples: cmake --install failed (exit ${_rc}); it installs what is already "
                      "built: build everything first (cmake --build ${BINARY}).\n${_out}\n${_err}")
endif()
message(STATUS "cmake --install: ok")

# A header edited after the libraries were built makes the examples disagree with them (crashes, link errors):
# every failure message below names the headers newer than the newest installed library.
file(GLOB_RECURSE _libs "${PREFIX}/*/libafmkit_*.a")
set(_newest_lib 0)
foreach(_f ${_libs})
  file(TIMESTAMP "${_f}" _t "%s")
  if(_t GREATER _newest_lib)
    set(_newest_lib ${_t})
  endif()
endforeach()
set(STALE_NOTE "")
file(GLOB_RECURSE _src_headers "${SOURCE}/include/afmkit/*.hpp" "${SOURCE}/include/afmkit/*.h")
foreach(_f ${_src_headers})
  file(TIMESTAMP "${_f}" _t "%s")
  if(_t GREATER _newest_lib)
    string(APPEND STALE_NOTE "  ${_f}\n")
  endif()
endforeach()
if(STALE_NOTE)
  set(STALE_NOTE "NOTE: headers changed after the libraries were built (cmake --build ${BINARY} first):\n${STALE_NOTE}")
endif()

# ---- 2. layout and every public header against the prefix alone ------------------------------------------------
file(GLOB_RECURSE _config "${PREFIX}/*/afmkitConfig.cmake")
file(GLOB_RECURSE _pc "${PREFIX}/*/pkgconfig/afmkit.pc")
foreach(_f "${PREFIX}/bin/afmkit" "${PREFIX}/include/afmkit/core/version.hpp" "${PREFIX}/include/afmkit/afmkit_c.h"
           "${_config}" "${_pc}")
  if(NOT EXISTS "${_f}" OR IS_DIRECTORY "${_f}")
    message(FATAL_ERROR "install_and_build_examples: not installed: ${_f} (files kept in ${WORK})")
  endif()
endforeach()
# The C API: its shared library and its own pkg-config file (no C++ dependencies), when it is built.
file(GLOB_RECURSE _libc "${PREFIX}/*/libafmkit_c.so" "${PREFIX}/*/libafmkit_c.dylib" "${PREFIX}/*/afmkit_c.dll")
set(_pc_c "")
if(_libc)
  get_filename_component(_pc_c "${_pc}" DIRECTORY)
  set(_pc_c "${_pc_c}/afmkit_c.pc")
  if(NOT EXISTS "${_pc_c}")
    message(FATAL_ERROR "install_and_build_examples: not installed: ${_pc_c} (files kept in ${WORK})")
  endif()
endif()
get_filename_component(_cmakedir "${_config}" DIRECTORY)
foreach(_f afmkitConfigVersion.cmake afmkitTargets.cmake)
  if(NOT EXISTS "${_cmakedir}/${_f}")
    message(FATAL_ERROR "install_and_build_examples: not installed: ${_cmakedir}/${_f}")
  endif()
endforeach()
run("installed afmkit --version" _out "${PREFIX}/bin/afmkit" --version)

file(GLOB_RECURSE _headers RELATIVE "${PREFIX}/include" "${PREFIX}/include/afmkit/*.hpp" "${PREFIX}/include/afmkit/*.h")
list(SORT _headers)
list(LENGTH _headers _nheaders)
set(_tu "// generated by tests/install/install_and_build_examples.cmake\n")
foreach(_h ${_headers})
  string(APPEND _tu "#include <${_h}>\n")
endforeach()
string(APPEND _tu "int main() { return afmkit::version[0] == '\\0'; }\n")
file(WRITE "${WORK}/headers_src/all_headers.cpp" "${_tu}")
file(WRITE "${WORK}/headers_src/CMakeLists.txt"
  "cmake_minimum_required(VERSION 3.20)\nproject(afmkit_all_headers LANGUAGES CXX)\n"
  "find_package(afmkit REQUIRED)\nadd_executable(all_headers all_headers.cpp)\n"
  "target_link_libraries(all_headers PRIVATE afmkit::afmkit)\n")
message(STATUS "compiling one file that includes all ${_nheaders} installed headers")
build_against_prefix(all_headers "${WORK}/headers_src")

# ---- 3. every example with find_package(afmkit) -----------------------------------------------------------------
file(GLOB _examples LIST_DIRECTORIES true "${SOURCE}/examples/*")
set(_count 0)
foreach(_dir ${_examples})
  if(NOT IS_DIRECTORY "${_dir}" OR NOT EXISTS "${_dir}/CMakeLists.txt")
    continue()
  endif()
  get_filename_component(_name "${_dir}" NAME)
  build_against_prefix("${_name}" "${_dir}")
  set(_exe "${WORK}/${_name}/${_name}")
  if(NOT EXISTS "${_exe}")
    set(_exe "${WORK}/${_name}/${CONFIG}/${_name}")  # multi-config generators
  endif()
  run_example("${_name}" "${_exe}")
  math(EXPR _count "${_count} + 1")
endforeach()
if(_count EQUAL 0)
  message(FATAL_ERROR "install_and_build_examples: no example found in ${SOURCE}/examples/")
endif()

# ---- 4. the pkg-config route -------------------------------------------------------------------------------------
find_program(PKG_CONFIG_EXECUTABLE NAMES pkg-config pkgconf)
if(NOT PKG_CONFIG_EXECUTABLE)
  message(STATUS "pkg-config not found: skipping the pkg-config build (apt-get install pkg-config)")
else()
  get_filename_component(_pcdir "${_pc}" DIRECTORY)
  set(ENV{PKG_CONFIG_PATH} "${_pcdir}")
  run("pkg-config --cflags --libs afmkit" _flags "${PKG_CONFIG_EXECUTABLE}" --cflags --libs afmkit)
  string(STRIP "${_flags}" _flags)
  message(STATUS "pkg-config flags: ${_flags}")
  separate_arguments(_flags UNIX_COMMAND "${_flags}")
  run("pkg-config --variable=includedir afmkit" _incdir "${PKG_CONFIG_EXECUTABLE}" --variable=includedir afmkit)
  string(STRIP "${_incdir}" _incdir)
  if(NOT EXISTS "${_incdir}/afmkit/core/version.hpp")
    message(FATAL_ERROR "install_and_build_examples: afmkit.pc includedir ${_incdir} is not the installed one")
  endif()
  set(_cxx "${CXX}")
  if(NOT _cxx)
    set(_cxx c++)
  endif()
  set(_exe "${WORK}/pkg_config_delay_margin")
  run("compile delay_margin with pkg-config flags" _out "${_cxx}" -std=c++20 -O2 ${_extra}
      "${SOURCE}/examples/delay_margin/delay_margin.cpp" -o "${_exe}" ${_flags})
  run_example("delay_margin (pkg-config)" "${_exe}")

  # The C API from C99 with its own .pc: the shared library is found at run time through an rpath to libdir.
  if(_pc_c)
    run("pkg-config --cflags --libs afmkit_c" _cflags "${PKG_CONFIG_EXECUTABLE}" --cflags --libs afmkit_c)
    string(STRIP "${_cflags}" _cflags)
    message(STATUS "pkg-config flags (C API): ${_cflags}")
    separate_arguments(_cflags UNIX_COMMAND "${_cflags}")
    run("pkg-config --variable=libdir afmkit_c" _libdir "${PKG_CONFIG_EXECUTABLE}" --variable=libdir afmkit_c)
    string(STRIP "${_libdir}" _libdir)
    set(_cc "${CC}")
    if(NOT _cc)
      set(_cc cc)
    endif()
    set(_exe "${WORK}/pkg_config_filter_c")
    run("compile filter_c (C99) with pkg-config flags" _out "${_cc}" -std=c99 -O2 ${_extra}
        "${SOURCE}/examples/filter_c/filter_c.c" -o "${_exe}" ${_cflags} -lm "-Wl,-rpath,${_libdir}")
    run_example("filter_c (pkg-config)" "${_exe}")
  endif()
endif()

# ---- 5. the Python package (when the build has it: -DPYTHON=<interpreter>) ------------------------------------------
file(GLOB _pkg LIST_DIRECTORIES true "${PREFIX}/lib/python3*/dist-packages/afmkit")
if(PYTHON AND NOT _pkg)
  message(FATAL_ERROR "install_and_build_examples: the Python package afmkit was not installed under ${PREFIX}/lib")
elseif(_pkg)
  get_filename_component(_site "${_pkg}" DIRECTORY)
  # (a script file: a semicolon in an argument would split it into a CMake list)
  file(WRITE "${WORK}/import_afmkit.py"
       "import afmkit\nr = afmkit.tapping.hb(points=50)\nassert len(r) > 0\nprint(afmkit.__file__)\n")
  run("import the installed afmkit" _out ${CMAKE_COMMAND} -E env "PYTHONPATH=${_site}" PYTHONDONTWRITEBYTECODE=1
      "${PYTHON}" "${WORK}/import_afmkit.py")
  string(FIND "${_out}" "${_site}/afmkit/" _at)
  if(NOT _at EQUAL 0)
    message(FATAL_ERROR "install_and_build_examples: python imported afmkit from ${_out}, not from ${_site}")
  endif()
  # the installed program finds its installed package (no PYTHONPATH)
  run("installed afmkit report" _out "${PREFIX}/bin/afmkit" report --figures beyond-impact
      --output-dir "${WORK}/report")
  if(NOT EXISTS "${WORK}/report/index.html" OR NOT EXISTS "${WORK}/report/figures/beyond-impact.png")
    message(FATAL_ERROR "install_and_build_examples: the installed afmkit report wrote no page")
  endif()
endif()

file(REMOVE_RECURSE "${WORK}")
file(GLOB _left "${BINARY}/install-test/*")
if(NOT _left)
  file(REMOVE_RECURSE "${BINARY}/install-test")
endif()
message(STATUS "install_and_build_examples: all passed")
