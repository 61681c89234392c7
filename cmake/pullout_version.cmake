# The version the programs print (--version): the project version, plus `git describe` of the
# source tree when it is a git checkout at configure time ("0.1.0 (git v0.1.0-3-gabc1234-dirty)";
# a clone without tags gives the commit hash). A source tarball, or a tree without git, prints the
# project version alone. Reconfigure to refresh the git part.
#
# Defines the INTERFACE target pullout_version: #include "pullout/version.hpp" (kVersion,
# kVersionString).
set(PULLOUT_GIT_DESCRIBE "")
find_package(Git QUIET)
if(GIT_FOUND)
  # Only this repository's own history: a tarball unpacked inside some other checkout must not
  # take that checkout's description.
  execute_process(COMMAND "${GIT_EXECUTABLE}" -C "${PROJECT_SOURCE_DIR}" rev-parse --show-toplevel
    OUTPUT_VARIABLE _pullout_git_top OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE _pullout_git_rc)
  if(_pullout_git_rc EQUAL 0)
    get_filename_component(_pullout_git_top "${_pullout_git_top}" REALPATH)
    get_filename_component(_pullout_src "${PROJECT_SOURCE_DIR}" REALPATH)
    if(_pullout_git_top STREQUAL _pullout_src)
      execute_process(COMMAND "${GIT_EXECUTABLE}" -C "${PROJECT_SOURCE_DIR}" describe --tags --always --dirty
        OUTPUT_VARIABLE PULLOUT_GIT_DESCRIBE OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET
        RESULT_VARIABLE _pullout_git_rc)
      if(NOT _pullout_git_rc EQUAL 0)
        set(PULLOUT_GIT_DESCRIBE "")
      endif()
    endif()
  endif()
endif()
if(PULLOUT_GIT_DESCRIBE)
  set(PULLOUT_VERSION_STRING "${PROJECT_VERSION} (git ${PULLOUT_GIT_DESCRIBE})")
else()
  set(PULLOUT_VERSION_STRING "${PROJECT_VERSION}")
endif()
message(STATUS "pullout version: ${PULLOUT_VERSION_STRING}")

configure_file(${CMAKE_CURRENT_LIST_DIR}/version.hpp.in ${PROJECT_BINARY_DIR}/generated/version/pullout/version.hpp
  @ONLY)
add_library(pullout_version INTERFACE)
target_include_directories(pullout_version INTERFACE ${PROJECT_BINARY_DIR}/generated/version)
