# The shipped pencil profiles: data/pencils/*.toml are compiled into atelier_convert as string
# literals (a generated shipped_pencils.cc), so atelierd, atelier-convert and the tests have them
# without looking for files. Included from convert/CMakeLists.txt after add_library(atelier_convert).
# A .toml added or removed re-runs cmake (GLOB CONFIGURE_DEPENDS); one edited does too
# (CMAKE_CONFIGURE_DEPENDS); configure_file rewrites the .cc only when the text changed.
file(GLOB ATELIER_PENCIL_FILES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/data/pencils/*.toml)
list(SORT ATELIER_PENCIL_FILES)
set(ATELIER_PENCIL_ENTRIES "")
set(ATELIER_PENCIL_DELIMITER "atelier_pencil")  # raw string delimiter (at most 16 characters)
foreach(pencil_file IN LISTS ATELIER_PENCIL_FILES)
  get_filename_component(pencil_name "${pencil_file}" NAME_WE)
  file(READ "${pencil_file}" pencil_text)
  string(FIND "${pencil_text}" ")${ATELIER_PENCIL_DELIMITER}\"" clash)
  if(NOT clash EQUAL -1)
    message(FATAL_ERROR "${pencil_file} contains the raw string delimiter )${ATELIER_PENCIL_DELIMITER}\"")
  endif()
  string(APPEND ATELIER_PENCIL_ENTRIES
    "      {\"${pencil_name}\", R\"${ATELIER_PENCIL_DELIMITER}(${pencil_text})${ATELIER_PENCIL_DELIMITER}\"},\n")
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${pencil_file}")
endforeach()
configure_file(${CMAKE_CURRENT_LIST_DIR}/shipped_pencils.cc.in
  ${CMAKE_CURRENT_BINARY_DIR}/shipped_pencils.cc @ONLY)
target_sources(atelier_convert PRIVATE ${CMAKE_CURRENT_BINARY_DIR}/shipped_pencils.cc)
