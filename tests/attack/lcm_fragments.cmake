# Malformed LCM datagrams against every receiving binary (issue 23 item 1): the patched
# liblcm (cmake/PatchedLcm.cmake, deploy/lcm/) must keep each one running and serving, and
# count each datagram it drops. snapthread-fragment-sender writes the raw datagrams itself
# (no liblcm), so it can send what liblcm's own publish never would.
add_executable(snapthread-fragment-sender ${CMAKE_CURRENT_LIST_DIR}/fragment_sender.cc)
snapthread_project_code(snapthread-fragment-sender)

# One test case; label viewer as well, since it starts snapthread-viewer on Xvfb (the
# sanitizer stage runs those without LeakSanitizer: deploy/test.sh). Serial: five
# binaries, Xvfb and the sender at once on two cores. It attacks snapthread-web too, so
# it needs SNAPTHREAD_BUILD_WEB.
if(SNAPTHREAD_BUILD_WEB)
  add_executable(lcm_fragments_test ${CMAKE_CURRENT_LIST_DIR}/lcm_fragments_test.cc)
  target_link_libraries(lcm_fragments_test PRIVATE snapthread::messages snapthread::lcmtypes
    snapthread::test_support PkgConfig::LCM GTest::gtest GTest::gtest_main snapthread::warnings)
  set_target_properties(lcm_fragments_test PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests)
  add_dependencies(lcm_fragments_test snapthread-fragment-sender snapthread-server snapthread-device
    snapthread-viewer snapthread-web snapthread-logger)
  add_test(NAME lcm_fragments_test COMMAND lcm_fragments_test)
  set_tests_properties(lcm_fragments_test PROPERTIES LABELS "attack;viewer" TIMEOUT 300 RUN_SERIAL TRUE
    ENVIRONMENT "SNAPTHREAD_SOURCE_DIR=${PROJECT_SOURCE_DIR};SNAPTHREAD_BIN_DIR=${PROJECT_BINARY_DIR}/bin")
endif()

# The handler list of the patched liblcm: unsubscribing during a dispatch, in one process
# over udpm on loopback and memq:// (lcm-proj/lcm#619; deploy/lcm/0002-handler-list-race.patch).
# Both tests fail by design in a -DSNAPTHREAD_SYSTEM_LCM=ON build (Debian's liblcm).
snapthread_add_test(lcm_handler_list_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/lcm_handler_list_test.cc
  LIBS PkgConfig::LCM
  LABELS service)
