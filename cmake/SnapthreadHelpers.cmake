# snapthread_add_test(NAME SOURCES a.cc b.cc LIBS x y [LABELS l] [TIMEOUT s])
# One GoogleTest executable, registered with ctest through gtest_discover_tests.
function(snapthread_add_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest GTest::gtest_main snapthread::warnings)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests)
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  # An empty LABELS value would shift the PROPERTIES key/value pairs below (and lose
  # ENVIRONMENT), so every test gets a label.
  if(NOT ARG_LABELS)
    set(ARG_LABELS unit)
  endif()
  include(GoogleTest)
  gtest_discover_tests(${name}
    PROPERTIES TIMEOUT ${ARG_TIMEOUT} LABELS "${ARG_LABELS}"
               ENVIRONMENT "SNAPTHREAD_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
               # A second variable in ENVIRONMENT is lost (gtest_discover_tests splits the
               # list), so it goes through ENVIRONMENT_MODIFICATION.
               ENVIRONMENT_MODIFICATION "SNAPTHREAD_BIN_DIR=set:${PROJECT_BINARY_DIR}/bin"
    DISCOVERY_TIMEOUT 60)
endfunction()

# The one warnings target: strict warnings as errors on the project's own code only
# (third-party headers come in as SYSTEM includes and are not affected).
if(NOT TARGET snapthread_warnings)
  add_library(snapthread_warnings INTERFACE)
  add_library(snapthread::warnings ALIAS snapthread_warnings)
  target_compile_options(snapthread_warnings INTERFACE -Wall -Wextra -Wpedantic
                         $<$<BOOL:${SNAPTHREAD_WERROR}>:-Werror>)
endif()

# snapthread_project_code(TARGET): a library or program of this project (warnings, PIC).
function(snapthread_project_code target)
  target_link_libraries(${target} PRIVATE snapthread::warnings)
  get_target_property(_type ${target} TYPE)
  if(_type STREQUAL "STATIC_LIBRARY")
    set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  endif()
endfunction()

# snapthread_library(NAME SOURCES a.cc ... [PUBLIC libs...] [PRIVATE libs...]): a static
# library of this project, snapthread_NAME with the alias snapthread::NAME, whose folder
# is its public include directory, built with the project's warnings.
function(snapthread_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  add_library(snapthread_${name} STATIC ${ARG_SOURCES})
  add_library(snapthread::${name} ALIAS snapthread_${name})
  target_include_directories(snapthread_${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR})
  if(ARG_PUBLIC)
    target_link_libraries(snapthread_${name} PUBLIC ${ARG_PUBLIC})
  endif()
  if(ARG_PRIVATE)
    target_link_libraries(snapthread_${name} PRIVATE ${ARG_PRIVATE})
  endif()
  snapthread_project_code(snapthread_${name})
endfunction()
