# liblcm for every binary: LCM 1.3.1 from Debian's source with the project's patches
# (deploy/lcm/: datagram bounds checked without overflow, the handler-list race), built at
# configure time into <build>/lcm-prefix and imported as PkgConfig::LCM, the target name the
# rest of the build already uses. Debian's own liblcm1 crashes on two crafted UDP datagrams
# (docs/security.md), so it is used only when asked for with SNAPTHREAD_SYSTEM_LCM=ON.
#
# The copy follows the build's options: SNAPTHREAD_SANITIZE=ON gets an ASan+UBSan liblcm,
# SNAPTHREAD_FUZZ=ON a static one instrumented for libFuzzer (clang); otherwise -O2.
# It is rebuilt only when the tarball, a patch, the build script, the flavour or the compiler
# changes (a stamp file records them). Sets SNAPTHREAD_LCM_PREFIX (empty with the system's)
# and SNAPTHREAD_LCM_LOGGER (the lcm-logger to record sessions with in tests).
option(SNAPTHREAD_SYSTEM_LCM
  "Link Debian's unpatched liblcm (crashes on crafted fragments: only to compare)" OFF)

if(SNAPTHREAD_SYSTEM_LCM)
  message(WARNING "SNAPTHREAD_SYSTEM_LCM=ON: linking Debian's unpatched liblcm; "
    "a crafted datagram can crash every receiving binary")
  pkg_check_modules(LCM REQUIRED IMPORTED_TARGET lcm)
  set(SNAPTHREAD_LCM_PREFIX "")
  find_program(SNAPTHREAD_LCM_LOGGER lcm-logger REQUIRED)
  return()
endif()

if(SNAPTHREAD_FUZZ)
  set(_lcm_flavor fuzz)
elseif(SNAPTHREAD_SANITIZE)
  set(_lcm_flavor asan)
else()
  set(_lcm_flavor release)
endif()

if(DEFINED ENV{SNAPTHREAD_DEPS_DIR})
  set(_lcm_deps_default "$ENV{SNAPTHREAD_DEPS_DIR}")
else()
  set(_lcm_deps_default "${PROJECT_SOURCE_DIR}/.deps")
endif()
set(SNAPTHREAD_DEPS_DIR "${_lcm_deps_default}" CACHE PATH
  "Cache of downloaded third-party sources (never committed): LCM's tarball in lcm/")
set(_lcm_tarball "${SNAPTHREAD_DEPS_DIR}/lcm/lcm_1.3.1+repack1.orig.tar.gz")
set(_lcm_dir "${PROJECT_SOURCE_DIR}/deploy/lcm")

# The tarball: fetched (and its SHA-256 checked against Debian's .dsc) by deploy/lcm/fetch.sh,
# which deploy/setup.sh runs; run here too when a fresh tree has none yet.
if(NOT EXISTS "${_lcm_tarball}")
  message(STATUS "LCM source: fetching into ${SNAPTHREAD_DEPS_DIR}/lcm")
  execute_process(COMMAND "${_lcm_dir}/fetch.sh" "${SNAPTHREAD_DEPS_DIR}/lcm"
    RESULT_VARIABLE _lcm_rc)
  if(NOT _lcm_rc EQUAL 0 OR NOT EXISTS "${_lcm_tarball}")
    message(FATAL_ERROR "No LCM source tarball at ${_lcm_tarball}: run deploy/lcm/fetch.sh "
      "(needs root for a deb-src entry), or configure with -DSNAPTHREAD_SYSTEM_LCM=ON")
  endif()
endif()

set(SNAPTHREAD_LCM_PREFIX "${PROJECT_BINARY_DIR}/lcm-prefix")
set(_lcm_work "${PROJECT_BINARY_DIR}/lcm-build")
file(GLOB _lcm_patches "${_lcm_dir}/*.patch")
list(SORT _lcm_patches)
set(_lcm_inputs "flavor=${_lcm_flavor};cc=${CMAKE_C_COMPILER};cc_version=${CMAKE_C_COMPILER_VERSION}")
foreach(_f "${_lcm_tarball}" "${_lcm_dir}/build.sh" ${_lcm_patches})
  file(SHA256 "${_f}" _h)
  get_filename_component(_n "${_f}" NAME)
  list(APPEND _lcm_inputs "${_n}=${_h}")
endforeach()
string(SHA256 _lcm_key "${_lcm_inputs}")
set(_lcm_stamp "${SNAPTHREAD_LCM_PREFIX}/snapthread-lcm.stamp")
if(_lcm_flavor STREQUAL "fuzz")
  set(_lcm_library "${SNAPTHREAD_LCM_PREFIX}/lib/liblcm.a")
else()
  set(_lcm_library "${SNAPTHREAD_LCM_PREFIX}/lib/liblcm.so")
endif()

set(_lcm_have_key "")
if(EXISTS "${_lcm_stamp}" AND EXISTS "${_lcm_library}")
  file(READ "${_lcm_stamp}" _lcm_have_key)
  string(STRIP "${_lcm_have_key}" _lcm_have_key)
endif()
if(NOT _lcm_have_key STREQUAL _lcm_key)
  message(STATUS "LCM: building the patched ${_lcm_flavor} liblcm into ${SNAPTHREAD_LCM_PREFIX}")
  execute_process(
    COMMAND "${_lcm_dir}/build.sh" "${_lcm_tarball}" "${_lcm_work}" "${SNAPTHREAD_LCM_PREFIX}"
            "${_lcm_flavor}" "${CMAKE_C_COMPILER}"
    RESULT_VARIABLE _lcm_rc)
  if(NOT _lcm_rc EQUAL 0 OR NOT EXISTS "${_lcm_library}")
    message(FATAL_ERROR "Building the patched liblcm failed (deploy/lcm/build.sh, log in "
      "${_lcm_work}/build.log)")
  endif()
  file(WRITE "${_lcm_stamp}" "${_lcm_key}\n")
  file(REMOVE_RECURSE "${_lcm_work}")
endif()

# glib and gthread, as lcm.pc requires them.
pkg_check_modules(LCM_GLIB REQUIRED IMPORTED_TARGET glib-2.0 gthread-2.0)
find_package(Threads REQUIRED)
# Linked by full path: CMake puts lcm-prefix/lib into the build tree's RPATH, so the binaries
# in build/bin load this liblcm.so.1 and not the system's (same soname).
add_library(PkgConfig::LCM UNKNOWN IMPORTED)
set_target_properties(PkgConfig::LCM PROPERTIES
  IMPORTED_LOCATION "${_lcm_library}"
  INTERFACE_INCLUDE_DIRECTORIES "${SNAPTHREAD_LCM_PREFIX}/include"
  INTERFACE_LINK_LIBRARIES "PkgConfig::LCM_GLIB;Threads::Threads")
if(_lcm_flavor STREQUAL "fuzz")
  # The fuzz copy builds no tools (a fuzz build runs no process tests).
  find_program(SNAPTHREAD_LCM_LOGGER lcm-logger)
else()
  set(SNAPTHREAD_LCM_LOGGER "${SNAPTHREAD_LCM_PREFIX}/bin/lcm-logger")
endif()
message(STATUS "LCM: patched ${_lcm_flavor} liblcm ${_lcm_library}")
