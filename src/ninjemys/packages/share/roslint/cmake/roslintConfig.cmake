# roslint as ninjemys provides it: read by find_package(roslint) and catkin's COMPONENTS roslint.
# The same functions and targets as ROS 1's roslint: each linting call adds its command to the
# package's target roslint_<project>, which the workspace-wide target roslint depends on; nothing is
# linted during a normal build. The linters are ninjemys' (cpplint and pycodestyle with the ROS
# style rules), run by the Python that ran catkin_make.
if(roslint_CONFIG_INCLUDED)
  return()
endif()
set(roslint_CONFIG_INCLUDED TRUE)
set(roslint_FOUND_CATKIN_PROJECT TRUE)
set(roslint_INCLUDE_DIRS "")
set(roslint_LIBRARIES "")
set(roslint_LIBRARY_DIRS "")
set(roslint_EXPORTED_TARGETS "")
set(roslint_VERSION "0.12.0")
set(ROSLINT_PYTHON_EXECUTABLE "@NINJEMYS_PYTHON@")

macro(_roslint_targets)
  if(NOT TARGET roslint)
    add_custom_target(roslint)
  endif()
  if(NOT TARGET roslint_${PROJECT_NAME})
    add_custom_target(roslint_${PROJECT_NAME})
    add_dependencies(roslint roslint_${PROJECT_NAME})
  endif()
endmacro()

# roslint_custom(linter options file...): run a lint command of the user's on the files.
function(roslint_custom linter lintopts)
  if("${ARGN}" STREQUAL "")
    message(WARNING "roslint: no files provided for command")
    return()
  endif()
  _roslint_targets()
  add_custom_command(TARGET roslint_${PROJECT_NAME} POST_BUILD
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    COMMAND ${CATKIN_ENV} ${linter} ${lintopts} ${ARGN} VERBATIM)
endfunction()

# roslint_cpp([file...]): cpplint with the ROS C++ rules; no files means every .cpp/.h/.hpp of the package.
function(roslint_cpp)
  set(_files ${ARGN})
  if("${_files}" STREQUAL "")
    file(GLOB_RECURSE _files ${PROJECT_SOURCE_DIR}/*.cpp ${PROJECT_SOURCE_DIR}/*.h ${PROJECT_SOURCE_DIR}/*.hpp)
  endif()
  if(NOT DEFINED ROSLINT_CPP_CMD)
    set(ROSLINT_CPP_CMD ${ROSLINT_PYTHON_EXECUTABLE} -m ninjemys.tools.roslint cpplint)
  endif()
  roslint_custom("${ROSLINT_CPP_CMD}" "${ROSLINT_CPP_OPTS}" ${_files})
endfunction()

# roslint_python([file...]): pycodestyle (pep8) at 120 columns; no files means every .py of the package.
function(roslint_python)
  set(_files ${ARGN})
  if("${_files}" STREQUAL "")
    file(GLOB_RECURSE _files ${PROJECT_SOURCE_DIR}/*.py)
  endif()
  if(NOT DEFINED ROSLINT_PYTHON_CMD)
    set(ROSLINT_PYTHON_CMD ${ROSLINT_PYTHON_EXECUTABLE} -m ninjemys.tools.roslint pep8)
  endif()
  roslint_custom("${ROSLINT_PYTHON_CMD}" "${ROSLINT_PYTHON_OPTS}" ${_files})
endfunction()

# roslint_add_test(): the package's lint as a test of run_tests (a JUnit file roslint-<project>.xml).
function(roslint_add_test)
  if(NOT CATKIN_ENABLE_TESTING)
    return()
  endif()
  catkin_run_tests_target("roslint" "package" "roslint-${PROJECT_NAME}.xml"
    COMMAND "${ROSLINT_PYTHON_EXECUTABLE} -m ninjemys.tools.roslint junit ${CATKIN_TEST_RESULTS_DIR}/${PROJECT_NAME}/roslint-${PROJECT_NAME}.xml make roslint_${PROJECT_NAME}"
    WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR})
endfunction()
