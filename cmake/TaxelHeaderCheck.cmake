# SPDX-License-Identifier: MIT
# taxel_add_header_check(<target> <include dir> <glob relative to it> <library>): an OBJECT library
# with one generated translation unit per matching header, each including it twice (so every
# header compiles on its own and has an include guard). Sources are named header_check/<id>.cpp
# after the header's path (e.g. taxel_io_png_hpp.cpp), for per-file exceptions.
function(taxel_add_header_check target include_dir pattern library)
  file(GLOB_RECURSE _headers CONFIGURE_DEPENDS RELATIVE "${include_dir}" "${include_dir}/${pattern}")
  set(_tus)
  foreach(header IN LISTS _headers)
    string(MAKE_C_IDENTIFIER "${header}" _id)
    set(_tu "${CMAKE_CURRENT_BINARY_DIR}/header_check/${_id}.cpp")
    file(CONFIGURE OUTPUT "${_tu}" CONTENT "#include <${header}>\n#include <${header}>\n")
    list(APPEND _tus "${_tu}")
  endforeach()
  add_library(${target} OBJECT ${_tus})
  target_link_libraries(${target} PRIVATE ${library} taxel_project_options)
  # Nothing here is instantiated, so optimising only costs time (about a fifth with GCC 12).
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE -O0)
  endif()
endfunction()
