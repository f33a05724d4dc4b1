# Finds p4est and its companion library sc (Debian libp4est-dev ships no
# pkg-config or CMake package files). Defines the imported target P4est::P4est
# (p4est + sc, include directories as SYSTEM so their headers raise no
# warnings in our -Wall -Wextra -Wpedantic build).
find_path(P4EST_INCLUDE_DIR NAMES p8est.h)
find_path(SC_INCLUDE_DIR NAMES sc.h)
find_library(P4EST_LIBRARY NAMES p4est)
find_library(SC_LIBRARY NAMES sc)

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(P4est
  REQUIRED_VARS P4EST_LIBRARY SC_LIBRARY P4EST_INCLUDE_DIR SC_INCLUDE_DIR)

if(P4est_FOUND AND NOT TARGET P4est::P4est)
  add_library(P4est::Sc UNKNOWN IMPORTED)
  set_target_properties(P4est::Sc PROPERTIES
    IMPORTED_LOCATION "${SC_LIBRARY}"
    INTERFACE_SYSTEM_INCLUDE_DIRECTORIES "${SC_INCLUDE_DIR}"
    INTERFACE_INCLUDE_DIRECTORIES "${SC_INCLUDE_DIR}")
  add_library(P4est::P4est UNKNOWN IMPORTED)
  set_target_properties(P4est::P4est PROPERTIES
    IMPORTED_LOCATION "${P4EST_LIBRARY}"
    INTERFACE_SYSTEM_INCLUDE_DIRECTORIES "${P4EST_INCLUDE_DIR}"
    INTERFACE_INCLUDE_DIRECTORIES "${P4EST_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES P4est::Sc)
endif()
mark_as_advanced(P4EST_INCLUDE_DIR SC_INCLUDE_DIR P4EST_LIBRARY SC_LIBRARY)
