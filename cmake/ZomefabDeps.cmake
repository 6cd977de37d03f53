# Debian ships libmaxflow and liblinear without CMake package files; wrap them as imported targets.
find_path(MAXFLOW_INCLUDE_DIR maxflow.h PATH_SUFFIXES maxflow-3.0)
find_library(MAXFLOW_LIBRARY maxflow)
if(MAXFLOW_INCLUDE_DIR AND MAXFLOW_LIBRARY AND NOT TARGET maxflow::maxflow)
  add_library(maxflow::maxflow UNKNOWN IMPORTED)
  set_target_properties(maxflow::maxflow PROPERTIES IMPORTED_LOCATION ${MAXFLOW_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES ${MAXFLOW_INCLUDE_DIR})
endif()
find_path(LIBLINEAR_INCLUDE_DIR linear.h)
find_library(LIBLINEAR_LIBRARY linear)
if(LIBLINEAR_INCLUDE_DIR AND LIBLINEAR_LIBRARY AND NOT TARGET liblinear::liblinear)
  add_library(liblinear::liblinear UNKNOWN IMPORTED)
  set_target_properties(liblinear::liblinear PROPERTIES IMPORTED_LOCATION ${LIBLINEAR_LIBRARY}
    INTERFACE_INCLUDE_DIRECTORIES ${LIBLINEAR_INCLUDE_DIR})
endif()

