# cmake -DSRC=<python/afmkit> -DDST=<build/python/afmkit> -P python_link.cmake: symbolic links in DST to every
# entry of SRC (files and sub-packages), so the build tree holds the package next to the compiled _afmkit module.
file(MAKE_DIRECTORY ${DST})
file(GLOB _entries RELATIVE ${SRC} ${SRC}/*)
foreach(_e ${_entries})
  if(_e STREQUAL "__pycache__")
    continue()
  endif()
  if(NOT EXISTS ${DST}/${_e})
    file(CREATE_LINK ${SRC}/${_e} ${DST}/${_e} SYMBOLIC)
  endif()
endforeach()
