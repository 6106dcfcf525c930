# snapthread_add_test(NAME SOURCES a.cc b.cc LIBS x y [LABELS l] [TIMEOUT s] [SERIAL])
# One GoogleTest executable, registered with ctest through gtest_discover_tests. SERIAL:
# its tests run alone (RUN_SERIAL), for a test that loads the machine or the loopback on
# purpose (a flood) and would otherwise make its neighbours lose datagrams.
function(snapthread_add_test name)
  cmake_parse_arguments(ARG "SERIAL" "TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
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
  set(_serial "")
  if(ARG_SERIAL)
    set(_serial RUN_SERIAL TRUE)
  endif()
  include(GoogleTest)
  gtest_discover_tests(${name}
    PROPERTIES TIMEOUT ${ARG_TIMEOUT} LABELS "${ARG_LABELS}" ${_serial}
               ENVIRONMENT "SNAPTHREAD_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
               # A second variable in ENVIRONMENT is lost (gtest_discover_tests splits the
               # list), so it goes through ENVIRONMENT_MODIFICATION.
               ENVIRONMENT_MODIFICATION "SNAPTHREAD_BIN_DIR=set:${PROJECT_BINARY_DIR}/bin"
    DISCOVERY_TIMEOUT 60)
endfunction()

# snapthread_add_process_test(NAME SOURCES a.cc ... [LIBS x y] [LABELS l] [TIMEOUT s] [SERIAL]
#                             PROGRAMS snapthread-server ...)
# A test that runs the project's programs as child processes (tests/support: ChildProcess,
# SessionKeyFile, the binaries' folder): snapthread_add_test with snapthread::test_support
# linked, label `process` and a 120 s timeout unless given, and each of PROGRAMS built
# before the test.
function(snapthread_add_process_test name)
  cmake_parse_arguments(ARG "SERIAL" "TIMEOUT" "SOURCES;LIBS;LABELS;PROGRAMS" ${ARGN})
  if(NOT ARG_LABELS)
    set(ARG_LABELS process)
  endif()
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 120)
  endif()
  set(_serial "")
  if(ARG_SERIAL)
    set(_serial SERIAL)
  endif()
  snapthread_add_test(${name} SOURCES ${ARG_SOURCES} LIBS ${ARG_LIBS} snapthread::test_support
                      LABELS ${ARG_LABELS} TIMEOUT ${ARG_TIMEOUT} ${_serial})
  if(ARG_PROGRAMS)
    add_dependencies(${name} ${ARG_PROGRAMS})
  endif()
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

# --- Build-time aids: precompiled headers and unity batches -----------------------------
# snapthread_build_aids(): called once at the end of the top-level CMakeLists.txt, when
# every target exists. Neither aid changes what is built; with the sanitizer build's -O1 -g1
# they halve its compile time (docs/testing.md has the figures).
#
# Unity batches (SNAPTHREAD_UNITY): each project target's sources are compiled
# kSnapthreadUnityBatch at a time as one file, so the Eigen and GoogleTest code they share
# is parsed, instantiated and optimized once per batch instead of once per source. Sources
# in one batch share their anonymous namespaces: two that define the same internal name
# (a kName, a helper) fail to compile together; such a source is listed in
# kSnapthreadUnityAlone and compiled on its own (or the name made distinct).
#
# Precompiled headers (SNAPTHREAD_PCH): each project target (not imported, not an interface) whose
# links reach Eigen, GoogleTest or spdlog, directly or through other targets, gets those
# headers precompiled:
#  - test programs (they link GoogleTest) share one precompiled header, built once by
#    snapthread_test_pch (GoogleTest + Eigen; an object library built like a test program,
#    since GCC reuses a precompiled header only under the same flags);
#  - a library or program with at least kSnapthreadPchMinSources sources gets its own
#    (libraries are -fPIC, programs not; too few sources would not repay the header's build).
# Precompiled headers only save parsing: each source still includes what it uses, and the
# tree builds the same with -DSNAPTHREAD_PCH=OFF.
set(kSnapthreadPchMinSources 3)
set(kSnapthreadUnityBatch 4)
# Sources (from the top of the tree) that share an internal name with another source of
# their target, so compiled alone.
set(kSnapthreadUnityAlone
  common/models/cusp_model.cc common/models/curve2d_model.cc common/models/thread3d_model.cc
  common/models/rod_model.cc
  common/topology/diagram.cc
  device_client/device_client_app.cc
  tests/rod_evaluate_test.cc tests/service/device_wrench_test.cc tests/auth/freshness_filter_test.cc)
set(kSnapthreadPchEigen <Eigen/Core> <Eigen/SparseCore>)
set(kSnapthreadPchGTest <gtest/gtest.h>)
set(kSnapthreadPchSpdlog <spdlog/spdlog.h>)

# _snapthread_targets_below(DIR OUT): the targets defined in DIR and its subdirectories.
function(_snapthread_targets_below dir out)
  get_property(_targets DIRECTORY ${dir} PROPERTY BUILDSYSTEM_TARGETS)
  get_property(_subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
  foreach(_sub IN LISTS _subdirs)
    _snapthread_targets_below(${_sub} _more)
    list(APPEND _targets ${_more})
  endforeach()
  set(${out} ${_targets} PARENT_SCOPE)
endfunction()

# _snapthread_link_closure(TARGET OUT): every target TARGET links, directly or not
# (aliases resolved, $<LINK_ONLY:...> unwrapped, plain library names and flags dropped).
function(_snapthread_link_closure target out)
  set(_seen "")
  set(_todo ${target})
  while(_todo)
    list(POP_FRONT _todo _t)
    string(REGEX REPLACE "^\\$<LINK_ONLY:(.*)>$" "\\1" _t "${_t}")
    if(NOT TARGET "${_t}")
      continue()
    endif()
    get_target_property(_aliased ${_t} ALIASED_TARGET)
    if(_aliased)
      set(_t ${_aliased})
    endif()
    if(_t IN_LIST _seen)
      continue()
    endif()
    list(APPEND _seen ${_t})
    get_target_property(_type ${_t} TYPE)
    get_target_property(_imported ${_t} IMPORTED)
    set(_links "")
    if(NOT _type STREQUAL "INTERFACE_LIBRARY" AND NOT _imported)
      get_target_property(_direct ${_t} LINK_LIBRARIES)
      if(_direct)
        list(APPEND _links ${_direct})
      endif()
    endif()
    get_target_property(_interface ${_t} INTERFACE_LINK_LIBRARIES)
    if(_interface)
      list(APPEND _links ${_interface})
    endif()
    list(APPEND _todo ${_links})
  endwhile()
  set(${out} ${_seen} PARENT_SCOPE)
endfunction()

function(snapthread_build_aids)
  _snapthread_targets_below(${PROJECT_SOURCE_DIR} _all)
  set(_test_pch_made OFF)
  foreach(_t IN LISTS _all)
    get_target_property(_type ${_t} TYPE)
    if(NOT _type MATCHES "^(STATIC_LIBRARY|SHARED_LIBRARY|OBJECT_LIBRARY|EXECUTABLE)$")
      continue()
    endif()
    get_target_property(_sources ${_t} SOURCES)
    list(FILTER _sources INCLUDE REGEX "\\.(cc|cpp)$")
    list(LENGTH _sources _n)
    if(_n EQUAL 0)
      continue()
    endif()
    if(SNAPTHREAD_UNITY AND _n GREATER 1)
      set_target_properties(${_t} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE ${kSnapthreadUnityBatch})
      get_target_property(_source_dir ${_t} SOURCE_DIR)
      foreach(_source IN LISTS _sources)
        get_filename_component(_path ${_source} ABSOLUTE BASE_DIR ${_source_dir})
        file(RELATIVE_PATH _relative ${PROJECT_SOURCE_DIR} ${_path})
        if(_relative IN_LIST kSnapthreadUnityAlone)
          set_source_files_properties(${_path} TARGET_DIRECTORY ${_t} PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
        endif()
      endforeach()
    endif()
    if(NOT SNAPTHREAD_PCH)
      continue()
    endif()
    _snapthread_link_closure(${_t} _closure)
    set(_headers "")
    if(Eigen3::Eigen IN_LIST _closure)
      list(APPEND _headers ${kSnapthreadPchEigen})
    endif()
    if(spdlog::spdlog IN_LIST _closure)
      list(APPEND _headers ${kSnapthreadPchSpdlog})
    endif()
    if(_type STREQUAL "EXECUTABLE" AND GTest::gtest IN_LIST _closure)
      # A test program: the shared header, with its Eigen include path (should GCC refuse
      # the precompiled header and read the text) and -pthread, which the tests that link
      # LCM (glib) have anyway: GCC refuses a header built with another _REENTRANT.
      if(NOT _test_pch_made)
        set(_holder ${PROJECT_BINARY_DIR}/snapthread_test_pch.cc)
        file(CONFIGURE OUTPUT ${_holder} CONTENT "// Builds the test programs' shared precompiled header.\n")
        add_library(snapthread_test_pch OBJECT ${_holder})
        target_link_libraries(snapthread_test_pch PRIVATE GTest::gtest GTest::gtest_main Eigen3::Eigen
                              snapthread::warnings)
        target_compile_options(snapthread_test_pch PRIVATE -pthread)
        target_precompile_headers(snapthread_test_pch PRIVATE ${kSnapthreadPchGTest} ${kSnapthreadPchEigen})
        set(_test_pch_made ON)
      endif()
      target_link_libraries(${_t} PRIVATE Eigen3::Eigen)
      target_compile_options(${_t} PRIVATE -pthread)
      target_link_options(${_t} PRIVATE -pthread)
      target_precompile_headers(${_t} REUSE_FROM snapthread_test_pch)
    elseif(_headers AND _n GREATER_EQUAL kSnapthreadPchMinSources)
      target_precompile_headers(${_t} PRIVATE ${_headers})
    endif()
  endforeach()
endfunction()

# _snapthread_targets_outside_tests(OUT): the targets defined outside tests/, but the
# build's own helper (the test programs' shared precompiled header).
function(_snapthread_targets_outside_tests out)
  _snapthread_targets_below(${PROJECT_SOURCE_DIR} _all)
  set(_kept "")
  foreach(_t IN LISTS _all)
    get_target_property(_dir ${_t} SOURCE_DIR)
    file(RELATIVE_PATH _relative ${PROJECT_SOURCE_DIR} ${_dir})
    if(NOT _relative MATCHES "^tests(/|$)" AND NOT _t STREQUAL "snapthread_test_pch")
      list(APPEND _kept ${_t})
    endif()
  endforeach()
  set(${out} ${_kept} PARENT_SCOPE)
endfunction()

# snapthread-programs: every program (an executable outside tests/ that `all` builds) and
# the Python module where it is built, what deploy/run.sh builds whether or not the build
# directory has the tests turned on. Also <build>/snapthread_targets.txt: every target
# outside tests/ (libraries, programs, generated files), one per line, for docs_test
# (docs/architecture.md names each) and exit_codes_test (the programs among them).
function(snapthread_programs_target)
  _snapthread_targets_outside_tests(_targets)
  set(_programs "")
  foreach(_t IN LISTS _targets)
    get_target_property(_type ${_t} TYPE)
    get_target_property(_excluded ${_t} EXCLUDE_FROM_ALL)
    if(_type MATCHES "^(EXECUTABLE|MODULE_LIBRARY)$" AND NOT _excluded)
      list(APPEND _programs ${_t})
    endif()
  endforeach()
  add_custom_target(snapthread-programs)
  if(_programs)
    add_dependencies(snapthread-programs ${_programs})
  endif()
  list(JOIN _targets "\n" _names)
  file(WRITE ${PROJECT_BINARY_DIR}/snapthread_targets.txt "${_names}\n")
endfunction()
