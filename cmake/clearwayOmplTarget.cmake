# Defines ompl::ompl, the target OMPL 1.7 exports, after find_package(ompl) of an OMPL that has none.
# OMPL 1.5 (Debian bookworm) gives variables only, and its OMPL_LIBRARIES name Boost libraries that
# libompl-dev does not install; libompl alone links fine. Used by the build and by clearwayConfig.cmake,
# so that the exported clearway::ompl names ompl::ompl instead of this machine's paths. Leaves
# ompl::ompl undefined when libompl is not found.
if(NOT TARGET ompl::ompl)
  find_library(CLEARWAY_OMPL_LIBRARY NAMES ompl HINTS ${OMPL_LIBRARY_DIRS})
  if(CLEARWAY_OMPL_LIBRARY)
    add_library(ompl::ompl UNKNOWN IMPORTED)
    set_target_properties(ompl::ompl PROPERTIES IMPORTED_LOCATION "${CLEARWAY_OMPL_LIBRARY}"
      INTERFACE_INCLUDE_DIRECTORIES "${OMPL_INCLUDE_DIRS}")
  endif()
endif()
