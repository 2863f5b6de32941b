# The Python module `afmkit` (docs/python.md): the compiled part _afmkit (pybind11 from Debian's pybind11-dev) and
# the pure-Python package python/afmkit/ (figures, the report), assembled in build/python/afmkit so that
#   PYTHONPATH=build/python /usr/bin/python3 -c "import afmkit"
# works from the build tree. The interpreter is Debian's /usr/bin/python3 (its numpy, matplotlib, pytest), not
# whatever python3 comes first on PATH. Not built under the sanitizers (an instrumented extension needs the ASan
# runtime preloaded into the interpreter).
option(AFMKIT_BUILD_PYTHON "Build the Python module afmkit (pybind11)" ON)
if(AFMKIT_SANITIZE OR AFMKIT_BUILD_FUZZ)
  set(AFMKIT_BUILD_PYTHON OFF)
endif()
if(NOT DEFINED Python_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python_EXECUTABLE /usr/bin/python3)
endif()
if(NOT AFMKIT_BUILD_PYTHON)
  return()
endif()

set(PYBIND11_FINDPYTHON ON)
find_package(Python 3.9 COMPONENTS Interpreter Development.Module REQUIRED)
find_package(pybind11 2.6 CONFIG REQUIRED)
set(AFMKIT_PYTHON_INSTALL_DIR "lib/python3.${Python_VERSION_MINOR}/dist-packages" CACHE STRING
    "where `cmake --install` puts the Python package afmkit (relative to the prefix)")

file(GLOB _pysrc CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/python/src/*.cpp)
# NO_EXTRAS: no link-time optimisation (the bindings call the library, whose code is optimised already; LTO made
# the module's link the longest step of the main-job build) and no strip.
pybind11_add_module(afmkit_python MODULE NO_EXTRAS ${_pysrc})
afmkit_unity(afmkit_python)
set_target_properties(afmkit_python PROPERTIES OUTPUT_NAME _afmkit
  LIBRARY_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/python/afmkit)
target_link_libraries(afmkit_python PRIVATE afmkit_commands)
# `afmkit report` starts this interpreter on the package found next to the program
target_compile_definitions(afmkit_commands PRIVATE AFMKIT_PYTHON="${Python_EXECUTABLE}"
  AFMKIT_PYTHON_INSTALL_DIR="${AFMKIT_PYTHON_INSTALL_DIR}")

# The pure-Python files, linked (not copied) into build/python/afmkit at every build: edits show at once.
add_custom_target(afmkit_python_files ALL
  COMMAND ${CMAKE_COMMAND} -DSRC=${CMAKE_SOURCE_DIR}/python/afmkit -DDST=${CMAKE_BINARY_DIR}/python/afmkit
          -P ${CMAKE_SOURCE_DIR}/cmake/python_link.cmake
  COMMENT "linking the Python package into build/python/afmkit")
add_dependencies(afmkit_python afmkit_python_files)

install(TARGETS afmkit_python LIBRARY DESTINATION ${AFMKIT_PYTHON_INSTALL_DIR}/afmkit)
install(DIRECTORY ${CMAKE_SOURCE_DIR}/python/afmkit/ DESTINATION ${AFMKIT_PYTHON_INSTALL_DIR}/afmkit
  PATTERN __pycache__ EXCLUDE)

# pytest, one CTest test per tests/python/test_*.py (parallel under ctest -j), label python.
if(AFMKIT_BUILD_TESTS)
  file(GLOB _pytests CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/tests/python/test_*.py)
  foreach(_t ${_pytests})
    get_filename_component(_n ${_t} NAME_WE)
    add_test(NAME python_${_n}
      COMMAND ${Python_EXECUTABLE} -m pytest -q -p no:cacheprovider ${_t}
      WORKING_DIRECTORY ${CMAKE_BINARY_DIR})
    set_tests_properties(python_${_n} PROPERTIES LABELS python TIMEOUT 600
      ENVIRONMENT "PYTHONPATH=${CMAKE_BINARY_DIR}/python;PYTHONDONTWRITEBYTECODE=1;AFMKIT_CLI=$<TARGET_FILE:afmkit_cli>;AFMKIT_SOURCE_DIR=${CMAKE_SOURCE_DIR};AFMKIT_BUILD_DIR=${CMAKE_BINARY_DIR}")
  endforeach()
endif()
